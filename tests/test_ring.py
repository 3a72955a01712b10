"""Scene ``ring``: discrete radius to round-off against p R cos(pi/n) = N(R/R0),
second-order convergence to the continuum p R = N(R/R0), parameter checks."""
import math

import numpy as np
import pytest

from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.app.runner import run_scene
from skfem_mortar.scenes.ring import ring_radius

TIGHT = NewtonOptions(rtol=1e-13)


def test_ring_radius_closed_forms():
    # linear: p R = EA (R/R0 - 1)  =>  R = EA R0 / (EA - p R0)
    assert ring_radius(1.0, 1.0, 10.0, "linear") == pytest.approx(10 / 9, rel=1e-15)
    # svk example of benchmarks.md: R = sqrt(1 + 2 p R0 / EA) R0
    assert ring_radius(1.0, 1.0, 10.0, "svk") == pytest.approx(math.sqrt(1.2), rel=1e-15)
    assert ring_radius(1.0, 1.0, 10.0, "svk") == pytest.approx(1.0954451, abs=5e-8)
    R = ring_radius(1.0, 1.0, 10.0, "hencky")
    assert 10.0 * math.log(R) == pytest.approx(R, rel=1e-14)
    c = math.cos(math.pi / 12)
    assert ring_radius(2.0, 1.0, 10.0, "linear", 12) == pytest.approx(10 / (10 - 2 * c),
                                                                      rel=1e-15)


@pytest.mark.parametrize("law", ["linear", "svk", "hencky"])
@pytest.mark.parametrize("n", [4, 10, 64, 256])
def test_discrete_radius_to_round_off(law, n):
    m = run_scene("ring", {"law": law, "n_elements": n, "pressure": 1.2, "EA": 9.0,
                           "radius0": 0.7}, newton=TIGHT)["metrics"]
    # Newton stops at ~1e-13 of the force scale; the radius follows to about that
    # level times the (order one) condition of the ring
    assert m["radius_discrete_error"] < 1e-11
    assert m["radius_exact"] == pytest.approx(ring_radius(1.2, 0.7, 9.0, law), rel=1e-15)


def test_tension_only_changes_nothing_when_taut():
    a = run_scene("ring", {"n_elements": 16}, newton=TIGHT)["metrics"]
    b = run_scene("ring", {"n_elements": 16, "tension_only": True}, newton=TIGHT)["metrics"]
    assert b["radius"] == pytest.approx(a["radius"], rel=1e-12)


@pytest.mark.parametrize("law", ["linear", "svk", "hencky"])
def test_second_order_to_continuum(law):
    ns = np.array([8, 16, 32, 64, 128])
    err = np.array([run_scene("ring", {"law": law, "n_elements": int(n)},
                              newton=TIGHT)["metrics"]["radius_error"] for n in ns])
    rate = -np.polyfit(np.log(ns), np.log(err), 1)[0]
    # cos(pi/n) = 1 - pi^2/(2 n^2) + O(n^-4): rate 2, the O(n^-4) term shifts the
    # fitted slope by well under 0.05 on this range
    assert abs(rate - 2.0) < 0.05, (rate, err)


def test_summary_and_steps():
    s = run_scene("ring", {})
    assert s["converged"] and s["n_dofs"] == 2 * 64
    for key in ("radius", "radius_exact", "radius_error", "radius_discrete",
                "tension", "tension_exact", "tension_error"):
        assert key in s["metrics"]
    # svk: three Newton iterations per step at the default 4 steps (quadratic)
    assert all(st["newton_iterations"] <= 4 for st in s["steps"])


@pytest.mark.parametrize("params, match", [
    ({"n_elements": 7}, "n_elements"), ({"n_elements": 2}, "n_elements"),
    ({"pressure": 0.0}, "pressure"), ({"law": "hencky", "pressure": 5.0}, "pressure"),
    ({"law": "linear", "pressure": 10.0}, "pressure"), ({"radius0": -1.0}, "radius0"),
    ({"law": "neo"}, "law"), ({"EA": 0.0}, "EA"),
])
def test_bad_parameters(params, match):
    with pytest.raises(ValueError, match=match):
        run_scene("ring", params)


def test_pressure_limit_in_the_message():
    # hencky: p R = EA ln(R / R0) has a root iff p R0 <= EA / e (tangency at R = e R0)
    with pytest.raises(ValueError, match=r"below about 3\.678"):
        ring_radius(5.0, 1.0, 10.0, "hencky")
