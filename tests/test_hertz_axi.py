"""Scene ``hertz_axi``: Hertz contact of a sphere, axisymmetric, against the closed form."""
import math

import numpy as np
import pytest

from skfem_mortar.app.runner import build_scene, run_scene
from skfem_mortar.scenes.hertz_axi import hertz_sphere


def test_closed_form():
    # E = 200, nu = 0.3 on a rigid plane: E* = 200 / 0.91; a^3 = 3 F R / (4 E*);
    # the pressure p0 sqrt(1 - r^2/a^2) revolved carries F (2/3 pi a^2 p0 = F)
    ex = hertz_sphere(8.0, 0.3, 200.0, 0.3, None, 0.3)
    assert ex["E_star"] == pytest.approx(200.0 / 0.91, rel=1e-14)
    assert ex["contact_radius"] ** 3 == pytest.approx(3 * 0.3 * 8.0 / (4 * ex["E_star"]),
                                                      rel=1e-14)
    a, p0 = ex["contact_radius"], ex["peak_pressure"]
    r = np.linspace(0.0, a, 200001)
    F = np.trapezoid(2 * math.pi * r * p0 * np.sqrt(1 - (r / a) ** 2), r)
    assert F == pytest.approx(0.3, rel=1e-6)       # trapezoidal rule on 2e5 intervals
    # two equal elastic bodies halve E*: a grows by 2^(1/3)
    ex2 = hertz_sphere(8.0, 0.3, 200.0, 0.3, 200.0, 0.3)
    assert ex2["contact_radius"] == pytest.approx(2 ** (1 / 3) * a, rel=1e-13)


def _small_rigid(refine, method="nts"):
    return run_scene("hertz_axi", params={"refine": refine, "kinematics": "small"},
                     method=method)["metrics"]


def test_small_strain_rigid_plane_converges():
    """Small strain, rigid plane, NTS at h = a/15, a/30, a/60 (refine -1, 0, 1).

    The readings of linear Hertz theory (per unit reference area at the reference
    radii, ``_ref``; the scene's docstring) are within 1 % at a/30 (measured: peak
    0.006 %, fitted radius 0.32 %) and fall with h (peak 0.41, 0.006, 0.031 %: at
    a/60 the floor of the finite body, hertz's 0.03-0.04 %, bound 0.1 %; radius 1.32,
    0.32, 0.10 %).  The current-configuration readings carry the surface strain
    on top, about p0 / E = 0.9 % here (peak 0.55, 0.93, 0.96 %): reported, not
    checked.  The contact resultant is the multipliers' sum, F to the Newton
    tolerance (1e-10 relative, measured 0 to the digits); the trapezoidal 2 pi
    int p r dr of the nodal pressures is not (0.3 %, 0.08 %, 0.02 % low): reported."""
    m = [_small_rigid(r) for r in (-1, 0, 1)]
    for k in m:
        assert k["contact_force_error"] < 1e-10
    peak = [k["peak_pressure_ref_error"] for k in m]
    radius = [k["contact_radius_ref_error"] for k in m]
    assert peak[1] < 0.01 and radius[1] < 0.01
    assert peak[1] < peak[0] and peak[2] < peak[0] and peak[2] < 1e-3
    assert radius[2] < radius[1] < radius[0]


def test_bad_parameters():
    with pytest.raises(ValueError, match="a / R"):
        build_scene("hertz_axi", params={"load": 1e3}, method="nts")
    with pytest.raises(ValueError, match="base"):
        build_scene("hertz_axi", params={"base": "soft"}, method="nts")


@pytest.mark.parametrize("method, base, bound", [
    ("mortar-dual", "rigid", 0.01), ("mortar", "rigid", 0.01), ("mortar-dual", "elastic", 0.01)])
def test_mortar_at_a_over_30(method, base, bound):
    """Small strain at h = a/30, Hertz's readings (``_ref``): measured peak 0.006 %
    (dual = NTS on the rigid plane), 0.57 % (standard mortar: its consistent
    multipliers overshoot at the axis node, as at ``hertz``'s corner), 0.03 % (dual,
    elastic cylinder); fitted radius 0.32 %, 0.68 %, 0.13 %.  Bound 1 %, the
    issue's."""
    m = run_scene("hertz_axi", params={"kinematics": "small", "base": base},
                  method=method)["metrics"]
    assert m["contact_force_error"] < 1e-10
    assert m["peak_pressure_ref_error"] < bound
    assert m["contact_radius_ref_error"] < bound
