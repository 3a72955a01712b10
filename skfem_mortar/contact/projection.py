"""Closest-point projection of points onto cells of any type, by Newton in the cell's
own coordinates, vectorized over point/cell pairs.

The closest point of ``p`` on the cell ``x(xi) = sum_b N_b(xi) X_b`` (its map extended
beyond the reference cell: :attr:`Projection.inside` says whether ``xi`` lies in it)
makes the residual

    g_j(xi) = T_j(xi) . (x(xi) - p) = 0,      T_j = dx/dxi_j,

vanish; Newton steps ``xi <- xi - H^-1 g`` with ``H_jk = T_j . T_k + (x - p) .
dT_j/dxi_k``, or its Gauss-Newton part ``T_j . T_k`` where ``H`` is not positive
definite (a point nearer than the centre of curvature keeps a descent direction).  On a
straight 2-node segment one step from anywhere is exact; the closed form
:func:`project_line2` gives the same ``xi = 2 (p - X_1).(X_2 - X_1) / |X_2 - X_1|^2 -
1`` without building the cell's arrays.

Derivatives at the solution (``g = 0``, implicit function theorem):

    dxi/dp = H^-1 T^T,     dxi_j/dX_{b c} = -(H^-1)_{jk} (dN_b/dxi_k r_c + T_{k c} N_b),

``r = x(xi) - p``.  Second derivatives are the kernels' (jets), not given here.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .cell_map import norms
from .cells import CellType, cell_type

__all__ = ["Projection", "project", "project_line2", "inside_reference"]


@dataclass
class Projection:
    """Closest points of ``m`` point/cell pairs.

    Attributes
    ----------
    xi : ndarray (dim, m)
        Reference coordinates of the closest points.
    x : ndarray (d, m)
        The closest points ``x(xi)``.
    distance : ndarray (m,)
        ``|p - x(xi)|``.
    converged : bool ndarray (m,)
        Newton's step fell below ``tol``.
    inside : bool ndarray (m,)
        ``xi`` lies in the reference cell (within ``tol``).
    dxi_dp : ndarray (dim, m, d) or None
        ``d xi / d p``.
    dxi_dX : ndarray (dim, m, n_nodes, d) or None
        ``d xi / d X_b`` of the cell's nodes.
    """

    xi: np.ndarray
    x: np.ndarray
    distance: np.ndarray
    converged: np.ndarray
    inside: np.ndarray
    dxi_dp: np.ndarray | None = None
    dxi_dX: np.ndarray | None = None


def inside_reference(cell: "str | CellType", xi: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """Whether the points ``xi (dim, m)`` lie in the reference cell, ``tol`` outside
    allowed: between a line's corners; inside a surface cell's corner polygon
    (counter-clockwise)."""
    cell = cell_type(cell)
    c = np.asarray(cell.ref_nodes, dtype=float)[:, list(cell.corners)]
    xi = np.asarray(xi, dtype=float)
    if cell.dim == 1:
        lo, hi = c.min(), c.max()
        return (xi[0] >= lo - tol) & (xi[0] <= hi + tol)
    ok = np.ones(xi.shape[1:], dtype=bool)
    for a, b in zip(c.T, np.roll(c, -1, axis=1).T):
        e = b - a
        # signed distance of xi to the edge's line, positive inside (counter-clockwise)
        s = (e[0] * (xi[1] - a[1]) - e[1] * (xi[0] - a[0])) / np.hypot(*e)
        ok &= s >= -tol
    return ok


def _inverse(H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverses of ``H (dim, dim, m)`` (dim 1 or 2) and whether each is positive definite."""
    if H.shape[0] == 1:
        h = H[0, 0]
        pd = h > 0
        return (1.0 / np.where(h != 0, h, 1.0))[None, None], pd
    a, b, c, d = H[0, 0], H[0, 1], H[1, 0], H[1, 1]
    det = a * d - b * c
    pd = (a > 0) & (det > 0)
    s = 1.0 / np.where(det != 0, det, 1.0)
    return np.array([[d * s, -b * s], [-c * s, a * s]]), pd


def _state(cell: CellType, P: np.ndarray, p: np.ndarray, xi: np.ndarray):
    """``r = x(xi) - p (d, m)``, ``N (k, m)``, ``G (k, dim, m)``, ``T (d, dim, m)``,
    ``g (dim, m)`` and ``H (dim, dim, m)`` of cells with nodes ``P (d, m, k)``."""
    N, G, G2 = cell.shape(xi), cell.dshape(xi), cell.d2shape(xi)
    r = np.einsum("dmk,km->dm", P, N) - p
    T = np.einsum("dmk,kjm->djm", P, G)
    dT = np.einsum("dmk,kjlm->djlm", P, G2)
    g = np.einsum("djm,dm->jm", T, r)
    H = np.einsum("djm,dlm->jlm", T, T) + np.einsum("djlm,dm->jlm", dT, r)
    return r, N, G, T, g, H


