"""Finite differences of the axisymmetric contact pair, every method, with a slave node
on the axis (r = 0): the method's G and H (``w = 2 pi r`` enters the mortar integrals;
NTS's gap is unweighted, its tributary weights are), the whole pair's residual against
its tangent frictionless and with Coulomb and Tresca friction (Tresca's nodal bound
``bound * 2 pi int N_A r dGamma`` moves with the slave), and NTS's weights at the axis
node (``2 pi h^2 / 6`` on a flat segment)."""
import numpy as np
import pytest
from skfem import MeshTri

from fd import dense
from skfem_mortar import Coulomb, Tresca
from skfem_mortar.bodies.materials import LinearElastic
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.contact.friction import OPEN, SLIP, STICK
from skfem_mortar.contact.measures import AXISYMMETRIC
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane
from skfem_mortar.core.model import Model
from test_friction_pair import _mixed_multipliers, _tresca_multipliers


METHODS = ("nts", "mortar", "mortar-dual")


def _block(x0, x1, y0, y1, nx, ny, name, E=100.0):
    m = MeshTri.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    return Solid(m.with_defaults(), LinearElastic(E=E, nu=0.3), name=name)


def _on_plate(method, friction=None):
    """A solid cylinder r <= 2, 0 <= z <= 0.5 (its bottom's first node on the axis) on
    the rigid plate z = 0, in an axisymmetric model."""
    b = _block(0, 2, 0, 0.5, 8, 2, "block")
    plate = RigidPlane((1.0, 0.0), (0.0, 1.0), length=10.0)
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), plate, method, name="c",
                       friction=friction)
    return b, pair, Model([b, pair], geometry="axisymmetric")


def _stacked(method, friction=None):
    """A slave cylinder r <= 1 (6 bottom segments) on a finer master cylinder r <= 1.2
    (9 top segments), both meshed down to the axis."""
    top = _block(0.0, 1.0, 0.5, 1.0, 6, 2, "top")
    bot = _block(0.0, 1.2, 0.0, 0.5, 9, 2, "bottom", E=200.0)
    pair = ContactPair(ContactSurface.from_solid(top, "bottom"),
                       ContactSurface.from_solid(bot, "top"), method, name="c", friction=friction)
    return top, bot, pair, Model([top, bot, pair], geometry="axisymmetric")


def _state(model, bodies, rng, curve=0.0):
    """Displacements: pressed unevenly (a curved interface), noise 1e-4, the axis
    nodes' radial dofs 0 (as the bodies hold them)."""
    z = np.zeros(model.n)
    for b in bodies:
        u = z[b.offset:b.offset + b.n_dofs].reshape(-1, 2)
        X = b.mesh.p.T
        u[:, 1] = -0.004 * X[:, 0] ** 2 + curve * np.sin(2.0 * X[:, 0]) * X[:, 1]
        u += 1e-4 * rng.standard_normal(u.shape)
        u[X[:, 0] == 0.0, 0] = 0.0
    return z


def _ev_fd(pair, z):
    """G and H of the method at ``z`` against central differences of g and of G^T lam."""
    d = pair.discretization
    xs, xm = pair.slave.x(z), pair.master.x(z)
    lam = np.linspace(1.0, 2.0, pair.slave.n_nodes)
    ev = d.evaluate(xs, xm, lam, True)
    x0 = np.concatenate([xs.T.ravel(), xm.T.ravel()])
    n_s = xs.shape[1]

    def at(x):
        return x[:2 * n_s].reshape(-1, 2).T, x[2 * n_s:].reshape(-1, 2).T

    h = 1e-7
    Gfd, Hfd = np.zeros(ev.G.shape), np.zeros(ev.H.shape)
    for k in range(x0.size):
        e = np.zeros(x0.size)
        e[k] = h
        p, m = d.evaluate(*at(x0 + e), lam, True), d.evaluate(*at(x0 - e), lam, True)
        Gfd[:, k] = (p.g - m.g) / (2 * h)
        Hfd[:, k] = (p.G.T @ lam - m.G.T @ lam) / (2 * h)
    return ev, Gfd, Hfd


