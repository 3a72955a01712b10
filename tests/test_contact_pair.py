"""Tests of the contact pair item: KKT, tangent, action/reaction, convergence, cycling."""
import logging

import numpy as np
import pytest
from skfem import MeshTri

from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.item import Contribution, Item
from skfem_mortar.core.model import Model
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.solver.stepping import solve
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane

E = 100.0


def _block(x0, x1, y0, y1, nx, ny, name, E=E):
    m = MeshTri.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)).with_defaults()
    return Solid(m, NeoHooke(E=E, nu=0.0), name=name)


def _compressed_block(dy=-0.02, plane_y=0.0):
    """Unit block on a rigid plane y = plane_y, top pushed down by dy, bottom the slave."""
    b = _block(0, 1, 0, 1, 4, 4, "block")
    plane = RigidPlane((0.5, plane_y), (0.0, 1.0), length=10.0)
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), plane, "nts", name="c")
    items = [b, Dirichlet(b, b.dofs_on("top", "y"), dy),
             Dirichlet(b, b.dofs_on("left", "x"), 0.0), pair]
    return b, pair, Model(items)


def test_block_on_rigid_plane_pressure_is_analytic():
    # nu = 0 neo-Hooke (lambda = 0, mu = E/2): F = diag(1, ly), no lateral stress,
    # sigma_yy = P_yy = mu (ly - 1/ly); the block touches the plane everywhere.
    b, pair, model = _compressed_block(-0.02)
    res = solve(model, 2)
    ly = 0.98
    p_exact = -E / 2 * (ly - 1 / ly)
    d = pair.contact_data(res.z)
    # uniform state, reproduced exactly by linear triangles: round-off (the
    # residual tolerance rtol = 1e-10 of a force scale ~ E) bounds the error
    np.testing.assert_allclose(d["pressure"], p_exact, rtol=1e-8)
    np.testing.assert_allclose(d["gap"], 0.0, atol=1e-12)
    assert res.steps[-1].n_active == 5
    # total contact force on the slave equals the pressure times the width (+y)
    np.testing.assert_allclose(pair.total_force(res.z), [0.0, p_exact], atol=1e-8 * p_exact)


def test_lifted_block_stays_inactive():
    # plane 0.05 below the block, top moved down by 0.02: no contact, lam = 0
    b, pair, model = _compressed_block(-0.02, plane_y=-0.05)
    res = solve(model, 1)
    assert res.steps[-1].n_active == 0
    np.testing.assert_array_equal(res.z[pair.dofs], 0.0)


def _two_blocks(method="nts", shift=0.0):
    top = _block(0, 1, 1, 2, 3, 2, "top")
    bot = _block(0, 1, 0, 1, 5, 2, "bottom", E=2 * E)
    s = ContactSurface.from_solid(top, "bottom")
    m = ContactSurface.from_solid(bot, "top")
    pair = ContactPair(s, m, method, name="c")
    items = [top, bot, pair,
             Dirichlet(bot, bot.dofs_on("bottom"), 0.0),
             Dirichlet(top, top.dofs_on("top", "y"), -0.03),
             Dirichlet(top, top.dofs_on("top", "x"), shift)]
    return top, bot, pair, Model(items)


def test_action_reaction_two_blocks():
    top, bot, pair, model = _two_blocks(shift=0.01)
    res = solve(model, 2)
    fs, fm = pair.forces(res.z)
    total = np.abs(fs).sum()
    assert total > 1.0  # real contact forces
    # slave and master forces are G^T lam split in two: they cancel to round-off
    np.testing.assert_allclose(fs.sum(axis=1) + fm.sum(axis=1), 0.0, atol=1e-12 * total)
    # and they balance the reactions of each body: the residual at the top's
    # prescribed dofs equals minus the contact force on it
    R = res.residual()
    reaction = [R[top.offset + top.dofs_on("top", c)].sum() for c in ("x", "y")]
    # equilibrium of the top block at convergence (rtol 1e-10 of a force scale)
    np.testing.assert_allclose(reaction, -fs.sum(axis=1), rtol=1e-7, atol=1e-8)


