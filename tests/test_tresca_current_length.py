"""One meaning of the Tresca bound: a traction per unit *current* length, with
every method (issue 32).

Before, NTS weighed its nodal bound with the reference tributary lengths and
mortar with the current surface, so the same Tresca model slid with forces
1.8 % apart (the block's lateral expansion).  Now NTS's nodal bound is
``bound * a_A(x)`` on the current positions (with its derivative), so a block
sliding as a whole carries ``bound`` times its current contact length under
NTS (2- and 3-node segments), mortar and mortar-dual, and ``contact_data``
reads ``tangential_traction == bound`` at every sliding node.
"""
from __future__ import annotations

import numpy as np
import pytest
import skfem

from skfem_mortar import (ContactPair, ContactSurface, Dirichlet, Model, NeoHooke, RigidPlane,
                          Solid, Tresca, solve)
from skfem_mortar.core.chain import segment_lengths

METHODS = ("nts", "mortar", "mortar-dual")
BOUND = 0.004
MESHES = {"tri1": (skfem.MeshTri, None), "tri2": (skfem.MeshTri, skfem.MeshTri2),
          "quad2": (skfem.MeshQuad, skfem.MeshQuad2)}


def _solid(element, x0, x1, y0, y1, nx, ny, name):
    low, high = MESHES[element]
    m = low.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    m = (m if high is None else high.from_mesh(m)).with_defaults()
    return Solid(m, NeoHooke(E=1.0, nu=0.3), element=element, name=name)


def sliding_block(method, element, base=None):
    """A unit-wide block pressed by 6 % of its height (it widens by about 2 %),
    then its top slid by 0.1 with Tresca friction: on a rigid plane, or on a
    deformable tri2 base."""
    block = _solid(element, 0.0, 1.0, 0.5, 1.0, 8, 4, "block")
    items = [block]
    if base is None:
        master = RigidPlane((0.5, 0.5), (0.0, 1.0), length=10.0, name="plane")
    else:
        b = _solid(base, -0.5, 1.5, 0.0, 0.5, 16, 4, "base")
        items += [b, Dirichlet(b, b.dofs_on("bottom"), name="clamp")]
        master = ContactSurface.from_solid(b, "top")
    pair = ContactPair(ContactSurface.from_solid(block, "bottom"), master, method=method,
                       friction=Tresca(BOUND), name="contact")
    items += [pair,
              Dirichlet(block, block.dofs_on("top", "y"), name="press",
                        value=lambda t: -0.03 * min(2 * t, 1.0)),
              Dirichlet(block, block.dofs_on("top", "x"), name="slide",
                        value=lambda t: 0.1 * max(2 * t - 1, 0.0))]
    return Model(items), pair, block


def _bottom_width(block, z):
    """The block's current bottom width, corner to corner."""
    X = block.basis.doflocs[:, ::2]
    x = X[0] + z[block.offset:block.offset + block.n_dofs].reshape(-1, 2)[:, 0]
    bottom = np.isclose(X[1], 0.5)
    return x[bottom].max() - x[bottom].min()


def _sliding(pair, z):
    d = pair.contact_data(z)
    assert np.all(d["status"] == "slip")                       # gross sliding
    # the traction as contact_data reads it: the bound itself, per current length
    # (to Newton's tolerance; the reference-length reading was off by 2 %)
    np.testing.assert_allclose(np.abs(d["tangential_traction"]), BOUND, rtol=1e-9)
    return d


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("element", ["tri1", "tri2", "quad2"])
def test_sliding_force_is_the_bound_times_the_current_length(method, element):
    """On a rigid plane the contact is the block's flat bottom, so the analytic
    sliding force is ``bound`` times its current width (measured: NTS 1e-14,
    mortar and dual 2e-11 .. 2e-10 relative); the reference width is 2.7 % less."""
    model, pair, block = sliding_block(method, element)
    res = solve(model, n_steps=8)
    _sliding(pair, res.z)
    width = _bottom_width(block, res.z)
    assert width > 1.02                                        # the two meanings differ
    # Newton's tolerance on the multipliers (rtol 1e-10 of the step's force,
    # relative to a force 20 times the sliding one): 1e-9
    np.testing.assert_allclose(-pair.total_force(res.z)[0], BOUND * width, rtol=1e-9)


