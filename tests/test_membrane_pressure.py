"""The follower pressure in an axisymmetric model (loads/pressure.py): 2 pi r on
the current surface, its exact load stiffness on a membrane and on solid faces
(2- and 3-node facets), and its resultant against the projected area."""
import numpy as np
import pytest
from skfem import MeshTri

from fd import dense, fd_tangent
from skfem_mortar import Model
from skfem_mortar.bodies.membrane import Membrane
from skfem_mortar.bodies.material import LinearElastic
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.loads.pressure import FollowerPressure, facet_chain, revolved_load


def _membrane(n=6):
    th = np.linspace(0.0, 0.5 * np.pi, n + 1)
    return Membrane(np.vstack([np.cos(th), np.sin(th)]), H=0.1, mu=1.0)


def test_membrane_load_stiffness_is_exact():
    m = _membrane()
    load = FollowerPressure(m, 0.7, side="right")
    Model([m, load], geometry="axisymmetric")
    z = 0.1 * np.random.default_rng(2).standard_normal(m.n_dofs)
    _, K = dense(load.assemble(z, 0.8), m.n_dofs)
    # central differences of a quadratic residual: exact but for round-off (1e-10 of |K|)
    assert np.abs(K - fd_tangent(load, z, 0.8)).max() <= 1e-8 * np.abs(K).max()


def test_resultant_is_pressure_times_projected_area():
    """The axial force of p on a meridian from (a, 0) to the axis is p pi a^2 for any
    polygon (int 2 pi r dr), here before and after a random motion of the free nodes."""
    m = _membrane()
    load = FollowerPressure(m, 0.7, side="right")
    Model([m, load], geometry="axisymmetric")
    z = np.zeros(m.n_dofs)
    assert load.resultant(z)[1] == pytest.approx(0.7 * np.pi, rel=1e-14)
    z = 0.1 * np.random.default_rng(3).standard_normal(m.n_dofs)
    z[m.node_dofs[0, m.pole]] = 0.0
    a = m.x(z)[0, 0]
    assert load.resultant(z)[1] == pytest.approx(0.7 * np.pi * a * a, rel=1e-13)


@pytest.mark.parametrize("element", ["tri1", "tri2"])
def test_solid_face_load_stiffness_is_exact(element):
    """On solid facets (2 or 3 nodes): the facets of the face chain, the
    revolved load and its derivative by central differences."""
    mesh = MeshTri.init_tensor(np.linspace(0.5, 1.5, 4), np.linspace(0.0, 1.0, 3))
    mesh = mesh.with_boundaries({"inner": lambda x: np.isclose(x[0], 0.5)})
    body = Solid(mesh, LinearElastic(E=1.0, nu=0.3), element=element)
    dofs, X = facet_chain(body, "inner")
    x = X + 0.05 * np.random.default_rng(4).standard_normal(X.shape)
    f, k = revolved_load(x, 1.3, True)
    h, n_f = 1e-6, len(x)
    kfd = np.zeros_like(k)
    for j in range(x.shape[1] * 2):
        e = np.zeros(x.shape)
        e[:, j // 2, j % 2] = h
        kfd[:, :, j] = (revolved_load(x + e, 1.3, False)[0]
                        - revolved_load(x - e, 1.3, False)[0]) / (2 * h)
    assert np.abs(k - kfd).max() <= 1e-8 * np.abs(k).max()
    # the straight face r = 0.5 under p: the radial force p 2 pi r L, no axial force
    f0 = revolved_load(X, 1.0, False)[0].reshape(n_f, -1, 2)
    assert abs(f0[..., 0].sum()) == pytest.approx(2 * np.pi * 0.5 * 1.0, rel=1e-13)
    assert abs(f0[..., 1].sum()) <= 1e-14


def test_on_an_axisymmetric_solid_against_lame():
    """With the axisymmetric solid (bodies/axisymmetric.py; skipped on a branch without
    them): thick_sphere's quad2 wall (a = 1, b = 2, n = 4, neo-Hooke, nu = 0.3)
    under a follower pressure p = 1e-4 E on its inner face: u_r(a) within 1e-3 of
    Lame's (measured 2.1e-4: the follower and finite-strain effects, O(p / E), and
    the mesh's); held instead at Lame's cavity volume V0 + 2 pi a^2 u_a by volume
    control, the pressure unknown within 1e-3 of p (measured 1.3e-4); the load
    stiffness exact on the solid's quadratic facets."""
    from skfem_mortar.bodies.geometry_terms import TERMS
    if "axisymmetric" not in TERMS:
        pytest.skip("the axisymmetric solid is not on this branch")
    from skfem_mortar.bodies.hyperelastic import NeoHooke
    from skfem_mortar.core.dirichlet import Dirichlet
    from skfem_mortar.loads.volume import VolumeControl
    from skfem_mortar.scenes.thick_sphere import lame_displacement, sphere_mesh
    from skfem_mortar.solver.stepping import solve

    mesh, p = sphere_mesh(1.0, 2.0, 4, "quad2"), 1e-4
    u_a = lame_displacement(1.0, 1.0, 2.0, 1.0, 0.3, p)

    def model_with(load_of):
        body = Solid(mesh, NeoHooke(E=1.0, nu=0.3), element="quad2", name="sphere")
        load = load_of(body)
        return body, load, Model([body, Dirichlet(body, body.dofs_on("equator", "y"), 0.0),
                                  load], geometry="axisymmetric")

    body, load, model = model_with(lambda b: FollowerPressure(b, p, facets="inner"))
    z = 1e-2 * np.random.default_rng(0).standard_normal(model.n)
    _, K = dense(load.assemble(z, 1.0), model.n)
    assert np.abs(K - fd_tangent(load, z, 1.0)).max() <= 1e-8 * np.abs(K).max()
    z = solve(model, 1).z
    inner = np.unique(mesh.facets[:, mesh.boundaries["inner"]])
    X, u = body.X[:, inner], body.u(z)[body.node_dofs][:, inner]
    u_r = np.sum(u * X, axis=0) / np.hypot(*X)
    assert abs(u_r.mean() - u_a) <= 1e-3 * u_a

    def held(b):
        return VolumeControl(b, lambda lf: vc.reference_volume + lf * 2 * np.pi * u_a,
                             facets="inner")
    _, vc, model = model_with(held)
    assert vc.pressure(solve(model, 1).z) == pytest.approx(p, rel=1e-3)
