"""The contact layer: gaps, multipliers and the KKT conditions.

Oriented contact surfaces, rigid planes and circles (:mod:`.surfaces`), the contact search
(:mod:`.search`), the contact discretization protocol and its registry (:mod:`.discretization`),
node-to-segment (:mod:`.nts`, any line cell of the table; the cells' curves :mod:`.curves`) and mortar
contact (:mod:`.mortar_method`, with the kernel in :mod:`.mortar`, :mod:`.mortar_segmentation`
and :mod:`.jets`; for every line cell the one kernel :mod:`.mortar_kernel` with
:mod:`.mortar_quadratic_segmentation`), mesh tying (:mod:`.tie`), the contact pair
(:mod:`.pair`, :class:`~.pair.ContactPair`), its evaluation record (:mod:`.contact_eval`), the active set
(:mod:`.active_set`) and the preflight checks (:mod:`.preflight`).
"""

__all__ = ["BUILTIN_METHODS", "DEFAULT_METHOD"]

#: the contact methods that come with the package (registered where they are
#: defined, :mod:`.nts` and :mod:`.mortar_method`, which :mod:`.methods` imports;
#: the scenes and the command line offer these); here,
#: so that the command line learns them without importing the contact code
BUILTIN_METHODS = ("nts", "mortar", "mortar-dual")

#: the method of a pair, a scene, ``run``, ``demo``, ``study``'s references and
#: ``bench`` when none is named: dual mortar passes the non-matching patch test
#: (NTS is 6 to 47 % off on it) and gives pressures without standard mortar's
#: alternating edge tail (docs/methods.rst)
DEFAULT_METHOD = "mortar-dual"
