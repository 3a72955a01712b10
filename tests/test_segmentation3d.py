"""The 3D mortar segmentation (contact/segmentation3d.py): integration cells of tri3 and
quad4 face pairs against an independent polygon intersection (shapely, the ``dev``
extra), their origins, the back-mapping to the faces, degenerate pairs."""
import numpy as np
import pytest

from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.clipping import AREA_TOL
from skfem_mortar.contact.mortar_quadratic_segmentation import segment_lines
from skfem_mortar.contact.segmentation import EDGE_INTERSECTION, segmentation_for
from skfem_mortar.contact.segmentation3d import (clip_vertex_points, line_corners,
                                                 segment_faces)


def Polygon(points):
    """shapely's polygon, imported here and not at the top so that the tests are
    collected where shapely is missing (CI's sdist check collects with pytest
    alone); it is in the ``dev`` extra, so a missing shapely fails the tests."""
    from shapely.geometry import Polygon as ShapelyPolygon
    return ShapelyPolygon(points)

PAIRINGS = [("tri3", "tri3"), ("quad4", "quad4"), ("tri3", "quad4"), ("quad4", "tri3")]


def _tri_square(n, rng, z=0.0, up=True):
    """Delaunay triangles of the unit square: n + 1 points per side, n^2 random inside."""
    from scipy.spatial import Delaunay
    t = np.linspace(0.0, 1.0, n + 1)
    o, i = np.zeros(n + 1), np.ones(n + 1)
    side = np.r_[np.c_[t, o], np.c_[t, i], np.c_[o, t][1:-1], np.c_[i, t][1:-1]]
    P = np.r_[side, rng.uniform(0.02, 0.98, (n * n, 2))]
    T = Delaunay(P).simplices
    a, b = P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]]
    cw = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0] < 0
    T[cw] = T[cw][:, [0, 2, 1]]
    return np.c_[P, np.full(len(P), z)].T, T if up else T[:, [0, 2, 1]]


def _quad_square(n, rng, z=0.0, up=True, jitter=0.25):
    """An n x n grid of the unit square, inner nodes moved by up to ``jitter`` h."""
    t = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(t, t, indexing="ij")
    d = rng.uniform(-jitter / n, jitter / n, X.shape + (2,))
    X[1:-1] += d[1:-1, :, 0]
    Y[:, 1:-1] += d[:, 1:-1, 1]
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    Q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    return np.vstack([X.ravel(), Y.ravel(), np.full(X.size, z)]), Q if up else Q[:, ::-1]


MESH = {"tri3": _tri_square, "quad4": _quad_square}


def _back_map_error(x, conn, cell, e, xi, seg):
    """Largest distance between the cells' plane points and the face points at their
    back-mapped coordinates, projected onto the plane along n_0."""
    c = cell_type(cell)
    e3 = np.repeat(e, 3)
    X = np.einsum("kN,Nkd->Nd", c.shape(xi.reshape(-1, 2).T),
                  np.transpose(x[:, conn[e3]], (1, 2, 0)))
    n0, x0 = seg.normal[np.repeat(seg.e_s, 3)], seg.x0[np.repeat(seg.e_s, 3)]
    P = X - np.sum((X - x0) * n0, axis=1)[:, None] * n0
    return np.abs(P - seg.points().reshape(-1, 3)).max()


def _check_cells(xs, Ss, xm, Sm, cells, seg, back_tol):
    """What every segmentation must give: finite coordinates, cells above the area
    tolerance, vertices rebuilt from their origins, back-mapped points on the plane."""
    assert seg.converged
    assert np.all(np.isfinite(seg.xi)) and np.all(np.isfinite(seg.xi_m))
    assert np.all(seg.area > 0)
    # intersections of lines meeting at angles of these meshes: ~1e2 round-offs
    np.testing.assert_allclose(clip_vertex_points(xs, Ss, xm, Sm, cells, seg),
                               seg.points(), rtol=0, atol=1e-13)
    assert _back_map_error(xs, Ss, cells[0], seg.e_s, seg.xi, seg) < back_tol
    assert _back_map_error(xm, Sm, cells[1], seg.e_m, seg.xi_m, seg) < back_tol


