"""Friction in the contact pair: refusals, declarations, the whole pair's tangent
against central differences (NTS, mortar, dual; stick and slip; a curved master
crossed by a sliding slave), the status set, checkpoints, Newton's rate, outputs."""
import numpy as np
import pytest
from skfem import MeshTri

from fd import fd_tangent
from skfem_mortar import Coulomb, Tresca
from skfem_mortar.bodies.materials import LinearElastic
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.contact.friction import OPEN, SLIP, STICK, complementarity
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve

METHODS = ("nts", "mortar", "mortar-dual")


def _block(x0, x1, y0, y1, nx, ny, name, E=100.0, element="tri1"):
    m = MeshTri.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    if element == "tri2":
        from skfem import MeshTri2
        m = MeshTri2.from_mesh(m)
    return Solid(m.with_defaults(), LinearElastic(E=E, nu=0.3), element=element, name=name)


def _on_plane(method, friction=Coulomb(0.3), slide=0.05, n_steps=4):
    """A 2 x 0.5 block pressed on a rigid plane by 0.01, then its top slid by ``slide``."""
    b = _block(0, 2, 0, 0.5, 10, 3, "block")
    plane = RigidPlane((1.0, 0.0), (0.0, 1.0), length=10.0)
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), plane, method, name="c",
                       friction=friction)
    ty, tx = b.dofs_on("top", "y"), b.dofs_on("top", "x")
    model = Model([b, pair, Dirichlet(b, ty, lambda lf: -0.01 * min(2 * lf, 1.0)),
                   Dirichlet(b, tx, lambda lf: slide * max(2 * lf - 1.0, 0.0))])
    return b, pair, model, tx, ty


def _two_blocks(method, friction=Coulomb(0.4)):
    """A slave block (6 bottom segments) on a finer deformable master block (9 top segments)."""
    top = _block(0.2, 1.0, 0.5, 1.0, 6, 2, "top")
    bot = _block(0.0, 1.2, 0.0, 0.5, 9, 2, "bottom", E=200.0)
    pair = ContactPair(ContactSurface.from_solid(top, "bottom"),
                       ContactSurface.from_solid(bot, "top"), method, name="c",
                       friction=friction)
    return top, bot, pair, Model([top, bot, pair])


# ------------------------------------------------------------- refusals, declarations
def test_refusals():
    b = _block(0, 1, 0, 1, 2, 2, "b")
    plane = RigidPlane((0.5, 0.0), (0.0, 1.0), length=4.0)
    s = ContactSurface.from_solid(b, "bottom")
    with pytest.raises(ValueError, match="friction must be None, Coulomb"):
        ContactPair(s, plane, "nts", friction=0.3)
    with pytest.raises(ValueError, match="mu must be a finite real number >= 0"):
        Coulomb(-0.1)


@pytest.mark.parametrize("method", METHODS)
def test_declarations_and_unknowns(method):
    _, pair, model, _, _ = _on_plane(method)
    _, plain, plain_model, _, _ = _on_plane(method, friction=None)
    n = pair.slave.n_nodes
    assert pair.n_dofs == 2 * n and plain.n_dofs == n
    assert pair.multipliers_per_node == 2 and plain.multipliers_per_node == 1
    assert not pair.symmetrizable and not model.symmetrizable and pair.has_history
    assert model.n == plain_model.n + n
    # a frictionless pair keeps no friction state
    assert not {"friction_status", "friction_p_ref"} & set(plain.state_dict())
    assert {"friction_status", "friction_p_ref"} <= set(pair.state_dict())


# ---------------------------------------------------------------- the pair's tangent
def _mixed_multipliers(pair, z, rng):
    """Multipliers at ``z`` that make every masked node active with a positive slip
    bound, and about half of them stick, half slip: ``lam_n = c g + p`` and
    ``lam_t = c u_t + r Xi`` with ``|r| < 1`` (stick) or ``> 1`` (slip)."""
    pair.statuses.frozen = None
    ev, sl, _ = pair.friction_rows(z, tangent=False, active=np.ones(pair.slave.n_nodes, bool))
    n = pair.slave.n_nodes
    c = pair.c
    scale = 1.0 if pair.multiplier_kind == "traction" else float(np.mean(ev.area))
    p = scale * rng.uniform(1.0, 2.0, n)
    z[pair._normal] = c * ev.g + p
    xi = pair.friction.mu * p
    r = np.where(np.arange(n) % 2 == 0, rng.uniform(-0.6, 0.6, n),
                 rng.choice([-1.0, 1.0], n) * rng.uniform(1.4, 2.0, n))
    z[pair._tangential] = c * sl.u + r * xi
    return ev.mask & sl.mask


