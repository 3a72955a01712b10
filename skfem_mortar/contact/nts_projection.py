"""Node-to-segment projection and partner search: the candidate pairs of slave nodes and
master segments (:func:`candidates`), the choice among them (:func:`choose_segments`)
and the closest-point projection (:func:`project`); :mod:`.nts` builds the gap on it,
:mod:`.slip` uses the same search.

Projection and partner search
-----------------------------
Every call redoes the search (:func:`skfem_mortar.contact.search.node_segment_pairs`,
O(n log n)): candidates are the master segments whose bounding boxes, inflated
by ``margin``, contain the slave node, plus the two segments at the master
vertex nearest to it (a kd-tree query), so a node far from every box (deep
penetration after a large Newton step) still finds its partner.  Of the
candidates the one at the smallest distance from its clipped projection
``x^M(clip(xi, 0, 1))`` wins; ties (a node facing a convex vertex between two
segments, both clipped to it) go to the segment whose unclipped ``xi`` is
nearest to ``[0, 1]``.  The gap is then the distance to that segment's line
with the unclipped ``xi`` (a smooth function for a fixed segment; the switch of
segment at a vertex makes g_N non-smooth there -- the known NTS defect;
:class:`NTS` passes the previous iteration's segments as ``prefer`` so that a
node keeps its segment within a small hysteresis ``stick``).  A node
whose projection falls off the free end of an open master chain
(``xi < -end_tolerance`` on the first segment or ``xi > 1 + end_tolerance`` on
"""
from __future__ import annotations

import numpy as np

from .cells import CellType, cell_type
from .curves import N_NEWTON, XI_LIMIT, cell_nodes, check_line, curve, ends, is_affine
from .projection import project as project_points
from .search import nearest_vertex, node_segment_pairs
from .segmentation import line_cells
from .surfaces import segment_normals, segments_at_nodes

__all__ = ["project", "candidates", "choose_segments", "curve_rows", "curve_arrays",
           "project_curves", "LOCK_STICK", "XI_LIMIT"]

LOCK_STICK = 0.5
"""Hysteresis width (fraction of the segment length) of a node locked at a reflex vertex."""


def candidates(xs: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, margin: float,
               halo: int = 0, cell: "str | CellType" = "line2") -> np.ndarray:
    """The candidate (slave node, master segment) pairs of the projection, as sorted
    keys ``node * n_seg + segment``: the segments whose boxes, inflated by ``margin``,
    hold the node, and the two segments at the master vertex nearest to it (so a
    node far from every box, deep penetration after a large Newton step, still
    finds its partner), with ``halo`` chain neighbours on each side of those two
    (the chain through the cells' corners, :func:`~.curves.ends`, of the master
    ``cell`` type).
    """
    n_s, n_seg = xs.shape[1], len(seg_m)
    i_n, i_e = node_segment_pairs(xs, xm, seg_m, margin)
    seg_m = ends(seg_m, cell)
    seg_of_end, seg_of_start = segments_at_nodes(seg_m, xm.shape[1])
    _, jn = nearest_vertex(xm, xs)
    k2 = np.concatenate([np.arange(n_s), np.arange(n_s)])
    e2 = np.concatenate([seg_of_start[jn], seg_of_end[jn]])
    near = [e2]
    back, ahead = e2, e2
    for _ in range(halo):  # previous segment of e: ending[seg[e, 0]]; next: starting[seg[e, 1]]
        back = np.where(back >= 0, seg_of_end[seg_m[np.maximum(back, 0), 0]], -1)
        ahead = np.where(ahead >= 0, seg_of_start[seg_m[np.maximum(ahead, 0), 1]], -1)
        near += [back, ahead]
    e2 = np.concatenate(near)
    k2 = np.tile(k2, len(near))
    ok = e2 >= 0
    return np.unique(np.concatenate([i_n * n_seg + i_e, k2[ok] * n_seg + e2[ok]]))



