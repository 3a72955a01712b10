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
