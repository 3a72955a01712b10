"""The 3D integration points on jets (contact/points3d.py): exact first and second
derivatives against finite differences on random and near-degenerate face pairs, two
jet Newton steps are enough, the cells' weights against the overlap (shapely) and the
faces' areas, chunks and memory, refusals.  A small integrator here stands in for the
kernel: ``sum w J_s`` over a face's cells."""
import tracemalloc

import numpy as np
import pytest

from skfem_mortar.contact import points3d
from skfem_mortar.contact.cells import cell_type, quad_quadrature
from skfem_mortar.contact.points3d import CHUNK_BYTES, integration_points, point_chunks
from skfem_mortar.contact.segmentation3d import segment_faces
from test_segmentation3d import PAIRINGS, Polygon, _quad_square, _tri_square


def _jacobian(cell, X, xi):
    """``J_s = |T_1 x T_2|`` at ``xi (2, n, q)`` of faces of nodes ``X (n, k, 3)``."""
    T = np.einsum("kanq,nkd->adnq", cell.dshape(xi), X)
    return np.linalg.norm(np.cross(T[0], T[1], axis=0), axis=0)


def _face_sums(xs, Ss, cell, ip):
    """The test's integrator: ``sum w J_s`` over each slave face's cells."""
    X = np.transpose(xs[:, Ss[ip.e_s]], (1, 2, 0))
    xi = np.stack([ip.xi_s[0].v, ip.xi_s[1].v])
    return np.bincount(ip.e_s, (ip.w.v * _jacobian(cell, X, xi)).sum(1), minlength=len(Ss))


def _face(rng, kind, z, up, warp, shift=(0.0, 0.0), size=1.0):
    P = np.array([[0, 0], [1, 0], [0.2, 1.0]] if kind == "tri3"
                 else [[0, 0], [1, 0], [1.1, 0.9], [-0.1, 1.0]]) * size + shift
    P = P + rng.uniform(-0.05, 0.05, P.shape)
    X = np.c_[P, z + warp * rng.uniform(-1, 1, len(P))].T
    conn = np.arange(len(P))[None]
    return X, conn if up else conn[:, ::-1]


def _pair(case, ks, km, rng):
    """A slave and a master face for the named case (the master facing the slave)."""
    xs, Ss = _face(rng, ks, 0.0, True, 0.05 if case == "warped" else 0.0)
    if case in ("sliding", "warped"):
        xm, Sm = _face(rng, km, 0.1, False, 0.05 if case == "warped" else 0.0,
                       shift=rng.uniform(0.1, 0.4, 2))
    elif case == "vertex on edge":          # a master vertex on the slave's edge 0-1
        xm, Sm = _face(rng, km, 0.05, False, 0.0, shift=(0.3, 0.0))
        xm[:, 0] = xs[:, 0] + 0.4 * (xs[:, 1] - xs[:, 0]) + [0, 0, 0.05]
        xm[1, 1:] += 0.2
    elif case == "edge on edge":            # a master edge along the slave's edge 0-1
        xm, Sm = _face(rng, km, 0.05, True, 0.0, shift=(0.3, 0.0))
        xm[:, 0] = xs[:, 0] + 0.3 * (xs[:, 1] - xs[:, 0]) + [0, 0, 0.05]
        xm[:, 1] = xs[:, 0] + 1.3 * (xs[:, 1] - xs[:, 0]) + [0, 0, 0.05]
        xm[1, 2:] = xm[1, 2:] + 0.5
        Sm = Sm[:, ::-1]
    else:                                   # nearly coplanar: the master 1e-9 above
        xm, Sm = _face(rng, km, 1e-9, False, 0.0, shift=(0.3, 0.2))
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return R @ xs, Ss, R @ xm, Sm


CASES = ["sliding", "warped", "vertex on edge", "edge on edge", "nearly coplanar"]