def _has_mortar():
    try:
        import skfem_mortar.contact.mortar  # noqa: F401
        return True
    except ImportError:
        return False


ALL_METHODS = [m if m == "nts" or _has_mortar() else
               pytest.param(m, marks=pytest.mark.skip("mortar.py not available"))
               for m in ("nts", "mortar", "mortar-dual")]


@pytest.mark.parametrize("method", ALL_METHODS)
def test_contact_item_tangent_fd(method):
    """Central differences of the whole pair residual against its tangent, at a
    state with contact forces and a sheared interface (xi and n vary).
    eps = 1e-7 in z whose entries are O(0.01..1): truncation O(eps^2) and
    round-off O(1e-16 * |R| / eps) ~ 1e-9 * |R|, so atol 1e-6 |K| is safe."""
    top, bot, pair, model = _two_blocks(method, shift=0.02)
    res = solve(model, 1)
    rng = np.random.default_rng(0)
    z = res.z + 1e-4 * rng.standard_normal(model.n) * (np.arange(model.n) < model.n_u)
    pair.begin_step(z, 1.0)
    c0 = pair.assemble(z, 1.0)
    K = np.zeros((model.n, model.n))
    np.add.at(K, (c0.k_rows, c0.k_cols), c0.k_vals)
    active = pair.active.copy()

    def R(zz):
        pair.state.frozen = active  # same active set for the differences
        c = pair.assemble(zz, 1.0, tangent=False)
        pair.state.frozen = None
        return np.bincount(c.r_index, c.r_value, minlength=model.n)

    eps = 1e-7
    Kfd = np.zeros_like(K)
    for i in range(model.n):
        dz = np.zeros(model.n)
        dz[i] = eps
        Kfd[:, i] = (R(z + dz) - R(z - dz)) / (2 * eps)
    assert active.any()
    np.testing.assert_allclose(K, Kfd, rtol=0, atol=1e-6 * np.abs(K).max())


def test_quadratic_convergence_fixed_active_set():
    top, bot, pair, model = _two_blocks(shift=0.02)
    res = solve(model, 1, newton=NewtonOptions(rtol=1e-13))
    r = np.array(res.steps[0].residual_norms)
    # the last iterations (active set fixed) converge quadratically:
    # r_{k+1} <= C r_k^2 with C bounded (relative to the first residual)
    rr = r / r[0]
    tail = rr[-3:]
    assert res.steps[0].newton_iterations <= 10
    assert tail[-1] < 1e-12 and tail[-2] < 1e-4
    assert tail[-1] <= 10 * tail[-2] ** 2 + 1e-15


class _Springs(Item):
    """A linear 'body': nodes at X + u with stiffness K and load f (both n x n in y).

    Used to build a small contact problem whose active set iteration cycles.
    """

    dof_kind = "u"

    def __init__(self, X, Kyy, f, name="springs"):
        self.X = np.asarray(X, float)
        self.n_nodes = self.X.shape[1]
        self.n_dofs = 2 * self.n_nodes
        self.node_dofs = np.arange(self.n_dofs).reshape(-1, 2).T
        self.Kyy, self.f, self.name = np.asarray(Kyy, float), np.asarray(f, float), name

    def x(self, z):
        return self.X + z[self.dofs][self.node_dofs]

    def assemble(self, z, lf, tangent=True):
        u = z[self.dofs][self.node_dofs]
        r = np.zeros((2, self.n_nodes))
        r[0] = u[0]  # unit x springs
        r[1] = self.Kyy @ u[1] - lf * self.f
        K = np.zeros((self.n_dofs, self.n_dofs))
        K[self.node_dofs[0], self.node_dofs[0]] = 1.0
        K[np.ix_(self.node_dofs[1], self.node_dofs[1])] = self.Kyy
        return Contribution.from_dofs(self.offset + np.arange(self.n_dofs)[None],
                                      r.T.ravel()[None], K[None])