def _check_tangent(pair, model, z, need=(STICK, SLIP)):
    """The pair's tangent against central differences of its residual, the normal
    set and the statuses frozen at those of ``z`` (each branch is smooth)."""
    on = np.ones(pair.slave.n_nodes, bool)
    ev, sl, fr = pair.friction_rows(z, tangent=False, active=on & pair.evaluate(
        z, tangent=False, with_lam=False).mask)
    for code in need:
        assert np.any(fr.status == code), (code, fr.status)
    pair.state.frozen = ev.mask.copy()
    pair.statuses.frozen = fr.status.copy()
    # the exact derivatives (the default projects lam_t onto the slip disk in the
    # slip rows: the same at every solution, not at these states with |lam_t| > Xi)
    pair.friction_jacobian = "exact"
    c0 = pair.assemble(z, 1.0)
    K = np.zeros((model.n, model.n))
    np.add.at(K, (c0.k_rows, c0.k_cols), c0.k_vals)
    Kfd = fd_tangent(pair, z, 1.0, h=1e-7)
    rows = np.arange(model.n)
    tang = (rows >= pair._tangential.start) & (rows < pair._tangential.stop)
    assert np.abs(K[tang]).max() > 0 and np.abs(K[:, tang]).max() > 0
    # central differences with h = 1e-7 on unit-size geometry: truncation
    # O(h^2 |R'''|) ~ 1e-12 and round-off O(eps |R| / h) ~ 1e-9 |R|, so 1e-6 of
    # the largest entry is far above both and far below any wrong term
    np.testing.assert_allclose(K, Kfd, rtol=0, atol=1e-6 * np.abs(K).max())
    pair.state.frozen = None
    pair.statuses.frozen = None
    pair.friction_jacobian = "projected"
    return fr


@pytest.mark.parametrize("method", METHODS)
def test_tangent_fd_on_a_rigid_plane(method):
    """Stick and slip nodes of a block pressed and slid on a rigid plane."""
    b, pair, model, _, _ = _on_plane(method)
    z0 = np.zeros(model.n)
    pair.begin_step(z0, 1.0)  # the slip history: the reference state
    rng = np.random.default_rng(1)
    z = z0.copy()
    u = z[b.offset:b.offset + b.n_dofs].reshape(-1, 2)
    X = b.mesh.p.T
    u[:, 0] = 0.03 + 0.01 * X[:, 1]              # slid and sheared
    u[:, 1] = -0.005 * X[:, 0] ** 2             # and pressed unevenly (curved)
    z[:model.n_u] += 1e-3 * rng.standard_normal(model.n_u)
    _mixed_multipliers(pair, z, rng)
    _check_tangent(pair, model, z)


@pytest.mark.parametrize("method", METHODS)
def test_tangent_fd_curved_master_crossed(method):
    """A deformable, curved master; the slave slid by 1.7 master segments in the
    step (NTS: the arc length over the crossed segments; mortar: new partners)."""
    top, bot, pair, model = _two_blocks(method)
    z0 = np.zeros(model.n)
    pair.begin_step(z0, 1.0)
    rng = np.random.default_rng(2)
    z = z0.copy()
    ub = z[bot.offset:bot.offset + bot.n_dofs].reshape(-1, 2)
    Xb = bot.mesh.p.T
    ub[:, 1] = 0.04 * np.sin(2.5 * Xb[:, 0]) * Xb[:, 1]     # a curved master surface
    ut = z[top.offset:top.offset + top.n_dofs].reshape(-1, 2)
    Xt = top.mesh.p.T
    ut[:, 0] = 1.7 * 1.2 / 9                                # slid by 1.7 master segments
    ut[:, 1] = 0.04 * np.sin(2.5 * (Xt[:, 0] + ut[:, 0])) * 0.5 - 0.002
    z[:model.n_u] += 1e-4 * rng.standard_normal(model.n_u)
    _mixed_multipliers(pair, z, rng)
    _check_tangent(pair, model, z)
    if method == "nts":
        _, sl, _ = pair.friction_rows(z)
        assert np.abs(sl.info["crossed"]).max() >= 1   # segments crossed within the step


@pytest.mark.parametrize("method", METHODS)
def test_tangent_fd_tresca(method):
    b, pair, model, _, _ = _on_plane(method, friction=Tresca(0.5))
    z0 = np.zeros(model.n)
    pair.begin_step(z0, 1.0)
    rng = np.random.default_rng(3)
    z = z0.copy()
    z[:model.n_u] += 2e-3 * rng.standard_normal(model.n_u)
    _tresca_multipliers(pair, z)
    _check_tangent(pair, model, z)


def _tresca_multipliers(pair, z):
    """Multipliers at ``z`` with every node active and, alternately, half the
    Tresca bound (stick) and 1.5 times it (slip)."""
    ev, sl, fr = pair.friction_rows(z, active=np.ones(pair.slave.n_nodes, bool))
    z[pair._normal] = pair.c * ev.g + 1.0
    z[pair._tangential] = pair.c * sl.u + fr.bound * np.where(
        np.arange(fr.bound.size) % 2 == 0, 0.5, 1.5)