@pytest.mark.parametrize("cells", PAIRINGS)
@pytest.mark.parametrize("case", CASES)
def test_first_and_second_derivatives_against_finite_differences(cells, case):
    """Directional central differences of xi_s, xi_m and w (values: the gradient;
    gradients: the Hessian) with the segmentation's topology fixed, as the kernel
    holds it within a Newton step.  Step 1e-6: truncation ~1e-12 times the third
    derivatives, round-off ~1e-16 / 1e-6 = 1e-10 times the values, so 1e-7 relative
    to the Hessian's size; a missing term is of the order of the derivative itself."""
    rng = np.random.default_rng(sum(map(ord, case + "".join(cells))))
    xs, Ss, xm, Sm = _pair(case, *cells, rng)
    seg = segment_faces(xs, Ss, xm, Sm, cells, pairs=([0], [0]))
    assert seg.n > 0

    def jets(xs, xm):
        ip = integration_points(xs, Ss, xm, Sm, cells, seg, pad=False)
        return [ip.xi_s[0], ip.xi_s[1], ip.xi_m[0], ip.xi_m[1], ip.w]

    ref = jets(xs, xm)
    assert all(np.all(np.isfinite(j.v)) and np.all(np.isfinite(j.h)) for j in ref)
    k_s, h = xs.shape[1], 1e-6
    for _ in range(3):
        d = rng.normal(size=(3, k_s + xm.shape[1]))
        # the local variables: the faces' nodes in connectivity order, node-major
        dv = np.r_[d[:, Ss[0]].T.ravel(), d[:, k_s + Sm[0]].T.ravel()]
        plus, minus = jets(xs + h * d[:, :k_s], xm + h * d[:, k_s:]), \
            jets(xs - h * d[:, :k_s], xm - h * d[:, k_s:])
        for j, p, m in zip(ref, plus, minus):
            g = np.einsum("i...,i->...", j.g, dv)
            assert np.abs((p.v - m.v) / (2 * h) - g).max() <= 1e-7 * (1 + np.abs(g).max())
            H = np.einsum("ij...,j->i...", j.hessian(), dv)
            fd = (p.g - m.g) / (2 * h)
            assert np.abs(fd - H).max() <= 1e-7 * (1 + np.abs(H).max())


def test_two_jet_steps_are_exact_and_one_is_not(monkeypatch):
    """The back-projection's two Newton steps in jet arithmetic give the exact first and
    second derivatives: a third step changes them by round-off only; one step leaves
    the Hessian wrong (its error is the O(eps^2) term the second step removes)."""
    rng = np.random.default_rng(5)
    cells = ("quad4", "quad4")
    xs, Ss, xm, Sm = _pair("warped", *cells, rng)
    seg = segment_faces(xs, Ss, xm, Sm, cells, pairs=([0], [0]))
    out = {}
    for steps in (1, 2, 3):
        monkeypatch.setattr(points3d, "JET_STEPS", steps)
        ip = integration_points(xs, Ss, xm, Sm, cells, seg, pad=False)
        out[steps] = [ip.xi_m[0], ip.xi_s[0], ip.w]
    for a, b in zip(out[2], out[3]):
        assert np.abs(a.g - b.g).max() < 1e-13
        assert np.abs(a.hessian() - b.hessian()).max() < 1e-12
    assert np.abs(out[1][0].hessian() - out[2][0].hessian()).max() > 1e-3
    assert np.abs(out[1][0].g - out[2][0].g).max() < 1e-13


@pytest.mark.parametrize("cells", PAIRINGS)
def test_weights_on_flat_meshes_are_the_overlaps(cells):
    """Flat non-matching meshes of the unit square (the master 0.01 above, facing): per
    face pair, ``sum w J_s`` over its cells equals shapely's intersection area (J_s is
    of degree <= 1 on planar faces, the rule of degree 5 is exact: round-off, 1e-14);
    the slave faces' sums are their areas (every face covered)."""
    rng = np.random.default_rng(3)
    make = {"tri3": _tri_square, "quad4": _quad_square}
    xs, Ss = make[cells[0]](5, rng)
    xm, Sm = make[cells[1]](4, rng, z=0.01, up=False)
    seg = segment_faces(xs, Ss, xm, Sm, cells)
    ip = integration_points(xs, Ss, xm, Sm, cells, seg, second=False)
    cs = cell_type(cells[0])
    X = np.transpose(xs[:, Ss[ip.e_s]], (1, 2, 0))
    wj = (ip.w.v * _jacobian(cs, X, np.stack([ip.xi_s[0].v, ip.xi_s[1].v]))).sum(1)
    pairs = {}
    for a, b, v in zip(ip.e_s, ip.e_m, wj):
        pairs[a, b] = pairs.get((a, b), 0.0) + v
    for (a, b), v in pairs.items():
        ref = Polygon(xs[:2, Ss[a]].T).intersection(Polygon(xm[:2, Sm[b]].T)).area
        assert abs(v - ref) < 1e-14
    area = np.array([Polygon(xs[:2, f].T).area for f in Ss])
    assert np.abs(_face_sums(xs, Ss, cs, ip) - area).max() < 1e-14
    # the points' master coordinates map to the slave points' vertical projection
    cm = cell_type(cells[1])
    xm_pts = np.einsum("knq,dnk->dnq", cm.shape(np.stack([ip.xi_m[0].v, ip.xi_m[1].v])),
                       xm[:, Sm[ip.e_m]])
    xs_pts = np.einsum("knq,dnk->dnq", cs.shape(np.stack([ip.xi_s[0].v, ip.xi_s[1].v])),
                       xs[:, Ss[ip.e_s]])
    assert np.abs(xm_pts[:2] - xs_pts[:2]).max() < 1e-14


