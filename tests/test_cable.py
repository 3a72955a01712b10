"""Cable body: laws, residual against hand calculations, tangent against
central finite differences, construction helpers, slack handling, bad input."""
import numpy as np
import pytest

from skfem_mortar.bodies.cable import LAWS, Cable, get_law, newton_rtol
from skfem_mortar.core.errors import ConvergenceError, InversionError
from skfem_mortar.loads.pressure import FollowerPressure
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.scenes.ring import ring_radius
from skfem_mortar.solver.stepping import solve

from fd import dense, fd_tangent


# fd_tangent: for these unit-size cables the truncation error O(h^2 R_xxx) is
# ~1e-12 and round-off ~1e-10 (relative), which sets the FD tolerances below


def wavy_cable(n=6, closed=False, **kw):
    rng = np.random.default_rng(1)
    if closed:
        c = Cable.ring(1.0, n, **kw)
    else:
        s = np.linspace(0.0, 2.0, n + 1)
        c = Cable(np.vstack([s, 0.2 * np.sin(2 * s)]), **kw)
    z = 0.15 * rng.standard_normal(c.n_dofs)
    return c, z


# -- laws ----------------------------------------------------------------------
@pytest.mark.parametrize("law", sorted(LAWS))
def test_law_values_and_derivative(law):
    L = get_law(law)
    EA = 7.0
    lam = np.array([0.5, 0.9, 1.0, 1.3, 2.0])
    expected = {"linear": EA * (lam - 1), "svk": EA * lam * (lam ** 2 - 1) / 2,
                "hencky": EA * np.log(lam)}[law]
    np.testing.assert_allclose(L.force(lam, EA), expected, rtol=1e-15, atol=1e-15)
    # all laws: stress free and of slope EA at lambda = 1 (exact arithmetic)
    assert L.force(np.array([1.0]), EA)[0] == 0.0
    assert L.stiffness(np.array([1.0]), EA)[0] == pytest.approx(EA, rel=1e-15)
    h = 1e-6  # central difference: error ~ h^2 N''' ~ 1e-11, round-off ~ 1e-16 EA / h
    fd = (L.force(lam + h, EA) - L.force(lam - h, EA)) / (2 * h)
    np.testing.assert_allclose(L.stiffness(lam, EA), fd, rtol=1e-8)


def test_unknown_law_raises():
    with pytest.raises(ValueError, match="law must be one of"):
        get_law("rubber")


# -- residual against hand calculations ----------------------------------------------
@pytest.mark.parametrize("law", sorted(LAWS))
def test_single_element_force(law):
    c = Cable(np.array([[0.0, 2.0], [0.0, 0.0]]), EA=3.0, law=law)
    z = np.array([0.0, 0.0, 0.5, 0.0])  # stretch 1.25 along x
    R, _ = dense(c.assemble(z, 1.0), 4)
    N = get_law(law).force(np.array([1.25]), 3.0)[0]
    # node j is pulled back by the tension, node i forward: R = f_int
    np.testing.assert_allclose(R, [-N, 0.0, N, 0.0], rtol=1e-14, atol=1e-14)
    assert c.tension(z)[0] == pytest.approx(N, rel=1e-14)


@pytest.mark.parametrize("closed", [False, True])
def test_internal_forces_self_equilibrated(closed):
    # internal forces of any state have zero resultant and zero moment
    c, z = wavy_cable(7, closed=closed, law="svk", EA=5.0)
    R, _ = dense(c.assemble(z, 1.0), c.n_dofs)
    f = R.reshape(-1, 2)
    x = c.x(z).T
    assert np.abs(f.sum(axis=0)).max() < 1e-13 * np.abs(f).max()
    moment = np.sum(x[:, 0] * f[:, 1] - x[:, 1] * f[:, 0])
    assert abs(moment) < 1e-13 * np.abs(f).max()


# -- tangent against finite differences -------------------------------------------
@pytest.mark.parametrize("law", sorted(LAWS))
@pytest.mark.parametrize("closed", [False, True])
def test_tangent_fd(law, closed):
    c, z = wavy_cable(6, closed=closed, law=law, EA=4.0)
    _, K = dense(c.assemble(z, 1.0), c.n_dofs)
    Kfd = fd_tangent(c, z, 1.0)
    # see fd_tangent: errors ~1e-10 relative to the tangent's size
    assert np.abs(K - Kfd).max() < 1e-7 * np.abs(K).max()


