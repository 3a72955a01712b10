"""Friction on 3-node (quadratic) contact segments: the slip and the contact pair.

Slip (contact/slip.py on curved segments): ``u_t``, ``G_t = du_t/dx`` and
``H_t = sum lam_t d2 u_t/dx2`` against central differences on curved, sliding
configurations (NTS on one curved master segment and across segments forward
and backward; mortar standard and dual, 3-on-3, 3-on-2, 2-on-3), objectivity
(a rigid rotation by 30 degrees and a translation give zero slip, the
non-objective increment forms do not), the straight limits (the curved NTS
slip is the linear one on a straight chain; pure mortar sliding gives the
distance times the support).  The pair: friction on tri2 bodies, its whole
tangent against central differences (stick and slip), and a tri2 block sliding
on a rigid plane carries exactly ``mu N``.
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel, nts
from skfem_mortar.contact.mortar_slip_cells import tangential_evaluate
from skfem_mortar.contact.slip import mortar_history, mortar_slip, nts_slip
from test_mortar_quadratic import configuration
from test_nts_quadratic import _master, _slave
from test_slip import fd_jacobian, rotate

# Central differences with h = 1e-6 on unit-size geometry: truncation ~h^2 |u'''|
# and round-off ~eps |u| / h ~ 1e-10.  G agrees to ~1e-10; H (a difference of G)
# to ~1e-9 of its entries, except where the third derivatives are large (a mid
# node of a slave over a 2-node master: the error there is 4.5e-5, 4.5e-7, 5e-9 at
# h = 1e-5, 1e-6, 1e-7, falling as h^2, i.e. truncation); a missing chain-rule term
# is off by the size of the entries (1e-2 .. 1).
TOL_G = 1e-9
TOL_H = 2e-7            # relative to max |H|


def pack(xs, xm):
    return np.concatenate([xs.T.ravel(), xm.T.ravel()])


def unpack(z, n_s):
    return z[:2 * n_s].reshape(-1, 2).T, z[2 * n_s:].reshape(-1, 2).T


def fd_check(ev, z, lam):
    """The largest |G - G_fd| and |H - H_fd| / max|H| of the slip evaluation ``ev(z, **kw)``."""
    e = ev(z, lam_t=lam)
    G, H = e.G.toarray(), e.H.toarray()
    eg = np.abs(G - fd_jacobian(lambda q: ev(q, tangent=False).u, z)).max()
    eh = np.abs(H - fd_jacobian(lambda q: ev(q).G.T @ lam, z)).max() / np.abs(H).max()
    assert np.abs(H - H.T).max() <= 1e-14 * np.abs(H).max()        # a second derivative
    return e, eg, eh


# --------------------------------------------------------------------- NTS
def _nts_case(slide, quadratic_slave=False, seed=1):
    """The bent 3-node master of test_nts_quadratic (3 segments, chain right to
    left, mid nodes off-centre), a slave projected on it (the history), then the
    slave slid by ``slide`` along x and both perturbed."""
    xm0, seg_m = _master()
    xs0, seg_s, lam = _slave()
    if quadratic_slave:          # 3-node slave segments: the mid nodes are contact points
        seg_s, xs0, lam = np.array([[0, 2, 1], [2, 4, 3]]), xs0[:, :5], lam[:5]
    ev0 = nts.evaluate(xs0, seg_s, xm0, seg_m, tangent=False)
    rng = np.random.default_rng(seed)
    xs = xs0 + [[slide], [0.0]] + 0.005 * rng.standard_normal(xs0.shape)
    xm = xm0 + 0.005 * rng.standard_normal(xm0.shape)
    return xs0, xm0, xs, xm, seg_s, seg_m, lam, ev0


@pytest.mark.parametrize("slide,crossed", [(0.03, 0), (0.3, -1), (-0.3, 1)])
@pytest.mark.parametrize("quadratic_slave", [False, True])
def test_nts_curved_slip_derivatives(slide, crossed, quadratic_slave):
    """On one curved segment (0.03), and across a segment boundary backward (+0.3
    along x: the master chain runs right to left) and forward (-0.3)."""
    _, _, xs, xm, seg_s, seg_m, lam, ev0 = _nts_case(slide, quadratic_slave)
    n_s = xs.shape[1]
    seg = nts.evaluate(xs, seg_s, xm, seg_m, tangent=False).info["segment"]

    def ev(q, **kw):
        a, b = unpack(q, n_s)
        return nts_slip(a, b, seg_m, ev0.info["xi"], ev0.info["segment"], segment=seg, **kw)
    e, eg, eh = fd_check(ev, pack(xs, xm), lam)
    assert e.mask.sum() >= n_s - 1 and np.abs(e.u).max() > 0.5 * abs(slide)
    assert crossed in e.info["crossed"][e.mask]           # the case it says it is
    assert eg < TOL_G and eh < TOL_H


def test_nts_slip_on_a_3_node_slave_over_a_2_node_master():
    """3-on-2: the master is linear, the slave's mid nodes are contact points."""
    xm0, seg_m = _master(bend=0.0)
    xm0, seg_m = xm0[:, :4], seg_m[:, :2]
    xs0, _, lam = _slave()
    seg_s = np.array([[0, 2, 1], [2, 4, 3]])
    xs0, lam = xs0[:, :5], lam[:5]
    ev0 = nts.evaluate(xs0, seg_s, xm0, seg_m, tangent=False)
    xs = xs0 + [[0.27], [0.01]]
    seg = nts.evaluate(xs, seg_s, xm0, seg_m, tangent=False).info["segment"]

    def ev(q, **kw):
        a, b = unpack(q, 5)
        return nts_slip(a, b, seg_m, ev0.info["xi"], ev0.info["segment"], segment=seg, **kw)
    e, eg, eh = fd_check(ev, pack(xs, xm0), lam)
    # a flat master: the slip is the slide along the tangent (-x), to round-off
    assert e.mask.sum() == 5 and (e.info["crossed"] != 0).any()
    np.testing.assert_allclose(e.u, -0.27, atol=1e-14)
    assert eg < TOL_G and eh < TOL_H