@pytest.mark.parametrize("cells", PAIRINGS)
def test_flat_meshes_cells_cover_the_square_and_each_overlap(cells):
    rng = np.random.default_rng(sum(map(ord, "".join(cells))))
    xs, Ss = MESH[cells[0]](6, rng, 0.0, True)
    xm, Sm = MESH[cells[1]](5, rng, 0.01, False)       # facing, a gap of 0.01
    seg = segment_faces(xs, Ss, xm, Sm, cells)
    # about 500 cells of area ~1e-3, each to round-off: the sum to 1e-13
    assert abs(seg.area.sum() - 1.0) < 1e-13
    # affine faces: one Newton step is exact, what is left is round-off
    _check_cells(xs, Ss, xm, Sm, cells, seg, 1e-12)
    i_s, i_m = seg.candidates
    # the searched pairs are those whose boxes come within the two faces' box sizes
    # (brute force here), not all pairs
    box = [(x[:, S].min(axis=2), x[:, S].max(axis=2)) for x, S in ((xs, Ss), (xm, Sm))]
    size = [(hi - lo).max(axis=0) for lo, hi in box]
    reach = size[0][:, None] + size[1][None, :]
    near = np.all((box[0][0][:, :, None] - reach <= box[1][1][:, None, :])
                  & (box[1][0][:, None, :] <= box[0][1][:, :, None] + reach), axis=0)
    assert sorted(zip(*np.nonzero(near))) == sorted(zip(i_s, i_m))
    assert i_s.size < near.size
    mine = {}
    for a, b, area in zip(seg.e_s, seg.e_m, seg.area):
        mine[a, b] = mine.get((a, b), 0.0) + area
    for a, b in zip(i_s, i_m):
        ref = Polygon(xs[:2, Ss[a]].T).intersection(Polygon(xm[:2, Sm[b]].T)).area
        assert abs(mine.get((a, b), 0.0) - ref) < 1e-15 + AREA_TOL


def _random_face(rng, k):
    """A convex planar polygon of k corners about the origin, counter-clockwise."""
    while True:
        ang = np.sort(rng.uniform(0.0, 2.0 * np.pi, k))
        P = np.c_[np.cos(ang), np.sin(ang)] @ np.diag(rng.uniform(0.5, 1.5, 2))
        if Polygon(P).area > 0.3:
            return np.c_[P, np.zeros(k)]


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _plane(X):
    """The auxiliary plane of a face of corners X (k, 3), computed here: centre and
    unit normal of the bilinear (or affine) map at its reference centre."""
    if len(X) == 3:
        v = np.cross(X[1] - X[0], X[2] - X[0])
    else:
        v = np.cross(X[1] + X[2] - X[0] - X[3], X[2] + X[3] - X[0] - X[1])
    n = v / np.linalg.norm(v)
    t = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    t /= np.linalg.norm(t)
    return X.mean(axis=0), n, np.stack([t, np.cross(n, t)])


@pytest.mark.parametrize("cells", PAIRINGS)
def test_random_single_pairs_in_space(cells):
    rng = np.random.default_rng(7 + len(cells[0]) + 3 * len(cells[1]))
    ks, km = len(cell_type(cells[0]).corners), len(cell_type(cells[1]).corners)
    for _ in range(40):
        R = _rotation(rng)
        S = _random_face(rng, ks)
        S[:, 2] += rng.uniform(-0.1, 0.1, ks) * (ks == 4)          # a warped quad4
        M = _random_face(rng, km)[::-1] + [*rng.uniform(-1, 1, 2), 0.2]
        M[:, 2] += rng.uniform(-0.05, 0.05, km)                    # tilted, warped
        S, M = S @ R.T, M @ R.T
        seg = segment_faces(S.T, np.arange(ks)[None], M.T, np.arange(km)[None], cells,
                            pairs=([0], [0]))
        x0, n, T = _plane(S)
        ref = Polygon((S - x0) @ T.T).intersection(Polygon(((M - x0) @ T.T)[::-1])).area
        assert abs(seg.area.sum() - ref) < 1e-14 + AREA_TOL * Polygon((S - x0) @ T.T).area
        if seg.n:
            np.testing.assert_allclose(seg.normal[0], n, atol=1e-15)
            # warped faces: Newton stops after a step of 1e-12; the bound
            _check_cells(S.T, np.arange(ks)[None], M.T, np.arange(km)[None], cells, seg,
                         1e-10)


@pytest.mark.parametrize("n_s, n_m", [(4, 2), (4, 4), (3, 6)])
@pytest.mark.parametrize("shift", [0.0, 0.5])
def test_vertices_on_vertices_and_edges(n_s, n_m, shift):
    """Structured grids: vertices on vertices and on edges, collinear edges."""
    rng = np.random.default_rng(0)
    xs, Ss = _quad_square(n_s, rng, jitter=0.0)
    xm, Sm = _quad_square(n_m, rng, up=False, jitter=0.0)
    xm[0] += shift / n_m
    cells = ("quad4", "quad4")
    seg = segment_faces(xs, Ss, xm, Sm, cells)
    assert abs(seg.area.sum() - (1.0 - shift / n_m)) < 1e-14
    # the smallest overlap of these grids is 1 / (2 n_s n_m)^2 or more: no sliver kept
    assert seg.area.min() > 0.5 / (2 * n_s * n_m) ** 2
    _check_cells(xs, Ss, xm, Sm, cells, seg, 1e-12)