def project(p: np.ndarray, x: np.ndarray, conn: np.ndarray, cell: "str | CellType",
            cells: np.ndarray, xi0: np.ndarray | None = None, tol: float = 1e-12,
            max_iter: int = 30, derivatives: bool = False,
            limit: float | None = None) -> Projection:
    """The closest point of each point ``p[:, i]`` on cell ``cells[i]`` (module docstring).

    Parameters
    ----------
    p : ndarray (d, m)
        Points.
    x : ndarray (d, n)
        Node coordinates.
    conn : int ndarray (n_cell, cell.n_nodes)
    cell : str or CellType
    cells : int ndarray (m,)
        The cell of each point.
    xi0 : ndarray (dim, m), optional
        Start of Newton (default the reference cell's corner centroid).
    tol : float
        Newton stops where every step is below ``tol`` in reference coordinates.
    max_iter : int
        At most this many steps (``converged`` False where more were needed).
    derivatives : bool
        Also ``dxi/dp`` and ``dxi/dX``.
    limit : float, optional
        Every iterate is clipped to ``[-limit, limit]`` in each coordinate (the map's
        extension far beyond the cell, where a curved cell bends back, is not searched;
        NTS on curved lines: :data:`~.curves.XI_LIMIT`).  None: not clipped.
    """
    cell = cell_type(cell)
    p = np.asarray(p, dtype=float)
    cells = np.asarray(cells, dtype=np.int64).ravel()
    if p.ndim != 2 or p.shape[0] != cell.dim + 1 or p.shape[1] != cells.size:
        raise ValueError(f"p must have shape (d, m) = ({cell.dim + 1}, {cells.size}) "
                         f"for {cell.name} cells and {cells.size} cells, got {p.shape}")
    if not (np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol must be a finite number > 0, got {tol!r}")
    if limit is not None and not (np.isfinite(limit) and limit > 0):
        raise ValueError(f"limit must be a finite number > 0 or None, got {limit!r}")
    P = np.asarray(x, dtype=float)[:, np.asarray(conn)[cells]]              # (d, m, k)
    m = cells.size
    if xi0 is None:
        centre = np.asarray(cell.ref_nodes)[:, list(cell.corners)].mean(axis=1)
        xi = np.repeat(centre[:, None], m, axis=1)
    else:
        xi = np.array(xi0, dtype=float).reshape(cell.dim, m)
    done = np.zeros(m, dtype=bool)
    act = np.arange(m)                   # the pairs still iterating (only they are computed)
    for _ in range(max_iter):
        r, N, G, T, g, H = _state(cell, P[:, act], p[:, act], xi[:, act])
        Hi, pd = _inverse(H)
        Hgn, _ = _inverse(np.einsum("djm,dlm->jlm", T, T))
        step = -np.einsum("jlm,lm->jm", np.where(pd, Hi, Hgn), g)
        if limit is None:
            xi[:, act] = xi[:, act] + step
        else:                         # clipped: the change made is the step
            new = np.clip(xi[:, act] + step, -limit, limit)
            step, xi[:, act] = new - xi[:, act], new
        fin = np.max(np.abs(step), axis=0) <= tol
        done[act[fin]] = True
        act = act[~fin]
        if not act.size:
            break
    r, N, G, T, g, H = _state(cell, P, p, xi)
    out = Projection(xi, r + p, norms(r), done, inside_reference(cell, xi, tol=1e-10))
    if derivatives:
        Hi, _ = _inverse(H)
        out.dxi_dp = np.einsum("jlm,dlm->jmd", Hi, T)
        rhs = np.einsum("kjm,cm->jmkc", G, r) + np.einsum("cjm,km->jmkc", T, N)
        out.dxi_dX = -np.einsum("jlm,lmkc->jmkc", Hi, rhs)
    return out


def project_line2(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Closed form on straight segments ``a -> b`` (d, m): ``xi (m,)`` of the closest
    point of ``p (d, m)`` on each segment's line, ``xi = 2 (p - a).(b - a) / |b - a|^2 -
    1`` (line2's coordinate: -1 at ``a``, 1 at ``b``)."""
    t = b - a
    return 2.0 * np.sum((p - a) * t, axis=0) / np.sum(t * t, axis=0) - 1.0