def test_nts_curved_slip_is_objective_and_the_increment_form_is_not():
    """A rigid rotation by 30 degrees with a translation of the whole converged
    configuration: zero slip at every node to round-off; the non-objective
    ``e . (dx_s - dx^M(xi_prev))`` is not zero."""
    xs0, xm0, _, _, seg_s, seg_m, _, ev0 = _nts_case(0.0)
    xs, xm = rotate(xs0, 30.0, (0.4, -0.7)), rotate(xm0, 30.0, (0.4, -0.7))
    e = nts_slip(xs, xm, seg_m, ev0.info["xi"], ev0.info["segment"], tangent=False)
    assert e.mask.all()
    # round-off of arc lengths ~1 computed from rotated coordinates: a few 1e-16
    np.testing.assert_allclose(e.u, 0.0, atol=1e-13)
    t = 2.0 * ev0.info["xi"] - 1.0                       # the curve parameter
    N = [t * (t - 1) / 2, t * (t + 1) / 2, 1 - t * t]
    dxm = sum(N[a] * (xm - xm0)[:, seg_m[ev0.info["segment"], a]] for a in range(3))
    bad = np.sum(e.tangent * ((xs - xs0) - dxm), axis=0)
    assert np.abs(bad).max() > 1e-2                      # the test can fail
    e = nts_slip(xs0 + [[0.3], [0.2]], xm0 + [[0.3], [0.2]], seg_m, ev0.info["xi"],
                 ev0.info["segment"], tangent=False)
    np.testing.assert_allclose(e.u, 0.0, atol=1e-13)