@pytest.mark.parametrize("n_gauss, tol", [(2, 1e-3), (5, 1e-4), (8, 1e-6)])
def test_warped_quad4_faces_integrate_their_own_area(n_gauss, tol):
    """Warped quad4 slave faces (corners out of plane by up to 0.1 h) fully covered by a
    larger non-matching tri3 master: ``sum w J_s`` over each face's cells equals the
    face's area (a 400-point tensor rule) to the triangle rule's accuracy on the
    rational integrand ``J_s / (T_1 x T_2).n_0`` of the plane cells: measured 1.5e-4,
    1.8e-5, 2.9e-7 relative at degrees 2, 5, 8 (the worst face: jittered by 0.25 h and
    warped by about 0.2 of its size; 1.6e-11 at degree 8 on a single face warped by
    0.1), so the bounds fall with the degree and a wrong weight (an O(warp^2) error,
    about 1e-2 here) fails every one."""
    rng = np.random.default_rng(1)
    xs, Ss = _quad_square(6, rng)
    xs[2] = 0.1 / 6 * rng.uniform(-1, 1, xs.shape[1])
    xm, Sm = _tri_square(7, rng, z=0.05, up=False)
    xm[:2] = xm[:2] * 1.4 - 0.2
    cells = ("quad4", "tri3")
    seg = segment_faces(xs, Ss, xm, Sm, cells)
    ip = integration_points(xs, Ss, xm, Sm, cells, seg, second=False, n_gauss=n_gauss)
    cs = cell_type("quad4")
    p, w = quad_quadrature(40)
    Xf = np.transpose(xs[:, Ss], (1, 2, 0))
    area = _jacobian(cs, Xf, np.broadcast_to(p[:, None, :], (2, len(Ss), p.shape[1]))) @ w
    assert np.abs(_face_sums(xs, Ss, cs, ip) / area - 1.0).max() < tol


@pytest.mark.parametrize("slave", ["tri3", "quad4"])
def test_strips_of_partial_cover_give_no_nan(slave):
    """A slave face covered by the master over a strip of relative width 1e-1 to 1e-7
    along its edge 0-1: finite jets, positive weights, and ``sum w J_s`` the strip's
    area to 1e-15 (planar faces: the rule is exact; the vertices carry round-off of
    1e-16 times the face's size, so the area's error is that times the strip's length,
    not relative to the strip: measured 5e-17 at a width of 1e-4)."""
    xs = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]] if slave == "tri3"
                  else [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]).T
    Ss = np.arange(xs.shape[1])[None]
    for eps in 10.0 ** -np.arange(1, 8):
        xm = np.array([[-1, -1, 0.01], [-1, eps, 0.01], [2, eps, 0.01], [2, -1, 0.01]]).T
        Sm = np.array([[0, 1, 2, 3]])
        cells = (slave, "quad4")
        seg = segment_faces(xs, Ss, xm, Sm, cells, pairs=([0], [0]))
        ip = integration_points(xs, Ss, xm, Sm, cells, seg)
        for j in (*ip.xi_s, *ip.xi_m, ip.w):
            assert np.all(np.isfinite(j.v)) and np.all(np.isfinite(j.h))
        assert np.all(ip.w.v > 0)
        strip = eps * (1 - eps / 2) if slave == "tri3" else eps
        got = _face_sums(xs, Ss, cell_type(slave), ip)[0]
        assert abs(got - strip) < 1e-15