@pytest.mark.parametrize("method", METHODS)
def test_reserved_triplets_equal_the_plain_ones(method, monkeypatch):
    """The tangent over the reserved patterns (explicit zeros) is the plain one."""
    top, bot, pair, model = _two_blocks(method)
    z = np.zeros(model.n)
    pair.begin_step(z, 1.0)
    rng = np.random.default_rng(4)
    z[:model.n_u] += 1e-3 * rng.standard_normal(model.n_u)
    _mixed_multipliers(pair, z, rng)

    def dense(c):
        K = np.zeros((model.n, model.n))
        np.add.at(K, (c.k_rows, c.k_cols), c.k_vals)
        return K

    pair.state.frozen = np.ones(pair.slave.n_nodes, bool)
    c_res = pair.assemble(z, 1.0)
    assert c_res.reserved
    monkeypatch.setattr(pair, "_friction_reservation", lambda z, gd: None)
    c_plain = pair.assemble(z, 1.0)
    # the same terms summed in another order: round-off of the largest entry
    np.testing.assert_allclose(dense(c_res), dense(c_plain), rtol=0,
                               atol=1e-13 * np.abs(dense(c_plain)).max())


# ------------------------------------------------------------------- status set
def test_status_set_cycling_guard():
    from skfem_mortar.contact.active_set import StatusSet
    s = StatusSet(3, cycle_guard=True)
    s.converged = np.array([STICK, STICK, OPEN], np.int8)
    s.begin()
    first = s.update(np.array([SLIP, STICK, STICK], np.int8), track=True)
    # the first iteration keeps the converged statuses where in contact then and now
    assert list(first) == [STICK, STICK, STICK] and not s.changed
    a, b = np.array([SLIP, STICK, STICK], np.int8), np.array([STICK, SLIP, STICK], np.int8)
    s.update(a, True)
    s.update(b, True)
    out = s.update(a, True)           # a repeats: one node changes (the least index)
    assert s.cycles == 1 and list(out) == [SLIP, SLIP, STICK]
    assert list(s.update(np.array([OPEN, SLIP, STICK], np.int8), True)) == [OPEN, SLIP, STICK]


# -------------------------------------------------------------- converged states
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("jacobian", ["projected", "exact"])
def test_slide_converges_with_kkt_and_quadratic_rate(method, jacobian):
    b, pair, model, tx, ty = _on_plane(method, slide=0.05, n_steps=6)
    pair.friction_jacobian = jacobian
    # per step, per Newton iteration: whether the tangent's normal set or statuses
    # changed (the set Newton's step from that iteration uses)
    steps, assemble, begin = [], pair.assemble, pair.begin_step

    def begin_step(z, lf):
        steps.append([])
        begin(z, lf)

    def tracked(z, lf, tangent=True):
        out = assemble(z, lf, tangent)
        if tangent:
            steps[-1].append(pair.state.changed or pair.statuses.changed)
        return out
    pair.begin_step, pair.assemble = begin_step, tracked
    res = solve(model, 6, newton=NewtonOptions(rtol=1e-12))
    last = res.steps[-1]
    assert last.info["n_slip"] > 0 and last.info["n_stick"] == 0   # gross sliding
    assert any(0 < s.info["n_slip"] for s in res.steps[:-1])
    assert pair.violation(res.z, 1.0) == ""
    assert pair.pattern_misses == 0     # the reserved patterns held G_n, G_t, H_n, H_t
    d = pair.contact_data(res.z)
    on = d["status"] == "slip"
    # sliding nodes: |t_t| = mu p to the multipliers' convergence (Newton to
    # rtol 1e-12 of the force scale ~ 1 here, tractions ~ 0.1)
    np.testing.assert_allclose(np.abs(d["tangential_traction"][on]), 0.3 * d["pressure"][on],
                               rtol=1e-9)
    assert np.all(d["tangential_traction"][on] * d["slip"][on] < 0)  # opposes the slip
    # quadratic rate once the statuses settle: in every converged attempt (the
    # attempt whose assemblies number its iterations + 1), from the first
    # iteration whose sets did not change on, the order estimated from three
    # residuals above the round-off floor (1e-12 of the first),
    # p = log(r_k+2 / r_k+1) / log(r_k+1 / r_k), is about 2 (linear: 1); measured
    # 1.6 .. 2.0, the lower where the first of the three is still pre-asymptotic
    # (the constant C of r_k+1 = C r_k^2, 0.2 .. 6e3, depends on the rows' units)
    attempts = iter(steps)
    orders = []
    for s in res.steps:
        flags = next(f for f in attempts if len(f) == s.newton_iterations + 1)
        r = np.asarray(s.residual_norms) / s.residual_norms[0]
        changed = np.flatnonzero(flags)
        j = changed[-1] + 1 if changed.size else 0
        for i in range(j, r.size - 2):
            if r[i + 2] > 1e-12 and r[i] < 1e-2:
                orders.append(np.log(r[i + 2] / r[i + 1]) / np.log(r[i + 1] / r[i]))
    if jacobian == "exact":
        assert len(orders) >= 2 and min(orders) > 1.4, orders
        return
    # the projected derivatives converge too fast to leave three residuals above
    # the floor after the statuses settle (measured: 6 steps, 1 to 7 iterations,
    # against 8 to 14 steps and up to 20 iterations with the exact ones); their
    # rate is the exact Newton method's because at a solution the two tangents
    # are the same (sliding nodes have |lam_t| = Xi): compared at the converged
    # state with its statuses, to Newton's tolerance (1e-12) times the rows' size
    assert min(orders, default=2.0) > 1.4, orders
    assert sum(s.newton_iterations for s in res.steps) < 40
    pair.assemble = assemble
    pair.statuses.frozen = pair.statuses.converged.copy()
    K = {}
    for jac in ("projected", "exact"):
        pair.friction_jacobian = jac
        c = pair.assemble(res.z, 1.0)
        K[jac] = np.zeros((model.n, model.n))
        np.add.at(K[jac], (c.k_rows, c.k_cols), c.k_vals)
    pair.statuses.frozen = None
    np.testing.assert_allclose(K["projected"], K["exact"], rtol=0,
                               atol=1e-8 * np.abs(K["exact"]).max())


