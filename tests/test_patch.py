"""Contact patch test (benchmarks section 5)."""
import numpy as np
import pytest

from skfem_mortar.contact.pair import METHODS  # the method names: nts, mortar, mortar-dual
from skfem_mortar.app.runner import build_scene, run_scene


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("element", ["quad1", "tri1"])
@pytest.mark.parametrize("n", [1, 4, 7])
def test_matching_meshes_pass_to_round_off(method, element, n):
    # Uniform state: every node pressure equals q. Round-off: the residual
    # tolerance is 1e-10 of the force scale, and the pressure is q = 1e4 with
    # E = 1e6, so relative errors of ~1e-12 are round-off; 1e-9 leaves a margin.
    r = run_scene("patch", params={"n_top": n, "n_bottom": n, "element": element},
                  method=method)
    m = r["metrics"]
    assert r["converged"]
    assert m["pressure_error"] < 1e-9
    assert m["n_active"] == n + 1
    assert m["max_abs_gap"] < 1e-12  # gap zero to round-off of coordinates O(1)


@pytest.mark.parametrize("method", [m for m in METHODS if m != "nts"])
def test_non_matching_mortar_passes(method):
    r = run_scene("patch", params={"n_top": 5, "n_bottom": 4}, method=method)
    assert r["metrics"]["pressure_error"] < 1e-9  # as above: round-off


def test_non_matching_nts_fails_by_a_measured_amount():
    """Single-pass NTS does not pass the patch test on non-matching meshes.

    The number 0.062026 was measured (5 slave against 4 master quad1 elements,
    E = 1e6 both, q = 1e4, nu = 0; min nodal pressure 9379.74, max 10200.75):
    there is no closed form for the NTS error. It is a property of the
    discretization, not of Newton: the problem is solved to rtol 1e-10, so the
    number is reproducible to ~1e-8; the tolerance 1e-5 guards against
    changes of the element (projection, tributary lengths) while allowing
    platform round-off. The error is O(1) in the mesh mismatch, not round-off:
    the lower bound is the point of the test.
    """
    r = run_scene("patch", params={"n_top": 5, "n_bottom": 4}, method="nts")
    m = r["metrics"]
    assert m["pressure_error"] == pytest.approx(0.0620263, abs=1e-5)
    assert m["pressure_error"] > 1e-2


def test_stress_is_uniform_in_both_blocks_on_matching_meshes():
    # sigma_yy = -q in every element of both blocks (Cauchy stress of the
    # uniform state); round-off relative 1e-9 as above.
    setup, _, _ = build_scene("patch", params={"n_top": 3, "n_bottom": 3})
    from skfem_mortar.solver.stepping import solve
    res = solve(setup.model, 1)
    for name in ("top", "bottom"):
        body = setup.model.item(name)
        _, cells = body.output_data(res.z)
        np.testing.assert_allclose(cells["sigma_yy"][0], -1e4, rtol=1e-9)


def test_bad_parameter():
    with pytest.raises(ValueError, match="n_top"):
        run_scene("patch", params={"n_top": 0})
    with pytest.raises(ValueError, match="element"):
        run_scene("patch", params={"element": "tri3"})


def test_units_do_not_matter():
    # c comes from the stiffness: scaling E and q by 1e-6 changes neither the
    # Newton path nor the relative error (NTS, non-matching; equal to 1e-6
    # relative: the residual tolerance is relative too)
    a = run_scene("patch", params={"n_top": 5, "n_bottom": 4}, method="nts")
    b = run_scene("patch", params={"n_top": 5, "n_bottom": 4, "pressure": 1e-2,
                                   "E_top": 1.0, "E_bottom": 1.0}, method="nts")
    assert [s["newton_iterations"] for s in a["steps"]] == \
        [s["newton_iterations"] for s in b["steps"]]
    assert b["metrics"]["pressure_error"] == pytest.approx(a["metrics"]["pressure_error"],
                                                           rel=1e-6)


def test_nts_slave_node_on_a_master_vertex_converges():
    # 20 against 16 elements: slave nodes x = 0.25, 0.5, 0.75 sit exactly on
    # master vertices, where the deformed master has a kink. Without the
    # segment hysteresis Newton oscillated there forever (residual alternating
    # 1.54 / 1.47); with it one step of 3 iterations suffices, as on the other meshes.
    r = run_scene("patch", params={"n_top": 20, "n_bottom": 16}, method="nts")
    assert r["converged"] and r["steps"][0]["newton_iterations"] <= 4
    assert 0.01 < r["metrics"]["pressure_error"] < 0.2  # NTS: O(1) mismatch error (0.072)


# ------------------------------------------------------------------ issue 32, class 8
# top_width = 10 lay inside the stated range (0, 10] and was refused by the preflight
# as "rigid modes held by nothing": with n_top = 5 only the upper block's node at
# x = 0 lay over the lower block [0, 1], and the upper block, held vertically by
# contact alone, rotated about it.  The scene now states the true range (at least two
# of the upper block's bottom nodes over the lower block) and refuses before building.
@pytest.mark.parametrize("params", [
    {"top_width": 5.0},                          # n_top = 5: nodes at x = 0 and 1
    {"offset": 0.8},                             # nodes at x = 0.8 and 1
    {"offset": -0.8},                            # nodes at x = 0 and 0.2
    {"element": "tri2", "top_width": 10.0},      # the mid node at x = 1 counts
    {"top_width": 0.001},                        # the smallest overlap, 1e-3 of the width
])
def test_the_ends_of_the_overlap_range_run(params):
    """Mortar at the ends of the range: the uniform state to round-off.

    The round-off grows as the overlap ``w`` shrinks, about ``100 eps / w^2`` (the
    gaps are differences of coordinates of size 1 read on a support of size ``w``,
    and the pressure is a force over that support): measured at ``top_width`` 0.1,
    0.01, 0.001 about 2e-12, 1e-10, 4e-10 to 2.2e-8 (the last varies with the linear
    solver's threads and summation order, before and after line2 joined the one
    kernel).  Allowed: 1e-8 as elsewhere in this file's mortar tests, and ten times
    the model ``100 eps / w^2`` where that is larger (2.2e-7 at w = 0.001)."""
    r = run_scene("patch", params=params, method="mortar")
    assert r["converged"]
    w = min(params.get("top_width", 1.0), 1.0 - abs(params.get("offset", 0.0)))  # overlap
    assert r["metrics"]["pressure_error"] < max(1e-8, 10 * 100 * np.finfo(float).eps / w**2)


@pytest.mark.parametrize("params, name, allowed", [
    ({"top_width": 10.0}, "top_width", "[0.001, 5]"),
    ({"top_width": 5.001}, "top_width", "[0.001, 5]"),
    ({"offset": 0.8001}, "offset", "[-0.8, 0.8]"),
    ({"offset": -0.8001}, "offset", "[-0.8, 0.8]"),
    ({"element": "quad2", "n_top": 4, "top_width": 8.001}, "top_width", "[0.001, 8]"),
])
def test_beyond_the_ends_of_the_overlap_range_is_refused_up_front(params, name, allowed):
    with pytest.raises(ValueError) as info:
        build_scene("patch", params)
    msg = str(info.value)
    assert msg.startswith(f"parameter {name!r} must lie in about {allowed}"), msg
    assert "bottom nodes over the lower block = 1 must lie in [2, inf]" in msg
