"""The NTS nodal gap with its exact first and second derivatives, written once for
every cell of the table (:mod:`.cells`): lines of 2D bodies and cables, faces of 3D
bodies, in the cell's own coordinates.

A slave node ``x_s`` projects on the master cell ``x(xi) = sum_a N_a(xi) x_a``
(``xi`` of the cell's reference dimension ``dim``, ``x`` of ``d = dim + 1``
coordinates) at ``xi`` (the kinds' projections, :mod:`.nts_projection`,
:mod:`.nts_faces`).  The gap is ::

    g = n(xi) . (x_s - x(xi)),   n = c / |c|,   T_j = dx/dxi_j,
    c_i = s_i det[T_j . e_{i+1}, ..., T_j . e_{i+dim}]_{j = 1..dim}   (indices mod d),
    s_i = (-1)^(i (d - i)),

the cofactor vector of the tangents: ``c = (t_y, -t_x)`` on a line (``n`` outward on
the right of its direction), ``c = T_1 x T_2`` on a face (outward for
counter-clockwise faces).  With ``q = [x_s, x_1, ..., x_k]`` (``d + d k`` unknowns),
``T_j . (x(xi) - x_s) = 0`` and ``x_s - x || n`` at the closest point, so ``dg/dxi
= 0`` there::

    dg/dq = G_q,   d2g/dq2 = G_qq + G_qxi xi_q + xi_q^T G_xiq + G_xixi xi_q xi_q^T,

and only the exact gradient of ``xi`` enters (implicit function theorem).  Both
come from jets (:func:`gap_jets`): ``xi`` as the converged value refined by one
Newton step in first-order jets, ::

    xi = xi_0 - A^-1 f,   f_j = T_j . r,   A_jl = T_j . T_l + dT_j/dxi_l . r,
    r = x(xi_0) - x_s

(Cramer's rule), whose gradient is exact since ``f(xi_0) = 0``; the gap composed
from it in second-order jets, with ``x`` and ``T_j`` at ``xi_0 + dxi`` by Taylor ::

    T_j = T_j0 + dT_jl dxi_l,   x = x_0 + (T_j0 + T_j) dxi_j / 2,

exact for every map whose third derivatives vanish (line2, line3, piecewise-linear
lines, tri3, quad4: the cells NTS accepts, :func:`~.curves.check_line`,
:func:`~.nts_faces.check_face`).

Closed forms replace the jets only where they are faster and cross-tested against
them (:data:`CLOSED_FORMS`: ``line2``, tests/test_nts_cells.py).  A node whose
projection ties between faces takes the mean of their gaps, ``G`` and ``H``
(:func:`gap_eval`, the rule of :mod:`.nts_faces`); every row is scattered by the one
routine, :func:`~.contact_eval.node_gap_eval`.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from .cells import CellType
from .contact_eval import ContactEval, node_gap_eval
from .jets import Jet

__all__ = ["gap_jets", "gap_rows", "gap_eval", "line2_gap", "CLOSED_FORMS", "CHUNK_NODES"]

#: slave nodes per block of the gap's jets, whose temporaries hold (nv, nv, block)
#: arrays (nv = 15 on quad4).  Measured peak (tracemalloc) of a whole 3D evaluate with
#: H: 177 MiB at 1e4 slave faces, 580 MiB at 4e4 (unchunked: 370 MiB at 1e4); the rest
#: grows with the candidate pairs of the projection
CHUNK_NODES = 4096


def _comb(JP: list, c: int, coef: np.ndarray):
    """``sum_a coef_a P_a[c]`` in node order (jets)."""
    acc = JP[0][c] * coef[0]
    for a in range(1, len(JP)):
        acc = acc + JP[a][c] * coef[a]
    return acc


def _taylor(cell: CellType, JP: list, xi0: np.ndarray, dxi: list) -> tuple[list, list, list]:
    """``x``, ``T_j`` and ``dT_j/dxi_l`` (lists over components of jets) at ``xi0 +
    dxi`` by Taylor from ``xi0`` (module docstring: exact where the map's third
    derivatives vanish)."""
    N, G, G2 = cell.shape(xi0), cell.dshape(xi0), cell.d2shape(xi0)
    dim, d = cell.dim, len(JP[0])
    x: list = []
    T: list = [[] for _ in range(dim)]
    dT: list = [[[] for _ in range(dim)] for _ in range(dim)]
    for c in range(d):
        t0 = [_comb(JP, c, G[:, j]) for j in range(dim)]
        tt = [[_comb(JP, c, G2[:, j, l]) for l in range(dim)] for j in range(dim)]
        xc = _comb(JP, c, N)
        for j in range(dim):
            td = t0[j]
            for l in range(dim):
                td = td + tt[j][l] * dxi[l]
                dT[j][l].append(tt[j][l])
            T[j].append(td)
            xc = xc + (t0[j] + td) * dxi[j] * 0.5
        x.append(xc)
    return x, T, dT


def _dot(a: list, b: list):
    acc = a[0] * b[0]
    for c in range(1, len(a)):
        acc = acc + a[c] * b[c]
    return acc


def _det(M: list):
    """The determinant of a square list of lists (jets or arrays), by Laplace along
    the first row."""
    if len(M) == 1:
        return M[0][0]
    acc = None
    for j in range(len(M)):
        term = M[0][j] * _det([row[:j] + row[j + 1:] for row in M[1:]])
        acc = term if acc is None else (acc - term if j % 2 else acc + term)
    return acc


def _normal(T: list, d: int):
    """The cofactor vector ``c`` of the tangents ``T`` (module docstring), d jets."""
    dim = len(T)
    out = []
    for i in range(d):
        cols = [(i + 1 + s) % d for s in range(dim)]
        ci = _det([[T[j][col] for col in cols] for j in range(dim)])
        out.append(-ci if (i * (d - i)) % 2 else ci)
    return out


def gap_jets(cell: CellType, xs: np.ndarray, P: np.ndarray, xi: np.ndarray, second: bool) -> Jet:
    """The gaps of the points ``xs (d, m)`` on the cells with nodes ``P (d, m, k)`` as
    a jet of ``q = [x_s, x_1, ..., x_k]``, ``xi (dim, m)`` the converged closest
    points (module docstring)."""
    d, k, dim = xs.shape[0], cell.n_nodes, cell.dim
    vals = [xs[c] for c in range(d)] + [P[c, :, a] for a in range(k) for c in range(d)]
    nv = len(vals)
    var = [Jet.variable(v, i, nv, second) for i, v in enumerate(vals)]
    js, JP = var[:d], [var[d + d * a: 2 * d + d * a] for a in range(k)]
    # one Newton step from the converged xi at first order: its gradient is exact, and
    # the Hessian of g needs no more of xi (dg/dxi = 0 at the closest point)
    JP1 = [[c.first() for c in p] for p in JP]
    zero = Jet.constant(np.zeros_like(xi[0]), nv, False)
    x, T, dT = _taylor(cell, JP1, xi, [zero] * dim)
    r = [x[c] - js[c].first() for c in range(d)]
    f = [_dot(T[j], r) for j in range(dim)]
    A = [[_dot(T[j], T[l]) + _dot(dT[j][l], r) for l in range(dim)] for j in range(dim)]
    det = _det(A)
    step = [_det([row[:j] + [f[i]] + row[j + 1:] for i, row in enumerate(A)]) / det
            for j in range(dim)]                                 # Cramer: A^-1 f
    dxi = [Jet(-s.v, -s.g, Jet.constant(s.v, nv, True).h if second else None) for s in step]
    x, T, _ = _taylor(cell, JP, xi, dxi)
    n = _normal(T, d)
    inv = _dot(n, n).sqrt().inv()
    return _dot([js[c] - x[c] for c in range(d)], n) * inv


def gap_rows(cell: CellType, xs: np.ndarray, xm: np.ndarray, k: np.ndarray, m: np.ndarray,
             xi: np.ndarray, second: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The gaps ``(n,)``, ``dg/dq (n, nv)`` and ``d2g/dq2 (nv, nv, n)`` (or None) of the
    rows ``(k, m, xi)``: slave node, master cell nodes ``(n, n_nodes)``, closest point
    ``(dim, n)``; :func:`gap_jets` in blocks of :data:`CHUNK_NODES` rows."""
    d = xs.shape[0]
    nv = d + d * cell.n_nodes
    gv, dg = np.zeros(k.size), np.zeros((k.size, nv))
    h = np.zeros((nv, nv, k.size)) if second else None
    for lo in range(0, k.size, CHUNK_NODES):     # the jets' memory bounded per chunk
        c = slice(lo, lo + CHUNK_NODES)
        gj = gap_jets(cell, xs[:, k[c]], xm[:, m[c]], xi[:, c], second)
        gv[c], dg[c] = gj.v, gj.g.T
        if second:
            h[:, :, c] = gj.hessian()
    return gv, dg, h