@pytest.mark.parametrize("method", METHODS)
def test_checkpoint_round_trip_and_refusals(method):
    b, pair, model, tx, ty = _on_plane(method)
    res = solve(model, 4)
    st = pair.state_dict()
    for k in pair.discretization.slip_history_keys:
        assert st[k].size > 0
    assert set(st["friction_status"]) <= {OPEN, STICK, SLIP}
    _, other, _, _, _ = _on_plane(method)
    other.load_state_dict(st)
    st2 = other.state_dict()
    assert set(st2) == set(st)
    for k in st:
        np.testing.assert_array_equal(st2[k], st[k])
    bad = dict(st)
    bad["friction_status"] = np.full_like(st["friction_status"], 7)
    with pytest.raises(ValueError, match="friction_status"):
        other.load_state_dict(bad)
    bad = dict(st)
    bad["friction_p_ref"] = np.array([-1.0])
    with pytest.raises(ValueError, match="friction_p_ref"):
        other.load_state_dict(bad)
    key = pair.discretization.slip_history_keys[0]
    bad = dict(st)
    bad[key] = np.asarray(st[key])[:-1]
    with pytest.raises(ValueError):
        other.load_state_dict(bad)


def test_complementarity_imposed_status():
    r = complementarity(Coulomb(0.5), np.array([1.0, 1.0]), np.array([0.1, 0.1]),
                        np.zeros(2), np.zeros(2), 1.0, 1.0,
                        status=np.array([SLIP, STICK], np.int8))
    assert list(r.status) == [SLIP, STICK]
    # imposed slip: |s| lam_t - Xi s with s = lam_t = 0.1, Xi = 0.5; imposed stick: Xi c u_t = 0
    assert r.C[1] == 0.0 and r.C[0] == pytest.approx(0.1 * 0.1 - 0.5 * 0.1)
    with pytest.raises(ValueError, match="status"):
        complementarity(Coulomb(0.5), np.ones(2), np.zeros(2), np.zeros(2), np.zeros(2),
                        1.0, 1.0, status=np.array([5, 1]))


@pytest.mark.parametrize("method", METHODS)
def test_tresca_sliding_force_is_the_bound_times_the_contact_length(method):
    """Gross sliding under Tresca: the tangential resultant is ``bound`` times the
    current contact length with every method (NTS: the nodal bound weighs the
    current tributary lengths; mortar: traction multipliers on the current
    mortar integrals); to Newton's tolerance."""
    bound = 1e-3
    b, pair, model, tx, ty = _on_plane(method, friction=Tresca(bound), slide=0.05)
    res = solve(model, 8)
    d = pair.contact_data(res.z)
    act = pair.active
    assert np.all(d["status"][pair.active[d["node"]]] == "slip")
    ev = pair.evaluate(res.z, tangent=False, with_lam=False)
    length = ev.area[act].sum()
    assert abs(length / pair._area0[act].sum() - 1.0) > 5e-3   # the reference one differs
    # measured 4e-13 (NTS), 1e-16 (mortar); the block expands laterally by 0.6 %,
    # so the reference length would miss by that much
    np.testing.assert_allclose(-pair.total_force(res.z)[0], bound * length, rtol=1e-10)
