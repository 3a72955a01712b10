"""Scene ``cable_arc``: discrete arc to round-off, second-order convergence to
the continuum arc, slack and taut starts, independence of the regularization."""
import glob
import math

import meshio
import numpy as np
import pytest

from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.app.runner import run_scene
from skfem_mortar.bodies.cable import Cable
from skfem_mortar.loads.pressure import FollowerPressure
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.scenes.cable_arc import arc_discrete, arc_exact
from skfem_mortar.solver.stepping import solve

TIGHT = NewtonOptions(rtol=1e-12)


def test_arc_exact_relations():
    e = arc_exact(1.0, 2.5, 100.0, 1.0, "linear")
    # a = r sin(theta), L = 2 r theta, T = p r = EA (L/L0 - 1)
    assert e["radius"] * math.sin(e["theta"]) == pytest.approx(1.0, rel=1e-14)
    assert e["tension"] == pytest.approx(100.0 * (e["length"] / 2.5 - 1), rel=1e-12)
    d = arc_discrete(1.0, 2.5, 100.0, 1.0, "linear", 4096)
    # the discrete arc tends to the continuum one
    assert d["apex_height"] == pytest.approx(e["apex_height"], rel=1e-5)
    with pytest.raises(ValueError, match="pressure"):
        arc_exact(1.0, 2.5, 1.0, 100.0, "hencky")


@pytest.mark.parametrize("law", ["linear", "svk", "hencky"])
@pytest.mark.parametrize("L0", [2.0, 2.5, 4.0])
@pytest.mark.parametrize("n", [5, 32])
def test_discrete_to_round_off(law, L0, n):
    m = run_scene("cable_arc", {"law": law, "length0": L0, "n_elements": n},
                  newton=TIGHT)["metrics"]
    # Newton rtol 1e-12; the cable's condition (EA against the tension) costs
    # about two more digits on the tension
    assert m["apex_height_discrete_error"] < 1e-10
    assert m["tension_discrete_error"] < 1e-9


@pytest.mark.parametrize("law", ["linear", "hencky"])
def test_second_order_in_n(law):
    ns = np.array([8, 16, 32, 64, 128])
    runs = [run_scene("cable_arc", {"law": law, "n_elements": int(n)}, newton=TIGHT)
            for n in ns]
    for q in ("apex_height", "tension"):
        err = np.array([r["metrics"][f"{q}_error"] for r in runs])
        rate = -np.polyfit(np.log(ns), np.log(err), 1)[0]
        # the chord/arc defect is O(n^-2) with an O(n^-4) correction: slope 2 to
        # within a few hundredths on this range
        assert abs(rate - 2.0) < 0.05, (q, rate, err)


@pytest.mark.parametrize("tension_only", [False, True])
@pytest.mark.parametrize("steps", [1, 4])
def test_slack_start_solves(tension_only, steps):
    s = run_scene("cable_arc", {"length0": 3.0, "tension_only": tension_only},
                  steps=steps, newton=TIGHT)
    assert s["converged"]
    assert s["metrics"]["apex_height_discrete_error"] < 1e-10


@pytest.mark.parametrize("tension_only", [False, True])
def test_straight_taut_start_solves_and_regularization_is_harmless(tension_only):
    apex, tension = [], []
    for sag in (0.01, 0.05, 0.2):
        s = run_scene("cable_arc", {"length0": 2.0, "start_sag": sag,
                                    "tension_only": tension_only}, newton=TIGHT)
        apex.append(s["metrics"]["apex_height"])
        tension.append(s["metrics"]["tension"])
        assert s["metrics"]["apex_height_discrete_error"] < 1e-10
    # the sag only moves Newton's starting point: the answers agree to the
    # solver tolerance (rtol 1e-12, a few digits lost to conditioning)
    assert np.ptp(apex) < 1e-10 * apex[0]
    assert np.ptp(tension) < 1e-9 * tension[0]


def test_pretensioned_start():
    s = run_scene("cable_arc", {"length0": 1.8}, newton=TIGHT)
    assert s["metrics"]["apex_height_discrete_error"] < 1e-10


@pytest.mark.parametrize("params, match", [
    ({"n_elements": 1}, "n_elements"), ({"half_span": 0.0}, "half_span"),
    ({"start_sag": 0.0}, "start_sag"), ({"law": "hencky", "pressure": 1e3}, "pressure"),
])
def test_bad_parameters(params, match):
    with pytest.raises(ValueError, match=match):
        run_scene("cable_arc", params)


