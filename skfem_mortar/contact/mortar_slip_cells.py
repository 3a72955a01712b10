"""The mortar slip's integrand on the one kernel's integration cells, and the nodal tangents.

The configuration-dependent part of the weighted objective slip
(:func:`~skfem_mortar.contact.slip.mortar_slip`) is, at slave node ``A``::

    r_A = int Phi_A tau_A . (x_m(xi_m) - x_s(xi_s)) w dGamma
        = tau_A . (sum_C M_AC x_C - sum_B D_AB x_B),

``tau_A`` the nodal tangent of the slave node ``A``, a function of its averaged nodal
normal ``n_A`` alone (:func:`tangent_basis`; in 2D ``tau = (n_y, -n_x)``, the normal turned
by -90 degrees).  With ``Phi_A = sum_B C_AB N_B`` (``C = T`` standard, ``A~ T`` dual, ``T``
the crosspoint/boundary merge) this is ``r_A = sum_B C_AB f_AB``, summed over the
integration cells of the one mortar kernel (:mod:`~skfem_mortar.contact.mortar_kernel`)::

    f_AB = sum_k dG_k N_B(xi_s,k) tau(n_A) . (x_m(xi_m,k) - x_s(xi_s,k)),
    dG_k = w_k J_s(xi_s,k) measure(x_s(xi_s,k)),

a jet of the integration cell's local variables ``[x_s, x_m, n_s]``
(:mod:`~skfem_mortar.contact.integration_points`): ``tau_A`` is a function of the local
variable ``n_A``, so the kernel chains its first and second derivatives over the normal's
neighbourhood at assembly like the weighted gap's.  The row ``A`` enters through
``tau_A``, so :func:`slip_integrand` hands the kernel ``f[A][B]`` row by row
(``g_A = sum_B C_AB f[A][B]``), not one jet per ``B``.  :func:`slip_integrand` first
integrates the vector ``P_B = sum_k dG_k N_B (x_m - x_s)`` (``k_s d`` jets) and then dots
it with each ``tau_A`` (``f_AB = tau_A . P_B``, on the cells' values, not the points').

:func:`tangent_jets` gives the nodal tangents with their first and second derivatives over
each node's neighbourhood from the kernel's nodal normals
(:class:`~skfem_mortar.contact.normals.NodalNormals`) by the chain rule::

    dtau/dx = (dtau/dn) dn/dx,
    d2tau/dx2 = dn/dx^T (d2tau/dn2) dn/dx + sum_j (dtau/dn_j) d2n_j/dx2,

which the slip's history part ``tau_A . w_A`` needs (a nodal sum, not a cell integral).
Tangential quantities have ``d - 1`` components per node; only ``d = 2`` (one tangent) is
built: :func:`tangent_basis` refuses other normals.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from . import mortar_kernel
from .cells import CellType, cell_type
from .contact_eval import ContactEval
from .integration_points import IntegrationPoints, LocalVariables
from .jets import Jet
from .measures import PLANE, Measure
from .mortar_cells import combine, dot, shape_jets, slave_geometry
from .normals import NodalNormals
from .segmentation import line_cells

__all__ = ["tangent_basis", "slip_integrand", "tangent_jets", "tangential_evaluate"]


def tangent_basis(n: Sequence) -> list[list]:
    """The unit tangents of a unit normal ``n`` (``d`` components: jets or arrays).

    In 2D the one tangent ``tau = (n_y, -n_x)``, the normal turned by -90 degrees: for a
    slave facing a master it runs along the master's cells, against the slave chain.

    Returns
    -------
    list of ``d - 1`` tangents, each a list of ``d`` components.

    Raises
    ------
    ValueError
        Unless ``n`` has 2 components (tangential quantities of 3D contact, two per node,
        are not built).
    """
    if len(n) != 2:
        raise ValueError(f"n must have 2 components (a line's normal, one tangent); got "
                         f"{len(n)}: tangents of 3D contact are not built")
    return [[n[1], -n[0]]]


def slip_integrand(points: IntegrationPoints, local: LocalVariables,
                   cells: tuple[CellType, CellType], measure: Measure = PLANE) -> list:
    """The slip's integrand ``f[A][B]``, row ``A``'s tangent against ``N_B`` (module docstring).

    The integrand hook of :func:`~skfem_mortar.contact.mortar_kernel.evaluate`: jets
    ``(n,)`` of the local variables of ``n`` integration cells, ``k_s`` rows of ``k_s``::

        f[A][B] = sum_k dG_k N_B(xi_s,k) tau(n_A) . (x_m(xi_m,k) - x_s(xi_s,k))
    """
    cs, cm = cells
    N, xs, dG = slave_geometry(points, local, cs, measure)
    xm = combine(shape_jets(cm, points.xi_m), local.x_m, local.layout.d)
    diff = [q - p for p, q in zip(xs, xm)]
    P = [[(N[b] * dG * c).sum() for c in diff] for b in range(cs.n_nodes)]
    rows = []
    for a in range(cs.n_nodes):
        tau = tangent_basis(local.n_s[a])[0]
        rows.append([dot(tau, P[b]) for b in range(cs.n_nodes)])
    return rows


def tangent_jets(normals: NodalNormals, second: bool = True
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The first nodal tangent ``tau`` of every node and its derivatives (module docstring).

    Parameters
    ----------
    normals : NodalNormals
        With ``dn`` (and ``d2n`` for ``second``), e.g. ``info["normals"]`` of
        :func:`~skfem_mortar.contact.mortar_kernel.evaluate`.
    second : bool
        Also the second derivatives.

    Returns
    -------
    tau : ndarray (d, n_nodes)
    dtau : ndarray (d, n_nodes, K, d)
        ``dtau[i, A, j, c] = d tau_i(A) / d x_c(normals.nodes[A, j])``.
    d2tau : ndarray (d, n_nodes, K, d, K, d) or None
    """
    n = normals.n
    d, n_nodes = n.shape
    nj = [Jet.variable(n[i], i, d, second) for i in range(d)]
    t = tangent_basis(nj)[0]
    tau = np.stack([c.v for c in t])
    dt = np.stack([c.g for c in t])                                   # (d_i, d_j, n)
    dtau = np.einsum("ijn,jnkc->inkc", dt, normals.dn)
    d2tau = None
    if second:
        d2tau = np.einsum("ijn,jnkcle->inkcle", dt, normals.d2n)
        h = np.stack([c.hessian() for c in t])                        # (d_i, d_j, d_l, n)
        if np.any(h):
            d2tau = d2tau + np.einsum("ijln,jnkc,lnme->inkcme", h, normals.dn, normals.dn)
    return tau, dtau, d2tau


