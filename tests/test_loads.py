"""Follower pressure on cables and solid boundaries: nodal loads against hand
calculations, load stiffness against central finite differences, a homogeneous
pressurized block against its closed form, and Newton's convergence order
with and without the load stiffness."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq
from skfem import MeshQuad, MeshTri

from skfem_mortar.bodies.cable import Cable
from skfem_mortar.loads.pressure import FollowerPressure, facet_load_matrix
from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.solver.stepping import solve

from fd import dense, fd_tangent


# fd_tangent: the follower load is linear in x, so central differences have no
# truncation error and only round-off O(eps |R| / h) ~ 1e-10 (relative) remains


def test_facet_load_matrix():
    # 2-node: f_1 = f_2 = (p/2) Q (x_2 - x_1), i.e. p l / 2 along the normal
    np.testing.assert_allclose(facet_load_matrix(2), [[-0.5, 0.5], [-0.5, 0.5]], atol=1e-15)
    G = facet_load_matrix(3)
    # rows: int N_a x_xi dxi; a constant field has x_xi = 0 (columns sum to 0),
    # a linear one x = xi has x_xi = 1, so row a must give int N_a = 1/6, 1/6, 2/3
    np.testing.assert_allclose(G.sum(axis=1), 0.0, atol=1e-15)
    np.testing.assert_allclose(G @ [0.0, 1.0, 0.5], [1 / 6, 1 / 6, 2 / 3], atol=1e-15)
    with pytest.raises(ValueError, match="2 or 3 nodes"):
        facet_load_matrix(4)


@pytest.mark.parametrize("side, sign", [("left", 1), ("right", -1)])
def test_single_element_nodal_load(side, sign):
    c = Cable(np.array([[0.0, 1.0], [0.0, 0.0]]))
    load = FollowerPressure(c, 3.0, side=side)
    z = np.array([0.0, 0.0, 1.0, 1.0])          # current chord (2, 1), length sqrt 5
    R, _ = dense(load.assemble(z, 0.5), 4)
    # p lf l / 2 along the unit normal (-1, 2)/sqrt 5 (left of the chord)
    f = sign * 3.0 * 0.5 * math.sqrt(5) / 2 * np.array([-1.0, 2.0]) / math.sqrt(5)
    np.testing.assert_allclose(R, -np.r_[f, f], rtol=1e-14)


def test_resultants():
    rng = np.random.default_rng(0)
    ring = Cable.ring(1.0, 9)
    z = 0.2 * rng.standard_normal(ring.n_dofs)
    # uniform pressure on a closed curve: zero resultant, any shape
    load = FollowerPressure(ring, 2.0, side="right")
    assert np.abs(load.resultant(z)).max() < 1e-14
    arc = Cable.between((0, 0), (2, 0), 3.0, 7)
    z = 0.2 * rng.standard_normal(arc.n_dofs)
    x = arc.x(z)
    load = FollowerPressure(arc, 2.0, side="left")
    # open curve: p Q (x_end - x_start), whatever lies between
    chord = x[:, -1] - x[:, 0]
    np.testing.assert_allclose(load.resultant(z), 2.0 * np.array([-chord[1], chord[0]]),
                               rtol=1e-13)


@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("closed", [False, True])
def test_cable_load_stiffness_fd(side, closed):
    rng = np.random.default_rng(2)
    c = Cable.ring(1.0, 5) if closed else Cable.between((0, 0), (1, 0), 1.5, 5)
    load = FollowerPressure(c, 1.7, side=side)
    z = 0.2 * rng.standard_normal(c.n_dofs)
    _, K = dense(load.assemble(z, 0.6), c.n_dofs)
    Kfd = fd_tangent(load, z, 0.6, c.n_dofs)
    assert np.abs(K - Kfd).max() < 1e-8 * np.abs(K).max()
    asym = np.abs(K - K.T).max() / np.abs(K).max()
    if closed:   # pressure on a closed curve is conservative (-p * area): symmetric
        assert asym < 1e-14
    else:        # the end nodes' terms make it non-symmetric
        assert asym > 0.1
    off = FollowerPressure(c, 1.7, side=side, load_stiffness=False).assemble(z, 0.6)
    assert off.k_vals.size == 0


def _solid(element, refine=1):
    mesh = (MeshTri() if element.startswith("tri") else MeshQuad()).refined(refine)
    return Solid(mesh.with_defaults(), NeoHooke(E=10.0, nu=0.3), element)


@pytest.mark.parametrize("element", ["tri1", "tri2", "quad1", "quad2"])
def test_solid_load_stiffness_fd(element):
    s = _solid(element)
    load = FollowerPressure(s, 2.0, facets="top")
    rng = np.random.default_rng(4)
    z = 0.05 * rng.standard_normal(s.n_dofs)
    _, K = dense(load.assemble(z, 1.0), s.n_dofs)
    Kfd = fd_tangent(load, z, 1.0, s.n_dofs)
    assert np.abs(K).max() > 0
    assert np.abs(K - Kfd).max() < 1e-8 * np.abs(K).max()


@pytest.mark.parametrize("element", ["tri1", "tri2", "quad1", "quad2"])
def test_solid_pressure_points_inward(element):
    s = _solid(element, refine=2)
    z = np.zeros(s.n_dofs)
    for tag, direction in [("top", (0, -1)), ("bottom", (0, 1)), ("left", (1, 0)),
                           ("right", (-1, 0))]:
        load = FollowerPressure(s, 3.0, facets=tag)          # unit-length faces
        np.testing.assert_allclose(load.resultant(z), 3.0 * np.array(direction), atol=1e-14)
        out = FollowerPressure(s, 3.0, facets=tag, side="outward")
        np.testing.assert_allclose(out.resultant(z), -3.0 * np.array(direction), atol=1e-14)
    every = np.concatenate([s.mesh.boundaries[t] for t in ("top", "bottom", "left", "right")])
    z = 0.05 * np.random.default_rng(5).standard_normal(s.n_dofs)
    assert np.abs(FollowerPressure(s, 3.0, facets=every).resultant(z)).max() < 1e-14


@pytest.mark.parametrize("element", ["tri1", "tri2", "quad1", "quad2"])
def test_solid_pressure_work_is_twice_the_area(element):
    """Inward pressure on the whole boundary: sum_a f_a . x_a = -p int x . n ds
    = -2 p A (divergence theorem).  Under an affine map x = F X of the unit
    square A = det F, exactly, for straight and for quadratic facets."""
    s = _solid(element, refine=2)
    F = np.array([[1.3, 0.4], [-0.2, 0.9]])
    z = s.interpolate(lambda X: (F - np.eye(2)) @ X)
    tags = ("top", "bottom", "left", "right")
    load = FollowerPressure(s, 2.5, facets=np.concatenate([s.mesh.boundaries[t] for t in tags]))
    c = load.assemble(z, 1.0, tangent=False)
    f = -np.bincount(c.r_index, weights=c.r_value, minlength=s.n_dofs)   # R = -f_ext
    x = s.basis.doflocs[s.dof_component, np.arange(s.n_dofs)] + z
    # sums of O(1) products: round-off ~1e-15
    assert f @ x == pytest.approx(-2 * 2.5 * np.linalg.det(F), rel=1e-13)


@pytest.mark.parametrize("element", ["tri1", "tri2", "quad1", "quad2"])
def test_pressurized_block_homogeneous(element):
    """Unit square on symmetry supports, follower pressure p on top and right.

    Exact: F = s I with Cauchy stress -p I, i.e. for plane-strain neo-Hooke
    (mu (s^2 - 1) + 2 lambda ln s) / s^2 = -p.  Homogeneous, hence reproduced
    by every element to round-off (Newton rtol 1e-12).
    """
    s = _solid(element, refine=1)
    mu, lam, p = s.material.mu, s.material.lmbda, 2.0
    stretch = brentq(lambda v: (mu * (v * v - 1) + 2 * lam * math.log(v)) / v ** 2 + p,
                     0.1, 1.0, xtol=1e-16)
    model = Model([s, FollowerPressure(s, p, facets="top", name="top"),
                   FollowerPressure(s, p, facets="right", name="right"),
                   Dirichlet(s, s.dofs_on("left", "x"), name="left"),
                   Dirichlet(s, s.dofs_on("bottom", "y"), name="bottom")])
    res = solve(model, 2, newton=NewtonOptions(rtol=1e-12))
    x = s.x(res.z)
    np.testing.assert_allclose(x, stretch * s.X, atol=1e-12)


def test_bad_input():
    c = Cable.ring(1.0, 6)
    with pytest.raises(ValueError, match="pressure"):
        FollowerPressure(c, float("nan"))
    with pytest.raises(ValueError, match="side"):
        FollowerPressure(c, 1.0, side="inward")
    with pytest.raises(ValueError, match="facets is only for solids"):
        FollowerPressure(c, 1.0, facets="top")
    s = _solid("tri1")
    with pytest.raises(ValueError, match="facets"):
        FollowerPressure(s, 1.0)
    with pytest.raises(ValueError, match="mesh boundaries"):
        FollowerPressure(s, 1.0, facets="roof")
    with pytest.raises(ValueError, match="boundary"):
        FollowerPressure(s, 1.0, facets=np.nonzero(s.mesh.f2t[1] >= 0)[0][:1])
    with pytest.raises(ValueError, match="side"):
        FollowerPressure(s, 1.0, facets="top", side="left")
    with pytest.raises(ValueError, match="body"):
        FollowerPressure(object(), 1.0)


def _ring_newton(load_stiffness):
    n = 32
    c = Cable.ring(1.0, n, EA=10.0, law="svk")
    nd = c.node_dofs
    m = Model([c, FollowerPressure(c, 1.0, side="right", load_stiffness=load_stiffness),
               Dirichlet(c, [nd[0, 0], nd[1, 0], nd[1, n // 2]])])
    res = solve(m, 1, newton=NewtonOptions(rtol=1e-13, max_iter=100))
    return np.array(res.steps[0].residual_norms)


def test_newton_quadratic_with_load_stiffness_linear_without():
    r = _ring_newton(True)
    assert len(r) - 1 <= 6
    # quadratic: r_{k+1} <= C r_k^2 / r_0 with a modest C on the iterates
    # above round-off (1e-10 r_0); measured C ~ 0.1-0.2
    k = np.nonzero(r[:-1] > 1e-10 * r[0])[0][-2:]
    assert np.all(r[k + 1] * r[0] / r[k] ** 2 < 1.0)
    r = _ring_newton(False)
    # without it Newton still converges (same residual) but only linearly: the
    # contraction r_{k+1}/r_k settles at a constant (measured 0.42)
    assert len(r) - 1 >= 20
    ratio = r[-6:] / r[-7:-1]
    assert np.all((ratio > 0.2) & (ratio < 0.7))


@pytest.mark.parametrize("element", ["quad1", "quad2", "tri1"])
def test_a_traction_far_from_the_origin(element):
    """A dead traction on a mesh far from the origin (coordinates of 1e7 with cells of
    0.2: map coordinates in metres) gives the same nodal forces as near it and hands a
    callable the true coordinates.  scikit-fem finds the facet points by inverting the
    quad map to an absolute 1e-12, which such coordinates cannot always reach (this
    mesh of quads raised an Exception before; triangles never did); the load is
    integrated on the mesh moved to its facets' centroid.  Tolerance: the forces are
    sums of cell lengths of 0.2 read from coordinates of 1e7, so round-off of
    eps 1e7 / 0.2 ~ 1e-8 of a force."""
    from skfem_mortar import Traction

    def forces(x0, traction):
        mesh = (MeshQuad if element.startswith("quad") else MeshTri).init_tensor(
            x0 + np.linspace(0.1, 0.9, 5), np.linspace(0.5, 1.0, 5))
        mesh = mesh.with_boundaries({"top": lambda x: x[1] > 1.0 - 1e-9})
        body = Solid(mesh, NeoHooke(E=1.0, nu=0.3), element=element)
        return Traction(body, "top", traction).force

    near, far = forces(0.0, [0.5, -2.0]), forces(1e7, [0.5, -2.0])
    np.testing.assert_allclose(far, near, rtol=0, atol=1e-8)
    np.testing.assert_allclose([near[0::2].sum(), near[1::2].sum()], [0.4, -1.6], atol=1e-14)
    seen = []

    def shear(x):  # t = (s, 0), s = x - x0 - 0.1 along the top: total int_0^0.8 s ds = 0.32
        seen.append(float(np.min(x[0])))
        return np.stack([x[0] - (1e7 + 0.1), 0.0 * x[1]])

    f = forces(1e7, shear)
    assert 1e7 + 0.1 <= seen[0] < 1e7 + 0.9
    assert abs(f[0::2].sum() - 0.32) < 1e-8