def _mixed_slack_state(law):
    """A cable with alternating slack (lambda 0.8) and taut (lambda 1.3) elements."""
    X = np.vstack([np.arange(7.0), np.zeros(7)])
    c = Cable(X, EA=4.0, law=law, tension_only=True, slack_stiffness=0.0)
    s = np.concatenate([[0.0], np.cumsum(np.where(np.arange(6) % 2, 1.3, 0.8))])
    rng = np.random.default_rng(3)
    ang = 0.3 * rng.standard_normal(7)  # bend the chain without changing stretches
    pts = np.zeros((7, 2))
    for k in range(6):  # build the chain segment by segment (test set-up only)
        length = s[k + 1] - s[k]
        pts[k + 1] = pts[k] + length * np.array([np.cos(ang[k]), np.sin(ang[k])])
    z = (pts - X.T).ravel()
    return c, z


@pytest.mark.parametrize("law", sorted(LAWS))
def test_tension_only_tangent_fd(law):
    c, z = _mixed_slack_state(law)
    lam = c.stretch(z)
    assert np.all(np.abs(lam - 1.0) > 0.1)  # far from the kink at lambda = 1 (h = 1e-6)
    slack = lam < 1
    assert slack.any() and (~slack).any()
    np.testing.assert_array_equal(c.tension(z)[slack], 0.0)
    _, K = dense(c.assemble(z, 1.0), c.n_dofs)
    Kfd = fd_tangent(c, z, 1.0)
    assert np.abs(K - Kfd).max() < 1e-7 * np.abs(K).max()


def test_slack_regularization_is_tangent_only_and_exactly_as_documented():
    c, z = _mixed_slack_state("svk")
    c0 = Cable(c.X, EA=4.0, law="svk", tension_only=True, slack_stiffness=0.0)
    c1 = Cable(c.X, EA=4.0, law="svk", tension_only=True, slack_stiffness=0.5)
    R0, K0 = dense(c0.assemble(z, 1.0), c.n_dofs)
    R1, K1 = dense(c1.assemble(z, 1.0), c.n_dofs)
    np.testing.assert_array_equal(R0, R1)  # the residual is untouched
    # expected difference: 0.5 EA / L0 t t^T on the slack elements only
    x = c.x(z)
    dK = np.zeros_like(K0)
    for e, (i, j) in enumerate(c.elements):  # reference built element by element
        if c.stretch(z)[e] < 1:
            d = x[:, j] - x[:, i]
            t = d / np.linalg.norm(d)
            k = 0.5 * 4.0 / c.rest_length[e] * np.outer(t, t)
            dofs = np.r_[c.node_dofs[:, i], c.node_dofs[:, j]]
            dK[np.ix_(dofs, dofs)] += np.block([[k, -k], [-k, k]])
    np.testing.assert_allclose(K1 - K0, dK, atol=1e-13)


def test_tension_floor_is_tangent_only_and_exactly_as_documented():
    c0, z = wavy_cable(6, law="svk", EA=4.0)
    N = c0.tension(z)
    assert N.max() > 0
    floor = float(N.max())   # lf * floor = max(N) / 2: some elements floored, some not
    c1 = Cable(c0.X, EA=4.0, law="svk", tension_floor=floor)
    R0, K0 = dense(c0.assemble(z, 0.5), c0.n_dofs)
    R1, K1 = dense(c1.assemble(z, 0.5), c0.n_dofs)
    np.testing.assert_array_equal(R0, R1)  # the residual is untouched
    x = c0.x(z)
    dK = np.zeros_like(K0)
    for e, (i, j) in enumerate(c0.elements):  # reference built element by element
        d = x[:, j] - x[:, i]
        length = np.linalg.norm(d)
        t = d / length
        k = max(0.0, 0.5 * floor - N[e]) / length * (np.eye(2) - np.outer(t, t))
        dofs = np.r_[c0.node_dofs[:, i], c0.node_dofs[:, j]]
        dK[np.ix_(dofs, dofs)] += np.block([[k, -k], [-k, k]])
    assert np.any(N < 0.5 * floor) and np.any(N > 0.5 * floor)
    np.testing.assert_allclose(K1 - K0, dK, atol=1e-13)
    with pytest.raises(ValueError, match="tension_floor"):
        Cable(c0.X, tension_floor=-1.0)


