"""The slave nodes' mortar supports and tributary weights, read from the cell table.

Values only (no derivatives), for any cell type of the table: the shape functions and
their derivatives come from the cell's row (:attr:`~skfem_mortar.contact.cells.CellType.shape`,
:attr:`~skfem_mortar.contact.cells.CellType.dshape`), the whole-cell rule from its
:attr:`~skfem_mortar.contact.cells.CellType.quadrature` (a piecewise cell brings its
composite rule), so the linear and the curved mortar kernels share them.

* the tributary weight of slave node ``A``, over the whole slave surface, ::

      w_A = sum_e int N_A(xi) |v(xi)| dxi,   x(xi) = sum_B N_B(xi) x_B,

  ``|v| = |dx/dxi|`` on lines, ``|dx/dxi_1 x dx/dxi_2|`` on surface cells
  (:func:`cell_jacobian`);

* on lines, its mortar support, over the integration cells ``[xi_a, xi_b]`` of a
  segmentation (:class:`~skfem_mortar.contact.segmentation.Segmentation`), ::

      s_A = sum_c int_{xi_a}^{xi_b} N_A(xi) |dx/dxi| dxi,

  by the ``n_gauss``-point Gauss rule mapped onto each integration cell (an
  integration cell lies in one smooth piece of its slave cell).  The kernels mask a
  node whose ``s_A`` is at most ``MASK_TOL`` times ``w_A``
  (:data:`skfem_mortar.contact.mortar.MASK_TOL`);

* the merge of masked (and crosspoint) nodes, one rule for every cell of the table
  read from the row's edges (:func:`merge_nodes`): a merged node's function goes to the
  cell's kept nodes nearest to it along the edges (:func:`edge_distances`), in equal
  shares.  On line2 a merged node's goes to the other; on line3 a vertex's to the mid
  node if it is kept, else to the other vertex, the mid node's in halves to the kept
  vertices (the lines' rule of :func:`merge_matrix`, tested bit for bit); on
  tri3 to the other kept corners, on quad4 to its kept edge neighbours, else to the
  opposite corner (:mod:`~skfem_mortar.contact.dual3d`'s masking rule).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from .cell_map import area_vectors
from .cells import CellType, line_quadrature
from .measures import PLANE, Measure
from .segmentation import Segmentation

__all__ = ["cell_jacobian", "tributary_weights", "multiplier_support", "edge_distances",
           "merge_nodes", "merge_matrix", "N_GAUSS_ELEMENT"]

N_GAUSS_ELEMENT = 5
"""Default Gauss points of the element rule of ``D_e``, ``M_e`` (dual basis) and of
the tributary weights on curved cells (exact to degree 9; the integrands of a straight
element have degree 4)."""


def cell_jacobian(cell: CellType, X: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """``|v|`` at ``xi`` (dim, n, nq) of cells with node positions ``X`` (d, n, n_nodes):
    (n, nq), ``v`` the area vector of the tangents ``T_r = sum_B dN_B/dxi_r x_B``
    (:func:`~skfem_mortar.contact.cell_map.area_vectors`: ``|dx/dxi|`` on lines,
    ``|T_1 x T_2|`` on surface cells)."""
    T = np.einsum("ink,krnq->irnq", X, np.asarray(cell.dshape(xi)))   # (d, dim, n, nq)
    return np.sqrt((area_vectors(T) ** 2).sum(0))


def _weighted(dG: np.ndarray, cell: CellType, X: np.ndarray, N: np.ndarray,
              measure: Measure) -> np.ndarray:
    """``dGamma`` times the measure's weight ``w(x)`` at ``x = sum_B N_B x_B``
    (``X`` (2, n, n_nodes), ``N`` (n_nodes, n, nq)); unchanged for a unit measure."""
    if measure.unit:
        return dG
    x = np.einsum("ink,knq->inq", X, N)
    return dG * measure.weight(x)


def _scatter(n_s: int, nodes: np.ndarray, N: np.ndarray, dG: np.ndarray) -> np.ndarray:
    """``out_A = sum N_A dGamma`` summed into the nodes (n, n_nodes) of each cell."""
    out = np.zeros(n_s)
    for a in range(nodes.shape[1]):
        np.add.at(out, nodes[:, a], (N[a] * dG).sum(1))
    return out


def tributary_weights(xs: np.ndarray, seg: np.ndarray, cell: CellType, degree: int,
                      measure: Measure = PLANE, absolute: bool = False) -> np.ndarray:
    """``w_A = int N_A w(x) dGamma`` over the whole slave surface (module doc), (n_s,).

    ``degree``: the cell's rule is exact for polynomials of that degree in ``xi``
    (a straight cell's integrand ``N_A |dx/dxi|`` has the degree of ``N_A``).  On a
    straight line3 cell of length ``L`` with a centred mid node ``L/6, L/6, 2L/3``;
    ``L/2`` each for line2.  ``measure``: the weight ``w(x)`` of ``dGamma``
    (:mod:`~skfem_mortar.contact.measures`; linear in ``x``, so one degree more).
    ``absolute``: ``int |N_A| w dGamma`` instead, a positive scale even where
    ``int N_A w dGamma`` vanishes (a line3 vertex on the axis, ``w = 2 pi r``:
    ``int_0^h N_A r dr = 0`` on a straight cell).
    """
    xs = np.asarray(xs, dtype=float)
    seg = np.asarray(seg, dtype=np.int64)
    pts, w = cell.quadrature(degree + (0 if measure.unit else 1))
    xi = np.broadcast_to(pts[:, None, :], (pts.shape[0], seg.shape[0], pts.shape[1]))
    N = np.asarray(cell.shape(xi))
    dG = _weighted(cell_jacobian(cell, xs[:, seg], xi) * w, cell, xs[:, seg], N, measure)
    return _scatter(xs.shape[1], seg, np.abs(N) if absolute else N, dG)


def multiplier_support(xs: np.ndarray, seg_s: np.ndarray, sg: Segmentation, cell: CellType,
                       n_gauss: int, measure: Measure = PLANE) -> np.ndarray:
    """``s_A = int N_A w(x) dGamma`` over the integration cells of ``sg`` (module doc),
    (n_s,); negative for a far vertex of a partly covered line3 cell.  ``measure`` as
    :func:`tributary_weights` (one degree more)."""
    xs = np.asarray(xs, dtype=float)
    e = sg.e_s
    eta, w = line_quadrature(2 * n_gauss - 1 + (0 if measure.unit else 1))
    lo, hi = sg.xi[:, :1], sg.xi[:, 1:]
    xi = lo * ((1.0 - eta[0]) * 0.5) + hi * ((1.0 + eta[0]) * 0.5)
    N = np.asarray(cell.shape(xi[None]))
    dG = _weighted(cell_jacobian(cell, xs[:, seg_s[e]], xi[None]) * ((hi - lo) * 0.5) * w, cell,
                   xs[:, seg_s[e]], N, measure)
    return _scatter(xs.shape[1], seg_s[e], N, dG)


@lru_cache(maxsize=None)
def edge_distances(cell: CellType) -> np.ndarray:
    """Number of edge steps between each two nodes of a cell ``(k, k)``, through
    consecutive nodes of its ``cell.edges`` (tri3: 1 between any two corners; quad4: 1 to
    the neighbours, 2 across; line3, edge (0, 2, 1): 1 from a vertex to the mid node, 2
    between the vertices)."""
    k = cell.n_nodes
    dist = np.full((k, k), k, dtype=np.int64)
    np.fill_diagonal(dist, 0)
    for edge in cell.edges:
        for a, b in zip(edge[:-1], edge[1:]):
            dist[a, b] = dist[b, a] = 1
    for via in range(k):                       # Floyd-Warshall on a cell's few nodes
        dist = np.minimum(dist, dist[:, via:via + 1] + dist[via:via + 1, :])
    dist.setflags(write=False)
    return dist


def merge_nodes(merged: np.ndarray, cell: CellType) -> np.ndarray:
    """The merge ``T`` of a cell's multiplier-less nodes (module docstring):
    ``N~_A = sum_B T_AB N_B`` per cell.

    ``merged`` (n, k) bool: the cell's masked (or crosspoint) nodes.  Kept nodes keep
    their function; a merged node ``B``'s goes to the kept nodes nearest to it along the
    cell's edges (:func:`edge_distances`), in equal shares; merged rows are zero.
    ``sum_A T_AB = 1`` for every ``B`` unless the whole cell is merged, so the kept
    ``N~`` still sum to one.  (On a line of more than three nodes per edge this is not
    "the nearest kept node on each side": a node two steps away on one side loses to one
    step on the other.)

    Returns
    -------
    T : ndarray (n, k, k)
    """
    merged = np.asarray(merged, dtype=bool)
    if merged.ndim != 2 or merged.shape[1] != cell.n_nodes:
        raise ValueError(f"merged must have the columns of the cell {cell.name} "
                         f"({cell.n_nodes} nodes), got shape {merged.shape}")
    n, k = merged.shape
    keep = ~merged
    T = np.zeros((n, k, k))
    T[:, np.arange(k), np.arange(k)] = keep
    dist = edge_distances(cell)
    for b in range(k):
        d = np.where(keep, dist[b], k + 1)                        # (n, k)
        nearest = keep & (d == d.min(axis=1, keepdims=True))
        count = nearest.sum(axis=1, keepdims=True)
        share = np.where(nearest, 1.0 / np.maximum(count, 1), 0.0)
        T[:, :, b] += np.where(merged[:, b:b + 1], share, 0.0)
    return T


def merge_matrix(merged: np.ndarray, cell: CellType) -> np.ndarray:
    """The crosspoint/boundary modification ``N~_A = sum_B T_AB N_B`` per element.

    ``merged`` (n, n_nodes) bool: the element's nodes without a multiplier, in the
    columns of ``cell``.  Kept nodes keep their function; a merged node's goes to
    the nearest kept node on each side along the cell's edge (``cell.edges``), in
    halves when there is one on both sides, whole when on one.  For line3 (edge
    start, mid, end) a merged vertex's goes to the mid node if that is kept, else
    to the other vertex; a merged mid node's in halves to the kept vertices; for
    line2 a merged node's to the other.  Merged rows are zero.  ``sum_A T_AB = 1``
    for every ``B`` unless the whole element is merged, so ``sum_A N~_A = 1``.

    Returns
    -------
    T : ndarray (n, n_nodes, n_nodes)
    """
    merged = np.asarray(merged, dtype=bool)
    n, k = merged.shape
    if k != cell.n_nodes or len(cell.edges) != 1:   # a line cell is its own one edge
        raise ValueError(f"merged must have the columns of a line cell (one edge), got "
                         f"shape {merged.shape} for the cell {cell.name} ({cell.n_nodes} "
                         f"nodes, {len(cell.edges)} edges)")
    keep = ~merged
    order = cell.edges[0]                       # the nodes in order along the line
    T = np.zeros((n, k, k))
    for a in range(k):
        T[:, a, a] = keep[:, a]
    rows = np.arange(n)
    for p, b in enumerate(order):
        if not merged[:, b].any():
            continue
        sides = []
        for walk in (order[p - 1::-1] if p else (), order[p + 1:]):
            target = np.full(n, -1)
            for q in walk:                      # the nearest kept node on this side
                target = np.where((target < 0) & keep[:, q], q, target)
            sides.append(target)
        share = np.where((sides[0] >= 0) & (sides[1] >= 0), 0.5, 1.0)
        for t in sides:
            on = merged[:, b] & (t >= 0)
            T[rows[on], t[on], b] += share[on]
    return T
