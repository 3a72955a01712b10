"""Solid: residual, consistent tangent, dofs, loads and output."""
import numpy as np
import pytest
from scipy.optimize import brentq
from skfem import MeshQuad, MeshTri

from skfem_mortar.core.errors import InversionError
from skfem_mortar.bodies.materials import NeoHooke, SaintVenantKirchhoff
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.scenes.block import block_mesh
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.loads.traction import PointLoad, Traction

ELEMENTS = ["tri1", "tri2", "quad1", "quad2"]
MATERIALS = {"neo-hooke": NeoHooke(E=2.0, nu=0.3), "svk": SaintVenantKirchhoff(E=2.0, nu=0.2)}


def make_solid(element, material, refine=2, distort=0.25):
    return Solid(block_mesh(element[:-1], refine, distort, seed=3), material, element)


def finite_deformation(X):
    """A non-affine displacement with stretches of about 0.8-1.3 and shear."""
    G = np.array([[0.3, 0.2], [-0.1, -0.2]])
    return G @ X + 0.05 * np.sin(3.0 * X[::-1])


@pytest.mark.parametrize("element", ELEMENTS)
@pytest.mark.parametrize("mat", list(MATERIALS))
def test_tangent_matches_central_differences(element, mat):
    solid = make_solid(element, MATERIALS[mat])
    model = Model([solid])
    z = solid.interpolate(finite_deformation)
    R, K, _ = model.assemble(z, 1.0)
    rng = np.random.default_rng(0)
    for _ in range(2):
        d = rng.standard_normal(model.n)
        h = 1e-6
        fd = (model.assemble(z + h * d, 1.0, False)[0]
              - model.assemble(z - h * d, 1.0, False)[0]) / (2 * h)
        # central differences: truncation ~h^2 |R'''| ~ 1e-12 and round-off
        # ~eps |R| / h ~ 1e-10 relative to |K d|; 1e-6 keeps a wide margin
        # while a wrong tangent term (relative size >= 1e-2) fails clearly.
        assert np.linalg.norm(fd - K @ d) <= 1e-6 * np.linalg.norm(K @ d)


@pytest.mark.parametrize("element", ELEMENTS)
def test_tangent_is_symmetric(element):
    # hyperelastic material stiffness: K = d^2 Pi / du^2 is symmetric
    solid = make_solid(element, MATERIALS["neo-hooke"])
    K = Model([solid]).assemble(solid.interpolate(finite_deformation), 1.0)[1]
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()


@pytest.mark.parametrize("element", ELEMENTS)
@pytest.mark.parametrize("mat", list(MATERIALS))
def test_affine_state_loads_only_the_boundary(element, mat):
    """For homogeneous F, int Grad v : P = int_dOmega v . P N: interior residuals vanish
    and the right face (N = e_x) carries the force P e_x times its length 1."""
    material = MATERIALS[mat]
    solid = make_solid(element, material)
    Fh = np.array([[1.3, 0.2], [0.1, 0.9]])
    r = solid.internal_force(solid.interpolate(lambda X: (Fh - np.eye(2)) @ X))
    boundary = solid.dofs_on(solid.mesh.boundary_facets())
    interior = np.setdiff1d(np.arange(solid.n_dofs), boundary)
    P = material.stress(Fh)
    # round-off: |r| sums O(n) terms of size |P| h; 1e-12 |P| is ~1e4 ulps
    assert np.abs(r[interior]).max() <= 1e-12 * np.abs(P).max()
    assert r[solid.dofs_on("right", "x")].sum() == pytest.approx(P[0, 0], rel=1e-12)
    assert r[solid.dofs_on("right", "y")].sum() == pytest.approx(P[1, 0], rel=1e-12)
    assert r[solid.dofs_on("top", "y")].sum() == pytest.approx(P[1, 1], rel=1e-12)


@pytest.mark.parametrize("element", ELEMENTS)
def test_rigid_rotation_gives_zero_residual(element):
    solid = make_solid(element, MATERIALS["neo-hooke"])
    c, s = np.cos(0.9), np.sin(0.9)
    Q = np.array([[c, -s], [s, c]])
    r = solid.internal_force(solid.interpolate(lambda X: (Q - np.eye(2)) @ X + 0.3))
    # exact zero in exact arithmetic; round-off of P = mu (F - F^-T) ~ 1e-15 mu
    assert np.abs(r).max() <= 1e-13


def test_inverted_element_raises_inversion_error():
    solid = make_solid("tri1", MATERIALS["neo-hooke"], refine=2, distort=0.0)
    # push one interior vertex (0.5, 0.5) by 2 h = 0.5 to the right: it passes
    # its neighbours at x = 0.75, so the elements on its right side fold over
    node = int(np.argmin(np.linalg.norm(solid.X - 0.5, axis=0)))
    z = np.zeros(solid.n_dofs)
    z[solid.node_dofs[0, node]] = 0.5
    F = solid.deformation_gradient(z)
    J = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
    assert 0 < np.count_nonzero(J.min(axis=1) <= 0) < solid.mesh.nelements
    with pytest.raises(InversionError, match="det F <= 0"):
        Model([solid]).assemble(z, 1.0)
    with pytest.raises(InversionError):
        solid.internal_force(z)