def test_nts_curved_slip_is_the_linear_one_on_a_straight_chain():
    """Centred mid nodes on a straight chain: the curved master's arc length is the
    chord's, so the slip, its tangent and its slave derivatives equal the 2-node
    kernel's (round-off; the master derivatives differ: a vertex moved off the line
    bends the 3-node curve but turns the 2-node segment)."""
    xm3, seg3 = _master(bend=0.0)
    xm3[:, 4:] = 0.5 * (xm3[:, seg3[:, 0]] + xm3[:, seg3[:, 1]])    # centred mid nodes
    xm3 = rotate(xm3, 10.0, (0.0, 0.0))
    xs0, _, _ = _slave(y0=0.03)
    xs0 = rotate(xs0, 10.0, (0.0, 0.0))
    ev0 = nts.evaluate(xs0, np.c_[0:5, 1:6], xm3, seg3, tangent=False)
    xs = xs0 + rotate(np.array([[0.33], [0.0]]), 10.0, (0.0, 0.0))
    e3 = nts_slip(xs, xm3, seg3, ev0.info["xi"], ev0.info["segment"])
    e2 = nts_slip(xs, xm3[:, :4], seg3[:, :2], ev0.info["xi"], ev0.info["segment"])
    assert (e3.mask == e2.mask).all() and e3.mask.sum() >= 4 and (e3.info["crossed"] != 0).any()
    np.testing.assert_allclose(e3.u, e2.u, atol=1e-14)
    np.testing.assert_allclose(e3.tangent, e2.tangent, atol=1e-14)
    np.testing.assert_allclose(e3.G.toarray()[:, :12], e2.G.toarray()[:, :12], atol=1e-14)


def test_nts_slip_validates_its_history():
    xs0, xm0, _, _, _, seg_m, _, ev0 = _nts_case(0.0)
    with pytest.raises(ValueError, match="segment_prev must index master segments"):
        nts_slip(xs0, xm0, seg_m, ev0.info["xi"], np.full(xs0.shape[1], 3))


# ------------------------------------------------------------------ mortar
CASES = [(3, 3), (3, 2), (2, 3)]


def _mortar_case(ks, km, dual):
    xs0, ss, xm0, sm = configuration(ks, km, 0.37)
    hist = mortar_history(xs0, ss, xm0, sm, space=("dual" if dual else "standard"))
    return xs0, ss, xm0, sm, hist


@pytest.mark.parametrize("ks,km", CASES)
@pytest.mark.parametrize("dual", [False, True])
def test_mortar_curved_slip_derivatives(ks, km, dual):
    """The curved slave (the disk) slid by 0.06 over the curved base, both perturbed."""
    xs0, ss, xm0, sm, hist = _mortar_case(ks, km, dual)
    rng = np.random.default_rng(0)
    xs = xs0 + [[0.06], [0.0]] + 0.005 * rng.standard_normal(xs0.shape)
    xm = xm0 + 0.005 * rng.standard_normal(xm0.shape)
    n_s = xs.shape[1]
    lam = rng.standard_normal(n_s)

    def ev(q, **kw):
        a, b = unpack(q, n_s)
        return mortar_slip(a, ss, b, sm, hist["D_prev"], hist["M_prev"], space=("dual" if dual else "standard"), **kw)
    e, eg, eh = fd_check(ev, pack(xs, xm), lam)
    assert e.mask.all() and np.abs(e.u).max() > 1e-3        # a sliding state, all nodes
    assert eg < TOL_G and eh < TOL_H


@pytest.mark.parametrize("ks,km", CASES)
@pytest.mark.parametrize("dual", [False, True])
def test_mortar_curved_slip_is_objective_and_the_increment_form_is_not(ks, km, dual):
    xs0, ss, xm0, sm, hist = _mortar_case(ks, km, dual)
    xs, xm = rotate(xs0, 30.0, (0.4, -0.7)), rotate(xm0, 30.0, (0.4, -0.7))
    e = mortar_slip(xs, ss, xm, sm, hist["D_prev"], hist["M_prev"], space=("dual" if dual else "standard"), tangent=False)
    assert e.mask.all()
    # round-off of D x - M x with |x| ~ 1 and D, M ~ 0.1: a few 1e-17
    np.testing.assert_allclose(e.u, 0.0, atol=1e-15)
    bad = -np.sum(e.tangent * (hist["D_prev"] @ (xs - xs0).T
                               - hist["M_prev"] @ (xm - xm0).T).T, axis=0)
    assert np.abs(bad).max() > 1e-3                      # the test can fail
    e = mortar_slip(xs0 + [[0.3], [0.2]], ss, xm0 + [[0.3], [0.2]], sm, hist["D_prev"],
                    hist["M_prev"], space=("dual" if dual else "standard"), tangent=False)
    np.testing.assert_allclose(e.u, 0.0, atol=1e-15)


