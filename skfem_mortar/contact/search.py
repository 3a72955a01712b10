"""Contact search: candidate pairs of slave and master entities, O(n log n).

Every Newton iteration the contact discretizations ask which master segments
may interact with which slave segments (mortar) or slave nodes (NTS).  Each
entity is enclosed in its axis-aligned bounding box; two entities are a
candidate pair when their boxes, one of them inflated by ``margin`` on every
side, overlap:

    lo_a - margin <= hi_b   and   lo_b <= hi_a + margin     (in every coordinate).

Any dimension: points, boxes and cells have ``d`` coordinates (2 or 3); a cell is boxed
by its nodes, or by the hull points its cell type gives (:attr:`CellType.hull`: a curved
3-node segment's Bezier control point).

Algorithm
---------
Boxes are reduced to their centres ``c`` and half sizes ``h``.  Two boxes
overlap iff ``|c_a - c_b|_inf <= h_a + h_b + margin`` componentwise, so every
overlapping pair of "small" boxes lies within the max-norm radius
``r = max h_a + max h_b + margin`` of each other.  The centres of one set are
hashed into a uniform grid of square (cubic) cells of side ``r / 2`` (a sort of
the cell keys); each centre of the other set is paired with the centres in the
cells that meet the square (cube) of half width ``r`` around it (at most five
columns of cells in 2D, 5 x 5 in 3D, each one ``searchsorted`` range of the
sorted keys, the cells of a grid column along the last axis being consecutive
keys), and the pairs are then
filtered exactly.  O(n log n) for a surface mesh of bounded grading, numpy
alone.  Above :data:`GRID_POINTS` boxes the range query is scipy's
``cKDTree`` (a dual tree traversal), imported only then: measured
(``benchmarks/search_grid.py``, one thread) the grid is as fast as the tree
at 1e3 boxes and 10 to 30 % slower at 1e4 to 1e5, while importing
``scipy.spatial`` costs a small run about 0.1 s of its start.  The exact test
makes both give the same pairs.  "Large" boxes (half
size above four times the median of their set; e.g. a rigid plane of one long
segment) would inflate that radius for all the others, so they are tested
against every entity of the other set directly; there are only a few of them,
so this costs O(n_large n).  No all-pairs test is done.

The nearest vertex of a point (:func:`nearest_vertex`) uses the same grid:
the nearest vertex in the square of half width ``r`` around a point is the
nearest of all when it lies within ``r`` (every vertex outside is farther).
"""
from __future__ import annotations

from itertools import product

import numpy as np
from ..core.chain import polyline, segment_lengths
from ..core.timing import timed
from .cells import CellType, cell_type

__all__ = ["segment_pairs", "node_segment_pairs", "box_pairs", "segment_boxes", "nearest_vertex",
           "distance_to_polyline", "cell_sizes"]

_LARGE = 4.0  # a box is "large" above this many median half sizes


#: the cells of a 2D chain's connectivity passed without its cell type, by columns
_CHAIN_CELLS = {2: cell_type("line2"), 3: cell_type("line3")}


def _chain_cell(seg: np.ndarray) -> CellType:
    """The cell of a 2D chain's connectivity passed without its cell type: line2, or
    line3 for three columns.  Only for callers that do not pass ``cell`` yet (the 2D
    kernels); a :class:`~skfem_mortar.contact.surfaces.ContactSurface` carries its own."""
    return _CHAIN_CELLS.get(seg.shape[-1], _CHAIN_CELLS[2])