@pytest.mark.parametrize("method", METHODS)
def test_g_and_h_of_the_method_in_the_measure(method):
    top, bot, pair, model = _stacked(method)
    assert pair.discretization.measure is AXISYMMETRIC
    z = _state(model, (top, bot), np.random.default_rng(0), curve=0.02)
    ev, Gfd, Hfd = _ev_fd(pair, z)
    on = ev.mask
    assert on[0] and pair.slave.x(z)[0, 0] == 0.0        # the axis node takes part
    G = ev.G.toarray()
    # h = 1e-7 on unit geometry: truncation O(h^2) ~ 1e-14, round-off O(eps |g| / h)
    # ~ 1e-9 |G|; 1e-6 of the largest entry is far above both, far below a wrong term
    np.testing.assert_allclose(G[on], Gfd[on], rtol=0, atol=1e-6 * np.abs(G).max())
    H = ev.H.toarray()
    # the axis nodes' radial columns: the bodies hold u_r = 0 there, and a node moved
    # off the axis by the difference step leaves the mirror normal's regime (within
    # 1e-10 of the size), so central differences there measure the unmirrored field
    held = np.flatnonzero(np.concatenate([pair.slave.x(z)[0] == 0.0,
                                          pair.master.x(z)[0] == 0.0]))
    keep = np.setdiff1d(np.arange(H.shape[1]), 2 * held)
    np.testing.assert_allclose(H[np.ix_(keep, keep)], Hfd[np.ix_(keep, keep)], rtol=0,
                               atol=1e-6 * max(np.abs(H).max(), 1e-300))


def _fd(pair, model, z, h=1e-7):
    """The pair's tangent (dense) and its central differences over the pair's own
    columns (its surfaces' dofs and its multipliers; the pair's residual depends on
    nothing else, and its tangent must have no entry elsewhere)."""
    c0 = pair.assemble(z, 1.0)
    K = np.zeros((model.n, model.n))
    np.add.at(K, (c0.k_rows, c0.k_cols), c0.k_vals)
    gd = pair.global_dofs()
    cols = np.r_[gd[gd >= 0], pair.offset + np.arange(pair.n_dofs)]
    Kfd = np.zeros_like(K)
    for k in cols:
        e = np.zeros(model.n)
        e[k] = h
        Kfd[:, k] = (dense(pair.assemble(z + e, 1.0, tangent=False), model.n)[0]
                     - dense(pair.assemble(z - e, 1.0, tangent=False), model.n)[0]) / (2 * h)
    assert not np.delete(K, cols, axis=1).any()
    # the axis nodes' radial dofs: the bodies hold u_r = 0 there, and a node moved off
    # the axis by the difference step leaves the mirror normal's regime (within 1e-10
    # of the size), so central differences there measure the unmirrored field
    xs, xm = pair.slave.x(z), pair.master.x(z)
    held = gd[2 * np.flatnonzero(np.concatenate([xs[0] == 0.0, xm[0] == 0.0]))]
    held = held[held >= 0]
    K[held, :] = K[:, held] = Kfd[held, :] = Kfd[:, held] = 0.0
    return K, Kfd


def _frictionless_fd(pair, model, z):
    """The pair's tangent against central differences, the active set frozen."""
    pair.begin_step(z, 1.0)
    pair.state.frozen = pair.active.copy()
    K, Kfd = _fd(pair, model, z)
    pair.state.frozen = None
    assert pair.active[0]
    # as in tests/test_contact_pair.py: 1e-6 of the largest entry
    np.testing.assert_allclose(K, Kfd, rtol=0, atol=1e-6 * np.abs(K).max())


def _friction_fd(pair, model, z):
    """As tests/test_friction_pair.py's ``_check_tangent`` (the normal set and the
    statuses frozen at those of ``z``, both stick and slip nodes, the exact slip
    derivatives), over the pair's own columns (:func:`_fd`)."""
    on = np.ones(pair.slave.n_nodes, bool)
    ev, sl, fr = pair.friction_rows(z, tangent=False, active=on & pair.evaluate(
        z, tangent=False, with_lam=False).mask)
    assert np.any(fr.status == STICK) and np.any(fr.status == SLIP)
    assert fr.status[0] == OPEN                  # the axis node: symmetry holds it
    pair.state.frozen, pair.statuses.frozen = ev.mask.copy(), fr.status.copy()
    pair.friction_jacobian = "exact"
    K, Kfd = _fd(pair, model, z)
    pair.state.frozen = pair.statuses.frozen = None
    pair.friction_jacobian = "projected"
    # h = 1e-7 on unit-size geometry: truncation ~1e-12, round-off ~1e-9 |R|
    np.testing.assert_allclose(K, Kfd, rtol=0, atol=1e-6 * np.abs(K).max())


@pytest.mark.parametrize("method", METHODS)
def test_the_pair_frictionless(method):
    top, bot, pair, model = _stacked(method)
    z = _state(model, (top, bot), np.random.default_rng(1), curve=0.02)
    lam = np.linspace(1.0, 2.0, pair.slave.n_nodes)
    z[pair._normal] = lam if pair.multiplier_kind == "traction" else lam * pair.evaluate(
        z, tangent=False, with_lam=False).area
    pair.c = 1.0e3        # every masked node active (lam - c g >= 0 at these gaps)
    _frictionless_fd(pair, model, z)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("where", ["plate", "stacked"])