@pytest.mark.parametrize("ks,km", CASES)
def test_curved_tangential_offset_is_the_mortar_integrals_identity(ks, km):
    """``r_A`` integrated per Gauss point equals ``tau_A . (M x_m - D x_s)`` from the
    assembled integrals, and ``tau_A`` is the kernel's nodal normal turned."""
    xs, ss, xm, sm = configuration(ks, km, 0.37)
    for dual in (False, True):
        t = tangential_evaluate(xs, ss, xm, sm, space=("dual" if dual else "standard"), tangent=False)
        v = t.info["M"] @ xm.T - t.info["D"] @ xs.T
        np.testing.assert_allclose(t.g, np.sum(t.info["tangent"].T * v, axis=1), atol=1e-15)
        assert np.abs(t.g).max() > 1e-7                # curved: not round-off (1e-17)
        g = mortar_kernel.evaluate(xs, ss, xm, sm, space=("dual" if dual else "standard"), tangent=False)
        for key in ("D", "M"):                          # the same integrals as the gaps'
            assert abs(t.info[key] - g.info[key]).max() == 0.0


@pytest.mark.parametrize("dual", [False, True])
def test_mortar_pure_sliding_on_straight_3_node_surfaces(dual):
    """A straight 3-node slave slides by ``d`` along its tangent over a straight
    3-node master: ``u_t,A = d int Phi_A = d area_A`` (round-off)."""
    def line(x0, x1, y, n):
        xv = np.linspace(x0, x1, n + 1)
        X = np.r_[xv, 0.5 * (xv[:-1] + xv[1:])]
        return np.array([X, np.full(X.size, y)]), np.c_[0:n, 1:n + 1, n + 1:2 * n + 1]
    xs0, ss = line(0.0, 1.0, 1e-3, 4)
    xm0, sm = line(1.6, -0.6, 0.0, 5)
    hist = mortar_history(xs0, ss, xm0, sm, space=("dual" if dual else "standard"))
    area = mortar_kernel.evaluate(xs0, ss, xm0, sm, space=("dual" if dual else "standard"), tangent=False).area
    d = 0.137
    e = mortar_slip(xs0 + [[-d], [0.0]], ss, xm0, sm, hist["D_prev"], hist["M_prev"],
                    space=("dual" if dual else "standard"), tangent=False)
    np.testing.assert_allclose(e.tangent, np.repeat([[-1.0], [0.0]], xs0.shape[1], 1),
                               atol=1e-15)
    np.testing.assert_allclose(e.u, d * area, atol=1e-15)


# -------------------------------------------------------------------- the pair
from skfem import MeshQuad, MeshQuad2, MeshTri, MeshTri2  # noqa: E402

from skfem_mortar import Coulomb  # noqa: E402
from skfem_mortar.bodies.materials import LinearElastic  # noqa: E402
from skfem_mortar.bodies.solid import Solid  # noqa: E402
from skfem_mortar.contact.friction import SLIP, STICK  # noqa: E402
from skfem_mortar.contact.pair import ContactPair  # noqa: E402
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane  # noqa: E402
from skfem_mortar.core.dirichlet import Dirichlet  # noqa: E402
from skfem_mortar.core.model import Model  # noqa: E402
from skfem_mortar.scenes.slide import _PathTraction  # noqa: E402
from skfem_mortar.solver.stepping import solve  # noqa: E402
from test_friction_pair import _check_tangent, _mixed_multipliers  # noqa: E402

METHODS = ("nts", "mortar", "mortar-dual")
MESHES = {"tri1": (MeshTri, None), "tri2": (MeshTri, MeshTri2),
          "quad1": (MeshQuad, None), "quad2": (MeshQuad, MeshQuad2)}


def _solid(x0, x1, y0, y1, nx, ny, name, element, E=100.0):
    base, higher = MESHES[element]
    m = base.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    if higher is not None:
        m = higher.from_mesh(m)
    return Solid(m.with_defaults(), LinearElastic(E=E, nu=0.3), element=element, name=name)


def test_friction_pairs_on_3_node_segments_are_built():
    """No refusal any more: a quadratic surface takes friction with every method,
    with the 3-node surfaces' mid nodes as contact points (two multipliers each)."""
    q = _solid(0, 1, 0, 1, 2, 2, "q", "tri2")
    plane = RigidPlane((0.5, 0.0), (0.0, 1.0), length=4.0)
    for method in METHODS:
        pair = ContactPair(ContactSurface.from_solid(q, "bottom"), plane, method,
                           friction=Coulomb(0.2))
        assert pair.slave.order == 2 and pair.n_dofs == 2 * pair.slave.n_nodes == 2 * 5


