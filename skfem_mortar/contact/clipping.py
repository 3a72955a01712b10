"""Convex polygons clipped in a plane, vectorized over many polygon pairs (values).

The 3D mortar segmentation (:mod:`.segmentation3d`) projects a slave face and a
master face onto the slave face's auxiliary plane and intersects the two polygons
there.  This module does that intersection in plane coordinates ``u = (u_1, u_2)``
for ``m`` pairs at once: a *clip* polygon (the slave's) and a *subject* polygon (the
master's), both convex and counter-clockwise, each of at most :data:`MAX_CORNERS`
vertices, padded to a common width with a count per pair (a tri3 has 3 of 4 slots).

Sutherland-Hodgman
------------------
The subject polygon is cut by the line of each clip edge ``k`` in turn (from clip
vertex ``k`` to ``k + 1``, a loop over at most four edges, every pair at once):
a vertex ``v`` is kept when it lies on the inner (left) side::

    s(v) = e_k x (v - c_k) >= -tol |e_k|,     e_k = c_{k+1} - c_k,

and an edge ``S -> E`` whose ends lie on the two sides gives the point
``I = S + t (E - S)``, ``t = s(S) / (s(S) - s(E))`` (clamped to [0, 1]).  Each step adds
at most one vertex, so the result of two convex polygons of ``k_c`` and ``k_s`` vertices
has at most ``k_c + k_s`` (8 for two quadrilaterals).  ``tol`` (:data:`DIST_TOL`
times the clip polygon's diameter) counts a vertex on a clip line as inside, so a vertex
on an edge is kept as it is and makes no second, coincident vertex.

Origins
-------
Every vertex of the result records the *carrier* of its incoming edge: the subject
edge or the clip edge it lies on (an edge of the result is a piece of one of them).
A vertex is the meeting point of its incoming and outgoing carriers:

* two clip edges ``k - 1`` and ``k``: clip vertex ``k`` (:data:`SLAVE_VERTEX`);
* two subject edges ``j - 1`` and ``j``: subject vertex ``j`` (:data:`MASTER_VERTEX`);
* clip edge ``k`` and subject edge ``j``: their intersection
  (:data:`EDGE_INTERSECTION`, ``index = (k, j)``).

A vertex whose two carriers are one line or two edges of one polygon that do not
meet (only in degenerate polygons of no area: a vertex in the middle of an edge) is
dropped; it does not change the polygon.

Where three lines meet, or where a slave and a master edge are collinear, the two
carriers the clipping met first need not be the polygon's edges there, and a vertex
rebuilt from them moves, under a small motion, along a line that is not the
polygon's: the overlap (or the sum over the master faces around) is C1 there, but
the derivative of that description is not.  So after the clipping every vertex is
relabelled from the lines its two polygon edges lie on (:func:`_relabel`; an edge's
line is a slave edge when one holds both its ends, else a master edge; neighbours
are the nearest vertices farther than the tolerance): two slave edges, a slave
vertex; two master edges, a master vertex; one of each, their intersection.  A
collinear edge thus moves with the slave, consistently with the neighbouring pair
that only touches (no cell, nothing to a derivative).  Measured: a master edge
through a slave vertex (with a master vertex on the slave's opposite edge at the
same moment), the derivative of the overlap at the degenerate position was 0.035
(0.25) against 0.188 (0) on both sides, now equal (tests/test_points3d.py); the
kernel's G on aligned grids (master edges collinear with the slave's boundary, master
vertices on slave vertices and edges) was 3e-3 off the one-sided differences, now
4e-11 (H: one of the two one-sided differences where G itself has a kink).

Nearly parallel edges
---------------------
The intersection of a clip edge and a subject edge that meet at a small angle
``theta`` is ill-conditioned: the kernel rebuilds it from the two lines
(:func:`~skfem_mortar.contact.segmentation3d.clip_vertex_points`) with an error of
about ``eps h / sin(theta)`` along them, and a vertex moved along a line changes
the area of a fan cell whose apex lies off it.  Such a vertex (``|sin(theta)|`` below
:data:`PARALLEL_SINE`, ``1e-8 ~ sqrt(eps)``; an edge within ``DIST_TOL`` of a line
makes no intersection at all, so exactly collinear edges never get here) is dropped:
the polygon loses the triangle of the vertex and its two neighbours, of area at most
``1/2 l_1 l_2 sin(theta) < 1e-8 h^2 / 2``, while every vertex kept is rebuilt from its
origin to about ``1e-8 h`` at worst (``eps / sin(theta)``), to round-off on pairs
away from that near-degeneracy.

Convex parts
------------
A quadrilateral whose corners are not strictly convex in the plane (a projected
warped face) is cut at its reflex corner into two triangles first
(:func:`convex_parts`); a clockwise polygon (a projected master face) is reversed.

Integration cells
-----------------
The clip polygon is cut into triangles by a fan from its first vertex, cells
``(v_0, v_k, v_{k+1})``, ``k = 1 .. n - 2``.  A fan from a vertex (not from the
centroid, Popp et al.'s choice) keeps every cell vertex a clip vertex with one of the
three origins above, so the kernel differentiates three kinds of points and no
fourth (the centroid, a function of all the polygon's vertices); it gives ``n - 2``
cells instead of ``n``, and on a convex polygon no cell of negative area.  Cells of
area at most :data:`AREA_TOL` times the clip polygon's area are dropped (slivers of a
vertex on an edge, a polygon that only touches): what they carry is below the
round-off of the sum, and none of zero or negative area reaches a kernel.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .segmentation import EDGE_INTERSECTION, MASTER_VERTEX, SLAVE_VERTEX

__all__ = ["Clip", "clip_polygons", "fan_cells", "polygon_areas", "convex_parts",
           "boxes_meet", "MAX_CORNERS", "DIST_TOL", "AREA_TOL", "PARALLEL_SINE", "SPLIT_SINE"]

#: most vertices of an input polygon (quad4's corners)
MAX_CORNERS = 4
#: a vertex within this many clip-polygon diameters of a clip line counts as on it
DIST_TOL = 1e-12
#: integration cells of at most this many clip-polygon areas are dropped
AREA_TOL = 1e-12
#: edge intersections of lines meeting at a sine below this are dropped (module docstring)
PARALLEL_SINE = 1e-8
#: a quadrilateral with a corner sine below this is split in two (:func:`convex_parts`)
SPLIT_SINE = 1e-3


@dataclass
class Clip:
    """The intersections of ``m`` polygon pairs.

    Attributes
    ----------
    u : ndarray (m, K, 2)
        Vertices of each intersection, counter-clockwise, the first ``count`` valid
        (``K = k_c + k_s``).
    count : int ndarray (m,)
        Vertices of each intersection (0, or 3 and more).
    origin : int ndarray (m, K)
        :data:`SLAVE_VERTEX`, :data:`MASTER_VERTEX` or :data:`EDGE_INTERSECTION`
        (-1 past ``count``).
    index : int ndarray (m, K, 2)
        ``(k, -1)`` clip vertex ``k``; ``(-1, j)`` subject vertex ``j``; ``(k, j)``
        clip edge ``k`` and subject edge ``j`` (edge ``k`` runs from vertex ``k`` to
        ``k + 1``).
    """

    u: np.ndarray
    count: np.ndarray
    origin: np.ndarray
    index: np.ndarray


def polygon_areas(u: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Signed areas (m,) of polygons ``u (m, K, 2)`` of ``count`` vertices (shoelace
    ``1/2 sum_k u_k x u_{k+1}``, positive counter-clockwise)."""
    k = np.arange(u.shape[1])
    n = np.maximum(count, 1)[:, None]
    nxt = np.where(k[None, :] + 1 < n, k[None, :] + 1, 0)
    v = np.take_along_axis(u, nxt[..., None], axis=1)
    a = u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
    return 0.5 * np.where(k[None, :] < count[:, None], a, 0.0).sum(axis=1)


