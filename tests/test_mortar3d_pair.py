"""Mortar between faces through the method and the pair (issue 38): G and H of
``Mortar.evaluate`` against finite differences on random tri3/quad4 pairs (sliding,
partly overlapping, warped, near-degenerate), faces covered over a thin strip
(masked nodes, no NaN, the patch quantities exact), the preflight and the KKT check
of a 3D mortar pair, the generic pattern equal to the 2D one, and the refusals."""
import numpy as np
import pytest
import skfem

from skfem_mortar import ContactPair, ContactSurface, Dirichlet, Model, RigidPlane, Solid, solve
from skfem_mortar.bodies.material import LinearElastic
from skfem_mortar.contact.mortar_method import Mortar
from skfem_mortar.contact.mortar_pattern import stencil_pattern
from skfem_mortar.contact.rigid3d import RigidSphere
from skfem_mortar.loads.traction import Traction
from skfem_mortar.scenes._contact3d import grid_mesh, nodes_on_plane
from skfem_mortar.solver.newton import NewtonOptions

PAIRINGS = [("tri3", "tri3"), ("quad4", "quad4"), ("tri3", "quad4"), ("quad4", "tri3")]


# --------------------------------------------------------------------- surfaces
def _square(cell, n, rng, z=0.0, up=True, jitter=0.2, warp=0.0):
    """An n x n grid of the unit square (inner nodes moved by up to ``jitter`` h, heights
    by up to ``warp`` h: warped quads), as quad4 or each quad split into two tri3 along
    alternating diagonals; counter-clockwise seen from +z when ``up``."""
    t = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(t, t, indexing="ij")
    d = rng.uniform(-jitter / n, jitter / n, X.shape + (2,))
    X[1:-1] += d[1:-1, :, 0]
    Y[:, 1:-1] += d[:, 1:-1, 1]
    Z = z + rng.uniform(-warp / n, warp / n, X.shape)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    Q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    faces = Q
    if cell == "tri3":
        flip = (np.add.outer(np.arange(n), np.arange(n)) % 2).ravel().astype(bool)
        a = np.where(flip[:, None], Q[:, [0, 1, 2]], Q[:, [0, 1, 3]])
        b = np.where(flip[:, None], Q[:, [0, 2, 3]], Q[:, [1, 2, 3]])
        faces = np.r_[a, b]
    x = np.vstack([X.ravel(), Y.ravel(), Z.ravel()])
    return x, (faces if up else faces[:, ::-1])


def _surface(x, faces, cell, name):
    return ContactSurface(None, None, faces, X=x, name=name, cell=cell)


def _method(space, xs, fs, cs, xm, fm, cm, **options):
    """``Mortar`` between the faces (the method alone: its search, points, kernel)."""
    return Mortar(_surface(xs, fs, cs, "s"), _surface(xm, fm, cm, "m"),
                  multiplier_space=space, **options)


def _rotated(x, centre, angle, to):
    """``x`` rotated by ``angle`` about ``centre`` (in the x-y plane), then ``centre`` moved to ``to``."""
    c, s = np.cos(angle), np.sin(angle)
    y = x.copy()
    y[:2] = np.array([[c, -s], [s, c]]) @ (x[:2] - np.c_[list(centre)]) + np.c_[list(to)]
    return y


#: how near the near-degenerate pairs are (of the element size 1/2): exactly on an edge the
#: integrals are continuous but only one-sidedly differentiable (the clip polygon changes
#: its vertices), so G is checked on either side of the degeneracy, not across it
NEAR = 1e-3