def choose_segments(i_n: np.ndarray, i_e: np.ndarray, xi: np.ndarray, dist: np.ndarray,
                    n_s: int, prefer: np.ndarray | None = None, stick: float = 0.05,
                    lock: np.ndarray | None = None) -> np.ndarray:
    """The winning candidate of every slave node that has one (shared by the linear
    and the curved projection, :func:`project` and
    projection onto curved cells, :func:`_project_curve`).

    Among the candidate pairs ``(i_n, i_e)`` (slave node, master segment) with the
    parameter ``xi`` along the segment (``[0, 1]`` inside, unclipped) and the
    distance ``dist`` to the clipped projection, each node keeps its ``prefer``
    segment while ``xi`` on it lies in ``[-stick, 1 + stick]`` (locked nodes:
    ``[-LOCK_STICK, 1 + LOCK_STICK]``); otherwise the smallest ``dist`` wins,
    ties to the smaller overshoot ``max(-xi, xi - 1, 0)``, then the lower index.

    Returns
    -------
    int ndarray
        Indices into the candidate arrays, one per node with a candidate, in
        increasing node order.
    """
    over = np.maximum(np.maximum(-xi, xi - 1.0), 0.0)
    if prefer is not None:
        prefer = np.asarray(prefer, dtype=np.int64).ravel()
        if prefer.shape != (n_s,):
            raise ValueError(f"prefer must have shape ({n_s},), got {prefer.shape}")
        inside = (xi >= -stick) & (xi <= 1.0 + stick)
        if lock is not None:
            lock = np.asarray(lock, dtype=bool).ravel()
            if lock.shape != (n_s,):
                raise ValueError(f"lock must have shape ({n_s},), got {lock.shape}")
            inside |= lock[i_n] & (xi >= -LOCK_STICK) & (xi <= 1.0 + LOCK_STICK)
        keep = (i_e == prefer[i_n]) & inside
    else:
        keep = np.zeros(i_n.shape, dtype=bool)
    order = np.lexsort((over, dist, ~keep, i_n))
    return order[np.unique(i_n[order], return_index=True)[1]]


def project(xs: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, margin: float | None = None,
            end_tolerance: float = 1e-8, prefer: np.ndarray | None = None,
            stick: float = 0.05, lock: np.ndarray | None = None,
            cell: "str | CellType" = "line2", mirrored: np.ndarray | None = None) -> dict:
    """Closest-point projection of every slave node on the master chain (cells of type ``cell``).

    An affine cell (:func:`~.curves.is_affine`, ``line2``) in closed form, any other
    line cell by Newton in the cell's coordinate (:func:`_project_curve`).

    Parameters
    ----------
    xs : ndarray (2, n_s)
        Slave node coordinates.
    xm : ndarray (2, n_m)
        Master node coordinates.
    seg_m : int ndarray (n_seg, 2)
        Master segments, oriented (outward normal on the right).
    margin : float, optional
        Box inflation of the search (default: the median master segment length).
    end_tolerance : float
        Tolerance on ``xi`` at the free ends of an open master chain (>= 0).
    prefer : int ndarray (n_s,), optional
        The segment of each node at the previous iteration (-1: none).  It is
        kept while the node's ``xi`` on it stays in ``[-stick, 1 + stick]``
        (hysteresis: a node at a master vertex with a kink would otherwise
        jump between the two segments from one Newton iteration to the next
        and Newton would never converge).
    stick : float
        Hysteresis width, a fraction of the segment length (>= 0).
    lock : bool ndarray (n_s,), optional
        Nodes that keep their ``prefer`` segment while their ``xi`` stays in
        ``[-LOCK_STICK, 1 + LOCK_STICK]`` (the closest-point projection then
        continues onto the segment's extension line).  Used by
        :class:`NTS` for a node caught at a reflex vertex of the master (see docs/robustness.md).
    cell : str or CellType
        The master cell type (a line cell of the table, default ``line2``).
    mirrored : bool ndarray (n_m,), optional
        Master nodes on a symmetry line (an axisymmetric model's axis ``r = 0``,
        :meth:`NTS.set_measure <skfem_mortar.contact.nts.NTS.set_measure>`): a chain
        end there is no free end, the surface continues in its mirror image, so a
        node beyond it keeps its segment (the extension line: a slave node on the
        axis over a master pole whose last segment the deformation tilts).  None:
        every chain end is free.

    Returns
    -------
    dict with ``segment`` (n_s,) master segment index, ``xi`` (n_s,) unclipped
    parameter, ``mask`` (n_s,) bool, ``n``/``e`` (2, n_s) master normal and
    tangent, ``l`` (n_s,) segment length, ``g`` (n_s,) normal gap; curved cells also
    ``xi_curve``, the parameter in the cell's ``[-1, 1]`` (``xi`` is ``(1 + xi_curve) / 2``).
    """
    _check_projection(stick, end_tolerance)
    cell = cell_type(cell)
    if not is_affine(cell):
        return _project_curve(xs, xm, seg_m, margin, end_tolerance, prefer, stick, lock, cell,
                              mirrored)
    n_s, n_m = xs.shape[1], xm.shape[1]
    nrm, lm = segment_normals(xm, seg_m)
    if margin is None:
        margin = float(np.median(lm)) if lm.size else 0.0
    seg_of_end, seg_of_start = segments_at_nodes(seg_m, n_m)
    key = candidates(xs, xm, seg_m, margin)
    i_n, i_e = key // len(seg_m), key % len(seg_m)
    # projection on each candidate
    x1, x2 = xm[:, seg_m[i_e, 0]], xm[:, seg_m[i_e, 1]]
    t = x2 - x1
    l2 = np.sum(t * t, axis=0)
    d1 = xs[:, i_n] - x1
    xi = np.sum(d1 * t, axis=0) / l2
    xp = np.where(xi <= 0, x1, np.where(xi >= 1, x2, x1 + xi * t))
    dist = np.hypot(*(xs[:, i_n] - xp))
    best = choose_segments(i_n, i_e, xi, dist, n_s, prefer, stick, lock)
    k, e, xi = i_n[best], i_e[best], xi[best]
    segment = np.full(n_s, -1, dtype=np.int64)
    segment[k] = e
    xi_all = np.zeros(n_s)
    xi_all[k] = xi
    mask = segment >= 0
    # has the node left the free end of an open master chain?
    is_first, is_last = _free_ends(seg_m, seg_of_end, seg_of_start, mirrored)
    es = np.where(mask, segment, 0)
    off = (is_first[es] & (xi_all < -end_tolerance)) | (is_last[es] & (xi_all > 1 + end_tolerance))
    mask &= ~off
    n = nrm[:, es]
    l = lm[es]
    ev = (xm[:, seg_m[es, 1]] - xm[:, seg_m[es, 0]]) / l
    g = np.sum((xs - xm[:, seg_m[es, 0]]) * n, axis=0)
    g = np.where(mask, g, 0.0)
    return {"segment": np.where(mask, segment, -1), "xi": xi_all, "mask": mask,
            "n": n, "e": ev, "l": l, "g": g}


