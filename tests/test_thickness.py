"""The reference thickness H of a model: forces are totals over H, pressures per unit
thickness; point loads are not multiplied."""
import numpy as np
import pytest
from skfem import MeshTri

from skfem_mortar.app.runner import run_scene
from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.loads.pressure import FollowerPressure
from skfem_mortar.loads.traction import PointLoad, Traction


@pytest.mark.parametrize("method, params", [("nts", {"n_top": 4}), ("mortar", {}),
                                            ("mortar-dual", {"offset": 0.3}),
                                            ("mortar", {"kinematics": "small", "n_top": 7})])
def test_patch_with_a_tenth_of_the_thickness_gives_a_tenth_of_the_forces(method, params):
    thick = run_scene("patch", dict(params, thickness=1.0), method)
    thin = run_scene("patch", dict(params, thickness=0.1), method)
    a, b = thick["metrics"], thin["metrics"]
    # the same equations times H (a row scaling): the same Newton path
    assert [s["newton_iterations"] for s in thin["steps"]] == \
        [s["newton_iterations"] for s in thick["steps"]]
    for key in ("contact_force", "support_reaction"):
        # exact totals q H W: the solve's round-off, measured <= 5e-15 relative
        assert b[key] == pytest.approx(0.1 * a[key], rel=1e-12)
        assert b[f"{key}_error"] <= 1e-12
    for key in ("pressure_min", "pressure_max"):
        # pressures are per unit thickness: the same to round-off of the solve
        assert b[key] == pytest.approx(a[key], rel=1e-12)
    assert b["pressure_error"] <= 1e-12


def _model(H: float):
    mesh = MeshTri.init_symmetric().refined(1).with_defaults()
    solid = Solid(mesh, NeoHooke(E=1.0, nu=0.3))
    point = PointLoad(solid, solid.dofs_on("right", "y"), 0.01, name="point")
    items = [solid, Traction(solid, "right", (0.02, 0.0), name="traction"),
             FollowerPressure(solid, 0.03, facets="top", name="pressure"), point,
             Dirichlet(solid, solid.dofs_on("left"), 0.0)]
    return Model(items, thickness=H), solid, point


def test_model_multiplies_every_item_but_point_loads_by_the_thickness():
    m1, solid1, point1 = _model(1.0)
    m3, _, _ = _model(0.3)
    z = 0.01 * np.random.default_rng(5).standard_normal(m1.n)
    R1, K1, _ = m1.assemble(z, 0.7)
    R3, K3, _ = m3.assemble(z, 0.7)
    fp = np.zeros(m1.n)
    fp[point1.local_dofs] = 0.7 * point1.values            # the point load, -R
    # R = H (f_int - f_traction - f_pressure) - f_point: exact up to one rounding
    np.testing.assert_allclose(R3, 0.3 * (R1 + fp) - fp, rtol=0, atol=1e-16)
    # summed after (not before) the multiplication: a few roundings of the largest entry
    np.testing.assert_allclose(K3.toarray(), 0.3 * K1.toarray(), rtol=0,
                               atol=1e-14 * abs(K1).max())
    np.testing.assert_allclose(m3.load_residual(z, 0.7), 0.3 * (m1.load_residual(z, 0.7) + fp)
                               - fp, rtol=0, atol=1e-16)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, np.inf, "thick", None, "2", True])
def test_thickness_must_be_finite_and_positive(bad):
    with pytest.raises(ValueError, match="thickness must be a finite real number > 0"):
        _model(bad)


def test_scene_refuses_a_bad_thickness():
    with pytest.raises(ValueError, match="parameter 'thickness'"):
        run_scene("patch", {"thickness": 0.0})


def test_checkpoint_state_carries_the_thickness():
    m1, _, _ = _model(1.0)
    m2, _, _ = _model(0.5)
    state = m2.state_dict()
    assert float(state["thickness"]) == 0.5
    with pytest.raises(ValueError, match="thickness 0.5, this model has thickness 1"):
        m1.load_state_dict(state)
    m2.load_state_dict(state)
    # a state from before the thickness existed is one of thickness 1
    m1.load_state_dict({"varying": state["varying"]})
    with pytest.raises(ValueError, match="thickness 1, this model has thickness 0.5"):
        m2.load_state_dict({"varying": state["varying"]})


@pytest.mark.parametrize("method", ["nts", "mortar"])
def test_force_helpers_are_totals_over_the_thickness(method):
    """The model hands H to its items: the pair's contact forces and the pressure's
    resultant are totals over H (a tenth at H = 0.1), and the two sides of the
    contact still balance.  1e-12: the two runs differ by the Newton tolerance."""
    got = {}
    for H in (1.0, 0.1):
        _, res, setup = run_scene("patch", {"thickness": H}, method=method, return_result=True)
        pair = setup.model.item("contact")
        pressure = setup.model.item("pressure")
        fs, fm = pair.forces(res.z)
        assert pair.thickness == H and pressure.thickness == H
        np.testing.assert_allclose(fs.sum(axis=1), -fm.sum(axis=1), atol=1e-12 * np.abs(fs).sum())
        got[H] = pair.total_force(res.z), pressure.resultant(res.z, 1.0)
    for a, b in zip(got[1.0], got[0.1]):
        np.testing.assert_allclose(b, 0.1 * a, rtol=1e-12, atol=1e-12 * np.abs(a).max())
