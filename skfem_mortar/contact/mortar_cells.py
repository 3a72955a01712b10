"""The mortar integrals written once, over integration cells of any dimension.

From the integration points of a segmentation (the contract of
:mod:`~skfem_mortar.contact.integration_points`) and the cell rows
(:class:`~skfem_mortar.contact.cells.CellType`) this kernel computes, per integration
cell, in jets of the cell's local variables ``[x_s, x_m, n_s]``::

    dG_k  = w_k J_s(xi_s,k) measure(x_s(xi_s,k)),
    D_AB  = sum_k dG_k Phi_A(xi_s,k) N_B(xi_s,k),
    M_AC  = sum_k dG_k Phi_A(xi_s,k) N_C(xi_m,k),
    g_A   = sum_k dG_k Phi_A(xi_s,k) n(xi_s,k) . (x_m(xi_m,k) - x_s(xi_s,k)),

with ``x_s = sum_a N_a x_a``, ``x_m = sum_c N_c x_c``, the slave tangents
``T_r = sum_a dN_a/dxi_r x_a``, ``J_s = sqrt(det(T^T T))`` (``|T|`` on lines,
``|T_1 x T_2|`` on surfaces), the interpolated nodal normal ``n~ = sum_a N_a n_a`` and
``n = n~ / |n~|`` (as the 2D kernels normalize it), and ``Phi_A = N_A`` (standard
multipliers).  Nothing here depends on ``d``.

Assembly (:func:`~skfem_mortar.contact.mortar_groups.assemble`) chains the nodal
normals' derivatives over the neighbouring nodes (:class:`~skfem_mortar.contact.normals.NodalNormals`) into the
local derivatives::

    G = G_loc J,    H = J^T H_loc J + sum_(a, i) (df/dn_ai) d2n_ai/dx2,

``J`` the derivative of the local variables w.r.t. the extended ones (the cell's slave
and master node coordinates and, for each slave node ``a``, its normal's
neighbourhood), and scatters them through :class:`~skfem_mortar.contact.scatter.Triplets`
in the pair's dof order (slave node ``A``: ``d A + c``; master node ``C``:
``d n_s + d C + c``).

Exactness: the shape functions are composed with the jets of ``xi`` through the
cell's first and second derivatives; the Hessian of ``J_s`` (which holds ``dN``) takes
the third derivatives of ``N`` as zero, true for every cell of the table (line2, line3,
tri3, quad4 and piecewise-linear cells inside a piece).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .cells import CellType
from .integration_points import IntegrationPoints, LocalVariables, check_points
from .jets import Jet
from .measures import PLANE, Measure

__all__ = ["compose", "shape_jets", "combine", "dot", "slave_geometry", "CellIntegrals",
           "cell_integrals"]


def compose(f0: np.ndarray, f1: np.ndarray, f2: np.ndarray | None, xi: tuple) -> Jet:
    """``f(xi)`` as a jet from its value, gradient and Hessian at ``xi``.

    ``f0 (S)``, ``f1 (m, S)`` and ``f2 (m, m, S)`` (None: zero) in the ``m`` coordinates,
    given the jets ``xi``, by the chain rule::

        g = sum_r f1_r g_r,   h = sum_(r, t) f2_rt g_r g_t^T + sum_r f1_r h_r.

    Exact to second order.
    """
    second = xi[0].h is not None
    if (not np.any(f1) and (f2 is None or not np.any(f2))) or all(x.is_constant() for x in xi):
        return Jet.constant(f0, xi[0].g.shape[0], second)   # (a line2's dN; constant xi)
    g = sum(f1[r][None] * x.g for r, x in enumerate(xi))
    h = None
    if second:
        h = sum(f1[r][None, None] * x.h for r, x in enumerate(xi))
        if f2 is not None and np.any(f2):   # f2 symmetric: each pair (r, t) once
            for r, xr in enumerate(xi):
                for t in range(r, len(xi)):
                    c = f2[r, t] + f2[t, r] if t != r else f2[r, r]
                    if np.any(c):
                        h = h + xr.g[:, None] * (xi[t].g * c[None])[None]
    return Jet(np.asarray(f0), g, h)


def shape_jets(cell: CellType, xi: tuple, derivatives: bool = False):
    """The shape functions at the jets ``xi`` (``cell.dim`` of them, values ``S``).

    Returns ``N``: a list of ``cell.n_nodes`` jets; with ``derivatives`` also ``dN``:
    ``dN[a][r]`` the jet of ``dN_a/dxi_r`` (its own derivatives from ``d2shape``, the
    third derivatives taken as zero, module docstring).
    """
    X = np.stack([x.v for x in xi])
    N0, N1 = cell.shape(X), cell.dshape(X)
    N2 = cell.d2shape(X)
    N = [compose(N0[a], N1[a], N2[a], xi) for a in range(cell.n_nodes)]
    if not derivatives:
        return N
    dN = [[compose(N1[a, r], N2[a, r], None, xi) for r in range(cell.dim)]
          for a in range(cell.n_nodes)]
    return N, dN


def dot(a: list, b: list):
    """``sum_i a_i b_i`` (jets)."""
    acc = a[0] * b[0]
    for p, q in zip(a[1:], b[1:]):
        acc = acc + p * q
    return acc


def combine(N: list, x: list, d: int) -> list:
    """``sum_a N_a x_a`` component by component (``x[a][i]`` jets of shape (n,))."""
    shape = N[0].v.shape
    xq = [[x[a][i].spread(shape) for i in range(d)] for a in range(len(N))]
    out = []
    for i in range(d):
        acc = N[0] * xq[0][i]
        for a in range(1, len(N)):
            acc = acc + N[a] * xq[a][i]
        out.append(acc)
    return out


def _jacobian(T: list):
    """``sqrt(det(T^T T))`` of the tangents ``T[r]`` (lists of d components)."""
    if len(T) == 1:
        return dot(T[0], T[0]).sqrt()
    a, b, c = dot(T[0], T[0]), dot(T[0], T[1]), dot(T[1], T[1])
    return (a * c - b * b).sqrt()


def slave_geometry(points: IntegrationPoints, local: LocalVariables, cell: CellType,
                   measure: Measure = PLANE) -> tuple[list, list, Jet]:
    """At the points: the slave shape functions ``N`` (list of jets), ``x_s`` (``d`` jets)
    and ``dG = w J_s(xi_s) measure(x_s)`` (module docstring), what every integrand of the
    kernel is weighted with (``sum_k dG_k N_A f_k`` is ``int N_A f dGamma``)."""
    d = local.layout.d
    N, dN = shape_jets(cell, points.xi_s, derivatives=True)
    xs = points.geometry[0] if points.geometry is not None else combine(N, local.x_s, d)
    T = [combine([dN[a][r] for a in range(cell.n_nodes)], local.x_s, d)
         for r in range(cell.dim)]
    dG = points.w * _jacobian(T)
    if not measure.unit:
        dG = dG * measure.weight(xs)
    return N, xs, dG


class CellIntegrals(NamedTuple):
    """Per integration cell, with ``Phi_A = N_A``: ``g[A]`` jets (n,) of the local
    variables, ``D (n, k_s, k_s)``, ``M (n, k_s, k_m)`` values, ``support (n, k_s)`` =
    ``sum_B D_AB``; with ``mass``: ``int N_A`` (``n_A``, list of jets) and
    ``int N_A N_B`` (``n_AB``, dict of jets, ``A <= B``), what a dual space's
    ``A_e = D_e M_e^-1`` is made of."""

    g: list
    D: np.ndarray
    M: np.ndarray
    support: np.ndarray
    n_A: list | None = None
    n_AB: dict | None = None


def cell_integrals(points: IntegrationPoints, local: LocalVariables,
                   cells: tuple[CellType, CellType], measure: Measure = PLANE,
                   mass: bool = False, integrand=None) -> CellIntegrals:
    """``D``, ``M`` and the weighted gap ``g_A`` of each integration cell (module docstring).

    Parameters
    ----------
    points : IntegrationPoints
        From the segmentation, jets of ``local``.
    local : LocalVariables
    cells : (CellType, CellType)
        Slave and master cell types.
    measure : Measure
        ``w(x)`` of ``dGamma`` (unit: no product).
    mass : bool
        Also the jets of ``int N_A`` and ``int N_A N_B`` (for a dual space), by the
        points' second rule if they carry one (``points.mass``).
    integrand : callable, optional
        ``integrand(points, local, cells, measure) -> list`` of ``k_s`` jets ``(n,)`` (one
        per slave node of the cell, summed over the cell's points) that replaces the
        weighted gap ``g_A``, or ``k_s`` lists of ``k_s`` jets ``f[A][B]`` (row ``A``'s
        integrand against ``N_B``, combined as ``g_A = sum_B C_AB f[A][B]``: the mortar
        slip's ``tau_A . (x_m - x_s)``); None: the weighted gap.
    """
    check_points(points, local)
    cs, cm = cells
    d = local.layout.d
    N, xs, dG = slave_geometry(points, local, cs, measure)
    Nm = shape_jets(cm, points.xi_m)
    if integrand is None:
        nt = (points.geometry[1] if points.geometry is not None else
              combine(N, local.n_s, d))
        xm = combine(Nm, local.x_m, d)
        gn = dot(nt, [q - p for p, q in zip(xs, xm)]) * dot(nt, nt).sqrt().inv()
        g = [(N[a] * gn * dG).sum() for a in range(cs.n_nodes)]
    else:
        g = list(integrand(points, local, cells, measure))
        if len(g) != cs.n_nodes:
            raise ValueError(f"integrand must return {cs.n_nodes} jets or rows of jets (one "
                             f"per slave node of a {cs.name} cell), got {len(g)}")
    Nv, Nmv, dGv = (np.stack([j.v for j in L]) for L in (N, Nm, [dG]))
    D = np.einsum("akq,bkq,kq->kab", Nv, Nv, dGv[0])
    M = np.einsum("akq,ckq,kq->kac", Nv, Nmv, dGv[0])
    n_A = n_AB = None
    if mass:
        k = cs.n_nodes
        if points.mass is not None:
            N, _, dG = slave_geometry(points._replace(xi_s=points.mass[0], w=points.mass[1],
                                                      geometry=None), local, cs, measure)
        wN = [N[a] * dG for a in range(k)]
        n_A = [x.sum() for x in wN]
        n_AB = {(a, b): (wN[a] * N[b]).sum() for a in range(k) for b in range(a, k)}
    return CellIntegrals(g, D, M, D.sum(axis=2), n_A, n_AB)
