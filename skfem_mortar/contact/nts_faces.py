"""Node-to-segment contact on surface cells (``tri3``, ``quad4``: the faces of 3D bodies):
the closest-point projection of slave nodes onto master faces, the choice among
neighbouring faces, the normal gap and its exact first and second derivatives.

The 2D kernel's rules (:mod:`.nts_projection`) carried over the cell's dimension:

* **Candidates**: the master faces whose boxes, inflated by ``margin``, hold the node
  (:func:`~.search.node_segment_pairs`, O(n log n)), and every face at the master
  vertex nearest to it (a kd-tree query), so a node far from every box still finds
  its partner.
* **Projection** on each candidate: Newton in the face's two coordinates
  (:func:`~.projection.project`; a warped ``quad4`` included), its map extended
  beyond the reference cell.  The *overshoot* ``o`` of ``xi`` is its distance
  outside the reference cell in units of the cell's size (tri3: ``max(-xi_1, -xi_2,
  xi_1 + xi_2 - 1, 0)``; quad4: ``max(|xi_1| - 1, |xi_2| - 1, 0) / 2``).
* **Choice** (:func:`~.nts_projection.choose_segments` on ``-o``): the face of the
  previous iteration is kept while ``o <= stick`` (hysteresis); otherwise the
  smallest distance from the node to the face's nearest point (the Newton point
  when inside, else the nearest point of its boundary edges, which are straight on
  tri3 and quad4) wins, ties (below) to the smaller overshoot, then the face whose
  centroid is nearest, then the lower face index.
  So a node over the inside of a face takes it; a node outside every face near an
  edge or vertex takes a face through the nearest point of the surface.
* **Ties**: distances within :data:`TIE_TOL` times the faces' size count as equal,
  and so do overshoots within ``TIE_TOL``; faces still tied go to the one whose
  centroid is nearest the node, then the lower index (so a node and its mirror image
  pick mirror images of faces, whatever the round-off, and keep them by the
  hysteresis).  The node's other candidate faces whose nearest point lies as far
  from it as the chosen face's (within ``TIE_TOL`` h, and not beyond a free edge)
  share the node with it: its gap, ``G`` and ``H`` are the mean over
  these faces (:func:`tied_faces`).  A node above the edge or vertex where faces
  meet at an angle (a ridge or valley of the master) is equally far from them, and
  the mean is the centre of the gap's generalized gradient there; picking one face
  (the lower index) would push the node sideways along that face's normal.  So a
  mesh and its mirror image give mirrored answers: a whole (or half) model equals
  its half (or quarter) with symmetry planes, where the faces across the plane are
  the mirror images of the faces at it.
* **Free edges**: a node whose chosen face's nearest point lies on a free edge of the
  master (an edge of one face only, not on a symmetry plane: ``mirrored`` nodes at
  both ends) with ``o > end_tolerance`` has left the master: out of ``mask``
  (kept while ``o <= stick`` on the face it had at the last iteration).
* **Gap** with the unclipped ``xi`` on the chosen face (and on every tied one):
  ``g = n(xi) . (x_s - x(xi))``, ``n = T_1 x T_2 / |T_1 x T_2|``, ``T_j = dx/dxi_j``
  (``n`` outward for counter-clockwise faces, :mod:`.boundary_cells`), with its
  exact ``G`` and ``H``: the one gap of every cell type, :mod:`.nts_gap`
  (:func:`face_rows` hands it the rows).

Tributary weights ``a_A = int N_A w dGamma`` over the slave faces by the cell's
quadrature (:func:`face_weights`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .cells import CellType, cell_type
from .projection import project as project_points
from .search import nearest_vertex, node_segment_pairs

__all__ = ["FACE_CELLS", "overshoot", "face_candidates", "project_faces", "face_rows",
           "face_weights", "free_edges", "face_sizes", "face_edges",
           "face_distances", "check_face", "touching_faces", "tied_faces", "TIE_TOL"]

#: the surface cells NTS projects onto (linear faces; quadratic ones are refused)
FACE_CELLS = ("tri3", "quad4")

#: quadrature degree of the tributary weights ``int N_A dGamma``: exact on flat faces
#: (tri3, parallelogram quad4); the area element of a warped quad4 is the root of a
#: polynomial, and degree 9 (5 x 5 points) leaves a relative error of 9e-16 at a warp of
#: 0.1 cell and 2e-10 at 0.3 (degree 4: 7e-10 and 7e-7)
WEIGHT_DEGREE = 9


#: the nodes' ties between faces (module docstring): two faces are as far from a node
#: when their distances differ by at most this times the faces' size.  Far above the
#: round-off of the distances (1e-16 h: mirror images of a face give the same
#: distance to that), far below any gap that matters
TIE_TOL = 1e-9

def check_face(cell: "str | CellType", what: str) -> CellType:
    """``cell`` if NTS projects onto it (:data:`FACE_CELLS`), else ValueError naming
    the feature and the alternative."""
    cell = cell_type(cell)
    if cell.name not in FACE_CELLS:
        raise ValueError(f"{what}: contact on {cell.name} faces (quadratic 3D elements) is "
                         f"not offered yet; use linear elements (tet1 or hex1: tri3 or "
                         f"quad4 faces)")
    return cell


_EDGE_FUNCTIONS: dict[str, list] = {}


def _edge_functions(cell: CellType) -> list[tuple[np.ndarray, float, float]]:
    """``(nu, c, w)`` of each edge of the reference cell's corner polygon
    (counter-clockwise): ``nu^T xi - c`` is 0 on the edge's line and positive
    outside, ``-w`` at the corner farthest inside (:func:`overshoot`); made once per
    cell type."""
    out = _EDGE_FUNCTIONS.get(cell.name)
    if out is None:
        ref = np.asarray(cell.ref_nodes, dtype=float)[:, list(cell.corners)]
        out = []
        for a, b in zip(ref.T, np.roll(ref, -1, axis=1).T):
            nu = np.array([b[1] - a[1], a[0] - b[0]])          # outward: (e_y, -e_x)
            c = float(nu @ a)
            out.append((nu, c, float(np.max(c - nu @ ref))))
        _EDGE_FUNCTIONS[cell.name] = out
    return out


def _term(coef: float, x: np.ndarray) -> np.ndarray | None:
    """``coef * x``, exactly, without the product where ``coef`` is 0 or +-1."""
    return None if coef == 0 else x if coef == 1 else -x if coef == -1 else coef * x


def overshoot(cell: CellType, xi: np.ndarray) -> np.ndarray:
    """How far ``xi (2, m)`` lies outside the reference cell, in units of its size: the
    largest ``(nu_e^T xi - c_e) / w_e`` over its edges ``e`` (:func:`_edge_functions`:
    0 on the edge, -1 at the corner farthest inside), 0 inside.  tri3: ``max(-xi_1,
    -xi_2, xi_1 + xi_2 - 1, 0)``; quad4: ``max(|xi_1| - 1, |xi_2| - 1, 0) / 2``."""
    o = np.zeros(xi.shape[1:])
    for nu, c, w in _edge_functions(cell):
        terms = [t for t in (_term(nu[j], xi[j]) for j in range(len(nu))) if t is not None]
        v = terms[0] if len(terms) == 1 else sum(terms[1:], terms[0])
        if c:
            v = v - c
        np.maximum(o, v if w == 1 else v / w, out=o)
    return o


def face_sizes(x: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The longest corner-to-corner edge of each face (its size ``h``)."""
    P = x[:, faces]                                          # (d, n_f, k)
    e = P - np.roll(P, -1, axis=2)
    return np.sqrt(np.max(np.sum(e * e, axis=0), axis=1))