def test_x_is_reference_plus_displacement():
    solid = make_solid("quad2", MATERIALS["svk"])
    z = solid.interpolate(finite_deformation)
    np.testing.assert_allclose(solid.x(z), solid.X + finite_deformation(solid.X), atol=1e-15)
    assert solid.node_dofs.shape == (2, solid.n_nodes) == (2, solid.mesh.nvertices)


@pytest.mark.parametrize("element, per_facet", [("tri1", 1), ("tri2", 2), ("quad1", 1),
                                                ("quad2", 2)])
def test_dofs_on_boundary_include_facet_dofs(element, per_facet):
    solid = make_solid(element, MATERIALS["svk"], refine=2)
    n_facets = 4  # the left side of a 4 x 4 grid
    x = solid.dofs_on("left", "x")
    assert len(x) == per_facet * n_facets + 1
    assert len(solid.dofs_on("left")) == 2 * len(x)
    assert np.all(solid.dof_component[x] == 0)
    np.testing.assert_allclose(solid.basis.doflocs[0, x], 0.0, atol=1e-15)


def test_dofs_on_unknown_tag_lists_known_tags():
    solid = make_solid("tri1", MATERIALS["svk"])
    with pytest.raises(ValueError, match="known tags.*left"):
        solid.dofs_on("front")
    with pytest.raises(ValueError, match="component"):
        solid.dofs_on("left", component="z")


def test_bad_element_or_mesh_raises_value_error():
    with pytest.raises(ValueError, match="element must be one of"):
        Solid(MeshTri(), MATERIALS["svk"], "tri3")
    with pytest.raises(ValueError, match="quadrilaterals"):
        Solid(MeshTri(), MATERIALS["svk"], "quad1")
    with pytest.raises(ValueError, match="intorder"):
        Solid(MeshQuad(), MATERIALS["svk"], "quad1", intorder=0)


def test_traction_and_point_load_forces():
    solid = make_solid("tri2", MATERIALS["svk"])
    tr = Traction(solid, "right", [0.7, -0.2])
    model = Model([solid, tr])
    f = tr.force
    # a uniform traction on the unit-length right side: resultant = traction
    assert f[solid.dofs_on("right", "x")].sum() == pytest.approx(0.7, rel=1e-14)
    assert f[solid.dofs_on("right", "y")].sum() == pytest.approx(-0.2, rel=1e-14)
    assert np.count_nonzero(f[np.setdiff1d(np.arange(solid.n_dofs), solid.dofs_on("right"))]) == 0
    R0 = model.assemble(np.zeros(model.n), 0.5)[0]
    np.testing.assert_allclose(R0, -0.5 * f, atol=1e-15)  # dead load, enters with a minus
    pl = PointLoad(solid, [0, 3], [1.0, 2.0])
    R1 = Model([solid, pl]).assemble(np.zeros(model.n), 0.25)[0]
    np.testing.assert_allclose(R1[[0, 3]], [-0.25, -0.5])
    with pytest.raises(ValueError, match="known tags"):
        Traction(solid, "front", [1.0, 0.0])


def test_traction_driven_block_matches_uniaxial_neo_hooke():
    """Dead traction T on the right face: P_xx = T, P_yy = 0 fixes (lx, ly) exactly."""
    from skfem_mortar.solver.newton import NewtonOptions
    from skfem_mortar.solver.stepping import solve

    mat = NeoHooke(E=1.0, nu=0.3)
    mu, lam, T = mat.mu, mat.lmbda, 0.4
    solid = make_solid("quad1", mat, refine=2)
    model = Model([solid, Traction(solid, "right", [T, 0.0]),
                   Dirichlet(solid, solid.dofs_on("left", "x")),
                   Dirichlet(solid, solid.dofs_on("bottom", "y"))])
    res = solve(model, 4, newton=NewtonOptions(rtol=1e-13))

    def ly_of(lx):
        return brentq(lambda ly: mu * (ly ** 2 - 1) + lam * np.log(lx * ly), 1e-3, 2.0,
                      xtol=1e-15)

    lx = brentq(lambda lx: mu * (lx - 1 / lx) + lam * np.log(lx * ly_of(lx)) / lx - T,
                1.0, 3.0, xtol=1e-15)
    # affine state, exact on any mesh: round-off and the 1e-13 Newton tolerance
    np.testing.assert_allclose(solid.x(res.z), np.diag([lx, ly_of(lx)]) @ solid.X,
                               rtol=0, atol=1e-11)


