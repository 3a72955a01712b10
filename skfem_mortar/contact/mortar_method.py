"""Mortar contact (:func:`skfem_mortar.contact.mortar_kernel.evaluate`) as a contact discretization.

:class:`Mortar` is the method behind ``ContactPair(method="mortar")`` (standard
multipliers ``Phi_A = N_A``) and ``method="mortar-dual"`` (biorthogonal ones):
every call, for every pair of cells (line2, line3, a registered cell, faces), goes to
the one kernel :mod:`skfem_mortar.contact.mortar_kernel` (the segmentation of the
cells, :func:`~skfem_mortar.contact.segmentation.segmentation_for`; the faces'
points, :mod:`~skfem_mortar.contact.mortar_faces`); this class holds what the kernel
is told from one call to the next (the segmentation policy and a frozen
segmentation, the search reach, the crosspoints, the reserved pattern).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import scipy.sparse as sp

from . import mortar_kernel
from .mortar import biorthogonal
from .active_set import normal_nodal_force
from .contact_eval import ContactEval
from .measures import PLANE, Measure
from .normals import mirror_of_axis
from . import nts  # noqa: F401 (registers "nts" first: the built-ins in BUILTIN_METHODS order)
from .discretization import (ContactDiscretization, Factory, OptionTable, check_options, covers,
                             pattern_matrix, register_method, reserved_keys)
from .mortar_quadratic_segmentation import candidate_pairs
from .segmentation import Segmentation, segmentation_for, surface_cell
from .search import cell_sizes, segment_pairs
from .mirror_faces import evaluate_mirrored
from .mortar_faces import FACE_OPTIONS, N_GAUSS_FACES, face_points, takes_faces
from .mortar_pattern import stencil_pattern
from .points3d import N_GAUSS, check_rule

#: master faces within this many of their own sizes of a symmetry plane get mirror
#: images (:mod:`.mirror_faces`): the images that can meet a slave face on the plane
#: are those of the master faces at the plane or next to them
MIRROR_BAND = 2.0

__all__ = ["Mortar", "RESERVE_LENGTHS"]

#: the reserved pattern (:meth:`Mortar.pattern`) holds the element pairs of the
#: search with its margin widened by this many element lengths (the larger of
#: the median slave and master lengths): the surfaces may slide that far
#: against each other before the search finds a new pair
RESERVE_LENGTHS = 1.0


def _same_options(a: dict, b: dict) -> bool:
    """Equal per-call kernel options (:meth:`Mortar._extra`): the same reach, the
    same frozen segmentation object, equal crosspoints."""
    if a.keys() != b.keys():
        return False
    for k, v in a.items():
        w = b[k]
        if isinstance(v, np.ndarray):
            if not np.array_equal(v, w):
                return False
        elif k == "segmentation":
            if v is not w:
                return False
        elif v != w:
            return False
    return True


@dataclass
class _LastEvaluation:
    """A kernel call kept by :meth:`Mortar.evaluate`: its inputs (copies) and result."""

    ev: ContactEval
    xs: np.ndarray
    xm: np.ndarray
    lam: np.ndarray | None  # the multipliers of ``H`` (None: no ``H``)
    tangent: bool
    extra: dict
    pinned: np.ndarray | None

    @staticmethod
    def of(ev: ContactEval, xs, xm, lam, tangent: bool, extra: dict,
           pinned: np.ndarray | None) -> "_LastEvaluation":
        for a in (ev.g, ev.area, ev.mask):
            a.flags.writeable = False  # shared by the answers: nobody may change them
        with_h = tangent and lam is not None
        return _LastEvaluation(ev, np.array(xs, dtype=float), np.array(xm, dtype=float),
                               np.array(lam, dtype=float) if with_h else None, bool(tangent),
                               dict(extra), None if pinned is None else pinned.copy())

    def answer(self, xs, xm, lam, tangent: bool, extra: dict,
               pinned: np.ndarray | None) -> ContactEval | None:
        """The kept result for this call, or None when it does not hold it: other
        positions or options, a tangent it did not compute, ``H`` for other
        multipliers.  ``G`` and ``H`` are left out where the call does not ask
        for them (as the kernel leaves them out)."""
        with_h = tangent and lam is not None
        if ((tangent and not self.tangent) or (with_h and self.lam is None)
                or not (np.array_equal(xs, self.xs) and np.array_equal(xm, self.xm))
                or (with_h and not np.array_equal(lam, self.lam))
                or (pinned is None) != (self.pinned is None)
                or (pinned is not None and not np.array_equal(pinned, self.pinned))
                or not _same_options(extra, self.extra)):
            return None
        ev = self.ev
        return replace(ev, G=ev.G if tangent else None, H=ev.H if with_h else None,
                       info=ev.info.copy())


class Mortar(ContactDiscretization):
    """Mortar weighted gaps with standard or dual multipliers (the method's space).

    Parameters
    ----------
    slave, master : ContactSurface
    multiplier_space : str
        The registered multiplier space (:mod:`~skfem_mortar.contact.multiplier_spaces`):
        ``"standard"`` (``Phi_A = N_A``, method ``"mortar"``) or ``"dual"``
        (biorthogonal, ``"mortar-dual"``); the kernel asks it
        :func:`~skfem_mortar.contact.mortar.biorthogonal`.
    pair_name : str
        The pair's name (in messages).
    segmentation : {"iteration", "step"}
        Rebuild the mortar segments at every evaluation (default, exact), or
        once per load step attempt from its start positions, frozen during the
        step (see :func:`skfem_mortar.contact.mortar_kernel.evaluate`).
    **options
        ``margin`` (global search margin; default local, the two element
        lengths plus the reach) and ``n_gauss`` (Gauss points per mortar
        segment), passed to :func:`skfem_mortar.contact.mortar_kernel.evaluate`.

    The search reach: without a ``margin``, the local margin of the search
    grows by the motion of the contact nodes since the last converged state
    (:meth:`set_reference`), so a node that penetrates deeply within one step
    is still paired.  Pinned slave nodes (:meth:`set_pinned`) are crosspoints:
    their multiplier is merged into the neighbour's, so the multipliers still
    sum to one on their elements.

    The kernel's ``n_gauss`` default is one more than the cells' highest order (2 on
    line2, 3 on line3); the reserved pattern holds each cell's couplings (:meth:`pattern`).
    """

    multiplier_kind = "traction"
    multipliers_per_node = 1
    #: the names of :meth:`slip_history`'s arrays (a friction pair's checkpoint entries)
    slip_history_keys = tuple(f"{m}_prev_{p}" for m in "DM" for p in ("rows", "cols", "vals"))
    symmetric = True
    has_history = True  # the reserved pattern (all else is rebuilt at each step)

    OPTIONS: OptionTable = {
        "margin": (lambda v: v is None or (np.isfinite(v) and v > 0), "a finite number > 0"),
        "n_gauss": (lambda v: isinstance(v, (int, np.integer)) and 1 <= v <= 10,
                    "an integer in [1, 10]")}

    def __init__(self, slave: Any, master: Any, multiplier_space: str = "standard",
                 pair_name: str = "contact", segmentation: str = "iteration", **options: Any):
        biorthogonal(multiplier_space)        # a registered traction space (ValueError)
        self.method = ("mortar" if multiplier_space == "standard"
                       else f"mortar-{multiplier_space}")
        if segmentation not in ("iteration", "step"):
            raise ValueError(f"segmentation must be 'iteration' or 'step', got {segmentation!r}")
        self.slave, self.master, self.pair_name = slave, master, pair_name
        #: the multiplier space (:mod:`~.multiplier_spaces`, a registered name)
        self.multiplier_space = multiplier_space
        #: the two surfaces' cell types (:func:`~.segmentation.surface_cell`)
        self.cells = (surface_cell(slave), surface_cell(master))
        #: faces (tri3, quad4) segmented in 3D (:mod:`.mortar_faces`), else lines
        self.faces = takes_faces(self.cells, segmentation_for(self.cells), self.method, master,
                                 segmentation)
        check_options(self.method, options, FACE_OPTIONS if self.faces else self.OPTIONS)
        if self.faces:                 # the rule on quad4 faces that are no parallelograms
            check_rule(self.cells, options.get("n_gauss", N_GAUSS), ((slave.X, slave.segments),
                       (master.X, master.segments)), high=N_GAUSS_FACES)
        #: lines not both affine (:attr:`~.cells.CellType.affine`): the curved
        #: segmentation's search
        self.curved = not self.faces and not all(c.affine for c in self.cells)
        self._kernel = mortar_kernel.evaluate
        #: the segmentation of the cells (:func:`~.segmentation.segmentation_for`)
        self._segment = segmentation_for(self.cells)
        self.segmentation = segmentation
        self.options = dict(options)
        self._sg: Segmentation | None = None
        self._x0: tuple[np.ndarray, np.ndarray] | None = None
        self._pinned: np.ndarray | None = None
        #: (held pair keys, pattern) of :meth:`pattern`; reservations made
        self._reserved: tuple[np.ndarray, sp.csr_matrix] | None = None
        self.reservations = 0
        #: the last kernel call (:meth:`evaluate`)
        self._last: _LastEvaluation | None = None
        #: the weight of ``dGamma`` (:meth:`set_measure`; plane until told)
        self.measure: Measure = PLANE
        #: the symmetry planes (:meth:`set_symmetry`; none until told)
        self.planes: list = []

    def set_measure(self, measure: Measure) -> None:
        """The weight ``w(x)`` of ``dGamma`` in the model's geometry
        (:class:`~skfem_mortar.contact.discretization.MeasuredDiscretization`):
        every kernel call integrates in ``w(x_s) dGamma`` (``2 pi r`` axisymmetric), and
        slave nodes on the axis take the mirror (axial) normal
        (:func:`~skfem_mortar.contact.normals.mirror_of_axis`)."""
        if not isinstance(measure, Measure):
            raise ValueError(f"measure must be a Measure of contact.measures, got {measure!r}")
        self.measure = measure
        self._last = None

    def set_symmetry(self, planes: list) -> None:
        """The symmetry planes ``(unit normal, offset)`` of a quarter or half model
        (:class:`~skfem_mortar.contact.discretization.SymmetricDiscretization`): slave
        nodes on one take the mirror normal ``P s / |P s|`` in every kernel call (its
        ``mirror``)."""
        planes = [(np.asarray(n, dtype=float), float(c)) for n, c in planes]
        same = len(planes) == len(self.planes) and all(
            np.array_equal(n, m) and c == e for (n, c), (m, e) in zip(planes, self.planes))
        if not same:     # told before every step: the last evaluation stands if nothing moved
            self.planes, self._last = planes, None

    @property
    def _mirror(self) -> dict:
        """The segmentation's symmetry lines: the axis of an axisymmetric measure (its
        slave nodes take axial normals, as in the kernels); none in plane models."""
        mirror = mirror_of_axis(self.measure.axis)
        return {"mirror": mirror} if mirror else {}

    @property
    def _kernel_options(self) -> dict:
        """What every kernel call is told: the multiplier space, the options and
        (outside plane models) the measure."""
        mirror = {"mirror": self.planes} if self.planes else {}
        if self.measure.unit:
            return {"space": self.multiplier_space, **mirror, **self.options}
        return {"space": self.multiplier_space, "measure": self.measure, **mirror,
                **self.options}

    def set_pinned(self, pinned: np.ndarray | None) -> None:
        self._pinned = pinned

    def set_reference(self, xs0: np.ndarray | None, xm0: np.ndarray | None) -> None:
        self._x0 = None if xs0 is None else (xs0, xm0)

    def begin_step(self, xs: np.ndarray, xm: np.ndarray, first: bool) -> None:
        """Policy ``step``: segment the step's start positions, frozen."""
        if self.segmentation == "step":
            self._sg = None
            self._sg = self._segment(xs, self.slave.segments, xm, self.master.segments,
                                     self.cells, margin=self.options.get("margin"), frozen=True,
                                     **self._mirror)

    def _pairs(self, xs: np.ndarray, xm: np.ndarray, widen: float = 0.0) -> np.ndarray:
        """The candidate element pairs of the search :meth:`evaluate` runs at these
        positions (the frozen segmentation's pairs under policy ``step``), its
        margin widened by ``widen``, as sorted keys ``e_s * n_seg_m + e_m``."""
        seg_s, seg_m = self.slave.segments, self.master.segments
        if self._sg is not None and widen == 0.0:
            return np.unique(self._sg.e_s * len(seg_m) + self._sg.e_m)
        margin = self.options.get("margin")
        if self.curved:
            reach = (self.reach(xs, xm) if "margin" not in self.options and self._x0 is not None
                     else 0.0)
            i_s, i_m = candidate_pairs(xs, seg_s, xm, seg_m, margin, reach, widen)
        elif margin is not None:
            i_s, i_m = segment_pairs(xs, seg_s, xm, seg_m, margin + widen, cell_s=self.cells[0],
                                     cell_m=self.cells[1])
        else:
            reach = (self.reach(xs, xm) if "margin" not in self.options and self._x0 is not None
                     else 0.0)
            i_s, i_m = segment_pairs(xs, seg_s, xm, seg_m, reach + widen,
                                     cell_sizes(xs, seg_s, self.cells[0]),
                                     cell_sizes(xm, seg_m, self.cells[1]), *self.cells)
        return i_s * len(seg_m) + i_m

    def _searched(self, xs: np.ndarray, xm: np.ndarray) -> np.ndarray:
        """:meth:`_pairs` at these positions, read from the last evaluation when it
        searched at them (its segmentation keeps the candidates; the same search
        with the same margins), else searched again."""
        # (with mirror images the evaluation's candidates index the extended master)
        if self._sg is None and self._last is not None and not (self.faces and self.planes):
            extra, pinned = self._extra(xs, xm)
            ev = self._last.answer(xs, xm, None, False, extra, self._pinned if pinned else None)
            found = None if ev is None else getattr(ev.info["segmentation"], "candidates", None)
            if found is not None:
                return found[0] * len(self.master.segments) + found[1]
        return self._pairs(xs, xm)

    def _reserve(self, xs: np.ndarray, xm: np.ndarray, need: np.ndarray) -> None:
        """Reserve the pairs of the search widened by :data:`RESERVE_LENGTHS` element
        lengths and the current reach (and ``need``)."""
        seg_s, seg_m = self.slave.segments, self.master.segments
        h = max(float(np.median(cell_sizes(xs, seg_s, self.cells[0]))),
                float(np.median(cell_sizes(xm, seg_m, self.cells[1]))) if len(seg_m)
                else 0.0)
        # the search reach grows with the motion over the step: reserve it twice
        reach = self.reach(xs, xm) if self._x0 is not None else 0.0
        held = np.union1d(self._pairs(xs, xm, RESERVE_LENGTHS * h + reach), need)
        self._reserved = (held, self._pattern_of(held))
        self.reservations += 1

    def _pattern_of(self, held: np.ndarray) -> sp.csr_matrix:
        """Row ``A``: its own dofs, for each slave cell at ``A`` the nodes of its
        nodal-normal stencil (the cells sharing a node with it; line2: ``p, a, b, n``)
        and the nodes of its held master cells (:func:`~.mortar_pattern.stencil_pattern`).
        Every slave cell's own neighbourhood is held, held pair or not (local, cheap:
        the slave part never grows, so against a rigid master the pattern repeats from
        the first iteration on)."""
        n_seg_m = len(self.master.segments)
        return stencil_pattern(self.slave.segments, self.slave.n_nodes, self.master.segments,
                               self.master.n_nodes, held // max(n_seg_m, 1), held % max(n_seg_m, 1),
                               self.slave.X.shape[0])

    def pattern(self, xs: np.ndarray, xm: np.ndarray) -> sp.csr_matrix:
        """The reserved pattern (:class:`~skfem_mortar.contact.discretization.PatternedDiscretization`).

        The weighted gap ``g_A`` sums over the mortar segments of the slave
        elements at ``A``; a segment of the element ``(a, b)`` and the master
        element ``(m1, m2)`` depends on the slave nodes ``p, a, b, n`` (the nodal
        normals reach one node further) and on master nodes of the elements
        paired with ``(a, b)`` (``m1, m2`` and the nodes bounding the
        projectable part).  So row ``A`` holds, for each slave element at
        ``A``, its nodes ``p, a, b, n`` (every element, held pair or not: the
        slave part is local and never grows, so against a rigid master the
        pattern repeats from the first iteration on) and the nodes of its
        reserved master elements, besides ``A``'s own dofs.  Reserved:
        the pairs of the search with its margin widened by
        :data:`RESERVE_LENGTHS` element lengths and by the reach once more
        (the reach grows with the motion in the step); the same object is returned
        while the search's pairs (:meth:`evaluate`'s) lie in it, reserved anew
        only when they leave it.  The reservation carries over to the next step
        and into checkpoints (:meth:`state_dict`), so a resumed run reserves as
        the uninterrupted one.
        """
        need = self._searched(xs, xm)
        if self._reserved is None or not covers(self._reserved[0], need):
            self._reserve(xs, xm, need)
        return self._reserved[1]

    def reach(self, xs: np.ndarray, xm: np.ndarray) -> float:
        """Largest motion of a slave node plus that of a master node since the last
        converged state (times sqrt d, d the coordinates): a node open there can penetrate at most
        this deep, so the search adds it to its local margin (the element lengths)."""
        xs0, xm0 = self._x0
        ds = np.abs(xs - xs0).max(initial=0.0)
        dm = np.abs(xm - xm0).max(initial=0.0)
        return float(np.sqrt(float(xs.shape[0])) * (ds + dm))

    def _extra(self, xs: np.ndarray, xm: np.ndarray) -> tuple[dict, bool]:
        """The kernel's per-call options (frozen segmentation or reach,
        crosspoints) and whether nodes are pinned."""
        extra: dict = {}
        if self._sg is not None:
            extra["segmentation"] = self._sg
        elif "margin" not in self.options and self._x0 is not None:
            extra["reach"] = self.reach(xs, xm)
        pinned = self._pinned is not None and self._pinned.any()
        if pinned:
            extra["crosspoints"] = np.flatnonzero(self._pinned)
        return extra, pinned

    def _segmented(self, xs: np.ndarray, xm: np.ndarray, extra: dict) -> dict:
        """The kernel's options ``extra`` with the integration cells of the cells'
        segmentation (:func:`~.segmentation.segmentation_for`): the frozen ones of
        policy ``step``, else this configuration's (not frozen: the kernel
        differentiates their end points by origin)."""
        if "segmentation" in extra:
            return extra
        if self.faces:
            found = self._pairs(xs, xm)
            n_m = len(self.master.segments)
            return {**extra, "points": face_points(self.cells, self.options,
                                                   (found // n_m, found % n_m))}
        sg = self._segment(xs, self.slave.segments, xm, self.master.segments, self.cells,
                           margin=self.options.get("margin"), frozen=False,
                           reach=extra.get("reach", 0.0), **self._mirror)
        return {**extra, "segmentation": sg}

    def evaluate(self, xs: np.ndarray, xm: np.ndarray, lam: np.ndarray | None,
                 tangent: bool) -> ContactEval:
        """The kernel's :class:`ContactEval` at ``xs``, ``xm`` (``lam``: for ``H``).

        The last evaluation is kept: a call at the same positions, with the
        same per-call options (:meth:`_extra`: reach, frozen segmentation,
        crosspoints) and asking no more than it computed (no tangent, or a
        tangent without ``H``, or ``H`` for the same ``lam``) is answered from
        it, with ``G`` and ``H`` dropped where not asked for.  The kernel's
        values do not depend on what else it computes (``area`` and ``mask``
        are the same to the last bit with or without the tangent; ``g``, ``D``,
        ``M``, ``G`` too in one pass and one chunk, else to round-off:
        :func:`~.mortar_kernel.passes`), so the answer is the one a new call
        would give.  This
        is what a converged step asks repeatedly at its final state (the KKT
        check after the last assembly, the outputs after ``end_step``, which
        zeroes multipliers but moves no node) and at its start (preflight,
        initial active set).  The kept arrays are read-only.
        """
        extra, pinned = self._extra(xs, xm)
        pin = self._pinned if pinned else None
        hit = self._last.answer(xs, xm, lam, tangent, extra, pin) if self._last else None
        if hit is not None:
            return hit
        if self.faces and self.planes:   # the master with its mirror images (mirror_faces)
            band = MIRROR_BAND * cell_sizes(xm, self.master.segments, self.cells[1])
            ev = evaluate_mirrored(self._kernel, xs, self.slave.segments, xm,
                                   self.master.segments, self.planes, band, lam=lam,
                                   tangent=tangent, cells=self.cells,
                                   points=face_points(self.cells, self.options, None), **extra,
                                   **self._kernel_options)
        else:
            ev = self._kernel(xs, self.slave.segments, xm, self.master.segments, lam=lam,
                              tangent=tangent, cells=self.cells,
                              **self._segmented(xs, xm, extra), **self._kernel_options)
        if pinned:
            ev.mask = ev.mask & ~self._pinned
        self._last = _LastEvaluation.of(ev, xs, xm, lam, tangent, extra, pin)
        return self._last.answer(xs, xm, lam, tangent, extra, pin)

    # -- friction (FrictionDiscretization) ------------------------------------
    def slip_history(self, xs: np.ndarray, xm: np.ndarray, ev: ContactEval
                     ) -> dict[str, np.ndarray]:
        """The converged mortar integrals ``D`` and ``M`` of ``ev`` as COO
        triplets ``D_prev_rows``, ``D_prev_cols``, ``D_prev_vals`` (and ``M_prev_*``)."""
        out = {}
        for name in ("D", "M"):
            C = sp.coo_matrix(ev.info[name])
            C.sum_duplicates()
            out.update({f"{name}_prev_rows": C.row.astype(np.int64),
                        f"{name}_prev_cols": C.col.astype(np.int64),
                        f"{name}_prev_vals": C.data.astype(float)})
        return out

    def _prev(self, history: dict[str, np.ndarray]) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        ns, nm = self.slave.n_nodes, self.master.n_nodes
        return tuple(sp.csr_matrix((history[f"{k}_prev_vals"], (history[f"{k}_prev_rows"],
                                                               history[f"{k}_prev_cols"])),
                                   shape=(ns, n)) for k, n in (("D", ns), ("M", nm)))

    def check_slip_history(self, history: dict[str, np.ndarray]) -> None:
        ns, nm = self.slave.n_nodes, self.master.n_nodes
        for k, n in (("D", ns), ("M", nm)):
            r, c, v = (np.asarray(history[f"{k}_prev_{p}"]) for p in ("rows", "cols", "vals"))
            if not (r.ndim == c.ndim == v.ndim == 1 and r.size == c.size == v.size):
                raise ValueError(f"{self.pair_name}: checkpoint entries '{k}_prev_*' must be "
                                 "three 1-d arrays of one length")
            for what, a, hi in (("rows", r, ns), ("cols", c, n)):
                if a.size and (not np.issubdtype(a.dtype, np.integer) or a.min() < 0
                               or a.max() >= hi):
                    raise ValueError(f"{self.pair_name}: checkpoint entry '{k}_prev_{what}' "
                                     f"must be integers in [0, {hi})")
            if not np.all(np.isfinite(v)):
                raise ValueError(f"{self.pair_name}: checkpoint entry '{k}_prev_vals' is "
                                 "not finite")

    def slip(self, xs: np.ndarray, xm: np.ndarray, history: dict[str, np.ndarray],
             lam_t: np.ndarray | None, tangent: bool, ev: ContactEval):
        """:func:`~skfem_mortar.contact.slip.mortar_slip` from the converged ``D``,
        ``M`` with the options :meth:`evaluate` passes its kernel (the same
        segments, multiplier functions and mask)."""
        from .slip import mortar_slip
        extra, pinned = self._extra(xs, xm)
        D_prev, M_prev = self._prev(history)
        sl = mortar_slip(xs, self.slave.segments, xm, self.master.segments, D_prev, M_prev,
                         lam_t=lam_t, tangent=tangent, cells=self.cells,
                         **self._segmented(xs, xm, extra), **self._kernel_options)
        if pinned:
            sl.mask = sl.mask & ~self._pinned
        return sl

    def slip_pattern(self, history: dict[str, np.ndarray]) -> sp.csr_matrix:
        """Row ``A``: the dofs of the converged ``D`` and ``M`` rows of ``A`` (the
        previous partners ``w_A`` couples to)."""
        ns, nm = self.slave.n_nodes, self.master.n_nodes
        r = np.concatenate([history["D_prev_rows"], history["M_prev_rows"]])
        nodes = np.concatenate([history["D_prev_cols"], ns + history["M_prev_cols"]])
        d = self.slave.X.shape[0]
        return pattern_matrix(np.repeat(r, d), (d * nodes[:, None] + np.arange(d)).ravel(),
                              (ns, d * (ns + nm)))

    def state_dict(self) -> dict[str, np.ndarray]:
        """The reserved element pairs of :meth:`pattern` (``[]``: none yet)."""
        held = np.zeros(0, dtype=np.int64) if self._reserved is None else self._reserved[0]
        return {"reserved": held.copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        held = reserved_keys(self.pair_name, state["reserved"],
                             len(self.slave.segments) * len(self.master.segments))
        self._reserved = None if held is None else (held, self._pattern_of(held))

    def tail_signal(self, lam: np.ndarray, ev: Any) -> tuple[np.ndarray | None, bool]:
        """A biorthogonal space (:func:`~.mortar.biorthogonal`, dual): the
        multipliers; standard: the normal nodal forces (its multipliers alternate
        in sign at a too-wide edge)."""
        if biorthogonal(self.multiplier_space):
            return lam, False
        if ev.G is None:
            return None, True
        return normal_nodal_force(ev.G, lam, self.slave.n_nodes), True


# -- registered where they are defined (:mod:`.methods` imports this module)
def _mortar(space: str) -> Factory:
    def factory(slave: Any, master: Any, **options: Any) -> ContactDiscretization:
        return Mortar(slave, master, multiplier_space=space, **options)
    return factory


register_method("mortar", _mortar("standard"))
register_method("mortar-dual", _mortar("dual"))