def segment_boxes(x: np.ndarray, seg: np.ndarray, cell: "str | CellType | None" = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Bounding boxes of cells (segments in 2D).

    Parameters
    ----------
    x : ndarray (d, n)
        Node coordinates.
    seg : int ndarray (n_seg, cell.n_nodes)
        The nodes of each cell (a flat list: pairs).
    cell : str or CellType, optional
        The cell type; default line2, or line3 for three columns (:func:`_chain_cell`).

    Returns
    -------
    lo, hi : ndarray (d, n_seg)
        The componentwise min and max over the cell's nodes, or over the points of its
        :attr:`CellType.hull` (line3: also the Bezier control point ``2 x_mid - (x_start
        + x_end)/2``: the curve lies in the hull of its control polygon, so the box
        holds the whole curve).
    """
    x = np.asarray(x, dtype=float)
    seg = np.asarray(seg, dtype=np.int64)
    if seg.ndim != 2:
        seg = seg.reshape(-1, 2)
    cell = _chain_cell(seg) if cell is None else cell if isinstance(cell, CellType) \
        else cell_type(cell)
    if seg.shape[1] != cell.n_nodes:
        raise ValueError(f"seg must have {cell.n_nodes} columns for {cell.name} cells, "
                         f"got {seg.shape[1]}")
    a, b = x[:, seg[:, 0]], x[:, seg[:, 1]]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    if cell.hull is not None:
        pts = cell.hull(x[:, seg])
    elif cell.n_nodes > 2:
        pts = x[:, seg[:, 2:]]
    else:
        return lo, hi
    return np.minimum(lo, pts.min(axis=2)), np.maximum(hi, pts.max(axis=2))


def _check_margin(margin: float) -> float:
    margin = float(margin)
    if not np.isfinite(margin) or margin < 0.0:
        raise ValueError(f"margin must be a finite number >= 0, got {margin}")
    return margin


def _overlap(lo_a, hi_a, lo_b, hi_b, ia, ib, margin):
    """Exact test of the inflated-box overlap for index arrays ia, ib."""
    return np.all((lo_a[:, ia] - margin <= hi_b[:, ib])
                  & (lo_b[:, ib] <= hi_a[:, ia] + margin), axis=0)


#: most cells of the grid along an axis, by dimension (its keys stay far inside int64)
_MAX_CELLS = {2: 2**24, 3: 2**20}
#: the box and nearest-vertex searches use the grid (numpy) up to this many
#: points (both sets together) and ``scipy.spatial.cKDTree`` above: there the
#: tree is faster, and a run that large does not feel its import (0.1 s)
GRID_POINTS = 4000


def _ragged(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """``concatenate([arange(s, s + c) for s, c in zip(starts, counts)])``, vectorized."""
    ends = np.cumsum(counts)
    return np.repeat(starts - ends + counts, counts) + np.arange(ends[-1] if ends.size else 0)


#: the columns of cells a query visits: shifts 0..4 along each axis but the last
_SHIFTS = {d: list(product(range(5), repeat=d - 1)) for d in (2, 3)}


class _Grid:
    """Points hashed into a uniform grid of square (cubic) cells (side at least ``cell``).

    The cell of a point is ``k = floor((c - origin) / side)`` per axis, its key
    ``sum_a k_a s_a`` with strides ``s_a`` the product of the cell counts along the
    later axes (2D: ``k_x n_y + k_y``; the grid's box holding the points and the
    queries widened by ``reach``); the keys are sorted once, so the points of the cells
    ``k_0 .. k_1`` of a grid column along the last axis are one range of the sorted keys.
    """

    def __init__(self, c: np.ndarray, cell: float, others: np.ndarray, reach: float):
        lo = np.minimum(c.min(axis=1), others.min(axis=1) - reach)
        hi = np.maximum(c.max(axis=1), others.max(axis=1) + reach)
        self.side = max(float(cell), float((hi - lo).max()) / _MAX_CELLS[c.shape[0]], 1e-300)
        self.origin = lo
        n = [int(np.floor((hi[a] - lo[a]) / self.side)) + 1 for a in range(c.shape[0])]
        self.stride = [1] * c.shape[0]          # of the keys: cells along the later axes
        for a in range(c.shape[0] - 2, -1, -1):
            self.stride[a] = self.stride[a + 1] * n[a + 1]
        key = self.key(self.cells(c))
        self.order = np.argsort(key, kind="stable")
        self.sorted = key[self.order]

    def cells(self, c: np.ndarray) -> np.ndarray:
        return np.floor((c - self.origin[:, None]) / self.side).astype(np.int64)

    def key(self, k: np.ndarray) -> np.ndarray:
        """Keys of cells ``k (d, n)``: ``sum_a k_a stride_a`` (2D: ``k_x n_y + k_y``)."""
        out = k[0] * self.stride[0]
        for a in range(1, k.shape[0]):
            out += k[a] * self.stride[a] if self.stride[a] != 1 else k[a]
        return out

    def within(self, c: np.ndarray, r: float) -> tuple[np.ndarray, np.ndarray]:
        """Pairs ``(i, j)``, sorted by ``i``: point ``j`` of the grid lies in a cell
        that meets the square (cube) ``|y - c_i|_inf <= r`` (a superset of the points in
        that square, for ``r`` at most twice the side: five columns of cells along
        each axis but the last, each column one range of keys)."""
        k0, k1 = self.cells(c - r), self.cells(c + r)
        d = c.shape[0]
        lo = self.key(k0)                       # the first cell of the first column
        hi = lo + (k1[-1] - k0[-1]) * self.stride[-1]
        span = k1[:-1] - k0[:-1]                # (d - 1, n): columns past these are empty
        shifts = _SHIFTS[d]
        starts = np.empty((c.shape[1], len(shifts)), np.int64)
        counts = np.empty((c.shape[1], len(shifts)), np.int64)
        for col, shift in enumerate(shifts):
            step = shift[0] * self.stride[0]
            ok = span[0] >= shift[0]
            for a in range(1, d - 1):
                step += shift[a] * self.stride[a]
                ok &= span[a] >= shift[a]
            s = np.searchsorted(self.sorted, lo + step, side="left")
            e = np.searchsorted(self.sorted, hi + step, side="right")
            starts[:, col] = s
            counts[:, col] = np.where(ok, e - s, 0)
        i = np.repeat(np.arange(c.shape[1], dtype=np.int64), counts.sum(1))
        return i, self.order[_ragged(starts.ravel(), counts.ravel())].astype(np.int64)


def _near_pairs(ca: np.ndarray, cb: np.ndarray, r: float) -> tuple[np.ndarray, np.ndarray]:
    """Every pair ``(i, j)`` with ``|ca_i - cb_j|_inf <= r`` (and some up to about
    ``2.5 r`` apart: the caller filters exactly).

    Up to :data:`GRID_POINTS` points in all, from a grid of cells of side
    ``r / 2`` (:class:`_Grid`; ``r`` widened by a hair, so that round-off in
    the cell of a point never drops a pair within ``r``); above, by
    ``scipy.spatial.cKDTree`` (imported then only), which measured 10 to 30 %
    faster there (``benchmarks/search_grid.py``).  The exact test that
    follows makes both give the same pairs.
    """
    if ca.shape[1] + cb.shape[1] > GRID_POINTS:
        from scipy.spatial import cKDTree
        hits = cKDTree(ca.T).sparse_distance_matrix(cKDTree(cb.T), r, p=np.inf,
                                                     output_type="ndarray")
        return hits["i"].astype(np.int64), hits["j"].astype(np.int64)
    r = r * (1.0 + 1e-9)
    grid = _Grid(cb, 0.5 * r, ca, r)
    return grid.within(ca, r)


#: :func:`nearest_vertex` measures every distance up to this many point-vertex pairs
_ALL_PAIRS = 20_000
#: rounds of :func:`nearest_vertex` in the grid (the square searched grows four
#: times each round) before the points still unresolved go to a k-d tree
_NEAREST_ROUNDS = 2


def _distances(q: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``sqrt(sum_a (q_a - x_a)^2)`` (2D: ``sqrt(dx dx + dy dy)``), broadcast."""
    dx, dy = q[0] - x[0], q[1] - x[1]
    s = dx * dx + dy * dy
    for a in range(2, q.shape[0]):
        dz = q[a] - x[a]
        s += dz * dz
    return np.sqrt(s)


def nearest_vertex(x: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The vertex of ``x (d, m)`` nearest to each point ``p (d, n)`` and its distance.

    ``d_i = min_j |p_i - x_j|`` (Euclidean, ``sqrt(dx^2 + dy^2 [+ dz^2])``); among vertices
    at exactly the same distance the lowest index (the tree's own choice for
    the points left to it).  A uniform grid (module
    doc; up to 20,000 point-vertex pairs every distance is measured): the
    vertices in the square of half width ``r`` around a point
    (``r`` first twice the mean vertex spacing ``extent / m^(1/(d-1))``, ``extent``
    the larger side of their bounding box); a nearest one within ``r`` is the nearest of all.  The
    points without one are searched again with ``4 r``, and those still
    without (far from a dense surface, where the square would hold many
    vertices) by ``scipy.spatial.cKDTree``, imported only then; above
    :data:`GRID_POINTS` points and vertices all go to the tree (faster there).

    Returns
    -------
    distance : ndarray (n,)
    index : int ndarray (n,)
    """
    x = np.asarray(x, dtype=float)
    d = len(x) if x.ndim == 2 else 2
    x, p = x.reshape(d, -1), np.asarray(p, dtype=float).reshape(d, -1)
    n, m = p.shape[1], x.shape[1]
    dist, idx = np.full(n, np.inf), np.zeros(n, dtype=np.int64)
    if n == 0:
        return dist, idx
    if m == 0:
        raise ValueError("x must hold at least one vertex")
    if n * m <= _ALL_PAIRS:  # few: every point against every vertex
        dist = _distances(p[:, :, None], x[:, None, :])
        idx = np.argmin(dist, axis=1)  # the first of equal minima: the lowest index
        return dist[np.arange(n), idx], idx
    extent = float((x.max(axis=1) - x.min(axis=1)).max())
    r = max(2.0 * extent / (m if d == 2 else m ** (1.0 / (d - 1))), 1e-300)
    todo = np.arange(n)
    for _ in range(_NEAREST_ROUNDS if n + m <= GRID_POINTS else 0):
        if not todo.size:
            break
        q = p[:, todo]
        grid = _Grid(x, 0.5 * r, q, r)
        i, j = grid.within(q, r)
        dij = _distances(q[:, i], x[:, j])
        o = np.lexsort((j, dij, i))  # by point, then distance, then vertex index
        first = np.ones(o.size, dtype=bool)
        first[1:] = i[o[1:]] != i[o[:-1]]
        best = o[first]
        best = best[dij[best] <= r]  # no vertex outside the square is nearer
        dist[todo[i[best]]], idx[todo[i[best]]] = dij[best], j[best]
        found = np.zeros(todo.size, dtype=bool)
        found[i[best]] = True
        todo = todo[~found]
        r *= 4.0
    if todo.size:
        from scipy.spatial import cKDTree
        dist[todo], idx[todo] = cKDTree(x.T).query(p[:, todo].T)
    return dist, idx


def box_pairs(lo_a: np.ndarray, hi_a: np.ndarray, lo_b: np.ndarray, hi_b: np.ndarray,
              margin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """All pairs (i, j) of boxes ``a_i``, ``b_j`` that overlap after inflating by ``margin``.

    Parameters
    ----------
    lo_a, hi_a : ndarray (d, n_a)
        Lower and upper corners of the first set of boxes.
    lo_b, hi_b : ndarray (d, n_b)
        Same for the second set.
    margin : float
        Inflation (>= 0).

    Returns
    -------
    ia, ib : int ndarray (n_pairs,)
        Candidate pairs sorted by ``ia`` then ``ib``, no duplicates.
    """
    margin = _check_margin(margin)
    lo_a, hi_a = np.asarray(lo_a, float), np.asarray(hi_a, float)
    lo_b, hi_b = np.asarray(lo_b, float), np.asarray(hi_b, float)
    na, nb = lo_a.shape[1], lo_b.shape[1]
    empty = np.zeros(0, dtype=np.int64)
    if na == 0 or nb == 0:
        return empty, empty.copy()
    ca, ha = 0.5 * (lo_a + hi_a), 0.5 * (hi_a - lo_a)
    cb, hb = 0.5 * (lo_b + hi_b), 0.5 * (hi_b - lo_b)
    sa, sb = ha.max(axis=0), hb.max(axis=0)
    big_a = sa > _LARGE * np.median(sa) + 1e-300
    big_b = sb > _LARGE * np.median(sb) + 1e-300
    small_a, small_b = np.flatnonzero(~big_a), np.flatnonzero(~big_b)
    ia_parts, ib_parts = [empty], [empty]
    if small_a.size and small_b.size:
        r = sa[small_a].max() + sb[small_b].max() + margin
        # widen by round-off of the centres so that touching boxes are kept;
        # the exact test below decides
        scale = max(np.abs(ca).max(), np.abs(cb).max(), r)
        i, j = _near_pairs(ca[:, small_a], cb[:, small_b], r + 1e-12 * scale + 1e-300)
        ia_parts.append(small_a[i])
        ib_parts.append(small_b[j])
    # large boxes against everything of the other set (few of them)
    for big, n_other, first in ((np.flatnonzero(big_a), nb, True),
                                (np.flatnonzero(big_b), na, False)):
        if big.size == 0:
            continue
        i = np.repeat(big, n_other)
        j = np.tile(np.arange(n_other, dtype=np.int64), big.size)
        if first:
            ia_parts.append(i)
            ib_parts.append(j)
        else:
            ia_parts.append(j)
            ib_parts.append(i)
    ia = np.concatenate(ia_parts)
    ib = np.concatenate(ib_parts)
    keep = _overlap(lo_a, hi_a, lo_b, hi_b, ia, ib, margin)
    key = np.unique(ia[keep] * nb + ib[keep])
    return key // nb, key % nb


def segment_pairs(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                  margin: float, margin_s: np.ndarray | None = None,
                  margin_m: np.ndarray | None = None, cell_s: "str | CellType | None" = None,
                  cell_m: "str | CellType | None" = None) -> tuple[np.ndarray, np.ndarray]:
    """Candidate slave/master segment pairs whose bounding boxes come within ``margin``.

    With per-segment margins the slave box ``i`` is inflated by
    ``margin + margin_s[i]`` and the master box ``j`` by ``margin_m[j]``: the pair
    is a candidate when the boxes come within ``margin + margin_s[i] + margin_m[j]``
    (e.g. the two element lengths: a local reach on graded meshes, where a global
    one pairs every fine slave element with every master element within the
    largest element length).

    Parameters
    ----------
    xs : ndarray (d, n_s)
        Slave node coordinates.
    seg_s : int ndarray (n_seg_s, cell_s.n_nodes)
        Slave cells (indices into the slave nodes).
    xm : ndarray (d, n_m)
        Master node coordinates.
    seg_m : int ndarray (n_seg_m, cell_m.n_nodes)
        Master cells.
    margin : float
        Inflation of the slave boxes (>= 0).
    margin_s, margin_m : ndarray (n_seg_s,), (n_seg_m,), optional
        Further inflation of each slave and master box (>= 0).
    cell_s, cell_m : str or CellType, optional
        The cell types (:func:`segment_boxes`).

    Returns
    -------
    i_s, i_m : int ndarray (n_pairs,)
        Indices of slave and master segments, sorted by ``i_s`` then ``i_m``.
    """
    with timed("search"):
        lo_s, hi_s = segment_boxes(xs, seg_s, cell_s)
        lo_m, hi_m = segment_boxes(xm, seg_m, cell_m)
        for name, m, lo, hi in (("margin_s", margin_s, lo_s, hi_s),
                                ("margin_m", margin_m, lo_m, hi_m)):
            if m is None:
                continue
            m = np.asarray(m, dtype=float)
            if m.shape != lo.shape[1:] or not np.all(np.isfinite(m)) or np.any(m < 0):
                raise ValueError(f"{name} must be {lo.shape[1]} finite numbers >= 0")
            lo -= m
            hi += m
        return box_pairs(lo_s, hi_s, lo_m, hi_m, margin)


def node_segment_pairs(xn: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, margin: float,
                       cell: "str | CellType | None" = None) -> tuple[np.ndarray, np.ndarray]:
    """Candidate (node, master segment) pairs: the node lies in the segment's box inflated by ``margin``.

    Parameters
    ----------
    xn : ndarray (d, n)
        Node coordinates.
    xm : ndarray (d, n_m)
        Master node coordinates.
    seg_m : int ndarray (n_seg_m, cell.n_nodes)
        Master cells.
    margin : float
        Inflation (>= 0).
    cell : str or CellType, optional
        The master cell type (:func:`segment_boxes`).

    Returns
    -------
    i_node, i_m : int ndarray (n_pairs,)
        Sorted by node then segment.
    """
    with timed("search"):
        lo_m, hi_m = segment_boxes(xm, seg_m, cell)
        xn = np.asarray(xn, dtype=float).reshape(lo_m.shape[0], -1)
        return box_pairs(xn, xn, lo_m, hi_m, margin)


#: points per batch of :func:`distance_to_polyline` (each batch one box search)
_DIST_BATCH = 256


def distance_to_polyline(p: np.ndarray, x: np.ndarray, seg: np.ndarray, cell=None) -> np.ndarray:
    """Euclidean distance of each point ``p (2, n)`` to the segments ``seg`` of the
    nodes ``x (2, m)``: ``min_e |p - (x_1 + t (x_2 - x_1))|``, ``t`` clipped to [0, 1]
    (3-node segments: to their chords through the mid node, :func:`~skfem_mortar.core.chain.polyline`).

    The nearest vertex (:func:`nearest_vertex`) bounds each distance by ``d_v``; the closest
    segment then lies in its box inflated by ``d_v``, so the points, in batches
    sorted by ``d_v``, are paired with the segment boxes (:func:`box_pairs`) with
    the batch's largest ``d_v`` as margin, and the minimum is taken over those pairs only.
    """
    p = np.asarray(p, dtype=float).reshape(2, -1)
    out = np.empty(p.shape[1])
    if p.shape[1] == 0:
        return out
    seg = polyline(np.asarray(seg, dtype=np.int64), cell)  # curved/piecewise cells: their chords
    d_v, _ = nearest_vertex(x, p)
    order = np.argsort(d_v)
    lo, hi = segment_boxes(x, seg)
    for k in range(0, order.size, _DIST_BATCH):
        idx = order[k:k + _DIST_BATCH]
        pk = p[:, idx]  # an output query: not timed as the contact search
        i_p, i_e = box_pairs(pk, pk, lo, hi, float(d_v[idx].max()))
        a, b = x[:, seg[i_e, 0]], x[:, seg[i_e, 1]]
        d = b - a
        q = p[:, idx[i_p]]
        t = np.clip(np.sum((q - a) * d, axis=0)
                    / np.maximum(np.sum(d * d, axis=0), np.finfo(float).tiny), 0.0, 1.0)
        r = np.hypot(*(q - a - t * d))
        best = np.full(idx.size, np.inf)
        np.minimum.at(best, i_p, r)
        out[idx] = np.minimum(best, d_v[idx])  # a vertex is a point of the polyline too
    return out


def cell_sizes(x: np.ndarray, conn: np.ndarray, cell: "str | CellType") -> np.ndarray:
    """The size ``h`` (n_cell,) of each cell: its longest edge of the cell table
    (:attr:`CellType.edges`).  An edge that is the whole cell (a line cell) is measured
    along it (:func:`~skfem_mortar.core.chain.segment_lengths`: the arc length of a
    curved one), any other by the distance of its two ends (a face's corner-to-corner
    edge).  One measure for lines and faces alike: what the contact pair's tolerances
    and the searches' margins read as "an element length"."""
    cell = cell if isinstance(cell, CellType) else cell_type(cell)
    x, conn = np.asarray(x, dtype=float), np.asarray(conn, dtype=np.int64)
    if not conn.size:                  # no cells
        return np.zeros(0)
    h = None
    for edge in cell.edges:
        if len(edge) == cell.n_nodes:
            size = segment_lengths(x, conn, cell)
        else:
            e = x[:, conn[:, edge[-1]]] - x[:, conn[:, edge[0]]]
            size = np.sqrt(np.sum(e * e, axis=0))
        h = size if h is None else np.maximum(h, size)
    return h