def test_tension_floor_keeps_the_answer_and_helps_fine_cables():
    exact = run_scene("cable_arc", {"n_elements": 32, "tension_floor": 0.0}, newton=TIGHT)
    floored = run_scene("cable_arc", {"n_elements": 32, "tension_floor": 0.5}, newton=TIGHT)
    # tangent-only: same answer to the solver tolerance
    for q in ("apex_height", "tension"):
        assert floored["metrics"][q] == pytest.approx(exact["metrics"][q], rel=1e-10)
    # a fine svk cable from its stress-free start: without the floor the first
    # step wanders (measured 15 iterations at n = 1000), with it Newton is
    # quadratic from the start (measured 4)
    its = {fl: [st["newton_iterations"] for st in
                run_scene("cable_arc", {"n_elements": 1000, "law": "svk",
                                        "tension_floor": fl})["steps"]]
           for fl in (0.0, 0.1)}
    assert its[0.0][0] >= 10
    assert max(its[0.1]) <= 5


def test_output_series_holds_the_deformed_cable(tmp_path):
    s = run_scene("cable_arc", {"n_elements": 8}, out=tmp_path)
    last = sorted(glob.glob(str(tmp_path / "cable" / "*.vtu")))[-1]
    m = meshio.read(last)
    assert m.cells[0].type == "line" and len(m.cells[0].data) == 8
    y = m.points[:, 1] + m.point_data["displacement"][:, 1]
    assert y.max() == pytest.approx(s["metrics"]["apex_height"], rel=1e-12)
    # every element carries the same tension at the discrete solution; Newton's
    # default rtol 1e-10, amplified by EA / T ~ 100, bounds their spread
    np.testing.assert_allclose(m.cell_data["tension"][0], s["metrics"]["tension"], rtol=1e-7)


@pytest.mark.parametrize("law", ["linear", "svk", "hencky"])
@pytest.mark.parametrize("L0, EA, p, n", [
    (2.5, 1e6, 1.0, 400),    # nearly inextensible: EA / T ~ 1e6
    (6.0, 1e6, 1.0, 8),      # more than a semicircle
    (2.001, 100.0, 30.0, 8),  # stress-free arc too flat: regularized start
    (2.0, 100.0, 30.0, 400),  # taut start, large load
])
def test_extremes_solve_on_the_physical_branch(law, L0, EA, p, n):
    s = run_scene("cable_arc", {"law": law, "length0": L0, "EA": EA, "pressure": p,
                                "n_elements": n})
    # the discrete arc is the first root (smallest angle); hencky has a second,
    # far equilibrium that a poor start can reach.  Newton's tolerance here is
    # newton_rtol(EA, p a), up to 2e-7 for EA = 1e6: errors stay below 1e-6
    assert s["metrics"]["apex_height_discrete_error"] < 1e-6


@pytest.mark.parametrize("tension_only", [False, True])
@pytest.mark.parametrize("n", [8, 200])
def test_snap_through_from_the_wrong_side(tension_only, n):
    """Start bulging away from the pressure: the cable must pass through a
    slack or compressed state and settle on the physical arc (measured 15-20
    Newton iterations in the single load step)."""
    c = Cable.between((-1, 0), (1, 0), 2.5, n, bulge="right", EA=100.0,
                      tension_only=tension_only, tension_floor=0.1)
    model = Model([c, FollowerPressure(c, 1.0, side="left"), Dirichlet(c, c.support_dofs())])
    res = solve(model, 1, newton=NewtonOptions(max_iter=40))
    apex = c.x(res.z)[1].max()
    # Newton rtol 1e-10 (default), amplified by EA / T ~ 100 at most
    assert apex == pytest.approx(arc_discrete(1.0, 2.5, 100.0, 1.0, "linear", n)["apex_height"],
                                 rel=1e-8)


def test_pressure_limit_in_the_message():
    # linear: as theta -> pi, N ~ EA 2 pi a / (L0 sin) against p a / sin: p < 2 pi EA / L0
    with pytest.raises(ValueError, match=r"below about 251\.[23]"):
        arc_exact(1.0, 2.5, 100.0, 1e3, "linear")
