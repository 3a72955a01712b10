"""The isoparametric map of facet cells: points, tangents, area vectors and measures.

A cell of type ``cell`` (:mod:`.cells`) with node coordinates ``x_k`` (``d`` components,
``d = cell.dim + 1``) is the map ``x(xi) = sum_k N_k(xi) x_k`` of its reference cell.
Its tangents are ``T_j = dx/dxi_j = sum_k dN_k/dxi_j x_k`` and its *area vector*, the
outward normal scaled by the measure density, is

* curves in the plane (``dim`` 1): ``v = (t_y, -t_x)`` (the right-hand normal of
  ``t = dx/dxi``, the package's orientation: a counter-clockwise boundary has outward
  normals);
* surfaces in space (``dim`` 2): ``v = T_1 x T_2`` (counter-clockwise cells seen from
  outside have outward normals).

``|v|`` is the Jacobian ``dGamma / dxi`` and ``v / |v|`` the unit normal.  Everything is
vectorized over cells (and quadrature points): ``x (d, n)``, ``conn (n_cell, n_nodes)``.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from .cells import CellType, cell_type

__all__ = ["cell_points", "cell_tangents", "area_vectors", "cell_measures", "cell_normals",
           "reversal", "straight", "check_connectivity", "norms"]

#: degree of the rule :func:`cell_measures` uses on a cell that is not straight: 5 Gauss
#: points per direction, as :data:`~skfem_mortar.core.chain.N_GAUSS_CURVE`
CURVED_DEGREE = 9


def check_connectivity(conn, cell: "str | CellType", n_nodes: int | None = None
                       ) -> np.ndarray:
    """``conn`` as an int array ``(n_cell, cell.n_nodes)`` (ValueError naming it, the
    cell type and the columns it needs otherwise; indices below ``n_nodes`` if given)."""
    cell = cell_type(cell)
    c = np.asarray(conn)
    if c.ndim != 2 or c.shape[1] != cell.n_nodes or (c.size and c.dtype.kind not in "iu"):
        raise ValueError(f"connectivity of {cell.name} cells must be an integer array "
                         f"(n_cells, {cell.n_nodes}), got shape {c.shape}")
    c = c.astype(np.int64, copy=False)
    if c.size and (c.min() < 0 or (n_nodes is not None and c.max() >= n_nodes)):
        raise ValueError(f"connectivity must index the nodes 0 .. {n_nodes}, got "
                         f"{c.min()} .. {c.max()}")
    return c


def cell_points(x: np.ndarray, conn: np.ndarray, cell: "str | CellType",
                xi: np.ndarray) -> np.ndarray:
    """Points ``x(xi) = sum_k N_k(xi) x_k``: ``(d, n_cell, nq)`` for ``xi (dim, nq)``."""
    cell = cell_type(cell)
    return np.einsum("dsk,kq->dsq", np.asarray(x, dtype=float)[:, conn], cell.shape(xi))


def cell_tangents(x: np.ndarray, conn: np.ndarray, cell: "str | CellType",
                  xi: np.ndarray) -> np.ndarray:
    """Tangents ``T_j = sum_k dN_k/dxi_j x_k``: ``(d, dim, n_cell, nq)``."""
    cell = cell_type(cell)
    return np.einsum("dsk,kjq->djsq", np.asarray(x, dtype=float)[:, conn], cell.dshape(xi))


def area_vectors(T: np.ndarray) -> np.ndarray:
    """Area vectors ``v (d, ...)`` of tangents ``T (d, dim, ...)``: ``(t_y, -t_x)`` for
    curves in the plane, ``T_1 x T_2`` for surfaces in space (ValueError otherwise)."""
    d, dim = T.shape[:2]
    if (d, dim) == (2, 1):
        return np.stack([T[1, 0], -T[0, 0]])
    if (d, dim) == (3, 2):
        a, b = T[:, 0], T[:, 1]
        return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                         a[0] * b[1] - a[1] * b[0]])
    raise ValueError(f"cells of dimension {dim} in {d} dimensions have no normal: "
                     "curves (dim 1) live in the plane, surfaces (dim 2) in space")


def norms(v: np.ndarray) -> np.ndarray:
    """Euclidean lengths of the vectors ``v (d, ...)`` along the first axis, as
    ``hypot`` (scaled: no overflow or underflow of the squares)."""
    return np.hypot.reduce(v, axis=0)


@lru_cache(maxsize=None)
def straight(cell: CellType) -> bool:
    """Whether the cell's map has zero second derivatives at the points of its rules
    (line2, tri3, a piecewise-linear cell): its Jacobian is constant on each piece the
    rule knows, so a rule of degree 1 measures it exactly."""
    pts, _ = cell.quadrature(CURVED_DEGREE)
    return not np.any(cell.d2shape(pts))


def cell_measures(x: np.ndarray, conn: np.ndarray, cell: "str | CellType",
                  degree: int | None = None) -> np.ndarray:
    """Lengths or areas ``int |v| dxi`` (n_cell,) by the cell's rule of ``degree``
    (default 1 on straight cells, where it is exact, else :data:`CURVED_DEGREE`)."""
    cell = cell_type(cell)
    if degree is None:
        degree = 1 if straight(cell) else CURVED_DEGREE
    pts, w = cell.quadrature(degree)
    return norms(area_vectors(cell_tangents(x, conn, cell, pts))) @ w


def cell_normals(x: np.ndarray, conn: np.ndarray, cell: "str | CellType"
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals ``(d, n_cell)`` at each cell's reference centroid (the mean of its
    corners' reference coordinates) and the cells' measures (:func:`cell_measures`)."""
    cell = cell_type(cell)
    centre = np.asarray(cell.ref_nodes)[:, list(cell.corners)].mean(axis=1, keepdims=True)
    v = area_vectors(cell_tangents(x, conn, cell, centre))[..., 0]
    size = norms(v)
    return v / np.where(size > 0, size, 1.0), cell_measures(x, conn, cell)


@lru_cache(maxsize=None)
def reversal(cell: CellType) -> tuple[int, ...]:
    """The local node permutation that turns a cell over (its normal flipped): the
    reference reflection ``xi -> -xi`` of a line, ``(xi, eta) -> (eta, xi)`` of a
    surface cell, read off the reference nodes (line3: ``(1, 0, 2)``; tri3
    ``(0, 2, 1)``; quad4 ``(0, 3, 2, 1)``).  ValueError when the reference nodes are not
    symmetric under that reflection."""
    ref = np.asarray(cell.ref_nodes, dtype=float)
    image = -ref if cell.dim == 1 else ref[::-1]
    dist = np.abs(image[:, :, None] - ref[:, None, :]).max(axis=0)
    perm = dist.argmin(axis=1)
    if not np.allclose(dist[np.arange(cell.n_nodes), perm], 0.0, atol=1e-12) or \
            np.unique(perm).size != cell.n_nodes:
        raise ValueError(f"cell {cell.name!r}: its reference nodes are not symmetric under "
                         "the reflection that turns it over")
    return tuple(int(p) for p in perm)