def _two_blocks(method, top_element, bottom_element):
    """A slave block on a deformable master block (coarse: the FD runs over every dof)."""
    top = _solid(0.2, 1.0, 0.5, 1.0, 3, 1, "top", top_element)
    bot = _solid(0.0, 1.2, 0.0, 0.5, 4, 1, "bottom", bottom_element, E=200.0)
    pair = ContactPair(ContactSurface.from_solid(top, "bottom"),
                       ContactSurface.from_solid(bot, "top"), method, name="c",
                       friction=Coulomb(0.4))
    return top, bot, pair, Model([top, bot, pair])


def _node_positions(body):
    """Reference positions (n, 2) of the body's nodes in its dof order (vertices,
    then the P2 mid nodes)."""
    return body.basis.doflocs[:, ::2].T


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("top_element,bottom_element",
                         [("tri2", "tri2"), ("tri2", "tri1"), ("tri1", "tri2")])
def test_pair_tangent_fd_curved_master_crossed(method, top_element, bottom_element):
    """The whole pair's tangent with friction (stick and slip nodes) against central
    differences: a curved deformable master, the slave slid by 0.45 master segments
    within the step (3-on-3, 3-on-2, 2-on-3)."""
    top, bot, pair, model = _two_blocks(method, top_element, bottom_element)
    z0 = np.zeros(model.n)
    pair.begin_step(z0, 1.0)                       # the slip history: the reference state
    rng = np.random.default_rng(2)
    z = z0.copy()
    ub = z[bot.offset:bot.offset + bot.n_dofs].reshape(-1, 2)
    Xb = _node_positions(bot)
    ub[:, 1] = 0.04 * np.sin(2.5 * Xb[:, 0]) * Xb[:, 1]     # a curved master surface
    ut = z[top.offset:top.offset + top.n_dofs].reshape(-1, 2)
    Xt = _node_positions(top)
    ut[:, 0] = 0.45 * 1.2 / 4
    ut[:, 1] = 0.04 * np.sin(2.5 * (Xt[:, 0] + ut[:, 0])) * 0.5 - 0.002
    z[:model.n_u] += 1e-4 * rng.standard_normal(model.n_u)
    _mixed_multipliers(pair, z, rng)
    fr = _check_tangent(pair, model, z)                   # asserts stick and slip nodes
    assert np.sum(fr.status == STICK) >= 2 and np.sum(fr.status == SLIP) >= 2
    assert pair.pattern_misses == 0


@pytest.mark.parametrize("method", METHODS)
def test_pair_tangent_fd_on_a_rigid_plane(method):
    """A tri2 block pressed unevenly and slid on a rigid plane (3-on-2)."""
    b = _solid(0, 2, 0, 0.5, 4, 1, "block", "tri2")
    plane = RigidPlane((1.0, 0.0), (0.0, 1.0), length=10.0)
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), plane, method, name="c",
                       friction=Coulomb(0.3))
    model = Model([b, pair])
    z0 = np.zeros(model.n)
    pair.begin_step(z0, 1.0)
    rng = np.random.default_rng(1)
    z = z0.copy()
    u = z[b.offset:b.offset + b.n_dofs].reshape(-1, 2)
    X = _node_positions(b)
    u[:, 0] = 0.03 + 0.01 * X[:, 1]              # slid and sheared
    u[:, 1] = -0.005 * X[:, 0] ** 2             # and pressed unevenly (curved)
    z[:model.n_u] += 1e-3 * rng.standard_normal(model.n_u)
    _mixed_multipliers(pair, z, rng)
    _check_tangent(pair, model, z)