def test_methods_agree_on_a_deformable_base():
    """A quad2 block sliding on a deformable tri2 base: the tangential force each
    method resolves (its tangential tractions times its current tributary
    lengths) is ``bound`` times its current contact length, and the methods
    agree to the difference of their deformed contact lengths (measured 3.5e-4:
    NTS's width 1.01955 against mortar's 1.01921); with the reference length in
    NTS they were 1.9 % apart."""
    forces = {}
    for method in METHODS:
        model, pair, block = sliding_block(method, "quad2", base="tri2")
        res = solve(model, n_steps=8)
        d = _sliding(pair, res.z)
        area = pair.evaluate(res.z, tangent=False, with_lam=False).area[d["node"]]
        forces[method] = float(np.sum(np.abs(d["tangential_traction"]) * area))
        # the slave's current length: its (curved) segments' arc lengths; to
        # Newton's tolerance, as on the plane
        length = segment_lengths(pair.slave.x(res.z), pair.slave.segments).sum()
        np.testing.assert_allclose(forces[method], BOUND * length, rtol=1e-9)
        assert length / _bottom_width(block, res.z) - 1 < 1e-3   # about the chord
    f = np.array(list(forces.values()))
    assert np.ptp(f) / f.mean() < 1e-3, forces


@pytest.mark.parametrize("method", METHODS)
def test_tangent_fd_tresca_on_3_node_segments(method):
    """The whole pair's tangent against central differences with a Tresca bound on a
    curved, stretched tri2 slave (NTS: the derivative of the current tributary
    lengths in the tangential rows; stick and slip nodes)."""
    from test_friction_pair import _check_tangent, _tresca_multipliers
    b = _solid("tri2", 0.0, 2.0, 0.0, 0.5, 4, 1, "block")
    plane = RigidPlane((1.0, 0.0), (0.0, 1.0), length=10.0)
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), plane, method=method,
                       friction=Tresca(0.5), name="c")
    model = Model([b, pair])
    z0 = np.zeros(model.n)
    pair.begin_step(z0, 1.0)                     # the slip history: the reference state
    rng = np.random.default_rng(4)
    z = z0.copy()
    u = z[b.offset:b.offset + b.n_dofs].reshape(-1, 2)
    X = b.basis.doflocs[:, ::2].T
    u[:, 0] = 0.03 + 0.05 * X[:, 0]              # slid and stretched by 5 %
    u[:, 1] = -0.005 * X[:, 0] ** 2              # pressed unevenly (curved)
    z[:model.n_u] += 1e-3 * rng.standard_normal(model.n_u)
    _tresca_multipliers(pair, z)
    _check_tangent(pair, model, z)


@pytest.mark.parametrize("k", [2, 3])
def test_tributary_jacobian_is_the_derivative_of_the_tributary_lengths(k):
    """``da_A/dx`` against central differences on a curved, uneven chain (2-node
    and 3-node segments)."""
    from skfem_mortar.contact.tributary import tributary_jacobian, tributary_pattern
    from skfem_mortar.core.chain import tributary_lengths
    rng = np.random.default_rng(5)
    if k == 2:
        X = np.linspace(0.0, 1.0, 6)
        seg = np.c_[0:5, 1:6]
    else:
        v = np.linspace(0.0, 1.0, 4)
        X = np.r_[v, 0.5 * (v[:-1] + v[1:])]
        seg = np.c_[0:3, 1:4, 4:7]
    x = np.array([X, 0.3 * X ** 2]) + 0.02 * rng.standard_normal((2, X.size))
    J = tributary_jacobian(x, seg, None, "line2" if k == 2 else "line3").toarray()
    h = 1e-6
    fd = np.zeros_like(J)
    for j in range(x.size):
        d = np.zeros(x.size)
        d[j] = h
        dx = d.reshape(-1, 2).T
        fd[:, j] = (tributary_lengths(x + dx, seg) - tributary_lengths(x - dx, seg)) / (2 * h)
    # central differences, h = 1e-6 on unit-size geometry: truncation ~h^2, round-off
    # ~eps / h ~ 1e-10; a wrong term is of the size of the entries (0.1 .. 1)
    assert np.abs(J - fd).max() < 1e-8 * np.abs(J).max()
    assert np.all(tributary_pattern(seg, X.size).toarray()[J != 0] == 1.0)  # held