def tangential_evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                        lam: np.ndarray | None = None, tangent: bool = True,
                        cells: tuple | None = None, **kernel_options: Any) -> ContactEval:
    """The tangential offsets ``r_A``, ``G = dr/dx`` and ``H = sum_A lam_A d2r_A/dx2``, exact,
    by the one mortar kernel::

        r_A = tau_A . (sum_C M_AC x_C - sum_B D_AB x_B).

    :func:`~skfem_mortar.contact.mortar_kernel.evaluate` with :func:`slip_integrand`: the
    same integration cells, multiplier functions, mask, ``D`` and ``M`` as the weighted
    gap's (``kernel_options``: ``space``, ``n_gauss``, ``segmentation``, ``pairs``,
    ``margin``, ``crosspoints``, ``reach``, ``measure``, ``points``, ``mirror``); ``lam``
    the tangential multipliers; ``cells`` default: the lines of the connectivities'
    columns.

    Returns
    -------
    ContactEval
        ``g`` holds ``r_A``; ``info``: the current ``D``, ``M``, ``tangent`` (d, n_s) the
        values ``tau_A``, ``normals`` (the kernel's :class:`NodalNormals`) and
        ``segmentation``.
    """
    if cells is None:
        cells = line_cells(np.asarray(seg_s), np.asarray(seg_m))
    cells = tuple(cell_type(c) for c in cells)
    ev = mortar_kernel.evaluate(xs, seg_s, xm, seg_m, lam=lam, tangent=tangent, cells=cells,
                                integrand=slip_integrand, **kernel_options)
    ev.info["tangent"] = np.stack(tangent_basis(ev.info["normals"].n)[0])
    return ev
