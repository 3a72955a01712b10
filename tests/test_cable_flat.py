"""Cable pressed against a rigid plane (benchmarks section 4) against the analytic answer."""
import math

import numpy as np
import pytest

from skfem_mortar.contact.pair import METHODS  # the method names: nts, mortar, mortar-dual
from skfem_mortar.app.runner import run_scene
from skfem_mortar.scenes.cable_flat import flat_exact


def test_exact_solution_matches_benchmark_example():
    # benchmarks.md section 4 (numbers given there to 6 digits)
    ex = flat_exact(1.0, 2.0, 100.0, 20.0, 0.5, "linear")
    assert ex["radius"] == pytest.approx(0.939972, abs=1e-6)
    assert ex["contact_half_width"] == pytest.approx(0.169355, abs=1e-6)
    assert ex["tension"] == pytest.approx(18.7994, abs=1e-4)
    assert ex["contact_force"] == pytest.approx(6.77419, abs=1e-5)
    # and it satisfies the geometric relations it was derived from
    a, d, r, c = 1.0, 0.5, ex["radius"], ex["contact_half_width"]
    assert (a - c) ** 2 + (r - d) ** 2 == pytest.approx(r * r, rel=1e-12)
    L = 2 * c + 2 * r * math.atan2(a - c, r - d)
    assert 20.0 * r == pytest.approx(100.0 * (L / 2.0 - 1.0), rel=1e-12)


def test_exact_is_null_outside_its_range():
    assert flat_exact(1.0, 2.0, 100.0, 0.5, 0.5, "linear") is None  # arc does not reach
    r = run_scene("cable_flat", params={"pressure": 0.5, "n_elements": 20})
    m = r["metrics"]
    assert m["contact_force_exact"] is None and m["contact_force_error"] is None
    assert m["contact_force"] == 0.0 and m["n_active"] == 0


@pytest.mark.parametrize("method", METHODS)
def test_force_and_tension_at_n200(method):
    # required accuracy 1e-3 at n = 200 elements (measured: ~1e-5 .. 3e-5)
    m = run_scene("cable_flat", params={"n_elements": 200}, method=method)["metrics"]
    assert m["contact_force_error"] < 1e-3
    assert m["tension_error"] < 1e-3
    # the contact half-width is resolved to O(h): within 3 elements (h = 0.01)
    assert abs(m["contact_half_width"] - m["contact_half_width_exact"]) < 3 * 2.0 / 200


@pytest.mark.parametrize("method", ["nts"])
def test_error_envelope(method):
    """Errors below C h on four meshes (not asserted monotone: NTS errors
    oscillate as the contact edges cross nodes).

    C h = h / c: each edge of the contact zone is misplaced by at most one
    element h = L0 / n, which changes the force 2 c p by at most 2 p h, a
    relative error h / c (c = 0.169: C ~ 11.8 / n). The tension follows from the
    same geometry, so the same envelope is used for it. Measured errors are
    10-1000 times below the envelope.
    """
    ex = flat_exact(1.0, 2.0, 100.0, 20.0, 0.5, "linear")
    for n in (50, 100, 200, 400):
        m = run_scene("cable_flat", params={"n_elements": n}, method=method)["metrics"]
        h = 2.0 / n
        bound = h / ex["contact_half_width"]
        assert m["contact_force_error"] < bound, n
        assert m["tension_error"] < bound, n


def test_contact_pressure_is_p_on_the_flat_part():
    # interior contact nodes of NTS carry exactly p times their tributary length
    # (a straight cable on the plane under pressure p): the middle node's
    # pressure equals p to the equilibrium tolerance (rtol 1e-10 of the forces)
    from skfem_mortar.app.runner import build_scene
    from skfem_mortar.solver.stepping import solve
    setup, _, _ = build_scene("cable_flat", params={"n_elements": 100}, method="nts")
    res = solve(setup.model, 8)
    d = setup.contact(res.z)
    mid = np.argmin(np.abs(d["x"]))
    assert d["pressure"][mid] == pytest.approx(20.0, rel=1e-8)
    assert abs(d["gap"][mid]) < 1e-10
    assert setup.model.item("contact").active.sum() > 3


def test_bad_parameters():
    with pytest.raises(ValueError, match="length0"):
        run_scene("cable_flat", params={"length0": 1.5})
    with pytest.raises(ValueError, match="plane_gap"):
        run_scene("cable_flat", params={"length0": 3.0, "plane_gap": 0.2})
    with pytest.raises(ValueError, match="law"):
        run_scene("cable_flat", params={"law": "rubber"})


# ------------------------------------------------------------------ issue 32, class 8
def test_a_null_exact_value_is_explained():
    """pressure = 10 (what ``--set pressure=1_0`` gave) lies below the pressure at which
    the free cable reaches the plane: no contact, no exact values.  They were written
    as null without a word; the metric ``exact_note`` now says why and from which
    pressure on contact starts (the free arc through both supports tangent to the
    plane: radius 1.25, length 2.3182, tension 100 (2.3182 / 2 - 1), over 1.25)."""
    m = run_scene("cable_flat", params={"pressure": 10.0}, method="nts")["metrics"]
    assert m["n_active"] == 0 and m["contact_force"] == 0.0
    assert m["contact_force_exact"] is None and m["tension_error"] is None
    assert m["exact_note"].startswith("no exact values: at pressure 10 the free cable does "
                                      "not reach the plane (contact starts above pressure "
                                      "12.7295")
    a, d, L0, EA = 1.0, 0.5, 2.0, 100.0
    r = (a * a + d * d) / (2 * d)
    assert f"{EA * (2 * r * math.atan2(a, r - d) / L0 - 1) / r:.6g}" == "12.7295"
    # with contact the exact values are there and no note is written
    m = run_scene("cable_flat", params={"pressure": 13.0}, method="nts")["metrics"]
    assert m["contact_force_exact"] > 0 and "exact_note" not in m


def test_an_underscored_number_is_refused():
    """``--set pressure=1_0`` ran with pressure 10 (Python's float() reads "1_0" as 10)."""
    with pytest.raises(ValueError, match=r"parameter 'pressure' must be a float in \(0, inf\), "
                                         r"got '1_0' \(not a plain number"):
        run_scene("cable_flat", params={"pressure": "1_0"})
