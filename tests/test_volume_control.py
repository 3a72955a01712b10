"""Volume control (loads/volume.py): the exact, symmetric tangent of the
constraint with the pressure unknown, the meridian volume's closed forms and
orientation, and the volume held by a converged solve."""
import numpy as np
import pytest

from fd import dense, fd_tangent
from skfem_mortar import Model
from skfem_mortar.bodies.membrane import Membrane
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.loads.volume import MeridianVolume, VolumeControl
from skfem_mortar.solver.stepping import solve


def _hemisphere(n=8, reverse=False):
    th = np.linspace(0.0, 0.5 * np.pi, n + 1)
    X = np.vstack([np.cos(th), np.sin(th)])
    return Membrane(X[:, ::-1].copy() if reverse else X, H=0.1, mu=1.0)


def test_tangent_is_exact_and_symmetric():
    m = _hemisphere()
    vc = VolumeControl(m, 3.0)
    model = Model([m, vc], geometry="axisymmetric")
    z = 0.1 * np.random.default_rng(1).standard_normal(model.n)
    z[vc.offset] = 0.6                                  # the pressure unknown
    _, K = dense(vc.assemble(z, 0.8), model.n)
    # V is a cubic of the positions: central differences leave round-off only
    assert np.abs(K - fd_tangent(vc, z, 0.8)).max() <= 1e-8 * np.abs(K).max()
    assert np.array_equal(K, K.T)                       # assembled symmetric, entry by entry
    assert K[vc.offset, vc.offset] == 0.0


def test_meridian_volume_closed_forms():
    """A cylinder r = a, z in [0, h]: pi a^2 h; a cone from (a, 0) to (0, h):
    pi a^2 h / 3; a 3-node facet on r = z (a cone too) the same, exactly."""
    f = MeridianVolume()
    cyl = np.array([[[2.0, 0.0], [2.0, 3.0]]])
    assert f.evaluate(cyl, False)[0] == pytest.approx(np.pi * 4 * 3, rel=1e-15)
    cone = np.array([[[2.0, 0.0], [0.0, 3.0]]])
    assert f.evaluate(cone, False)[0] == pytest.approx(np.pi * 4, rel=1e-15)
    quad = np.array([[[2.0, 0.0], [0.0, 3.0], [1.0, 1.5]]])
    assert f.evaluate(quad, False)[0] == pytest.approx(np.pi * 4, rel=1e-15)
    assert MeridianVolume(walls=1.5).evaluate(cone, False)[0] == pytest.approx(np.pi * 4 + 1.5)


def test_orientation_and_target():
    """Either direction of the meridian gives the same positive reference volume
    (the inscribed polygon's, below 2 pi / 3 by about (pi / 2n)^2 / 4 relative:
    0.96 % at n = 8, to 5 % of itself); the target ramps."""
    a, b = VolumeControl(_hemisphere(), 3.0), VolumeControl(_hemisphere(reverse=True), 3.0)
    assert a.reference_volume == pytest.approx(b.reference_volume, rel=1e-14)
    deficit = 1.0 - a.reference_volume / (2 * np.pi / 3)
    assert deficit == pytest.approx((np.pi / 16) ** 2 / 4, rel=0.05)
    assert a.target(0.5) == pytest.approx(0.5 * (a.reference_volume + 3.0), rel=1e-15)
    with pytest.raises(ValueError, match="volume must be"):
        VolumeControl(_hemisphere(), -1.0)
    with pytest.raises(ValueError, match="negative volume"):   # walls: no turning
        VolumeControl(_hemisphere(), 3.0, function=MeridianVolume(walls=-5.0))
    with pytest.raises(ValueError, match="encloses no volume"):
        VolumeControl(Membrane(np.array([[1.0, 2.0], [0.0, 0.0]]), mu=1.0), 1.0)


def test_solve_holds_the_volume():
    m = _hemisphere(16)
    vc = VolumeControl(m, lambda lf: vc.reference_volume * (1 + 0.5 * lf) ** 3)
    model = Model([m, vc, Dirichlet(m, m.node_dofs[1, [0]], 0.0)], geometry="axisymmetric")
    res = solve(model, 4)
    # Newton's rtol 1e-10 of the step's load (the volume increment, about 1)
    assert vc.enclosed(res.z) == pytest.approx(vc.target(1.0), rel=1e-9)
    assert vc.pressure(res.z) > 0.0                      # inflating: a positive pressure


@pytest.mark.parametrize("element", ["tri1", "tri2"])
def test_solid_face_turned_with_its_midside_node(element):
    """A solid's face r = 0.5, z in [0, 1] (the body on its right going up: the
    facets come clockwise, V = -pi / 4) is turned to V0 = pi / 4 exactly; a
    3-node facet keeps its midside node last (turning all three would not)."""
    from skfem import MeshTri
    from skfem_mortar.bodies.material import LinearElastic
    from skfem_mortar.bodies.solid import Solid

    mesh = MeshTri.init_tensor(np.linspace(0.5, 1.5, 3), np.linspace(0.0, 1.0, 4))
    mesh = mesh.with_boundaries({"inner": lambda x: np.isclose(x[0], 0.5)})
    body = Solid(mesh, LinearElastic(E=1.0, nu=0.3), element=element)
    vc = VolumeControl(body, 1.0, facets="inner")
    assert vc.reference_volume == pytest.approx(np.pi / 4, rel=1e-14)
    z = np.zeros(body.n_dofs + 1)
    assert vc.enclosed(z) == pytest.approx(np.pi / 4, rel=1e-14)
    vc.offset = body.n_dofs
    z = 0.05 * np.random.default_rng(5).standard_normal(z.size)
    _, K = dense(vc.assemble(z, 0.5), z.size)
    assert np.abs(K - fd_tangent(vc, z, 0.5)).max() <= 1e-8 * np.abs(K).max()