def curve_rows(pr: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows of the gap (:func:`~.nts_gap.gap_eval`) of :func:`project`'s output: a
    row ``(node, segment, xi)`` per node in ``mask``, ``xi (1, n)`` in the cell's
    coordinate ``[-1, 1]`` (``2 xi - 1`` of an affine cell's ``[0, 1]``)."""
    k = np.flatnonzero(pr["mask"])
    xi = pr["xi_curve"][k] if "xi_curve" in pr else 2.0 * pr["xi"][k] - 1.0
    return k, pr["segment"][k], xi[None]


def _check(x: np.ndarray, seg: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[0] != 2:
        raise ValueError(f"{what} coordinates must have shape (2, n), got {x.shape}")
    seg = np.asarray(seg, dtype=np.int64)
    if seg.ndim == 1:                    # a flat list of (start, end) pairs
        seg = seg.reshape(-1, 2)
    if seg.size and (seg.min() < 0 or seg.max() >= x.shape[1]):
        raise ValueError(f"{what} segments must index nodes in [0, {x.shape[1]})")
    return x, seg



def curve_arrays(xs, seg_s, xm, seg_m, cells) -> tuple:
    """The checked arrays and the cell types ``(xs, seg_s, xm, seg_m, cs, cm)`` of an
    NTS call between curves (:func:`~.nts.evaluate`): coordinates ``(2, n)``, cells
    indexing them, line cells of degree at most 2 (:func:`~.curves.check_line`)."""
    xs, seg_s = _check(xs, seg_s, "slave")
    xm, seg_m = _check(xm, seg_m, "master")
    cs, cm = (check_line(c, "nts") for c in line_cells(seg_s, seg_m, cells))
    return xs, seg_s, xm, seg_m, cs, cm


def project_curves(xs, xm, seg_m, cell, margin, end_tolerance, prefer, stick, lock,
                    mirrored) -> dict:
    """:func:`project` in the argument order of the kinds' projections
    (:data:`~.nts.KIND_ENTRIES`)."""
    return project(xs, xm, seg_m, margin, end_tolerance, prefer, stick, lock, cell=cell,
                   mirrored=mirrored)


def _free_ends(chain: np.ndarray, seg_of_end: np.ndarray, seg_of_start: np.ndarray,
               mirrored: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Per master segment: whether it starts, and whether it ends, a free end of an open
    chain (no neighbour there, and not a ``mirrored`` node, :func:`project`)."""
    is_first = seg_of_end[chain[:, 0]] < 0
    is_last = seg_of_start[chain[:, 1]] < 0
    if mirrored is not None:
        is_first &= ~mirrored[chain[:, 0]]
        is_last &= ~mirrored[chain[:, 1]]
    return is_first, is_last


def _check_projection(stick: float, end_tolerance: float) -> None:
    if not (np.isfinite(stick) and stick >= 0):
        raise ValueError(f"stick must be a finite number >= 0, got {stick}")
    if not (np.isfinite(end_tolerance) and end_tolerance >= 0):
        raise ValueError(f"end_tolerance must be a finite number >= 0, got {end_tolerance}")


def _newton(xq: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, cell: CellType,
            i_e: np.ndarray) -> np.ndarray:
    """The closest points ``xi (m,)`` of the points ``xq (2, m)`` on the cells ``i_e``:
    the general Newton in the cell's coordinates (:func:`~.projection.project`, the
    one of faces too) from the chord's projection, every iterate within
    ``[-XI_LIMIT, XI_LIMIT]``."""
    c0, c1 = cell.corners
    a, b = xm[:, seg_m[i_e, c0]], xm[:, seg_m[i_e, c1]]
    t = b - a
    xi0 = 2.0 * np.sum((xq - a) * t, axis=0) / np.maximum(np.sum(t * t, axis=0), 1e-300) - 1.0
    xi0 = np.clip(xi0, -XI_LIMIT, XI_LIMIT)
    return project_points(xq, xm, seg_m, cell, i_e, xi0=xi0[None], max_iter=N_NEWTON,
                          limit=XI_LIMIT).xi[0]


def _project_curve(xs: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, margin: float | None,
                   end_tolerance: float, prefer: np.ndarray | None, stick: float,
                   lock: np.ndarray | None, cell: CellType,
                   mirrored: np.ndarray | None = None) -> dict:
    """:func:`project` onto curved line cells: Newton in the cell's coordinate
    (:func:`_newton`) on every candidate, the choice of
    :func:`choose_segments` with ``xi`` mapped to ``[0, 1]``, the distance to the
    projection clipped to the cell.  Except at a free end: a node that keeps its
    segment by the hysteresis keeps it up to ``stick`` beyond the end (the affine
    projection drops it beyond ``end_tolerance``); a slave end over the master end
    otherwise toggles in and out.  ``n``, ``e`` at the projection, ``l`` the chord."""
    n_s, n_m, n_seg = xs.shape[1], xm.shape[1], len(seg_m)
    chain = ends(seg_m, cell)
    chord = np.hypot(*(xm[:, chain[:, 1]] - xm[:, chain[:, 0]]))
    if margin is None:
        margin = float(np.median(chord)) if chord.size else 0.0
    seg_of_end, seg_of_start = segments_at_nodes(chain, n_m)
    key = candidates(xs, xm, seg_m, margin, cell=cell)
    i_n, i_e = key // n_seg, key % n_seg
    P = cell_nodes(xm, seg_m, i_e)
    xq = xs[:, i_n]
    xi_c = _newton(xq, xm, seg_m, cell, i_e)
    u = 0.5 * (1.0 + xi_c)                       # along the segment, [0, 1] inside
    (cx, cy), _, _ = curve(cell, P, np.clip(xi_c, -1.0, 1.0))
    dist = np.hypot(xq[0] - cx, xq[1] - cy)
    best = choose_segments(i_n, i_e, u, dist, n_s, prefer, stick, lock)
    k, e = i_n[best], i_e[best]
    segment = np.full(n_s, -1, dtype=np.int64)
    segment[k] = e
    xi_all = np.zeros(n_s)
    xi_all[k] = xi_c[best]
    mask = segment >= 0
    is_first, is_last = _free_ends(chain, seg_of_end, seg_of_start, mirrored)
    es = np.where(mask, segment, 0)
    u_all = 0.5 * (1.0 + xi_all)
    # a node that kept its segment (the hysteresis ``prefer``) stays on it within
    # ``stick`` beyond a free end too: sliding off by round-off-sized amounts (a
    # slave end over the master end) would toggle it on and off every iteration
    kept = np.zeros(n_s, dtype=bool)
    if prefer is not None:
        kept = mask & (segment == prefer)
    tol = np.where(kept, max(stick, end_tolerance), end_tolerance)
    off = (is_first[es] & (u_all < -tol)) | (is_last[es] & (u_all > 1 + tol))
    mask &= ~off
    x, t, _ = curve(cell, cell_nodes(xm, seg_m, es), xi_all)
    lt = np.hypot(t[0], t[1])
    e_vec = np.vstack(t) / np.where(lt > 0, lt, 1.0)
    n = np.vstack([e_vec[1], -e_vec[0]])
    g = np.where(mask, np.sum((xs - np.vstack(x)) * n, axis=0), 0.0)
    return {"segment": np.where(mask, segment, -1), "xi": u_all, "xi_curve": xi_all,
            "mask": mask, "n": n, "e": e_vec, "l": chord[es], "g": g}