@pytest.mark.parametrize("element", ELEMENTS)
def test_output_mesh_and_data(element):
    mat = MATERIALS["neo-hooke"]
    solid = make_solid(element, mat)
    Fh = np.diag([1.2, 0.9])
    z = solid.interpolate(lambda X: (Fh - np.eye(2)) @ X)
    pts, cells = solid.output_mesh()
    assert pts.shape == (solid.n_nodes, 2)
    assert cells[0][0] == ("triangle" if element.startswith("tri") else "quad")
    assert cells[0][1].shape == (solid.mesh.nelements, 3 if element.startswith("tri") else 4)
    pdata, cdata = solid.output_data(z)
    np.testing.assert_allclose(pdata["displacement"], ((Fh - np.eye(2)) @ solid.X).T,
                               atol=1e-15)
    J = 1.08
    B = Fh @ Fh.T
    sig = (mat.mu * (B - np.eye(2)) + mat.lmbda * np.log(J) * np.eye(2)) / J
    szz = mat.lmbda * np.log(J) / J
    for key, val in [("sigma_xx", sig[0, 0]), ("sigma_yy", sig[1, 1]), ("sigma_xy", 0.0),
                     ("sigma_zz", szz)]:
        np.testing.assert_allclose(cdata[key][0], val, atol=1e-13)
    vm = np.sqrt(0.5 * ((sig[0, 0] - sig[1, 1]) ** 2 + (sig[1, 1] - szz) ** 2
                        + (szz - sig[0, 0]) ** 2))
    np.testing.assert_allclose(cdata["von_mises"][0], vm, rtol=1e-12)


@pytest.mark.parametrize("element", ["tri2", "quad2"])
def test_curved_quadratic_mesh(element):
    """Quadratic geometry (MeshTri2 disk / MeshQuad2): vertices first, tangent consistent."""
    from skfem import MeshQuad2, MeshTri2
    mesh = MeshTri2.init_circle(1) if element == "tri2" else MeshQuad2().refined(1)
    solid = Solid(mesh, MATERIALS["neo-hooke"], element)
    assert solid.X.shape == (2, mesh.nvertices)
    np.testing.assert_array_equal(solid.X, mesh.doflocs[:, :mesh.nvertices])
    model = Model([solid])
    z = solid.interpolate(finite_deformation)
    np.testing.assert_allclose(solid.x(z), solid.X + finite_deformation(solid.X), atol=1e-15)
    R, K, _ = model.assemble(z, 1.0)
    d = np.random.default_rng(1).standard_normal(model.n)
    h = 1e-6
    fd = (model.assemble(z + h * d, 1.0, False)[0]
          - model.assemble(z - h * d, 1.0, False)[0]) / (2 * h)
    # same central-difference budget as test_tangent_matches_central_differences
    assert np.linalg.norm(fd - K @ d) <= 1e-6 * np.linalg.norm(K @ d)


def test_two_bodies_get_their_own_blocks():
    """The second body's unknowns start at the first body's n_dofs; its residual and
    tangent land in its own block and nowhere else."""
    a = make_solid("tri1", MATERIALS["neo-hooke"])
    b = Solid(block_mesh("quad", 1, 0.0), MATERIALS["svk"], "quad2", name="other")
    model = Model([a, b])
    assert (a.offset, b.offset, model.n) == (0, a.n_dofs, a.n_dofs + b.n_dofs)
    za, zb = a.interpolate(finite_deformation), b.interpolate(finite_deformation)
    z = np.concatenate([za, zb])
    R, K, _ = model.assemble(z, 1.0)
    # reference: the same body alone in a model (offset 0)
    b_alone = Solid(block_mesh("quad", 1, 0.0), MATERIALS["svk"], "quad2")
    Rb, Kb, _ = Model([b_alone]).assemble(zb, 1.0)
    np.testing.assert_array_equal(R[a.n_dofs:], Rb)
    np.testing.assert_array_equal(K[a.n_dofs:, a.n_dofs:].toarray(), Kb.toarray())
    np.testing.assert_array_equal(R[:a.n_dofs], Model([a]).assemble(za, 1.0)[0])
    assert K[:a.n_dofs, a.n_dofs:].nnz == 0 and K[a.n_dofs:, :a.n_dofs].nnz == 0
    np.testing.assert_allclose(b.x(z), b.X + finite_deformation(b.X), atol=1e-15)


def test_traction_given_as_function_of_position():
    """T(x) = (y, 1 - y) on the right side x = 1: resultants int_0^1 y dy = 1/2 and
    int_0^1 (1 - y) dy = 1/2, moment about the origin int_0^1 (x T_y - y T_x) dy = 1/2 - 1/3.
    Quadratic elements integrate the linear traction exactly (round-off only)."""
    solid = make_solid("tri2", MATERIALS["svk"])
    f = Traction(solid, "right", lambda x: np.array([x[1], 1.0 - x[1]])).force
    xd, yd = solid.dofs_on("right", "x"), solid.dofs_on("right", "y")
    assert f[xd].sum() == pytest.approx(0.5, rel=1e-13)
    assert f[yd].sum() == pytest.approx(0.5, rel=1e-13)
    loc = solid.basis.doflocs
    moment = np.sum(loc[0, yd] * f[yd]) - np.sum(loc[1, xd] * f[xd])
    assert moment == pytest.approx(0.5 - 1.0 / 3.0, rel=1e-13)