@pytest.mark.parametrize("cells", [("tri3", "tri3"), ("quad4", "quad4")])
def test_matching_meshes(cells):
    xs, Ss = MESH[cells[0]](4, np.random.default_rng(5))
    seg = segment_faces(xs, Ss, xs.copy(), Ss[:, ::-1].copy(), cells)
    assert abs(seg.area.sum() - 1.0) < 1e-14
    counts = np.bincount(seg.e_s, minlength=len(Ss))
    assert np.all(counts == len(cell_type(cells[0]).corners) - 2)   # its own fan only
    assert np.all(seg.e_s == seg.e_m)
    _check_cells(xs, Ss, xs, Ss[:, ::-1], cells, seg, 1e-12)


@pytest.mark.parametrize("case", ["vertex crosses edge", "edge crosses vertex"])
def test_area_is_continuous_when_a_vertex_crosses_an_edge(case):
    """The cells' area as a master face slides through a degenerate position: no NaN,
    no cell below the tolerance, difference quotients bounded and continuous (the
    overlap area is C1 there)."""
    xs, Ss = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]).T, np.array([[0, 1, 2]])

    def area(t):
        if case == "vertex crosses edge":      # master vertex through y = 0 at x = 0.4
            xm = np.array([[0.4, t, 0.01], [0.9, 0.5, 0.01], [0.1, 0.5, 0.01]]).T
        else:                                  # master edge through the slave vertex (1, 0)
            xm = np.array([[0.5, t - 0.5, 0.01], [1.5, t + 0.5, 0.01],
                           [0.5, t + 0.5, 0.01]]).T
        seg = segment_faces(xs, Ss, xm, np.array([[0, 2, 1]]), ("tri3", "tri3"),
                            pairs=([0], [0]))
        assert np.all(np.isfinite(seg.xi)) and np.all(np.isfinite(seg.xi_m))
        assert np.all(seg.area > AREA_TOL * 0.5)
        return seg.area.sum()

    h = 1e-6
    a = np.array([area(t) for t in np.linspace(-50 * h, 50 * h, 101)])   # t = 0 exactly
    dq = np.diff(a) / h
    # |dA/dt| is at most the length of the master's edges through the moving point
    # (here below 1.5); the quotients change by O(h) times the second derivative (about
    # 1) plus round-off / h (1e-10): 1e-5 fails a kink (a jump of order 0.1 in dA/dt)
    assert np.abs(dq).max() < 1.5
    assert np.abs(np.diff(dq)).max() < 1e-5


def test_nearly_parallel_edges():
    """A master edge crossing a slave edge at a slope d from 1e-14 to 1e-6: the area to
    d/2 (a dropped near-parallel intersection loses at most a triangle of d/2 l1 l2),
    every kept vertex rebuilt from its origin to 1e-7 (eps / PARALLEL_SINE = 2e-8 times
    the lines' lengths, up to 2: keeping the intersections misses this by 1e-5)."""
    rng = np.random.default_rng(0)
    T = np.array([[0, 1, 2, 3]])
    for _ in range(100):
        R = np.linalg.qr(rng.normal(size=(2, 2)))[0]
        d, x0 = 10 ** rng.uniform(-14, -6), rng.uniform(0.1, 0.9)
        xs = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]).T
        xm = np.array([[-0.5, -d * (0.5 + x0), 0.01], [-0.5, 0.5, 0.01], [1.5, 0.5, 0.01],
                       [1.5, d * (1.5 - x0), 0.01]]).T        # its lower edge through (x0, 0)
        xs[:2], xm[:2] = R @ xs[:2], R @ xm[:2]
        seg = segment_faces(xs, T, xm, T, ("quad4", "quad4"), pairs=([0], [0]))
        exact = 0.5 - d * (1.0 - x0) ** 2 / 2.0
        assert abs(seg.area.sum() - exact) < d / 2 + 1e-15
        rebuilt = clip_vertex_points(xs, T, xm, T, ("quad4", "quad4"), seg)
        assert np.abs(rebuilt - seg.points()).max() < 1e-7