def _diameters(u: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Largest extent (m,) of each polygon's bounding box."""
    valid = (np.arange(u.shape[1])[None, :] < count[:, None])[..., None]
    hi = np.where(valid, u, -np.inf).max(axis=1)
    lo = np.where(valid, u, np.inf).min(axis=1)
    return np.maximum(hi - lo, 0.0).max(axis=1)


def _clip_step(V, C, n, a, e, tol, code):
    """One Sutherland-Hodgman step: polygons ``V (m, K, 2)`` (in-carriers ``C``,
    counts ``n``) cut by the lines through ``a (m, 2)`` along ``e (m, 2)``, keeping the
    left side (``s >= -tol``); new vertices on the line get in-carrier ``code (m,)``."""
    m, K = C.shape
    k = np.arange(K)[None, :]
    s = e[:, None, 0] * (V[..., 1] - a[:, None, 1]) - e[:, None, 1] * (V[..., 0] - a[:, None, 0])
    valid = k < n[:, None]
    prev = np.where(k == 0, np.maximum(n, 1)[:, None] - 1, k - 1)
    inside = s >= -tol[:, None]
    s_prev = np.take_along_axis(s, prev, axis=1)
    V_prev = np.take_along_axis(V, prev[..., None], axis=1)
    cross = valid & (inside != np.take_along_axis(inside, prev, axis=1))
    den = np.where(cross, s_prev - s, 1.0)
    t = np.clip(np.where(cross, s_prev / den, 0.0), 0.0, 1.0)
    I = V_prev + t[..., None] * (V - V_prev)
    C_I = np.where(inside, code[:, None], C)          # entering: along the clip line
    slots = np.stack([I, V], axis=2).reshape(m, 2 * K, 2)
    carriers = np.stack([C_I, C], axis=2).reshape(m, 2 * K)
    keep = np.stack([cross, valid & inside], axis=2).reshape(m, 2 * K)
    pos = np.cumsum(keep, axis=1) - 1
    V2, C2 = np.zeros_like(V), np.full_like(C, -1)
    rows = np.broadcast_to(np.arange(m)[:, None], keep.shape)
    V2[rows[keep], pos[keep]] = slots[keep]
    C2[rows[keep], pos[keep]] = carriers[keep]
    return V2, C2, keep.sum(axis=1)


def _labels(C, n, k_c, k_s):
    """Origins and indices of the vertices from their in- and out-carriers (carriers:
    subject edge ``j`` as ``j``, clip edge ``k`` as ``-1 - k``); the vertices whose
    carriers do not meet in one point get origin -1."""
    m, K = C.shape
    k = np.arange(K)[None, :]
    valid = k < n[:, None]
    nxt = np.where(k + 1 < n[:, None], k + 1, 0)
    a, b = C, np.take_along_axis(C, nxt, axis=1)            # incoming, outgoing
    origin = np.full((m, K), -1, dtype=np.int64)
    index = np.full((m, K, 2), -1, dtype=np.int64)
    for sub, kk, kind, col in ((a >= 0, k_s, MASTER_VERTEX, 1),
                               (a < 0, k_c, SLAVE_VERTEX, 0)):
        same = sub & ((b >= 0) == (a >= 0)) & valid
        ia, ib = (a, b) if kind == MASTER_VERTEX else (-1 - a, -1 - b)
        ok = same & (ib == (ia + 1) % np.maximum(kk, 1)[:, None]) & (ia != ib)
        origin[ok] = kind
        index[..., col][ok] = ib[ok]
    mixed = valid & ((a >= 0) != (b >= 0))
    origin[mixed] = EDGE_INTERSECTION
    index[..., 0][mixed] = np.where(a < 0, -1 - a, -1 - b)[mixed]
    index[..., 1][mixed] = np.where(a >= 0, a, b)[mixed]
    return origin, index


def _near_parallel(clip, k_c, subject, k_s, origin, index):
    """The edge intersections whose two lines meet at a sine below
    :data:`PARALLEL_SINE` (module docstring)."""
    rows = np.arange(origin.shape[0])[:, None]
    a, b = np.maximum(index[..., 0], 0), np.maximum(index[..., 1], 0)
    d_c = clip[rows, (a + 1) % k_c[:, None]] - clip[rows, a]
    d_s = subject[rows, (b + 1) % k_s[:, None]] - subject[rows, b]
    cross = d_c[..., 0] * d_s[..., 1] - d_c[..., 1] * d_s[..., 0]
    size = np.hypot(d_c[..., 0], d_c[..., 1]) * np.hypot(d_s[..., 0], d_s[..., 1])
    return (origin == EDGE_INTERSECTION) & (np.abs(cross) < PARALLEL_SINE * size)


def _compact(u, origin, index):
    """Drop the vertices of origin -1, keeping the order."""
    keep = origin >= 0
    count = keep.sum(axis=1)
    pos = np.cumsum(keep, axis=1) - 1
    rows = np.broadcast_to(np.arange(u.shape[0])[:, None], keep.shape)
    u2, o2 = np.zeros_like(u), np.full_like(origin, -1)
    i2 = np.full_like(index, -1)
    u2[rows[keep], pos[keep]] = u[keep]
    o2[rows[keep], pos[keep]] = origin[keep]
    i2[rows[keep], pos[keep]] = index[keep]
    return u2, count, o2, i2


def clip_polygons(clip: np.ndarray, k_c: np.ndarray, subject: np.ndarray,
                  k_s: np.ndarray) -> Clip:
    """The intersection of each convex polygon pair (module docstring).

    Parameters
    ----------
    clip : ndarray (m, 4, 2)
        The clip (slave) polygons, counter-clockwise, the first ``k_c`` slots valid.
    k_c : int ndarray (m,)
        Their vertex counts (3 or 4).
    subject : ndarray (m, 4, 2)
        The subject (master) polygons, counter-clockwise.
    k_s : int ndarray (m,)
        Their vertex counts (3 or 4).

    Returns
    -------
    Clip
        Vertices with their origins; ``count`` 0 where the polygons do not overlap.

    Raises
    ------
    ValueError
        When the arrays do not have the shapes above or a count is not 3 or 4.
    """
    clip, subject = np.asarray(clip, dtype=float), np.asarray(subject, dtype=float)
    k_c, k_s = np.asarray(k_c, dtype=np.int64), np.asarray(k_s, dtype=np.int64)
    m = clip.shape[0] if clip.ndim == 3 else -1
    for name, arr in (("clip", clip), ("subject", subject)):
        if arr.shape != (m, MAX_CORNERS, 2):
            raise ValueError(f"{name} must have shape (m, {MAX_CORNERS}, 2), got {arr.shape}")
    for name, kk in (("k_c", k_c), ("k_s", k_s)):
        if kk.shape != (m,) or np.any((kk < 3) | (kk > MAX_CORNERS)):
            raise ValueError(f"{name} must be ({m},) vertex counts in [3, {MAX_CORNERS}]")
    K = 2 * MAX_CORNERS
    V = np.zeros((m, K, 2))
    V[:, :MAX_CORNERS] = subject
    C = np.full((m, K), -1, dtype=np.int64)
    C[:, :MAX_CORNERS] = (np.arange(MAX_CORNERS)[None, :] - 1) % k_s[:, None]
    n = k_s.copy()
    tol = DIST_TOL * _diameters(clip, k_c)
    rows = np.arange(m)
    for k in range(MAX_CORNERS):
        act = k < k_c
        a = clip[:, k]
        e = clip[rows, np.where(k + 1 < k_c, k + 1, 0)] - a
        V2, C2, n2 = _clip_step(V, C, n, a, e, tol * np.hypot(e[:, 0], e[:, 1]),
                                np.full(m, -1 - k, dtype=np.int64))
        V = np.where(act[:, None, None], V2, V)
        C = np.where(act[:, None], C2, C)
        n = np.where(act, n2, n)
    origin, index = _labels(C, n, k_c, k_s)
    origin[_near_parallel(clip, k_c, subject, k_s, origin, index)] = -1
    u, count, origin, index = _compact(V, origin, index)
    _relabel(u, count, origin, index, (clip, k_c), (subject, k_s), tol)
    count = np.where(count >= 3, count, 0)
    return Clip(u, count, origin, index)


def _line_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of points ``p`` from the lines through ``a`` and ``b`` (``(..., 2)``)."""
    e = b - a
    cross = e[..., 0] * (p - a)[..., 1] - e[..., 1] * (p - a)[..., 0]
    return np.abs(cross) / np.maximum(np.hypot(e[..., 0], e[..., 1]), 1e-300)


def _next_slots(count: np.ndarray, u: np.ndarray, tol: np.ndarray, r: np.ndarray,
                c: np.ndarray, step: int = 1) -> np.ndarray:
    """The slot of each vertex ``(r, c)``'s next (``step`` 1) or previous (-1) polygon
    vertex farther than ``tol`` from it (a vertex kept twice, once per origin, is
    skipped)."""
    n, p, t = count[r], u[r, c], tol[r]
    out = (c + step) % n
    todo = np.linalg.norm(u[r, out] - p, axis=-1) <= t
    for s in range(2, u.shape[1]):
        if not todo.any():
            break
        cand = (c + s * step) % n
        far = todo & (np.linalg.norm(u[r, cand] - p, axis=-1) > t)
        out[far] = cand[far]
        todo &= ~far
    return out


def _edge_carriers(u, r, c, nxt, polys, t) -> tuple[np.ndarray, np.ndarray]:
    """The line each polygon edge ``(r, c) -> (r, nxt)`` lies on: ``kind`` 0 a clip
    (slave) edge, 1 a subject (master) edge, -1 none found, and its number; a slave
    edge where both hold (collinear edges)."""
    p, q, e = u[r, c], u[r, nxt], np.arange(r.size)
    kind, line = np.full(r.size, -1), np.full(r.size, -1)
    for side in (1, 0):                        # the slave's last: it wins on collinear edges
        P, n = polys[side][0][r], polys[side][1][r]
        for k in range(P.shape[1]):
            a, b = P[:, k], P[e, (k + 1) % n]
            on = (k < n) & (_line_distance(p, a, b) <= t) & (_line_distance(q, a, b) <= t)
            kind[on], line[on] = side, k
    return kind, line


def _relabel(u: np.ndarray, count: np.ndarray, origin: np.ndarray, index: np.ndarray,
             clip: tuple, subject: tuple, tol: np.ndarray) -> None:
    """Each vertex's origin from the lines its two polygon edges lie on (module
    docstring, Origins), in place: two slave edges meeting at their corner, a slave
    vertex; two master edges, a master vertex; one of each, their intersection (lines
    meeting at a sine below :data:`PARALLEL_SINE` keep the clipping's label)."""
    K = origin.shape[1]
    r, c = np.nonzero((count[:, None] >= 3) & (np.arange(K)[None, :] < count[:, None]))
    if r.size == 0:
        return
    t = tol[r]
    nxt = _next_slots(count, u, tol, r, c)
    kind, line = _edge_carriers(u, r, c, nxt, (clip, subject), t)
    at = np.full(origin.shape, -1)
    at[r, c] = np.arange(r.size)
    into = at[r, _next_slots(count, u, tol, r, c, -1)]   # the edge ending at each vertex
    has = (into >= 0) & (kind >= 0)
    has[has] &= kind[into[has]] >= 0
    k_in = np.where(has, kind[np.maximum(into, 0)], -1)
    l_in = np.where(has, line[np.maximum(into, 0)], -1)
    polys = (clip, subject)
    for side, code in ((0, SLAVE_VERTEX), (1, MASTER_VERTEX)):
        n = polys[side][1][r]
        corner = has & (k_in == side) & (kind == side) & (line == (l_in + 1) % n)
        origin[r[corner], c[corner]] = code
        index[r[corner], c[corner]] = -1
        index[r[corner], c[corner], side] = line[corner]
        u[r[corner], c[corner]] = polys[side][0][r[corner], line[corner]]
    mixed = has & (k_in >= 0) & (k_in != kind)
    ls = np.where(kind == 0, line, l_in)
    lm = np.where(kind == 1, line, l_in)
    e = np.arange(r.size)
    P, Q = clip[0][r], subject[0][r]
    d1 = P[e, (ls + 1) % polys[0][1][r]] - P[e, ls]
    d2 = Q[e, (lm + 1) % polys[1][1][r]] - Q[e, lm]
    sine = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.maximum(
        np.hypot(*d1.T) * np.hypot(*d2.T), 1e-300)
    mixed &= np.abs(sine) >= PARALLEL_SINE
    origin[r[mixed], c[mixed]] = EDGE_INTERSECTION
    index[r[mixed], c[mixed], 0] = ls[mixed]
    index[r[mixed], c[mixed], 1] = lm[mixed]


def fan_cells(clip: Clip, area_ref: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The integration cells of the clip polygons: a fan from each polygon's first
    vertex (module docstring), cells of area at most ``AREA_TOL * area_ref`` dropped.

    Parameters
    ----------
    clip : Clip
    area_ref : ndarray (m,)
        The area each pair's tolerance is relative to (the slave face's).

    Returns
    -------
    pair : int ndarray (n,)
        The pair of each cell.
    corner : int ndarray (n, 3)
        Its vertices' slots in ``clip.u[pair]`` (counter-clockwise).
    area : ndarray (n,)
        Its area, > ``AREA_TOL * area_ref[pair]``.
    """
    m, K = clip.origin.shape
    k = np.arange(1, K - 1)
    corner = np.stack(np.broadcast_arrays(np.zeros_like(k), k, k + 1), axis=-1)  # (K-2, 3)
    pair = np.repeat(np.arange(m), K - 2)
    corner = np.tile(corner, (m, 1))
    ok = corner[:, 2] < clip.count[pair]
    pair, corner = pair[ok], corner[ok]
    P = clip.u[pair[:, None], corner]                                     # (n, 3, 2)
    d1, d2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    area = 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    keep = area > AREA_TOL * np.asarray(area_ref, dtype=float)[pair]
    return pair[keep], corner[keep], area[keep]


def convex_parts(U: np.ndarray, k: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each polygon ``U (m, 4, 2)`` of ``k`` corners (3 or 4) as one or two convex
    counter-clockwise polygons of its corners: the polygon itself, its order reversed
    where it runs clockwise; a quadrilateral with a corner sine ``(e_in x e_out) /
    (|e_in| |e_out|)`` (signed by its orientation) below :data:`SPLIT_SINE` split at
    that corner ``r`` into ``(r, r+1, r+2)`` and ``(r, r+2, r+3)``.

    Returns
    -------
    owner : int ndarray (p,)
        The polygon each part comes from, ascending.
    vmap : int ndarray (p, 4)
        Its corners (-1 unused).
    count : int ndarray (p,)
        Its corner count.
    """
    m = U.shape[0]
    idx = np.arange(4)[None, :]
    sign = np.where(polygon_areas(U, k) >= 0, 1.0, -1.0)
    prev = np.where(idx == 0, k[:, None] - 1, idx - 1)
    nxt = np.where(idx + 1 < k[:, None], idx + 1, 0)
    e_in = U - np.take_along_axis(U, prev[..., None], axis=1)
    e_out = np.take_along_axis(U, nxt[..., None], axis=1) - U
    cross = e_in[..., 0] * e_out[..., 1] - e_in[..., 1] * e_out[..., 0]
    lens = np.linalg.norm(e_in, axis=2) * np.linalg.norm(e_out, axis=2)
    sine = sign[:, None] * cross / np.where(lens > 0, lens, 1.0)
    sine = np.where(idx < k[:, None], sine, np.inf)
    r = np.argmin(sine, axis=1)
    split = (k == 4) & (sine[np.arange(m), r] < SPLIT_SINE)
    whole = np.where(idx < k[:, None], idx, -1)
    tri_a = np.stack([r, r + 1, r + 2, r], axis=1) % 4
    tri_b = np.stack([r, r + 2, r + 3, r], axis=1) % 4
    tri_a[:, 3], tri_b[:, 3] = -1, -1
    owner = np.concatenate([np.flatnonzero(~split), np.flatnonzero(split),
                            np.flatnonzero(split)])
    vmap = np.concatenate([whole[~split], tri_a[split], tri_b[split]])
    count = np.where(vmap[:, 3] >= 0, 4, 3)
    order = np.argsort(owner, kind="stable")
    owner, vmap, count = owner[order], vmap[order], count[order]
    flip = sign[owner] < 0         # reverse to counter-clockwise: v_0, v_{c-1}, ..., v_1
    rev = np.where(count[:, None] == 4, [0, 3, 2, 1], [0, 2, 1, 3])
    vmap[flip] = np.take_along_axis(vmap[flip], rev[flip], axis=1)
    return owner, vmap, count


def boxes_meet(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Whether the bounding boxes of the plane polygons ``A (m, k_a, 2)`` and
    ``B (m, k_b, 2)`` meet, within ``DIST_TOL`` times their size (pairs that cannot
    overlap skip the clipping)."""
    lo_a, hi_a, lo_b, hi_b = A.min(axis=1), A.max(axis=1), B.min(axis=1), B.max(axis=1)
    tol = DIST_TOL * np.maximum((hi_a - lo_a).max(axis=1), (hi_b - lo_b).max(axis=1))
    return np.all((lo_a <= hi_b + tol[:, None]) & (lo_b <= hi_a + tol[:, None]), axis=1)