def _case(case, cells, rng):
    """Slave (up) and master (down, 0.02 above it unless nearly coplanar) surfaces."""
    cs, cm = cells
    regular = case in ("vertex_on_edge", "edge_on_edge")
    warp = 0.15 if case == "warped" else 0.0
    xs, fs = _square(cs, 2, rng, jitter=0.0 if regular else 0.2, warp=warp)
    xm, fm = _square(cm, 3 if case != "edge_on_edge" else 2, rng, z=0.02, up=False,
                     jitter=0.0 if regular else 0.2, warp=warp)
    if case in ("sliding", "warped"):
        xm[:2] += [[0.37], [0.21]]          # slides off a corner: partly overlapping
    elif case == "vertex_on_edge":          # a master vertex NEAR the slave edge x = 1/2
        xm = _rotated(xm, (1 / 3, 1 / 3), 0.3, (0.5 + NEAR, 0.3))
    elif case == "edge_on_edge":            # grid lines near grid lines, shifted along them
        xm[0] += NEAR
        xm[1] += 0.25
    elif case == "coplanar":
        xm[2] = 1e-9                        # nearly coplanar: a gap of 1e-9 h
        xm[:2] += [[0.11], [0.07]]
    return xs, fs, xm, fm


def _fd(method, xs, xm, lam, h=1e-6, n_dir=1):
    """Largest relative errors of ``G d`` and ``H d`` against central differences along
    random directions ``d`` (the mask must not change between the probes)."""
    ev = method.evaluate(xs, xm, lam, True)
    G, H = ev.G.toarray(), ev.H.toarray()
    ns = xs.size
    x = np.r_[xs.T.ravel(), xm.T.ravel()]
    rng = np.random.default_rng(1)
    eg = eh = 0.0
    for _ in range(n_dir):
        d = rng.normal(size=x.size)
        p, m = ((method.evaluate(y[:ns].reshape(-1, 3).T, y[ns:].reshape(-1, 3).T, lam, True))
                for y in (x + h * d, x - h * d))
        assert np.array_equal(p.mask, ev.mask) and np.array_equal(m.mask, ev.mask)
        eg = max(eg, np.abs((p.g - m.g) / (2 * h) - G @ d).max() / np.abs(G).max())
        dG = (p.G.toarray() - m.G.toarray()).T @ lam / (2 * h)
        eh = max(eh, np.abs(dG - H @ d).max() / np.abs(H).max())
    return ev, eg, eh


# central differences at h = 1e-6 (1e-9 by the degenerate pairs) leave O(h^2) truncation
# and eps |g| / h round-off: measured G 1.1e-11 to 5.3e-11 and H (differenced from G)
# 1.1e-10 to 9.2e-10 over every case here; a missing or wrong term is O(1) relative, so
# the bounds keep a factor of 10 to 20 over the worst measured case
TOL_G, TOL_H = 1e-9, 1e-8


@pytest.mark.parametrize("cells", PAIRINGS, ids=["/".join(c) for c in PAIRINGS])
@pytest.mark.parametrize("case,space", [("sliding", "standard"), ("warped", "dual")])
def test_mortar_faces_G_and_H_against_finite_differences(case, space, cells):
    """Partly overlapping (a master sliding off a corner), flat or warped quads."""
    rng = np.random.default_rng(7)
    xs, fs, xm, fm = _case(case, cells, rng)
    method = _method(space, xs, fs, cells[0], xm, fm, cells[1])
    lam = rng.uniform(0.5, 1.5, xs.shape[1])
    ev, eg, eh = _fd(method, xs, xm, lam)
    assert ev.mask.any() and ev.info["D"].sum() < 0.9     # partly overlapping
    assert eg < TOL_G and eh < TOL_H, (eg, eh)


@pytest.mark.parametrize("cells", [("tri3", "quad4"), ("quad4", "tri3")],
                         ids=["tri3/quad4", "quad4/tri3"])
@pytest.mark.parametrize("case", ["vertex_on_edge", "edge_on_edge", "coplanar"])
def test_mortar_faces_near_degenerate_pairs(case, cells):
    """Vertex on an edge, edge on an edge, nearly coplanar: finite, and G and H exact."""
    rng = np.random.default_rng(11)
    xs, fs, xm, fm = _case(case, cells, rng)
    method = _method("dual", xs, fs, cells[0], xm, fm, cells[1])
    lam = rng.uniform(0.5, 1.5, xs.shape[1])
    ev, eg, eh = _fd(method, xs, xm, lam, h=1e-3 * NEAR)   # steps that stay on one side
    assert np.all(np.isfinite(ev.g)) and np.all(np.isfinite(ev.H.data))
    assert eg < TOL_G and eh < TOL_H, (eg, eh)


