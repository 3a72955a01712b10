"""The 3D mortar segmentation: slave/master face pairs into triangular integration cells.

The second implementation of the segmentation protocol
(:mod:`~skfem_mortar.contact.segmentation`; the first is the 2D
:func:`~skfem_mortar.contact.mortar_quadratic_segmentation.segment_lines`), for
surface cells (``dim`` 2: tri3 and quad4 faces of tet1 and hex1 bodies).  Values only:
what a kernel differentiates is stated below and in :func:`clip_vertex_points`.

For each candidate slave/master face pair of the search (:func:`~skfem_mortar.contact.
search.segment_pairs`, O(n log n)):

1. **Auxiliary plane** of the slave face (Popp et al., 4C): through the face's centre
   ``x_0 = x_s(xi_c)`` (``xi_c`` the mean of the reference corners: ``(1/3, 1/3)``,
   ``(0, 0)``) with the face's own unit normal there, ``n_0 = v(xi_c) / |v(xi_c)|``,
   ``v = T_1 x T_2`` (the face's geometry, not the averaged nodal normals: those are
   the kernel's, for the gap).  In-plane axes ``t_1`` (the face's first edge with its
   ``n_0`` part removed, normalized) and ``t_2 = n_0 x t_1``; plane coordinates
   ``u = ((x - x_0).t_1, (x - x_0).t_2)``, which is the projection along ``n_0``.
2. **Facing**: a pair is kept when the master face's centre normal ``n_m`` has
   ``n_m . n_0 < 0`` (the faces look at each other, as in 4C); else it is dropped.
3. **Polygons**: the corners of both faces in plane coordinates, the master's order
   reversed when its projection runs clockwise (it does for a facing master).  A
   quad4 whose projected corners are not strictly convex (a corner's sine
   ``(e_in x e_out) / (|e_in| |e_out|)`` below
   :data:`~skfem_mortar.contact.clipping.SPLIT_SINE`; a planar face projects onto a
   convex polygon, the projection being affine, so this needs a warp comparable to
   the projected face's width) is split at that corner ``r`` into the
   triangles ``(r, r+1, r+2)`` and ``(r, r+2, r+3)``; the diagonal is line code
   ``4 + r mod 2`` below.  A convex projected bilinear quad is the one-to-one
   image of its face: its straight edges project to straight edges, so the polygon
   is the projection of the face exactly, warped or not.
4. **Clipping** (:func:`~skfem_mortar.contact.clipping.clip_polygons`,
   Sutherland-Hodgman, the master polygon cut by the slave's edges) and a fan of
   triangles from the first clip vertex (:func:`~skfem_mortar.contact.clipping.
   fan_cells`; cells of at most ``AREA_TOL`` times the slave polygon's area dropped).
5. **Back to the faces**: each clip vertex ``q`` (on the plane) in slave and master
   coordinates by Newton along ``n_0``: ``t_a . (x(xi) - q) = 0``, ``a = 1, 2``,
   Jacobian ``t_a . T_b(xi)`` (one step on an affine face, a few on a bilinear one),
   from the reference centre (a face's own triangle: its barycentric point); a
   slave vertex's slave coordinates and a master vertex's master coordinates are the
   reference corners exactly.

Origins and what they depend on
-------------------------------
``origin`` and ``src`` per cell vertex (``src[..., 0]`` slave, ``src[..., 1]`` master,
-1 unused):

* :data:`SLAVE_VERTEX`, ``(i, -1)``: ``q = P(X_s,i)``, ``P(x) = x - ((x - x_0).n_0) n_0``;
* :data:`MASTER_VERTEX`, ``(-1, j)``: ``q = P(X_m,j)``;
* :data:`EDGE_INTERSECTION`, ``(i, j)``: the slave line ``i`` and the master line ``j``
  meet, ``q = P(a + t (b - a))``, ``t = [(c - a) x (d - c)].n_0 / [(b - a) x (d - c)].n_0``
  with ``a, b`` and ``c, d`` the lines' corners.  Line ``i < k`` is the face edge from
  corner ``i`` to ``i + 1``; line ``4`` and ``5`` of a split quad4 are the diagonals
  ``(0, 2)`` and ``(1, 3)``.

``x_0`` and ``n_0`` are functions of the slave face's nodes, so every vertex (and
every point of a cell: its slave and master coordinates by the implicit function of
step 5) depends on the slave face's and the master face's nodes only, at most 8 nodes
(24 variables); the gap's nodal normals bring in more, in the kernel.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .cell_map import cell_normals, cell_points, check_connectivity
from .cells import CellType, cell_type
from .clipping import boxes_meet, clip_polygons, convex_parts, fan_cells, polygon_areas
from .segmentation import (EDGE_INTERSECTION, MASTER_VERTEX, SLAVE_VERTEX,
                           check_kernel_cells, register_default)

__all__ = ["FaceSegmentation", "segment_faces", "clip_vertex_points", "auxiliary_planes",
           "line_corners", "FACES"]

#: the face cells the 3D segmentation handles
FACES = ("tri3", "quad4")
#: Newton along n_0 stops after a step below this (reference coordinates; quadratic
#: convergence leaves round-off after it, while steps stall at about 1e-14)
NEWTON_TOL = 1e-12
#: most Newton steps of the back-mapping
NEWTON_STEPS = 30
#: candidate pairs segmented at once: the peak of the temporary arrays is about 0.4 kB
#: per pair (``benchmarks/segmentation3d.py``), so about 20 MB a chunk
CHUNK_PAIRS = 50_000


@dataclass
class FaceSegmentation:
    """Triangular integration cells of a 3D slave/master surface pair (values).

    The 3D form of :class:`~skfem_mortar.contact.segmentation.Segmentation`: the same
    ``e_s``, ``e_m``, ``n``, ``origin``, ``vertices()``, ``frozen`` and
    ``candidates``; three vertices per cell in two reference coordinates.

    Attributes
    ----------
    e_s, e_m : int ndarray (n,)
        Slave and master parent face of each cell.
    xi, xi_m : ndarray (n, 3, 2)
        The cell's vertices (counter-clockwise about ``n_0``) in slave and in master
        reference coordinates.
    origin : int ndarray (n, 3)
        :data:`SLAVE_VERTEX`, :data:`MASTER_VERTEX` or :data:`EDGE_INTERSECTION`.
    src : int ndarray (n, 3, 2)
        The slave and master corner or line of each vertex (module docstring).
    u : ndarray (n, 3, 2)
        The vertices in the auxiliary plane's coordinates.
    area : ndarray (n,)
        The cells' areas in the auxiliary plane.
    x0, normal : ndarray (n_seg_s, 3)
        Each slave face's auxiliary plane: its centre and unit normal ``n_0``.
    axes : ndarray (n_seg_s, 2, 3)
        The plane's axes ``t_1``, ``t_2``.
    converged : bool
        Every back-mapping Newton converged.
    frozen : bool
    candidates : (i_s, i_m) or None
        The searched candidate pairs, None when the pairs were given.
    """

    e_s: np.ndarray
    e_m: np.ndarray
    xi: np.ndarray
    xi_m: np.ndarray
    origin: np.ndarray
    src: np.ndarray
    u: np.ndarray
    area: np.ndarray
    x0: np.ndarray
    normal: np.ndarray
    axes: np.ndarray
    converged: bool = True
    frozen: bool = True
    candidates: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def n(self) -> int:
        """Number of integration cells."""
        return int(self.e_s.size)

    def vertices(self) -> tuple[np.ndarray, np.ndarray]:
        """The vertices in slave and in master coordinates, (n, 3 vertices, dim 2)."""
        return self.xi, self.xi_m

    def points(self) -> np.ndarray:
        """The vertices in space, on the auxiliary planes: ``x_0 + u_1 t_1 + u_2 t_2``,
        (n, 3, 3)."""
        return _plane_points(self.u, self.x0[self.e_s], self.axes[self.e_s])


def _plane_points(u: np.ndarray, x0: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``x_0 + u_1 t_1 + u_2 t_2`` for ``u (m, K, 2)``, ``x0 (m, 3)``, ``axes (m, 2, 3)``."""
    return x0[:, None, :] + np.einsum("mka,mad->mkd", u, axes)