def _sliding_block(method, element, n=8, mu=0.3, N=0.02, slide=0.02):
    """``slide`` with a quadratic block: pressed by ``N`` (``t <= 1/4``), then its
    top pushed by ``slide`` along the rigid plane."""
    b = _solid(0.0, 2.0, 0.0, 0.5, n, max(1, n // 4), "block", element, E=1.0)
    plane = RigidPlane((1.0, 0.0), (0.0, 1.0), length=20.0, name="plane")
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), plane, method, name="contact",
                       friction=Coulomb(mu))
    tx = b.dofs_on("top", "x")
    model = Model([b, pair,
                   _PathTraction(b, "top", (0.0, -N / 2.0), lambda t: min(4.0 * t, 1.0)),
                   Dirichlet(b, tx, value=lambda t: slide * max(t - 0.25, 0.0) / 0.75)])
    return b, pair, model, tx


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("element", ["tri2", "quad2"])
def test_quadratic_block_slides_at_mu_n(method, element):
    """Gross sliding of a quadratic block: every contact node slides and the
    tangential resultant of the contact is ``mu N``.  NTS: to Newton's tolerance
    (measured 0 and 2e-14 on tri2, quad2).  Mortar: ``|t_t| = mu p`` at every node,
    but the traction acts along the slave's averaged nodal tangent, tilted next to
    the lifted trailing edge, so the resultant departs from ``mu N`` by that tilt
    (measured 5e-7 standard, 6e-6 dual on tri2; 7e-7, 5e-6 on quad2; the tri1
    block of the same mesh 4e-5, 2e-5)."""
    mu, N = 0.3, 0.02
    b, pair, model, tx = _sliding_block(method, element)
    res = solve(model, 10)
    F = pair.total_force(res.z)
    st = pair.statuses.converged
    assert np.sum(st == SLIP) >= 10 and np.sum(st == STICK) == 0       # gross sliding
    assert pair.violation(res.z, 1.0) == "" and pair.pattern_misses == 0
    np.testing.assert_allclose(F[1], N, rtol=1e-10)       # the press, to Newton's tolerance
    tol = 1e-11 if method == "nts" else 5e-5
    assert abs(-F[0] - mu * N) <= tol * mu * N
    # the support's reaction pushes the block: equal to the contact's, opposite
    R = b.reaction(model.assemble(res.z, 1.0, tangent=False)[0], tx)
    np.testing.assert_allclose(R, -F[0], rtol=1e-8)
    d = pair.contact_data(res.z)
    on = d["status"] == "slip"
    np.testing.assert_allclose(np.abs(d["tangential_traction"][on]), mu * d["pressure"][on],
                               rtol=1e-8)
    assert np.all(d["tangential_traction"][on] * d["slip"][on] < 0)   # opposes the slip


@pytest.mark.parametrize("method", METHODS)
def test_quadratic_friction_history_is_checkpointed_and_resume_repeats_the_run(method):
    """The slip history of 3-node surfaces (NTS ``xi_prev``, ``segment_prev``; mortar
    the curved kernel's ``D_prev``, ``M_prev``) and the statuses are item state: a
    solve restarted from the states of the first converged pushing step (partial
    slip, where the slip history decides the next step: NTS with ``xi_prev``
    scaled by 0.9 and shifted by 0.05 fails in that next step) repeats the uninterrupted solve to the
    last bit (the same arithmetic)."""
    from skfem_mortar.solver.stepping import Restart, stateful_items
    _, pair, model, _ = _sliding_block(method, "tri2", n=4)
    saved = []

    def keep(rec, z):
        saved.append((rec, z.copy(), {k: {n: np.array(a, copy=True)
                                          for n, a in it.state_dict().items()}
                                      for k, it in stateful_items(model).items()}))
    full = solve(model, 6, callback=keep)
    st = pair.state_dict()
    for key in pair.discretization.slip_history_keys:
        assert np.asarray(st[key]).size > 0
    k = next(i for i, (rec, _, _) in enumerate(saved) if rec.load_factor > 0.3)
    rec, z, items = saved[k]
    _, pair2, model2, _ = _sliding_block(method, "tri2", n=4)
    again = solve(model2, 6, restart=Restart(z, rec.load_factor, [s for s, _, _ in saved[:k + 1]],
                                             rec.controller, previous=saved[k - 1][1],
                                             items=items))
    np.testing.assert_array_equal(again.z, full.z)
    assert [s.newton_iterations for s in again.steps] == [s.newton_iterations for s in full.steps]
    np.testing.assert_array_equal(pair2.statuses.converged, pair.statuses.converged)
