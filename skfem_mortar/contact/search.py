"""Contact search: candidate pairs of slave and master entities, O(n log n).

Every Newton iteration the contact discretizations ask which master segments
may interact with which slave segments (mortar) or slave nodes (NTS).  Each
entity is enclosed in its axis-aligned bounding box; two entities are a
candidate pair when their boxes, one of them inflated by ``margin`` on every
side, overlap:

    lo_a - margin <= hi_b   and   lo_b <= hi_a + margin     (in x and in y).

Algorithm
---------
Boxes are reduced to their centres ``c`` and half sizes ``h``.  Two boxes
overlap iff ``|c_a - c_b|_inf <= h_a + h_b + margin`` componentwise, so every
overlapping pair of "small" boxes is found by a kd-tree range query in the
max-norm with the radius ``max h_a + max h_b + margin`` (``cKDTree``, a dual
tree traversal, O(n log n) for a surface mesh of bounded grading) and then
filtered exactly.  "Large" boxes (half size above four times the median of their set; e.g. a
rigid plane of one long segment) would inflate that radius for all the others,
so they are tested against every entity of the other set directly; there are
only a few of them, so this costs O(n_large n).  No all-pairs test is done.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..core.chain import polyline
from ..core.timing import timed

__all__ = ["segment_pairs", "node_segment_pairs", "box_pairs", "segment_boxes"]

_LARGE = 4.0  # a box is "large" above this many median half sizes


def segment_boxes(x: np.ndarray, seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounding boxes of segments.

    Parameters
    ----------
    x : ndarray (2, n)
        Node coordinates.
    seg : int ndarray (n_seg, 2) or (n_seg, 3)
        End nodes of each segment (and the mid node of a 3-node one).

    Returns
    -------
    lo, hi : ndarray (2, n_seg)
        ``lo = min(x[:, seg[:, 0]], x[:, seg[:, 1]])`` and the max likewise; for a
        3-node segment also over its Bezier control point ``2 x_mid - (x_start +
        x_end)/2``: the curve lies in the hull of its control polygon, so the box
        holds the whole curve.
    """
    x = np.asarray(x, dtype=float)
    seg = np.asarray(seg, dtype=np.int64)
    if seg.ndim != 2 or seg.shape[1] not in (2, 3):
        seg = seg.reshape(-1, 2)
    a, b = x[:, seg[:, 0]], x[:, seg[:, 1]]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    if seg.shape[1] == 3:
        c = 2.0 * x[:, seg[:, 2]] - 0.5 * (a + b)
        lo, hi = np.minimum(lo, c), np.maximum(hi, c)
    return lo, hi


def _check_margin(margin: float) -> float:
    margin = float(margin)
    if not np.isfinite(margin) or margin < 0.0:
        raise ValueError(f"margin must be a finite number >= 0, got {margin}")
    return margin


def _overlap(lo_a, hi_a, lo_b, hi_b, ia, ib, margin):
    """Exact test of the inflated-box overlap for index arrays ia, ib."""
    return np.all((lo_a[:, ia] - margin <= hi_b[:, ib])
                  & (lo_b[:, ib] <= hi_a[:, ia] + margin), axis=0)


def box_pairs(lo_a: np.ndarray, hi_a: np.ndarray, lo_b: np.ndarray, hi_b: np.ndarray,
              margin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """All pairs (i, j) of boxes ``a_i``, ``b_j`` that overlap after inflating by ``margin``.

    Parameters
    ----------
    lo_a, hi_a : ndarray (2, n_a)
        Lower and upper corners of the first set of boxes.
    lo_b, hi_b : ndarray (2, n_b)
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
        ta, tb = cKDTree(ca[:, small_a].T), cKDTree(cb[:, small_b].T)
        # widen by round-off of the centres so that touching boxes are kept;
        # the exact test below decides
        scale = max(np.abs(ca).max(), np.abs(cb).max(), r)
        hits = ta.sparse_distance_matrix(tb, r + 1e-12 * scale + 1e-300, p=np.inf,
                                         output_type="ndarray")
        i = small_a[hits["i"].astype(np.int64)]
        j = small_b[hits["j"].astype(np.int64)]
        ia_parts.append(i)
        ib_parts.append(j)
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
                  margin_m: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Candidate slave/master segment pairs whose bounding boxes come within ``margin``.

    With per-segment margins the slave box ``i`` is inflated by
    ``margin + margin_s[i]`` and the master box ``j`` by ``margin_m[j]``: the pair
    is a candidate when the boxes come within ``margin + margin_s[i] + margin_m[j]``
    (e.g. the two element lengths: a local reach on graded meshes, where a global
    one pairs every fine slave element with every master element within the
    largest element length).

    Parameters
    ----------
    xs : ndarray (2, n_s)
        Slave node coordinates.
    seg_s : int ndarray (n_seg_s, 2)
        Slave segments (indices into the slave nodes).
    xm : ndarray (2, n_m)
        Master node coordinates.
    seg_m : int ndarray (n_seg_m, 2)
        Master segments.
    margin : float
        Inflation of the slave boxes (>= 0).
    margin_s, margin_m : ndarray (n_seg_s,), (n_seg_m,), optional
        Further inflation of each slave and master box (>= 0).

    Returns
    -------
    i_s, i_m : int ndarray (n_pairs,)
        Indices of slave and master segments, sorted by ``i_s`` then ``i_m``.
    """
    with timed("search"):
        lo_s, hi_s = segment_boxes(xs, seg_s)
        lo_m, hi_m = segment_boxes(xm, seg_m)
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


def node_segment_pairs(xn: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, margin: float
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Candidate (node, master segment) pairs: the node lies in the segment's box inflated by ``margin``.

    Parameters
    ----------
    xn : ndarray (2, n)
        Node coordinates.
    xm : ndarray (2, n_m)
        Master node coordinates.
    seg_m : int ndarray (n_seg_m, 2)
        Master segments.
    margin : float
        Inflation (>= 0).

    Returns
    -------
    i_node, i_m : int ndarray (n_pairs,)
        Sorted by node then segment.
    """
    with timed("search"):
        xn = np.asarray(xn, dtype=float).reshape(2, -1)
        lo_m, hi_m = segment_boxes(xm, seg_m)
        return box_pairs(xn, xn, lo_m, hi_m, margin)


#: points per batch of :func:`distance_to_polyline` (each batch one box search)
_DIST_BATCH = 256


def distance_to_polyline(p: np.ndarray, x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Euclidean distance of each point ``p (2, n)`` to the segments ``seg`` of the
    nodes ``x (2, m)``: ``min_e |p - (x_1 + t (x_2 - x_1))|``, ``t`` clipped to [0, 1]
    (3-node segments: to their chords through the mid node, :func:`~skfem_mortar.core.chain.polyline`).

    The nearest vertex (a k-d tree) bounds each distance by ``d_v``; the closest
    segment then lies in its box inflated by ``d_v``, so the points, in batches
    sorted by ``d_v``, are paired with the segment boxes (:func:`box_pairs`) with
    the batch's largest ``d_v`` as margin, and the minimum is taken over those pairs only.
    """
    p = np.asarray(p, dtype=float).reshape(2, -1)
    out = np.empty(p.shape[1])
    if p.shape[1] == 0:
        return out
    seg = polyline(np.asarray(seg, dtype=np.int64))  # 3-node segments: their two chords
    d_v, _ = cKDTree(x.T).query(p.T)
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