def auxiliary_planes(x: np.ndarray, conn: np.ndarray, cell: "str | CellType"
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The auxiliary plane of each face (module docstring, step 1).

    Returns
    -------
    x0, normal : ndarray (n_cell, 3)
        Centre and unit normal (zero for a face of no area).
    axes : ndarray (n_cell, 2, 3)
        ``t_1`` and ``t_2 = n_0 x t_1``.
    """
    cell = cell_type(cell)
    centre = np.asarray(cell.ref_nodes)[:, list(cell.corners)].mean(axis=1, keepdims=True)
    x0 = cell_points(x, conn, cell, centre)[:, :, 0].T
    n0 = cell_normals(x, conn, cell)[0].T
    e = x[:, conn[:, 1]].T - x[:, conn[:, 0]].T
    e = e - np.sum(e * n0, axis=1, keepdims=True) * n0
    size = np.linalg.norm(e, axis=1, keepdims=True)
    t1 = e / np.where(size > 0, size, 1.0)
    return x0, n0, np.stack([t1, np.cross(n0, t1)], axis=1)


def line_corners(k: int) -> np.ndarray:
    """The corners ``(k + 2, 2)`` of each line code of a face of ``k`` corners: edge
    ``i`` is ``(i, i + 1 mod k)``, codes ``k`` and ``k + 1`` the diagonals ``(0, 2)``
    and ``(1, 3)`` (quad4's only)."""
    edges = [(i, (i + 1) % k) for i in range(k)]
    return np.array(edges + [(0, 2), (1, 3)], dtype=np.int64)


def _line_code(a: np.ndarray, b: np.ndarray, k: np.ndarray) -> np.ndarray:
    """The line code of the corners ``a -> b`` of faces of ``k`` corners."""
    return np.where(b == (a + 1) % k, a, np.where(a == (b + 1) % k, b, k + np.minimum(a, b)))


def _gather(U: np.ndarray, rows: np.ndarray, vmap: np.ndarray) -> np.ndarray:
    """The polygons ``U[rows]`` at the corners ``vmap`` (unused slots zero)."""
    out = U[rows[:, None], np.maximum(vmap, 0)]
    out[vmap < 0] = 0.0
    return out


def _pair_subs(e_s_sub, n_sub_s, first_s, n_sub_m, first_m):
    """Every combination of a pair's slave and master sub-polygons: pair, slave
    sub-polygon and master sub-polygon of each (ragged, vectorized)."""
    n_sub_s = n_sub_s[e_s_sub]
    total = n_sub_s * n_sub_m
    pair = np.repeat(np.arange(total.size), total)
    local = np.arange(pair.size) - np.repeat(np.cumsum(total) - total, total)
    a, b = local // n_sub_m[pair], local % n_sub_m[pair]
    return pair, first_s[e_s_sub[pair]] + a, first_m[pair] + b


def _counts_first(owner: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    counts = np.bincount(owner, minlength=n)
    return counts, np.cumsum(counts) - counts


def _newton_back(cell: CellType, P: np.ndarray, q: np.ndarray, axes: np.ndarray,
                 xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reference coordinates ``xi (2, N)`` of the points ``q (N, 3)`` projected along
    the plane normal onto faces of nodes ``P (N, k, 3)``: ``t_a . (x(xi) - q) = 0``
    (module docstring, step 5), from ``xi``; and whether each converged."""
    done = np.zeros(q.shape[0], dtype=bool)
    Pa = np.einsum("Nkd,Nad->aNk", P, axes)          # the nodes' plane coordinates
    qa = np.einsum("Nd,Nad->aN", q, axes)
    for _ in range(NEWTON_STEPS):
        N, G = cell.shape(xi), cell.dshape(xi)
        r = np.stack([sum(Pa[a, :, k] * N[k] for k in range(N.shape[0])) - qa[a]
                      for a in range(2)], axis=1)
        J = np.stack([np.stack([sum(Pa[a, :, k] * G[k, b] for k in range(N.shape[0]))
                                for b in range(2)], axis=1) for a in range(2)], axis=1)
        det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
        det = np.where(det != 0, det, 1.0)
        step = -np.stack([J[:, 1, 1] * r[:, 0] - J[:, 0, 1] * r[:, 1],
                          J[:, 0, 0] * r[:, 1] - J[:, 1, 0] * r[:, 0]]) / det
        step[:, done] = 0.0
        xi = xi + step
        done |= np.max(np.abs(step), axis=0) <= NEWTON_TOL
        if done.all():
            break
    return xi, done


def _start(cell: CellType, U: np.ndarray, vmap: np.ndarray, count: np.ndarray,
           u: np.ndarray) -> np.ndarray:
    """Newton's start ``(2, N)`` for plane points ``u (N, 2)`` in sub-polygons of
    corners ``U (N, 4, 2)``, ``vmap`` and ``count``: the barycentric point of a
    triangle's reference corners, the reference centre of a quadrilateral."""
    ref = np.asarray(cell.ref_nodes, dtype=float)
    centre = ref[:, list(cell.corners)].mean(axis=1)
    a, b, c = (U[:, i] for i in range(3))
    det = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    det = np.where(det != 0, det, 1.0)
    d = u - a
    l1 = (d[:, 0] * (c - a)[:, 1] - d[:, 1] * (c - a)[:, 0]) / det
    l2 = ((b - a)[:, 0] * d[:, 1] - (b - a)[:, 1] * d[:, 0]) / det
    R = ref[:, np.maximum(vmap[:, :3], 0)]                                  # (2, N, 3)
    bary = R[..., 0] + l1 * (R[..., 1] - R[..., 0]) + l2 * (R[..., 2] - R[..., 0])
    return np.where(count == 3, bary, centre[:, None])


def _coordinates(name: str, x) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[0] != 3 or not np.all(np.isfinite(x)):
        raise ValueError(f"{name} must be finite node coordinates of shape (3, n), "
                         f"got shape {x.shape}")
    return x


def _candidates(xs, seg_s, xm, seg_m, cells, pairs, margin, reach):
    """The candidate pairs: given, or searched (``margin``, else each face's
    bounding-box size plus ``reach``), and the searched ones (None when given)."""
    if pairs is not None:
        i_s, i_m = (np.asarray(p, dtype=np.int64).ravel() for p in pairs)
        if i_s.shape != i_m.shape or (i_s.size and (
                i_s.min() < 0 or i_s.max() >= len(seg_s) or i_m.min() < 0
                or i_m.max() >= len(seg_m))):
            raise ValueError("pairs must be two index arrays of one length, into the "
                             f"{len(seg_s)} slave and {len(seg_m)} master faces")
        return (i_s, i_m), None
    from .search import segment_boxes, segment_pairs
    if margin is None:
        reach = float(reach)
        if not (np.isfinite(reach) and reach >= 0):
            raise ValueError(f"reach must be a finite number >= 0, got {reach!r}")
        size = [np.max(hi - lo, axis=0) for lo, hi in
                (segment_boxes(xs, seg_s, cells[0]), segment_boxes(xm, seg_m, cells[1]))]
        found = segment_pairs(xs, seg_s, xm, seg_m, reach, size[0], size[1], *cells)
    else:
        found = segment_pairs(xs, seg_s, xm, seg_m, margin, cell_s=cells[0],
                              cell_m=cells[1])
    return found, found


def _corner_coords(x, conn, cell, x0, axes):
    """Plane coordinates ``(m, 4, 2)`` of the faces' corners (padded with zeros)."""
    U = np.zeros((conn.shape[0], 4, 2))
    corners = list(cell.corners)
    for d in range(3):                     # sum_d (X_d - x0_d) t_a,d, no einsum: m is large
        dX = x[d][conn[:, corners]] - x0[:, d:d + 1]
        U[:, :len(corners)] += dX[..., None] * axes[:, None, :, d]
    return U


def _local_labels(origin, index, vmap_s, cnt_s, k_s, vmap_m, cnt_m, k_m):
    """The clip vertices' ``src (m, K, 2)`` in the faces' corners and line codes from
    the sub-polygons' vertex and edge indices."""
    rows = np.arange(origin.shape[0])[:, None]
    a, b = np.maximum(index[..., 0], 0), np.maximum(index[..., 1], 0)
    cs, cm = vmap_s[rows, a], vmap_m[rows, b]
    ns = vmap_s[rows, (a + 1) % cnt_s[:, None]]
    nm = vmap_m[rows, (b + 1) % cnt_m[:, None]]
    src = np.full(index.shape, -1, dtype=np.int64)
    sv, mv, ei = origin == SLAVE_VERTEX, origin == MASTER_VERTEX, origin == EDGE_INTERSECTION
    src[..., 0][sv] = cs[sv]
    src[..., 1][mv] = cm[mv]
    src[..., 0][ei] = _line_code(cs, ns, k_s)[ei]
    src[..., 1][ei] = _line_code(cm, nm, k_m)[ei]
    return src


def _back_map(cell, x, conn, e, U, vmap, cnt, q, u, axes, corner):
    """Reference coordinates ``(N, 2)`` of the plane points ``q (N, 3)`` on faces ``e``
    (Newton along the plane normal, step 5), the reference corner exactly where
    ``corner >= 0``; and whether Newton converged everywhere."""
    if q.shape[0] == 0:
        return np.zeros((0, 2)), True
    ref = np.asarray(cell.ref_nodes, dtype=float)
    xi = ref[:, np.maximum(corner, 0)]
    todo = np.flatnonzero(corner < 0)
    P = np.transpose(x[:, conn[e[todo]]], (1, 2, 0))
    xi[:, todo], ok = _newton_back(cell, P, q[todo], axes[todo],
                                   _start(cell, U[todo], vmap[todo], cnt[todo], u[todo]))
    return xi.T, bool(np.all(ok))


def segment_faces(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                  cells: "tuple[str | CellType, str | CellType]",
                  pairs: tuple[np.ndarray, np.ndarray] | None = None,
                  margin: float | None = None, frozen: bool = True,
                  reach: float = 0.0) -> FaceSegmentation:
    """The 3D segmentation (:class:`~skfem_mortar.contact.segmentation.Segmenter`) of
    tri3 and quad4 faces: auxiliary plane, clipping, fan cells, back-mapping (module
    docstring).

    Parameters
    ----------
    xs, xm : ndarray (3, n_s), (3, n_m)
        Slave and master node coordinates.
    seg_s, seg_m : int ndarray (n_seg, n_nodes)
        Slave and master faces.
    cells : (CellType or str, CellType or str)
        The slave and master cell types, each tri3 or quad4.
    pairs : (i_s, i_m), optional
        Candidate face pairs; default searched
        (:func:`~skfem_mortar.contact.search.segment_pairs`).
    margin : float, optional
        The search's margin; default each face's bounding-box size plus ``reach``.
    frozen : bool
        Recorded for the kernel (as in 2D).
    reach : float
        See ``margin``.

    Raises
    ------
    ValueError
        When a cell type is not tri3 or quad4 (quadratic faces are not supported: use
        tet1 or hex1 bodies), coordinates or connectivity are not of the shapes above,
        or ``pairs`` index outside the faces.
    """
    cs, cm = cell_type(cells[0]), cell_type(cells[1])
    check_kernel_cells((cs, cm), FACES, "the 3D segmentation (quadratic faces are not "
                       "supported: use tet1 or hex1 bodies)")
    xs, xm = _coordinates("xs", xs), _coordinates("xm", xm)
    seg_s = check_connectivity(seg_s, cs, xs.shape[1])
    seg_m = check_connectivity(seg_m, cm, xm.shape[1])
    (i_s, i_m), candidates = _candidates(xs, seg_s, xm, seg_m, (cs, cm), pairs, margin, reach)
    x0, n0, axes = auxiliary_planes(xs, seg_s, cs)
    U_s = _corner_coords(xs, seg_s, cs, x0, axes)
    k_s = np.full(len(seg_s), len(cs.corners))
    slave = _Slave(cs, xs, seg_s, x0, axes, U_s, polygon_areas(U_s, k_s),
                   convex_parts(U_s, k_s))
    facing = np.sum(cell_normals(xm, seg_m, cm)[0].T[i_m] * n0[i_s], axis=1) < 0
    i_s, i_m = i_s[facing], i_m[facing]
    parts = [_segment_chunk(slave, cm, xm, seg_m, i_s[k:k + CHUNK_PAIRS], i_m[k:k + CHUNK_PAIRS])
             for k in range(0, max(i_s.size, 1), CHUNK_PAIRS)]
    out = [np.concatenate([p[j] for p in parts]) for j in range(8)]
    return FaceSegmentation(*out, x0, n0, axes, all(p[8] for p in parts), bool(frozen),
                            candidates)


@dataclass
class _Slave:
    """What the chunks share of the slave faces: the cell, nodes and faces, the
    auxiliary planes, the corners' plane coordinates, the polygons' areas, the
    sub-polygons (owner, corner map, count)."""

    cell: CellType
    x: np.ndarray
    conn: np.ndarray
    x0: np.ndarray
    axes: np.ndarray
    U: np.ndarray
    area: np.ndarray
    subs: tuple[np.ndarray, np.ndarray, np.ndarray]


def _segment_chunk(slave: _Slave, cm: CellType, xm: np.ndarray, seg_m: np.ndarray,
                   i_s: np.ndarray, i_m: np.ndarray) -> tuple:
    """Steps 3 to 5 of the module docstring for the facing pairs ``(i_s, i_m)``: the
    cells' ``e_s, e_m, xi, xi_m, origin, src, u, area`` and whether Newton converged."""
    cs, k_s, k_m = slave.cell, len(slave.cell.corners), len(cm.corners)
    U_m = _corner_coords(xm, seg_m[i_m], cm, slave.x0[i_s], slave.axes[i_s])
    near = boxes_meet(slave.U[i_s, :k_s], U_m[:, :k_m])
    i_s, i_m, U_m = i_s[near], i_m[near], U_m[near]
    own_s, vmap_s, cnt_s = slave.subs
    own_m, vmap_m, cnt_m = convex_parts(U_m, np.full(i_s.size, k_m))
    pair, sub_s, sub_m = _pair_subs(i_s, *_counts_first(own_s, len(slave.U)),
                                    *_counts_first(own_m, i_s.size))
    poly_s = _gather(slave.U, own_s[sub_s], vmap_s[sub_s])
    poly_m = _gather(U_m, own_m[sub_m], vmap_m[sub_m])
    clip = clip_polygons(poly_s, cnt_s[sub_s], poly_m, cnt_m[sub_m])
    cell_pair, slot, area = fan_cells(clip, np.abs(slave.area[i_s[pair]]))
    src = _local_labels(clip.origin, clip.index, vmap_s[sub_s], cnt_s[sub_s], k_s,
                        vmap_m[sub_m], cnt_m[sub_m], k_m)
    # every clip vertex of a kept cell, once: back to slave and master coordinates
    K = clip.u.shape[1]
    used = np.unique(cell_pair[:, None] * K + slot)
    r, c = used // K, used % K
    e_s, e_m = i_s[pair[r]], i_m[pair[r]]
    u, o, sv = clip.u[r, c], clip.origin[r, c], src[r, c]
    axes = slave.axes[e_s]
    q = slave.x0[e_s] + u[:, :1] * axes[:, 0] + u[:, 1:] * axes[:, 1]
    xi_s, ok_s = _back_map(cs, slave.x, slave.conn, e_s, poly_s[r], vmap_s[sub_s[r]],
                           cnt_s[sub_s[r]], q, u, axes, np.where(o == SLAVE_VERTEX, sv[:, 0], -1))
    xi_m, ok_m = _back_map(cm, xm, seg_m, e_m, poly_m[r], vmap_m[sub_m[r]], cnt_m[sub_m[r]],
                           q, u, axes, np.where(o == MASTER_VERTEX, sv[:, 1], -1))
    at = np.searchsorted(used, cell_pair[:, None] * K + slot)                  # (n, 3)
    cp = pair[cell_pair]
    return (i_s[cp], i_m[cp], xi_s[at], xi_m[at], o[at], sv[at], u[at], area,
            ok_s and ok_m)


def clip_vertex_points(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray,
                       seg_m: np.ndarray, cells: "tuple[str | CellType, str | CellType]",
                       seg: FaceSegmentation) -> np.ndarray:
    """The cells' vertices ``(n, 3, 3)`` on the auxiliary planes, computed from their
    origins alone (module docstring): the formulas a kernel differentiates, here in
    values (they reproduce :meth:`FaceSegmentation.points` to round-off).

    ``P(x) = x - ((x - x_0).n_0) n_0``; a slave or master vertex is ``P(X)``, an edge
    intersection ``P(a + t (b - a))`` with
    ``t = [(c - a) x (d - c)].n_0 / [(b - a) x (d - c)].n_0``.
    """
    cs, cm = cell_type(cells[0]), cell_type(cells[1])
    xs, xm = _coordinates("xs", xs), _coordinates("xm", xm)
    x0, n0 = seg.x0[seg.e_s][:, None, :], seg.normal[seg.e_s][:, None, :]
    Xs = np.transpose(xs[:, np.asarray(seg_s)[seg.e_s]], (1, 2, 0))[:, None]  # (n,1,k,3)
    Xm = np.transpose(xm[:, np.asarray(seg_m)[seg.e_m]], (1, 2, 0))[:, None]
    i, j = np.maximum(seg.src[..., 0], 0), np.maximum(seg.src[..., 1], 0)
    lines_s, lines_m = line_corners(len(cs.corners))[i], line_corners(len(cm.corners))[j]
    take = lambda X, k: np.take_along_axis(X, k[..., None, None], axis=2)[:, :, 0]  # noqa: E731
    a, b = take(Xs, lines_s[..., 0]), take(Xs, lines_s[..., 1])
    c, d = take(Xm, lines_m[..., 0]), take(Xm, lines_m[..., 1])
    num = np.sum(np.cross(c - a, d - c) * n0, axis=-1)
    den = np.sum(np.cross(b - a, d - c) * n0, axis=-1)
    edge = seg.origin == EDGE_INTERSECTION
    t = np.where(edge, num / np.where(edge & (den != 0), den, 1.0), 0.0)
    p = np.where(edge[..., None], a + t[..., None] * (b - a), 0.0)
    sv, mv = seg.origin == SLAVE_VERTEX, seg.origin == MASTER_VERTEX
    p = np.where(sv[..., None], take(Xs, np.where(sv, i, 0)), p)
    p = np.where(mv[..., None], take(Xm, np.where(mv, j, 0)), p)
    return p - np.sum((p - x0) * n0, axis=-1, keepdims=True) * n0


register_default(2, segment_faces)