def test_non_convex_projection_is_split_in_two_triangles():
    """A quad4 master whose projection is a dart (corner 2 reflex): split on the diagonal
    (0, 2), whose intersections with slave edges carry line code 4."""
    xs = np.array([[0.05, 0.05, 0], [0.5, 0.05, 0], [0.5, 0.5, 0], [0.05, 0.5, 0.0]]).T
    xm = np.array([[0, 0, 0.1], [1, 0, 0.1], [0.3, 0.3, 0.4], [0, 1, 0.1]]).T
    Ss, Sm = np.array([[0, 1, 2, 3]]), np.array([[0, 3, 2, 1]])
    cells = ("quad4", "quad4")
    seg = segment_faces(xs, Ss, xm, Sm, cells, pairs=([0], [0]))
    ref = Polygon(xs[:2].T).intersection(Polygon(xm[:2].T)).area
    assert abs(seg.area.sum() - ref) < 1e-15
    on_diagonal = (seg.origin == EDGE_INTERSECTION) & (seg.src[..., 1] == 4)
    assert on_diagonal.any() and np.all(line_corners(4)[4] == [0, 2])
    _check_cells(xs, Ss, xm, Sm, cells, seg, 1e-12)


def test_faces_that_do_not_face_each_other_give_no_cells():
    x = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]).T
    seg = segment_faces(x, np.array([[0, 1, 2]]), x + [[0], [0], [0.01]],
                        np.array([[0, 1, 2]]), ("tri3", "tri3"))
    assert seg.n == 0 and seg.candidates[0].size == 1


def test_touching_faces_and_faces_of_no_area_give_no_cells_and_no_nan():
    xs = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]).T
    touching = {                                   # master faces, facing the slave
        "edge": np.array([[1, 0, 0.01], [0, 1, 0.01], [1, 1, 0.01]]).T,
        "vertex": np.array([[1, 0, 0.01], [2, 1, 0.01], [2, 0, 0.01]]).T,
        "no area": np.array([[0.2, 0.2, 0.01], [0.4, 0.2, 0.01], [0.6, 0.2, 0.01]]).T,
    }
    T = np.array([[0, 1, 2]])
    for name, xm in touching.items():
        normal = np.cross(xm[:, 1] - xm[:, 0], xm[:, 2] - xm[:, 0])
        assert normal[2] < 0 or name == "no area"           # facing: clipped, not dropped
        seg = segment_faces(xs, T, xm, T, ("tri3", "tri3"), pairs=([0], [0]))
        assert seg.n == 0, name
    flat = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]).T        # a slave of no area
    seg = segment_faces(flat, T, touching["edge"], T, ("tri3", "tri3"), pairs=([0], [0]))
    assert seg.n == 0 and np.all(np.isfinite(seg.normal)) and np.all(np.isfinite(seg.axes))


def test_registered_for_surfaces_only():
    tri3, quad4, line2 = (cell_type(n) for n in ("tri3", "quad4", "line2"))
    assert segmentation_for((tri3, quad4)) is segment_faces
    assert segmentation_for((line2, line2)) is segment_lines


def test_bad_input_is_refused():
    x = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]).T
    T = np.array([[0, 1, 2]])
    with pytest.raises(ValueError, match=r"slave cells must be one of \['tri3', 'quad4'\]"):
        segment_faces(x[:2], np.array([[0, 1]]), x, T, ("line2", "tri3"))
    with pytest.raises(ValueError, match=r"xm must be finite node coordinates of shape \(3, n\)"):
        segment_faces(x, T, x[:2], T, ("tri3", "tri3"))
    with pytest.raises(ValueError, match="connectivity of tri3 cells"):
        segment_faces(x, T, x, np.array([[0, 1, 2, 2]]), ("tri3", "tri3"))
    with pytest.raises(ValueError, match="pairs must be two index arrays"):
        segment_faces(x, T, x, T, ("tri3", "tri3"), pairs=([0], [1]))
    with pytest.raises(ValueError, match="reach must be a finite number >= 0"):
        segment_faces(x, T, x, T, ("tri3", "tri3"), reach=-1.0)


def test_chunks_give_the_same_cells(monkeypatch):
    import skfem_mortar.contact.segmentation3d as s3
    rng = np.random.default_rng(3)
    xs, Ss = _quad_square(5, rng)
    xm, Sm = _tri_square(4, rng, 0.01, False)
    whole = segment_faces(xs, Ss, xm, Sm, ("quad4", "tri3"))
    monkeypatch.setattr(s3, "CHUNK_PAIRS", 7)
    parts = segment_faces(xs, Ss, xm, Sm, ("quad4", "tri3"))
    assert whole.candidates[0].size > 10 * 7                      # many chunks
    for name in ("e_s", "e_m", "xi", "xi_m", "origin", "src", "u", "area"):
        np.testing.assert_array_equal(getattr(parts, name), getattr(whole, name))
