"""Mortar contact in 2D and 3D: the weighted gap, the mask, the multiplier spaces' test.

A slave node A carries a multiplier ``lam_A`` with the shape function ``Phi_A``
(standard: ``Phi_A = N_A``; dual: biorthogonal to ``N_A``); the slave surface is
``x_s = sum_B N_B x_B`` and the master surface ``x_m = sum_C N_C x_C``.  The
contact work is ``sum_A lam_A g_A`` with the weighted gap::

    g_A = - sum_B n_AB . x_B + sum_C n_AC . x_C
        = int_Gc Phi_A(xi1) (x_m(xi2) - x_s(xi1)) . n(xi1) dGamma,

    n_AB = int_Gc Phi_A(xi1) N_B(xi1) n dGamma,   D_AB = int_Gc Phi_A(xi1) N_B(xi1) dGamma,
    n_AC = int_Gc Phi_A(xi1) N_C(xi2) n dGamma,   M_AC = int_Gc Phi_A(xi1) N_C(xi2) dGamma,

with ``n = n~ / |n~|``, ``n~ = sum_a N_a n_a`` the interpolated averaged nodal normal
of the slave surface (outward from the slave body), so ``g > 0`` is open.

Every pair of cells (line2, line3, registered line cells, tri3 and quad4 faces) is
evaluated, with the exact first and second derivatives of ``g``, by the one kernel
:func:`skfem_mortar.contact.mortar_kernel.evaluate`; this module holds what the kernel
and the method share: the mask tolerance :data:`MASK_TOL` and :func:`biorthogonal`,
which asks a multiplier space whether it builds ``Phi_A`` from each slave cell's
``D_e``, ``M_e``.

Segmentation policies
---------------------
``iteration`` (default): the kernel segments the current configuration at every call;
``g`` is piecewise smooth (C1 across a node crossing) and ``G``, ``H`` are its exact
derivatives.  ``step``: the segmentation is built once per load step attempt from its
start positions and frozen (``frozen=True``): the pair list, the end points of every
integration cell in the slave coordinates and so the dual coefficients are held, and
``G``, ``H`` are the exact derivatives of that frozen ``g``.

Known limits: the projectable part of a slave cell is taken as the hull of its
integration cells (a gap in the master surface inside one slave cell is bridged by
the dual coefficients); a slave cell facing two overlapping pieces of master surface
integrates both; a cell with all its nodes crosspoints gets no multiplier.
"""
from __future__ import annotations

from .multiplier_spaces import MultiplierSpace, make_space

__all__ = ["MASK_TOL", "biorthogonal"]

MASK_TOL = 1e-6
"""Slave nodes whose mortar support ``int N_A w dGamma`` is below this fraction of their
tributary weight are masked out and merged into their neighbours like crosspoints
(:func:`skfem_mortar.contact.mortar_kernel.evaluate`).  The support grows like the
square of the covered fraction of a cell when the sliver lies at its far end, so this
is a covered fraction of about 1e-3: there the row of ``G`` nearly vanishes and, with
dual multipliers, the coefficients on a sliver grow like the inverse square of the
covered fraction, so ``g_A`` is dominated by round-off (measured on line2: 7 % error
at a covered fraction of 1e-5, wrong sign at 1e-7).  Without the merge the sliver's
traction is lost (patch test error about 1.8 f^2 at a covered fraction f)."""


def biorthogonal(space: "MultiplierSpace | str" = "standard") -> bool:
    """Whether the multiplier space ``space`` builds ``Phi_A`` from each slave cell's
    ``D_e``, ``M_e``.

    ``space`` is a :class:`~skfem_mortar.contact.multiplier_spaces.MultiplierSpace` or
    a registered name.  A space with ``coefficients(D_e, M_e)`` (``A_e = D_e M_e^-1``,
    biorthogonal: ``int Phi_A N_B = delta_AB int N_A``) gets them on the projectable
    part of each cell, differentiated; any other traction space ``Phi_A = N_A``.

    Raises
    ------
    ValueError
        When ``space`` is not a registered name or its ``kind`` is not ``"traction"``.
    """
    s = space if isinstance(space, MultiplierSpace) else make_space(space)
    if s.kind != "traction":
        raise ValueError(f"space must be a traction multiplier space for the mortar kernels, "
                         f"got {s.name!r} (kind {s.kind!r})")
    return callable(getattr(s, "coefficients", None))