def line2_gap(xs: np.ndarray, xm: np.ndarray, k: np.ndarray, m: np.ndarray, pr: dict,
              second: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """:func:`gap_rows` on straight 2-node lines in closed form, from the projection
    ``pr`` (:func:`~.nts_projection.project`: ``n``, ``e`` the unit normal and tangent,
    ``xi`` in ``[0, 1]``, ``l`` the length, ``g``) at the nodes ``k``.  With ``q = [x,
    x_1, x_2]``::

        dg/dq = [n; -(1 - xi) n; -xi n],
        d2g/dq2 = (a c^T + c a^T) / l - (g / l^2) a a^T,
        a = [0; n; -n],   c = [e; -(1 - xi) e; -xi e]

    (from ``dn/dt = -e n^T / l`` and ``dxi/dq = c / l - (g / l^2) a``)."""
    n, e, xi, l, g = pr["n"], pr["e"], pr["xi"], pr["l"], pr["g"]
    nk, ek, xk = n[:, k].T, e[:, k].T, xi[k][:, None]  # (m, 2)
    dg = np.hstack([nk, -(1 - xk) * nk, -xk * nk])  # (m, 6)
    if not second:
        return g[k], dg, None
    a = np.hstack([np.zeros_like(nk), nk, -nk])
    c = np.hstack([ek, -(1 - xk) * ek, -xk * ek])
    lk, gk = l[k][:, None, None], g[k][:, None, None]
    ac = a[:, :, None] * c[:, None, :]
    h = (ac + ac.transpose(0, 2, 1)) / lk - gk / lk**2 * (a[:, :, None] * a[:, None, :])
    return g[k], dg, h.transpose(1, 2, 0)


#: closed forms of :func:`gap_rows` by cell name, each faster than the jets and
#: cross-tested against them (tests/test_nts_cells.py)
CLOSED_FORMS: dict[str, Callable] = {"line2": line2_gap}


def gap_eval(xs: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, cell: CellType, pr: dict,
             rows: tuple[np.ndarray, np.ndarray, np.ndarray], lam: np.ndarray | None,
             area: np.ndarray, info: dict) -> ContactEval:
    """The :class:`ContactEval` of the projection ``pr`` (``mask``, ``g``) with ``G`` and
    ``H = sum_k lam_k d2g_k/dx2``.

    ``rows = (k, e, xi)``: a row per (slave node, master cell) that carries the node's
    gap, its chosen cell first, then the cells tied with it (:mod:`.nts_faces`), with
    their closest points ``xi (dim, n)``.  A node's gap, ``G`` and ``H`` are the mean
    over its rows.  Local dof order: slave node ``k`` -> ``d k + c``; master node
    ``j`` -> ``d n_s + d j + c``.
    """
    k, e, xi = rows
    g = pr["g"]
    m = seg_m[e]
    second = lam is not None
    closed = CLOSED_FORMS.get(cell.name)
    if closed is not None:
        gv, dg, h = closed(xs, xm, k, m, pr, second)
    else:
        gv, dg, h = gap_rows(cell, xs, xm, k, m, xi, second)
    g = g.copy()
    if k.size > np.count_nonzero(pr["mask"]):   # the mean over a node's tied cells
        w = 1.0 / np.bincount(k, minlength=g.size)[k]
        dg *= w[:, None]
        if second:
            h *= w
        g[pr["mask"]] = 0.0
        np.add.at(g, k, gv * w)
    else:
        g[k] = gv
    return node_gap_eval(g, k, m, dg, h, lam, xm.shape[1], xs.shape[0], area, pr["mask"], info)