def _faces_at_nodes(faces: np.ndarray, n: int) -> sp.csr_matrix:
    """Node -> face incidence (n, n_f)."""
    k = faces.shape[1]
    return sp.csr_matrix((np.ones(faces.size), (faces.ravel(), np.repeat(np.arange(len(faces)), k))),
                         shape=(n, len(faces)))


def face_candidates(xs: np.ndarray, xm: np.ndarray, faces: np.ndarray, cell: CellType,
                    margin: float) -> np.ndarray:
    """Candidate (slave node, master face) pairs as sorted keys ``node * n_f + face``:
    the faces whose boxes, inflated by ``margin``, hold the node, and every face at
    the master vertex nearest to it."""
    n_f = len(faces)
    i_n, i_e = node_segment_pairs(xs, xm, faces, margin, cell)
    _, jn = nearest_vertex(xm, xs)
    inc = _faces_at_nodes(faces, xm.shape[1])[jn].tocoo()
    return np.unique(np.concatenate([i_n * n_f + i_e, inc.row * n_f + inc.col]))


def _edge_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of points ``p`` from the segments ``a -> b`` (all (d, m))."""
    t = b - a
    s = np.clip(np.sum((p - a) * t, axis=0) / np.maximum(np.sum(t * t, axis=0), 1e-300), 0, 1)
    r = p - a - s * t
    return np.sqrt(np.sum(r * r, axis=0))


def _nearest_on_face(p, xm, faces, cell, pr) -> tuple[np.ndarray, np.ndarray]:
    """Distance from ``p (d, m)`` to the nearest point of each candidate face and the
    local edge holding it (-1 inside)."""
    edges = [(a, b) for a, b in zip(cell.corners, np.roll(cell.corners, -1))]
    P = xm[:, faces]                                           # (d, m, k)
    de = np.stack([_edge_distance(p, P[:, :, a], P[:, :, b]) for a, b in edges])
    inside = overshoot(cell, pr.xi) <= 0.0
    edge = np.where(inside, -1, np.argmin(de, axis=0))
    return np.where(inside, pr.distance, de.min(axis=0)), edge


def face_edges(faces: np.ndarray, cell: "str | CellType") -> np.ndarray:
    """The corner-to-corner edges of every face, (n_f * n_corners, 2) (repeated where
    faces share an edge)."""
    c = np.asarray(cell_type(cell).corners)
    return np.stack([faces[:, c], faces[:, np.roll(c, -1)]], axis=2).reshape(-1, 2)


def face_distances(p: np.ndarray, xm: np.ndarray, faces: np.ndarray,
                   cell: "str | CellType") -> np.ndarray:
    """Distance of the points ``p (3, n)`` from the faces' surface (the nearest point of
    their chosen face, :func:`project_faces`)."""
    faces = np.asarray(faces, dtype=np.int64)
    h = float(np.median(face_sizes(xm, faces))) if len(faces) else 0.0
    return project_faces(p, xm, faces, cell_type(cell), h)["dist"]


def touching_faces(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                   cs: CellType, cm: CellType, tol: float) -> np.ndarray:
    """:func:`~.active_set.touching_nodes` on faces: the slave nodes within ``tol`` of
    the master surface, and the slave node nearest the projection of each master
    vertex within ``tol`` of the slave surface (the closest approach of two faceted
    surfaces is at a vertex of one of them, or an edge-edge crossing that both nearby
    vertices approach within the faces' size times their angle).  Bool ``(n_s,)``."""
    out = np.zeros(xs.shape[1], dtype=bool)
    if not (len(seg_s) and len(seg_m)):
        return out
    out |= project_faces(xs, xm, seg_m, cm, tol + float(np.median(face_sizes(xm, seg_m))))[
        "dist"] <= tol
    pm = xm[:, np.unique(seg_m)]
    pr = project_faces(pm, xs, seg_s, cs, tol + float(np.median(face_sizes(xs, seg_s))))
    on = np.flatnonzero(pr["dist"] <= tol)
    if on.size:
        corners = seg_s[pr["nearest"][on]][:, list(cs.corners)]       # (m, k)
        d = np.sum((xs[:, corners] - pm[:, on, None]) ** 2, axis=0)
        out[corners[np.arange(on.size), np.argmin(d, axis=1)]] = True
    return out


def tied_faces(i_n: np.ndarray, best: np.ndarray, dist: np.ndarray, h: np.ndarray,
               ok: np.ndarray) -> np.ndarray:
    """The candidates (indices into ``i_n``) tied with their node's chosen one
    (module docstring): not chosen, ``ok`` (not beyond a free edge), and
    ``|dist - dist_chosen| <= TIE_TOL max(h, h_chosen)`` with ``dist`` the distance
    to each candidate face's nearest point and ``h`` its size; ``best`` the chosen
    candidate of each node that has one, in node order."""
    n = np.full(int(i_n.max()) + 1 if i_n.size else 0, -1, dtype=np.int64)
    n[i_n[best]] = best
    c = n[i_n]
    tol = TIE_TOL * np.maximum(h, h[c])
    tie = ok & (c >= 0) & (c != np.arange(i_n.size)) & (np.abs(dist - dist[c]) <= tol)
    return np.flatnonzero(tie)


def _choose(xs, xm, faces, i_n, i_e, over, dist, n_s, prefer, stick, lock) -> np.ndarray:
    """:func:`~.nts_projection.choose_segments` with ties made exact: a distance within
    ``TIE_TOL h`` of the node's smallest counts as the smallest, an overshoot below
    ``TIE_TOL`` as 0, and the candidates still tied go to the face whose centroid is
    nearest the node, then the lower index (module docstring: mirror images of a
    face and node pick mirror images, whatever the round-off)."""
    from .nts_projection import choose_segments
    dmin = np.full(n_s, np.inf)
    np.minimum.at(dmin, i_n, dist)
    d = np.where(dist <= dmin[i_n] + TIE_TOL * face_sizes(xm, faces[i_e]), dmin[i_n], dist)
    o = np.where(over <= TIE_TOL, 0.0, over)
    centre = np.linalg.norm(xs[:, i_n] - xm[:, faces[i_e]].mean(axis=2), axis=0)
    order = np.lexsort((centre, i_n))
    return order[choose_segments(i_n[order], i_e[order], -o[order], d[order], n_s, prefer,
                                 stick, lock)]


def _unclipped_gaps(cell: CellType, xs: np.ndarray, P: np.ndarray, xi: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """``g = n(xi) . (x_s - x(xi))`` and ``n`` of the points ``xs (3, m)`` on the faces
    with nodes ``P (3, m, k)`` at their unclipped ``xi (2, m)``."""
    x, T = _map(cell, P, xi)
    nv = np.cross(T[:, 0], T[:, 1], axis=0)
    n = nv / np.maximum(np.sqrt(np.sum(nv * nv, axis=0)), 1e-300)
    return np.sum((xs - x) * n, axis=0), n


def free_edges(faces: np.ndarray, cell: CellType, mirrored: np.ndarray | None) -> np.ndarray:
    """Bool (n_f, n_edges): the edge of one face only (the master surface's border),
    not lying on a symmetry plane (both ends ``mirrored``)."""
    c = np.asarray(cell.corners)
    a, b = faces[:, c], faces[:, np.roll(c, -1)]
    key = np.minimum(a, b) * (faces.max() + 1) + np.maximum(a, b)
    _, inv, count = np.unique(key.ravel(), return_inverse=True, return_counts=True)
    free = (count[inv] == 1).reshape(a.shape)
    if mirrored is not None:
        free &= ~(mirrored[a] & mirrored[b])
    return free


def project_faces(xs: np.ndarray, xm: np.ndarray, faces: np.ndarray, cell: CellType,
                  margin: float | None = None, end_tolerance: float = 1e-8,
                  prefer: np.ndarray | None = None, stick: float = 0.05,
                  lock: np.ndarray | None = None, mirrored: np.ndarray | None = None) -> dict:
    """Closest-point projection of the slave nodes ``xs (3, n_s)`` on the master faces
    (module docstring).

    Returns
    -------
    dict with ``segment`` (n_s,) the chosen face (-1: none), ``xi`` (2, n_s) its
    unclipped coordinates, ``mask`` (n_s,), ``n`` (3, n_s) the face normal there,
    ``g`` (n_s,) the gap (the mean over the tied faces; 0 out of ``mask``),
    ``overshoot`` (n_s,) and ``dist`` (n_s,) the distance to the chosen face's
    nearest point and ``nearest`` (n_s,) that face (both also out of ``mask``: a
    node beyond a free edge; ``inf`` and -1 without a candidate), and ``ties``:
    ``(node, face, xi)`` of the faces tied with a chosen one of a node in ``mask``.
    ``margin`` (of :func:`face_candidates`) defaults to the median face size.
    """
    n_s, n_f = xs.shape[1], len(faces)
    if margin is None:
        margin = float(np.median(face_sizes(xm, faces))) if n_f else 0.0
    key = face_candidates(xs, xm, faces, cell, margin)
    i_n, i_e = key // n_f, key % n_f
    pr = project_points(xs[:, i_n], xm, faces, cell, i_e)
    dist, edge = _nearest_on_face(xs[:, i_n], xm, faces[i_e], cell, pr)
    over = overshoot(cell, pr.xi)
    best = _choose(xs, xm, faces, i_n, i_e, over, dist, n_s, prefer, stick, lock)
    k, e = i_n[best], i_e[best]
    segment = np.full(n_s, -1, dtype=np.int64)
    segment[k] = e
    xi = np.zeros((2, n_s))
    xi[:, k] = pr.xi[:, best]
    o = np.zeros(n_s)
    o[k] = over[best]
    ed = np.full(n_s, -1)
    ed[k] = edge[best]
    dn = np.full(n_s, np.inf)
    dn[k] = dist[best]
    mask = segment >= 0
    fe = free_edges(faces, cell, mirrored)
    es = np.where(mask, segment, 0)
    on_free = (ed >= 0) & fe[es, np.maximum(ed, 0)]
    kept = mask & (segment == prefer) if prefer is not None else np.zeros(n_s, dtype=bool)
    tol = np.where(kept, max(stick, end_tolerance), end_tolerance)
    mask &= ~(on_free & (o > tol))
    g, n = _unclipped_gaps(cell, xs, xm[:, faces[es]], xi)
    ok = ~((edge >= 0) & fe[i_e, np.maximum(edge, 0)] & (over > end_tolerance))
    t = tied_faces(i_n, best, dist, face_sizes(xm, faces[i_e]), ok)
    t = t[mask[i_n[t]]]
    if t.size:                    # the mean over the tied faces (module docstring)
        gt = _unclipped_gaps(cell, xs[:, i_n[t]], xm[:, faces[i_e[t]]], pr.xi[:, t])[0]
        count = 1.0 + np.bincount(i_n[t], minlength=n_s)
        g = (g + np.bincount(i_n[t], weights=gt, minlength=n_s)) / count
    g = np.where(mask, g, 0.0)
    return {"segment": np.where(mask, segment, -1), "xi": xi, "mask": mask, "n": n, "g": g,
            "overshoot": o, "dist": dn, "nearest": segment,
            "ties": (i_n[t], i_e[t], pr.xi[:, t])}


def face_rows(pr: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows of the gap (:func:`~.nts_gap.gap_eval`) of :func:`project_faces`'s
    output: a row ``(node, face, xi)`` per node in ``mask`` on its chosen face, then
    one per face tied with it (module docstring: the node takes their mean)."""
    mask = pr["mask"]
    tn, tf, txi = pr["ties"]
    return (np.concatenate([np.flatnonzero(mask), tn]),
            np.concatenate([pr["segment"][mask], tf]),
            np.concatenate([pr["xi"][:, mask], txi], axis=1))


def _map(cell: CellType, P: np.ndarray, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x(xi) (d, m)`` and ``T (d, 2, m)`` of the cells with nodes ``P (d, m, k)``."""
    N, G = cell.shape(xi), cell.dshape(xi)
    return np.einsum("dmk,km->dm", P, N), np.einsum("dmk,kjm->djm", P, G)


def face_weights(x: np.ndarray, faces: np.ndarray, cell: "str | CellType",
                 measure=None) -> np.ndarray:
    """Tributary weight of each node, ``a_A = int N_A w dGamma`` over its faces by the
    cell's rule of degree :data:`WEIGHT_DEGREE` (``w`` the weight of ``measure``; None
    or a unit measure: 1)."""
    cell = cell_type(cell)
    q, w = cell.quadrature(WEIGHT_DEGREE)
    N, G = cell.shape(q), cell.dshape(q)                      # (k, nq), (k, 2, nq)
    P = x[:, faces]                                           # (3, n_f, k)
    T = np.einsum("dfk,kjq->djfq", P, G)
    J = np.sqrt(np.sum(np.cross(T[:, 0], T[:, 1], axis=0) ** 2, axis=0))   # (n_f, nq)
    wJ = J * w
    if measure is not None and not measure.unit:
        wJ = wJ * measure.weight(tuple(np.einsum("dfk,kq->dfq", P, N)))
    return np.bincount(faces.ravel(), weights=(wJ @ N.T).ravel(), minlength=x.shape[1])