def test_chunks_and_memory():
    """Chunks of :func:`point_chunks` give the points of one call (to round-off: the
    value Newton stops on a chunk's largest step); a chunk's peak of Python-side
    allocations stays below 40 Hessians of CHUNK_BYTES (measured 31: 61 MB)."""
    rng = np.random.default_rng(2)
    cells = ("quad4", "quad4")
    xs, Ss = _quad_square(4, rng)
    xm, Sm = _quad_square(3, rng, z=0.05, up=False)
    seg = segment_faces(xs, Ss, xm, Sm, cells)
    whole = integration_points(xs, Ss, xm, Sm, cells, seg, pad=False)
    chunks = list(point_chunks(seg, cells, budget=8 * 24 * 24 * 9 * 7))
    assert len(chunks) == -(-seg.n // 7)
    parts = [integration_points(xs, Ss, xm, Sm, cells, seg, rows=c, pad=False)
             for c in chunks]
    h = np.concatenate([p.w.h for p in parts], axis=2)
    assert np.abs(h - whole.w.h).max() < 1e-14 * np.abs(whole.w.h).max()
    assert np.abs(np.concatenate([p.xi_m[1].v for p in parts]) - whole.xi_m[1].v).max() < 1e-14
    first = next(iter(point_chunks(seg, cells)))
    tracemalloc.start()
    integration_points(xs, Ss, xm, Sm, cells, seg, rows=first, pad=False)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    hessian = (first.stop - first.start) * 8 * 24 * 24 * 9
    assert hessian <= CHUNK_BYTES and peak < 40 * hessian


def test_padding_and_layout():
    """``pad=True`` appends the nodal normals' zero block: ``n_loc = 3 (2 k_s + k_m)``."""
    rng = np.random.default_rng(4)
    xs, Ss, xm, Sm = _pair("sliding", "quad4", "tri3", rng)
    seg = segment_faces(xs, Ss, xm, Sm, ("quad4", "tri3"), pairs=([0], [0]))
    a = integration_points(xs, Ss, xm, Sm, ("quad4", "tri3"), seg, pad=False)
    b = integration_points(xs, Ss, xm, Sm, ("quad4", "tri3"), seg)
    assert a.w.g.shape[0] == 21 and b.w.g.shape[0] == 33
    assert np.array_equal(b.w.g[:21], a.w.g) and not np.any(b.w.g[21:])
    assert np.array_equal(b.xi_m[0].h[:21, :21], a.xi_m[0].h) and not np.any(b.xi_m[0].h[21:])


def test_bad_input_is_refused():
    rng = np.random.default_rng(4)
    xs, Ss, xm, Sm = _pair("sliding", "tri3", "tri3", rng)
    seg = segment_faces(xs, Ss, xm, Sm, ("tri3", "tri3"), pairs=([0], [0]))
    with pytest.raises(ValueError, match="n_gauss must be an integer >= 1"):
        integration_points(xs, Ss, xm, Sm, ("tri3", "tri3"), seg, n_gauss=0)
    with pytest.raises(ValueError, match=r"cells\[1\] must be one of \['tri3', 'quad4'\]"):
        integration_points(xs, Ss, xm, Sm, ("tri3", "line2"), seg)


def test_face_points_keep_the_contract():
    """:class:`FacePoints` through the contract's calls: the kernel's local variables
    (``LocalVariables.of``, normals included) give jets of ``3 (2 k_s + k_m)`` variables
    that ``check_points`` accepts, equal to :func:`integration_points` (padded)."""
    from skfem_mortar.contact.integration_points import LocalVariables, check_points
    from skfem_mortar.contact.points3d import FacePoints
    rng = np.random.default_rng(6)
    cells = ("quad4", "tri3")
    xs, Ss = _quad_square(3, rng)
    xm, Sm = _tri_square(2, rng, z=0.02, up=False)
    fp = FacePoints(cells)
    ic = fp.integration_cells(xs, Ss, xm, Sm, None)
    S = Ss[ic.e_s]
    loc = LocalVariables.of(xs.T[S], xm.T[Sm[ic.e_m]], rng.normal(size=S.shape + (3,)))
    pts = fp.integration_points(ic, loc)
    check_points(pts, loc)
    ref = integration_points(xs, Ss, xm, Sm, cells, ic.data[0])
    assert pts.w.g.shape[0] == 3 * (4 + 3)      # the leading variables: no normals
    for a, b in zip((*pts.xi_s, *pts.xi_m, pts.w), (*ref.xi_s, *ref.xi_m, ref.w)):
        a = a.widen(3 * (2 * 4 + 3))
        assert np.array_equal(a.v, b.v) and np.array_equal(a.h, b.h)
    with pytest.raises(ValueError, match="n_gauss must be an integer >= 1"):
        FacePoints(cells, n_gauss=0)


@pytest.mark.parametrize("case", ["vertex crosses edge", "edge crosses vertex", "both"])
def test_integrals_are_continuous_through_degenerate_positions(case):
    """M_AC = sum w J_s N_A(xi_s) N_C(xi_m) as a master face slides through a vertex on
    an edge, or a master edge through a slave vertex whose wedge it covers (the cells'
    topology changes at t = 0 exactly; without the clipping's snap of that vertex to
    the slave corner its derivative at t = 0 was 0.035 against 0.188 on both sides),
    and both at once with a master vertex on the slave's hypotenuse whose master edge
    leaves the slave there (0.25 against 0 before the carriers' check):
    no NaN, and its derivative
    along the slide from the jets (chained through the master node that moves) is
    continuous: successive values differ by O(h) times the second derivative (1e-4 at
    h = 2e-6; a kink from a cell appearing with a wrong weight would be O(1)), and it
    matches the difference quotients of the values to 1e-6 (h^2 f''' + round-off / h)."""
    xs, Ss = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]).T, np.array([[0, 1, 2]])
    cells, tri = ("tri3", "tri3"), cell_type("tri3")
    Sm = np.array([[0, 2, 1]])

    def master(t):
        if case == "vertex crosses edge":      # master vertex 0 through y = 0 at x = 0.4
            return np.array([[0.4, t, 0.01], [0.9, 0.5, 0.01], [0.1, 0.5, 0.01]]).T, [10]
        top = [0.3, t + 0.4, 0.01] if case == "edge crosses vertex" else [0.5, t + 0.5, 0.01]
        return (np.array([[0.5, t - 0.5, 0.01], [1.5, t + 0.5, 0.01],   # an edge through
                          top]).T, [10, 13, 16])                          # slave vertex 1

    def M(t):
        xm, moving = master(t)
        seg = segment_faces(xs, Ss, xm, Sm, cells, pairs=([0], [0]))
        ip = integration_points(xs, Ss, xm, Sm, cells, seg, second=False, pad=False)
        Ns = tri.shape(np.stack([ip.xi_s[0].v, ip.xi_s[1].v]))
        xi_m = np.stack([ip.xi_m[0].v, ip.xi_m[1].v])
        Nm = tri.shape(xi_m)
        dNm = tri.dshape(xi_m)
        wJ = ip.w.v * _jacobian(tri, np.transpose(xs[:, Ss[ip.e_s]], (1, 2, 0)),
                                np.stack([ip.xi_s[0].v, ip.xi_s[1].v]))
        val = np.einsum("anq,cnq,nq->ac", Ns, Nm, wJ)
        # d/dt through the moving variables: w, xi_s, xi_m and J_s (slave-only: fixed)
        dwJ = sum(ip.w.g[i] for i in moving) * wJ / ip.w.v
        dxs = [sum(ip.xi_s[a].g[i] for i in moving) for a in range(2)]
        dxm = [sum(ip.xi_m[a].g[i] for i in moving) for a in range(2)]
        dNs = tri.dshape(np.stack([ip.xi_s[0].v, ip.xi_s[1].v]))
        dJ = 0.0  # J_s is constant on a flat tri3
        der = (np.einsum("anq,cnq,nq->ac", Ns, Nm, dwJ)
               + sum(np.einsum("anq,cnq,nq->ac", dNs[:, b], Nm, wJ * dxs[b]) for b in range(2))
               + sum(np.einsum("anq,cnq,nq->ac", Ns, dNm[:, b], wJ * dxm[b]) for b in range(2)))
        assert np.all(np.isfinite(val)) and np.all(np.isfinite(der)) and dJ == 0.0
        return val, der

    h = 2e-6
    ts = np.linspace(-20 * h, 20 * h, 41)
    vals, ders = zip(*(M(t) for t in ts))
    vals, ders = np.array(vals), np.array(ders)
    assert np.abs(np.diff(ders, axis=0)).max() < 1e-4
    quotients = (vals[2:] - vals[:-2]) / (2 * h)
    assert np.abs(quotients - ders[1:-1]).max() < 1e-6