# --------------------------------------------------------------------- thin strips
@pytest.mark.parametrize("space", ["standard", "dual"])
@pytest.mark.parametrize("cs", ["tri3", "quad4"])
def test_faces_covered_over_a_thin_strip(cs, space):
    """A slave face covered over a strip of relative width eps (1e-1 .. 1e-7): no NaN;
    gaps of the sign of the gap (positive apart, negative in penetration); the nodes
    with support keep the patch identities of a flat pair at constant gap g0 (each
    face's multiplier functions sum to one over the covered part, merged or not):
    ``g_A = g0 sum_B D_AB`` and ``sum_A D_AB = int_covered N_B`` (a constant multiplier
    transmits exactly its force), to 1e-8 of the largest entry (round-off: measured
    1e-15; a node's function lost by the mask would be off by O(eps))."""
    rng = np.random.default_rng(5)
    xs, fs = _square(cs, 2, rng, jitter=0.0)
    for eps in 10.0 ** -np.arange(1, 8):
        for g0 in (0.01, -0.01):
            edge = 0.5 + 0.5 * eps                        # master x in [-1, edge]
            xm = np.array([[-1.0, edge, edge, -1.0], [-1.0, -1.0, 2.0, 2.0], [g0] * 4])
            fm = np.array([[0, 3, 2, 1]])
            m = _method(space, xs, fs, cs, xm, fm, "quad4")
            ev = m.evaluate(xs, xm, np.ones(xs.shape[1]), True)
            D, M = ev.info["D"].toarray(), ev.info["M"].toarray()
            for a in (ev.g, ev.G.data, ev.H.data, D, M):
                assert np.all(np.isfinite(a))
            k = ev.mask
            assert np.all(np.sign(ev.g[k]) == np.sign(g0)), (eps, g0)
            assert np.abs(ev.g[k] - g0 * D.sum(axis=1)[k]).max() <= 1e-8 * abs(g0) * D.max()
            assert np.abs(D.sum(axis=0) - ev.area).max() <= 1e-8 * D.max(), (eps, g0)
            assert M.sum() == pytest.approx(D.sum(), rel=1e-12)   # both: the covered area


# --------------------------------------------------------------------- the pattern
def test_generic_pattern_equals_the_chain_pattern_in_2d():
    """On a line2 chain the stencil rows are the old ``p, a, b, n`` rows: the set of
    entries of :func:`stencil_pattern` equals the 2D pattern built by hand."""
    n_s, n_m = 6, 4
    seg_s = np.c_[np.arange(n_s - 1), np.arange(1, n_s)]
    seg_m = np.c_[np.arange(n_m - 1), np.arange(1, n_m)]
    e_s, e_m = np.array([0, 2, 2, 4]), np.array([0, 1, 2, 2])
    P = stencil_pattern(seg_s, n_s, seg_m, n_m, e_s, e_m, 2).toarray() > 0
    ref = np.zeros_like(P)
    for e, (a, b) in enumerate(seg_s):
        nodes = {a, b, max(a - 1, 0), min(b + 1, n_s - 1)}
        nodes |= {int(seg_m[j, c]) + n_s for i, j in zip(e_s, e_m) if i == e for c in (0, 1)}
        for A in (a, b):
            for nd in nodes:
                ref[A, 2 * nd:2 * nd + 2] = True
    ref[np.arange(n_s), 2 * np.arange(n_s)] = ref[np.arange(n_s), 2 * np.arange(n_s) + 1] = True
    assert np.array_equal(P, ref)