def test_the_pair_with_coulomb(method, where):
    if where == "plate":
        b, pair, model = _on_plate(method, Coulomb(0.3))
        bodies = (b,)
    else:
        top, bot, pair, model = _stacked(method, Coulomb(0.4))
        bodies = (top, bot)
    z0 = np.zeros(model.n)
    pair.begin_step(z0, 1.0)          # the slip history: the reference state
    rng = np.random.default_rng(2)
    z = _state(model, bodies, rng, curve=0.02 if where == "stacked" else 0.0)
    for b in bodies:                  # slid radially by 0.03 (the axis node stays)
        u = z[b.offset:b.offset + b.n_dofs].reshape(-1, 2)
        u[:, 0] += 0.03 * b.mesh.p[0] * (b is bodies[0])
    _mixed_multipliers(pair, z, rng)
    _friction_fd(pair, model, z)


@pytest.mark.parametrize("method", METHODS)
def test_the_pair_with_tresca(method):
    b, pair, model = _on_plate(method, Tresca(0.5))
    z0 = np.zeros(model.n)
    pair.begin_step(z0, 1.0)
    z = _state(model, (b,), np.random.default_rng(3))
    _tresca_multipliers(pair, z)
    _friction_fd(pair, model, z)


def test_nts_weights_at_the_axis_node():
    """NTS's area: 2 pi int N_A r dGamma over the current slave, 2 pi h^2 / 6 at the
    axis node of a flat bottom with h = 0.25 (exact: the rule integrates degree 9)."""
    b, pair, model = _on_plate("nts")
    ev = pair.evaluate(np.zeros(model.n), tangent=False, with_lam=False)
    h = 0.25
    r = np.sort(pair.slave.X[0])
    exact = np.r_[2 * np.pi * h * h / 6,
                  2 * np.pi * h * r[1:-1],                       # interior: h r_A (exact)
                  2 * np.pi * h * (r[-1] / 2 - h / 6)]
    np.testing.assert_allclose(ev.area[np.argsort(pair.slave.X[0])], exact, rtol=1e-14)
    assert ev.area.sum() == pytest.approx(np.pi * 2.0 ** 2, rel=1e-14)   # the disk's area


@pytest.mark.parametrize("cell", ["line2", "line3"])
def test_tributary_weights_and_their_jacobian_in_the_measure(cell):
    """``a_A = int N_A 2 pi r dGamma`` on a bent chain from the axis, its derivative
    (what NTS's Tresca bound chains in) against central differences, and the weights'
    sum against the exact surface area of the revolved chords (line2: the frustums'
    ``pi (r_1 + r_2) l``; line3 straight cells likewise)."""
    from skfem_mortar.contact.curves import tributary_weights
    from skfem_mortar.contact.tributary import tributary_jacobian
    rng = np.random.default_rng(5)
    if cell == "line2":
        x = np.array([[0.0, 0.1, 0.25, 0.4], [0.0, 0.01, -0.02, 0.03]])
        seg = np.array([[0, 1], [1, 2], [2, 3]])
    else:
        x = np.array([[0.0, 0.2, 0.1, 0.35, 0.28], [0.0, 0.02, 0.015, 0.0, 0.01]])
        seg = np.array([[0, 1, 2], [1, 3, 4]])
    x = x + 1e-3 * rng.standard_normal(x.shape) * (x[0] > 0)
    J = tributary_jacobian(x, seg, None, cell, AXISYMMETRIC).toarray()
    h = 1e-7
    Jfd = np.zeros_like(J)
    flat = x.T.ravel()
    for k in range(flat.size):
        e = np.zeros(flat.size)
        e[k] = h
        ap = tributary_weights((flat + e).reshape(-1, 2).T, seg, cell, AXISYMMETRIC)
        am = tributary_weights((flat - e).reshape(-1, 2).T, seg, cell, AXISYMMETRIC)
        Jfd[:, k] = (ap - am) / (2 * h)
    # h = 1e-7, entries O(1): truncation ~1e-14, round-off ~1e-9
    np.testing.assert_allclose(J, Jfd, rtol=0, atol=1e-7 * np.abs(J).max())
    if cell == "line2":
        a, b = x[:, seg[:, 0]], x[:, seg[:, 1]]
        area = np.sum(np.pi * (a[0] + b[0]) * np.hypot(*(b - a)))
        w = tributary_weights(x, seg, cell, AXISYMMETRIC)
        assert w.sum() == pytest.approx(area, rel=1e-14)
        assert w[0] == pytest.approx(2 * np.pi * np.hypot(*(b[:, 0] - a[:, 0])) * b[0, 0] / 6,
                                     rel=1e-14)    # the axis node: 2 pi l r_2 / 6