# An LCP  K u - f = lam >= 0, u >= 0, u.lam = 0 (u the height of 3 nodes above the
# rigid plane y = 0) with K symmetric positive definite but not an M-matrix,
# found by a random search: from the initial active set (all nodes, gap 0) the
# primal-dual active set iteration with c = 1 visits {0,1,2} -> {2} -> {0} ->
# {0,1,2} -> ... forever.
K_CYC = np.array([[3.185, 3.423, -3.234], [3.423, 5.779, -6.113], [-3.234, -6.113, 6.821]])
F_CYC = np.array([0.053, 1.553, -1.762])


def _cycling_model(guard):
    X = np.array([[0.0, 1.0, 2.0], [0.0, 0.0, 0.0]])
    body = _Springs(X, K_CYC, F_CYC)
    s = ContactSurface(body, np.arange(3), np.array([[2, 1], [1, 0]]))
    plane = RigidPlane((1.0, 0.0), (0.0, 1.0))
    pair = ContactPair(s, plane, "nts", name="c", c=1.0, cycle_guard=guard)
    return body, pair, Model([body, pair])


def _lcp_solution():
    """Enumerate the 8 active sets; the KKT solution of a P-matrix LCP is unique."""
    import itertools
    for A in itertools.product([False, True], repeat=3):
        A = np.array(A)
        I = ~A
        u = np.zeros(3)
        if I.any():
            u[I] = np.linalg.solve(K_CYC[np.ix_(I, I)], F_CYC[I])
        lam = K_CYC @ u - F_CYC
        lam[I] = 0
        if np.all(u >= -1e-14) and np.all(lam >= -1e-14):
            return u, lam
    raise AssertionError("no solution")


def test_active_set_cycles_without_guard():
    from skfem_mortar.core.errors import ConvergenceError
    np.testing.assert_array_less(0, np.linalg.eigvalsh(K_CYC))  # SPD
    body, pair, model = _cycling_model(False)
    with pytest.raises(ConvergenceError):
        solve(model, 1, newton=NewtonOptions(max_iter=20), min_step=0.2)


def test_active_set_guard_converges(caplog):
    body, pair, model = _cycling_model(True)
    with caplog.at_level(logging.INFO, logger="skfem_mortar.contact.pair"):
        res = solve(model, 1, newton=NewtonOptions(max_iter=20), min_step=0.2)
    assert "cycling" in caplog.text
    assert res.steps[0].info["active_set_cycles"] >= 1
    u, lam = _lcp_solution()
    # the LCP is solved exactly by the final linear solve: round-off of a 3x3 system
    np.testing.assert_allclose(body.x(res.z)[1], u, atol=1e-12)
    np.testing.assert_allclose(res.z[pair.dofs], lam, atol=1e-12)


def test_segmentation_policy():
    b = _block(0, 1, 0, 1, 2, 2, "b")
    s = ContactSurface.from_solid(b, "bottom")
    with pytest.raises(ValueError, match="segmentation"):
        ContactPair(s, RigidPlane((0, 0), (0, 1)), "nts", segmentation="step")
    with pytest.raises(ValueError, match="segmentation"):
        ContactPair(s, RigidPlane((0, 0), (0, 1)), "mortar", segmentation="never")


@pytest.mark.skipif(not _has_mortar(), reason="mortar.py not available")
def test_step_segmentation_block_on_plane():
    # the frozen (per step) mortar segmentation on a flat interface is exact:
    # the analytic uniform pressure as in the NTS test above
    b = _block(0, 1, 0, 1, 4, 4, "block")
    plane = RigidPlane((0.5, 0.0), (0.0, 1.0), length=10.0)
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), plane, "mortar", name="c",
                       segmentation="step")
    model = Model([b, Dirichlet(b, b.dofs_on("top", "y"), -0.02),
                   Dirichlet(b, b.dofs_on("left", "x"), 0.0), pair])
    res = solve(model, 2)
    np.testing.assert_allclose(pair.contact_data(res.z)["pressure"],
                               -E / 2 * (0.98 - 1 / 0.98), rtol=1e-8)