def test_slack_ring_needs_the_regularization_and_solves_with_it():
    """A ring 20 % too long (every element slack at the start) under pressure."""
    n = 16

    def model(ks):
        base = Cable.ring(1.0, n)
        c = Cable(base.X, closed=True, EA=10.0, law="svk", tension_only=True,
                  rest_length=1.2 * base.rest_length, slack_stiffness=ks)
        nd = c.node_dofs
        return c, Model([c, FollowerPressure(c, 1.0, side="right"),
                         Dirichlet(c, [nd[0, 0], nd[1, 0], nd[1, n // 2]])])

    c, m = model(1.0)
    res = solve(m, 1, newton=NewtonOptions(rtol=1e-12))
    x = c.x(res.z)
    R = np.mean(np.hypot(*(x - x.mean(axis=1, keepdims=True))))
    # the discrete ring with R0 = 1.2 (rest lengths scaled by 1.2), Newton to 1e-12
    assert R == pytest.approx(ring_radius(1.0, 1.2, 10.0, "svk", n), rel=1e-11)
    _, m0 = model(0.0)
    with pytest.raises(ConvergenceError):   # exact (zero) slack tangent: singular
        solve(m0, 1, newton=NewtonOptions(rtol=1e-12), min_step=0.1)


# -- construction helpers -----------------------------------------------------------
@pytest.mark.parametrize("n", [1, 2, 7, 16])
@pytest.mark.parametrize("L0", [2.5, 3.0, 6.0])
def test_between_slack_start_is_stress_free_arc(n, L0):
    c = Cable.between((-1.0, 0.0), (1.0, 0.0), L0, n, bulge="left", EA=2.0)
    z = np.zeros(c.n_dofs)
    d = np.diff(c.X, axis=1)
    chords = np.hypot(*d)
    if n == 1:  # a single element cannot bulge: straight and pre-stretched
        assert c.stretch(z)[0] == pytest.approx(2.0 / L0)
        return
    # equal chords L0/n, all stress free, ends on the supports (round-off of brentq)
    np.testing.assert_allclose(chords, L0 / n, rtol=1e-12)
    np.testing.assert_allclose(c.tension(z), 0.0, atol=1e-11)
    np.testing.assert_allclose(c.X[:, [0, -1]], [[-1, 1], [0, 0]], atol=1e-15)
    # nodes on one circle centred on the y axis, bulging to +y (left of -x -> +x)
    assert np.all(c.X[1, 1:-1] > 0)
    yc = np.linalg.lstsq(np.column_stack([2 * c.X[1], np.ones(n + 1)]),
                         c.X[0] ** 2 + c.X[1] ** 2, rcond=None)[0]
    r = np.hypot(c.X[0], c.X[1] - yc[0])
    np.testing.assert_allclose(r, r[0], rtol=1e-12)
    right = Cable.between((-1.0, 0.0), (1.0, 0.0), L0, n, bulge="right")
    np.testing.assert_allclose(right.X[1], -c.X[1], atol=1e-15)


def test_between_taut_start_regularization():
    c = Cable.between((0.0, 0.0), (3.0, 0.0), 3.0, 12, start_sag=0.05, EA=2.0)
    np.testing.assert_allclose(c.rest_length, 0.25, rtol=1e-15)
    h = c.X[1].max()
    assert h == pytest.approx(0.05 * 3.0, rel=1e-12)  # even n: the middle node is the apex
    lam = c.stretch(np.zeros(c.n_dofs))
    # shallow arc of height h over span s: length/s = 1 + (8/3)(h/s)^2 + O((h/s)^4)
    assert np.all(lam > 1.0)
    assert np.sum(lam) / 12 == pytest.approx(1 + 8 / 3 * 0.05 ** 2, rel=1e-4)


def test_between_pretensioned_straight():
    c = Cable.between((0.0, 0.0), (2.0, 0.0), 1.6, 4, EA=2.0)
    np.testing.assert_allclose(c.X[1], 0.0)
    np.testing.assert_allclose(c.stretch(np.zeros(c.n_dofs)), 1.25, rtol=1e-14)


def test_ring_and_from_points():
    c = Cable.ring(2.0, 10, center=(1.0, -1.0))
    np.testing.assert_allclose(np.hypot(c.X[0] - 1, c.X[1] + 1), 2.0, rtol=1e-15)
    assert c.closed and len(c.elements) == 10 and c.elements[-1].tolist() == [9, 0]
    # counter-clockwise: positive signed area (shoelace)
    x, y = c.X
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0
    p = Cable.from_points([[0, 0], [1, 0], [1, 1]])
    assert p.n_nodes == 3 and p.elements.tolist() == [[0, 1], [1, 2]]
    np.testing.assert_allclose(p.rest_length, 1.0)
    np.testing.assert_array_equal(p.support_dofs(), [0, 1, 4, 5])
    np.testing.assert_array_equal(p.node_dofs, [[0, 2, 4], [1, 3, 5]])


def test_output():
    c = Cable.ring(1.0, 6, EA=3.0)
    z = 0.1 * np.ones(c.n_dofs)
    pts, cells = c.output_mesh()
    assert pts.shape == (6, 2) and cells[0][0] == "line" and cells[0][1].shape == (6, 2)
    pdata, cdata = c.output_data(z)
    np.testing.assert_allclose(pdata["displacement"], 0.1)
    assert cdata["tension"][0].shape == (6,) and cdata["stretch"][0].shape == (6,)


# -- bad input ---------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs, match", [
    (dict(EA=0.0), "EA"), (dict(EA=-1.0), "EA"), (dict(law="foo"), "law"),
    (dict(slack_stiffness=-1.0), "slack_stiffness"), (dict(rest_length=0.0), "rest_length"),
])
def test_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Cable(np.array([[0.0, 1.0], [0.0, 0.0]]), **kwargs)


def test_bad_geometry_and_helpers():
    with pytest.raises(ValueError, match="X must have shape"):
        Cable(np.zeros((3, 4)))
    with pytest.raises(ValueError, match="coincident nodes"):
        Cable(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="radius0"):
        Cable.ring(-1.0, 8)
    with pytest.raises(ValueError, match="n_elements"):
        Cable.ring(1.0, 2)
    with pytest.raises(ValueError, match="length0"):
        Cable.between((0, 0), (1, 0), -1.0, 4)
    with pytest.raises(ValueError, match="start_sag"):
        Cable.between((0, 0), (1, 0), 1.0, 4, start_sag=0.0)
    with pytest.raises(ValueError, match="bulge must be"):
        Cable.between((0, 0), (1, 0), 2.0, 4, bulge="up")
    with pytest.raises(ValueError, match="closed ring has no end"):
        Cable.ring(1.0, 8).support_dofs()


def test_collapsed_element_raises_inversion():
    c = Cable(np.array([[0.0, 1.0], [0.0, 0.0]]))
    with pytest.raises(InversionError):
        c.assemble(np.array([0.0, 0.0, -1.0, 0.0]), 1.0)
    with pytest.raises(InversionError):
        c.assemble(np.array([np.nan, 0.0, 0.0, 0.0]), 1.0)


def test_newton_rtol():
    assert newton_rtol(100.0, 1.0) == 1e-10                 # round-off allows 1e-10
    assert newton_rtol(1e6, 1.0) == pytest.approx(1e9 * np.finfo(float).eps)
    with pytest.raises(ValueError, match="tension"):
        newton_rtol(1.0, 0.0)


def test_between_flat_stress_free_arc_gets_the_regularized_start():
    # stress-free arc of L0 = 1.001 over a unit span: height ~ sqrt(3e-3/8) = 0.019
    c = Cable.between((0, 0), (1, 0), 1.001, 10, start_sag=0.05)
    assert c.X[1].max() == pytest.approx(0.05, rel=1e-12)
    assert np.all(c.stretch(np.zeros(c.n_dofs)) > 1)     # stretched: tension at start
    c = Cable.between((0, 0), (1, 0), 1.001, 10, start_sag=0.01)
    np.testing.assert_allclose(c.stretch(np.zeros(c.n_dofs)), 1.0, atol=1e-12)