# --------------------------------------------------------------------- the pair
def _block(element, n, z0, name, rng=None):
    mesh = grid_mesh(element, *[np.linspace(0.0, 1.0, n + 1)] * 2,
                     np.linspace(z0, z0 + 0.5, 2))
    mesh = mesh.with_boundaries({"bottom": lambda x: np.abs(x[2] - z0) < 1e-9,
                                 "top": lambda x: np.abs(x[2] - z0 - 0.5) < 1e-9})
    return Solid(mesh, LinearElastic(E=1.0, nu=0.3), element, name=name)


def _stacked(method, flip=False, load=0.01):
    """Two stacked blocks, 4 on 2 cells, the upper one's bottom the slave, a traction on
    its top, rollers under the lower one and on both mid-planes (small strain)."""
    lower, upper = _block("hex1", 2, 0.0, "lower"), _block("tet1", 2, 0.5, "upper")
    slave = ContactSurface.from_solid(upper, "bottom")
    pair = ContactPair(slave.reversed() if flip else slave,
                       ContactSurface.from_solid(lower, "top"), method=method)
    rollers = [Dirichlet(b, nodes=nodes_on_plane(b.mesh, k, 0.5, 1e-9), component=k,
                         name=f"{b.name}_{k}") for b in (lower, upper) for k in (0, 1)]
    items = [upper, lower, pair, Traction(upper, "top", (0.0, 0.0, -load), name="load"),
             Dirichlet(lower, lower.dofs_on("bottom", "z"), 0.0, name="support"), *rollers]
    return Model(items, geometry="3d"), pair


@pytest.mark.parametrize("method", ["mortar", "mortar-dual"])
def test_kkt_check_of_a_3d_mortar_pair(method):
    """The converged state passes the KKT check; the same state with the upper block
    pushed into the lower one by 1e-3 (far above the gap tolerance) is named a penetration."""
    model, pair = _stacked(method)
    res = solve(model, n_steps=1, newton=NewtonOptions(rtol=1e-12))
    assert pair.violation(res.z, 1.0) == ""
    assert pair.forces(res.z)[0].sum(axis=1)[2] == pytest.approx(0.01, rel=1e-10)
    z = res.z.copy()
    upper = pair.slave.body
    z[upper.dofs_on("bottom", "z")] -= 1e-3
    assert "penetration" in pair.violation(z, 1.0)


def test_the_preflight_runs_for_mortar_in_3d():
    """A flipped slave orientation is refused before the first step, as for NTS."""
    model, _ = _stacked("mortar-dual", flip=True)
    with pytest.raises(ValueError, match="point into the body"):
        solve(model, n_steps=1)


# --------------------------------------------------------------------- refusals
def test_mortar_between_faces_refusals_name_the_alternative():
    rng = np.random.default_rng(0)
    xs, fs = _square("tri3", 2, rng)
    xm, fm = _square("quad4", 2, rng, z=0.1, up=False)
    with pytest.raises(ValueError, match=r"n_gauss must be an integer in \[1, 20\]"):
        _method("dual", xs, fs, "tri3", xm, fm, "quad4", n_gauss=21)
    with pytest.raises(ValueError, match="segmentation='step'.*use segmentation='iteration'"):
        _method("dual", xs, fs, "tri3", xm, fm, "quad4", segmentation="step")
    with pytest.raises(ValueError, match="RigidSphere.*use method='nts'"):
        Mortar(_surface(xs, fs, "tri3", "s"), RigidSphere((0.5, 0.5, 1.0), 0.5),
               multiplier_space="dual")


def test_symmetry_planes_refused_in_a_plane_model():
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    body = Solid(mesh.with_defaults(), LinearElastic(E=1.0, nu=0.3), "quad1", name="b")
    with pytest.raises(ValueError, match="symmetry planes have 3 components.*Dirichlet"):
        ContactPair(ContactSurface.from_solid(body, "top"), RigidPlane((0, 2), (0, -1)),
                    method="mortar", symmetry=[((1, 0, 0), 0.0)])