@pytest.mark.parametrize("cells", PAIRINGS)
def test_aligned_grids_derivative_is_the_one_sided_differences(cells):
    """Aligned grids, as in a patch test: master edges collinear with the slave's
    boundary and inner lines, master vertices on slave vertices and edges.  The
    assembled ``M_AC = sum w J_s N_A N_C(xi_m)`` is C1 in a tangential master shift
    (a sum over the master faces around), and its derivative from the jets must be
    both one-sided differences (h = 1e-6: O(h) times M'', measured 2.5e-6 of the
    largest entry; bound 1e-5).  Without the clipping's labelling of each vertex by
    its polygon edges (a collinear edge by the slave's line) it is off by 0.9 to 1.1."""
    rng = np.random.default_rng(0)
    xs, Q = _quad_square(3, rng, jitter=0.0)
    xm, Qm = _quad_square(4, rng, up=False, jitter=0.0)
    xm[:2], xm[2] = xm[:2] * 2.0 - 0.5, 0.01          # lines at -0.5, 0, 0.5, 1, 1.5
    tri = lambda q: np.r_[q[:, [0, 1, 2]], q[:, [0, 2, 3]]]  # noqa: E731
    Ss = Q if cells[0] == "quad4" else tri(Q)
    Sm = Qm if cells[1] == "quad4" else tri(Qm)
    cs, cm = cell_type(cells[0]), cell_type(cells[1])
    shift = [3 * cs.n_nodes + 3 * b for b in range(cm.n_nodes)]       # master x's

    def M(t):
        x = xm + [[t], [0.0], [0.0]]
        seg = segment_faces(xs, Ss, x, Sm, cells)
        ip = integration_points(xs, Ss, x, Sm, cells, seg, second=False, pad=False)
        xi_s = np.stack([j.v for j in ip.xi_s])
        xi_m = np.stack([j.v for j in ip.xi_m])
        wJ = ip.w.v * _jacobian(cs, np.transpose(xs[:, Ss[ip.e_s]], (1, 2, 0)), xi_s)
        d = lambda j: sum(j.g[i] for i in shift)  # noqa: E731
        Ns, Nm, dNs, dNm = cs.shape(xi_s), cm.shape(xi_m), cs.dshape(xi_s), cm.dshape(xi_m)
        loc = np.einsum("anq,cnq,nq->nac", Ns, Nm, wJ)
        der = (np.einsum("anq,cnq,nq->nac", Ns, Nm, d(ip.w) * wJ / ip.w.v)
               + sum(np.einsum("anq,cnq,nq->nac", dNs[:, b], Nm, wJ * d(ip.xi_s[b]))
                     + np.einsum("anq,cnq,nq->nac", Ns, dNm[:, b], wJ * d(ip.xi_m[b]))
                     for b in range(2)))
        out = [np.zeros((xs.shape[1], xm.shape[1])) for _ in range(2)]
        rows, cols = Ss[ip.e_s][:, :, None], Sm[ip.e_m][:, None, :]
        for o, v in zip(out, (loc, der)):
            np.add.at(o, (np.broadcast_to(rows, v.shape), np.broadcast_to(cols, v.shape)), v)
        return out

    (m0, d0), (mp, _), (mm, _) = M(0.0), M(1e-6), M(-1e-6)
    scale = np.abs(d0).max() + np.abs(m0).max()
    assert np.abs((mp - m0) / 1e-6 - d0).max() < 1e-5 * scale
    assert np.abs((m0 - mm) / 1e-6 - d0).max() < 1e-5 * scale
