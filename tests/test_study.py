"""The speed-accuracy study: rows, failures as rows, resume, Dask gives the same rows."""
import csv
import json

import numpy as np
import pytest

from skfem_mortar.app import study
from skfem_mortar.app.study import plan_study, run_study
from skfem_mortar.app.study_report import pareto_front

#: the columns that hold timings (they differ between runs; all else is deterministic)
TIMING = ("wall_time_s", "wall_time_spread", "timing_unsteady", "timings")


def untimed(row):
    return {k: v for k, v in row.items() if k not in TIMING and not k.startswith("time.")}


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_quick_study_rows_and_files(tmp_path):
    rows = run_study(["block", "ring"], tmp_path, quick=True, repeat=1,
                     sets={"material": "neo-hooke,svk", "nu": "0.45"})
    plan = plan_study(["block", "ring"], quick=True, sets={"material": "neo-hooke,svk",
                                                           "nu": "0.45"})
    assert len(rows) == len(plan.runs) == len(read_rows(tmp_path / "results.csv"))
    for name in ("pareto.png", "report.md"):
        assert (tmp_path / name).stat().st_size > 100
    for r in rows:
        if r["scene"] == "ring":
            assert r["status"] == "ok"
            assert r["error"] == json.loads(r["metrics"])["radius_error"]
    # SVK at stretch 2 with nu = 0.45 has no uniaxial solution: a failed row, not a crash
    svk = [r for r in rows if r.get("param.material") == "svk"]
    assert svk and all(r["status"].startswith("failed: ValueError") for r in svk)
    assert "Cheapest within tolerance" in (tmp_path / "report.md").read_text()


def test_resume_skips_finished_rows(tmp_path, monkeypatch):
    run_study(["ring"], tmp_path, quick=True, repeat=1)
    calls = []
    real = study.execute
    monkeypatch.setattr(study, "execute", lambda run: calls.append(run) or real(run))
    rows = run_study(["ring"], tmp_path, quick=True, sets={"n_elements": "8,16,32,64"},
                     resume=True, repeat=1)
    assert [c["params"]["n_elements"] for c in calls] == [64]
    # rows read back from the CSV hold strings, the new one its typed value
    assert [int(r["param.n_elements"]) for r in rows] == [8, 16, 32, 64]


def test_unknown_axis_is_an_error(tmp_path):
    with pytest.raises(ValueError, match="no parameter"):
        plan_study(["ring"], sets={"no_such": "1,2"})
    with pytest.raises(ValueError, match="'n_elements'"):
        plan_study(["ring"], sets={"n_elements": "2"})


def test_pareto_front():
    t = np.array([1.0, 2.0, 3.0, 0.5, 2.5])
    e = np.array([1e-2, 1e-3, 1e-4, 1e-1, 1e-2])
    # (2.5, 1e-2) is dominated by (1, 1e-2) and (2, 1e-3)
    assert list(pareto_front(t, e)) == [3, 0, 1, 2]


@pytest.mark.slow
def test_dask_gives_the_same_rows(tmp_path):
    pytest.importorskip("distributed")
    serial = run_study(["block", "ring"], tmp_path / "serial", quick=True, repeat=2)
    dask = run_study(["block", "ring"], tmp_path / "dask", quick=True, workers=2, repeat=2)

    def strip(rows):
        return [{k: v for k, v in untimed(r).items() if k != "metrics"} for r in rows]

    assert strip(serial) == strip(dask)
    # the metrics are the same numbers wherever the run happened
    for a, b in zip(serial, dask):
        assert json.loads(a["metrics"]) == json.loads(b["metrics"])


def test_nts_runs_once_across_mortar_only_axes():
    plan = plan_study(["seed"], quick=True, sets={"n_gauss": "2,4", "segmentation": "iteration,step"})
    by_method = {}
    for r in plan.runs:
        by_method.setdefault(r["method"], []).append(r)
    assert len(by_method["nts"]) == 1 and "n_gauss" not in by_method["nts"][0]["params"]
    assert len(by_method["mortar"]) == 4


@pytest.mark.slow
def test_hertz_and_patch_quick_study(tmp_path):
    rows = run_study(["hertz", "patch"], tmp_path, quick=True, methods=["mortar", "nts"],
                     tolerance=0.02, repeat=1)
    assert all(r["status"] == "ok" for r in rows)
    hertz = sorted((r for r in rows if r["scene"] == "hertz" and r["method"] == "mortar"),
                   key=lambda r: r["param.refine"])
    errors = [r["error"] for r in hertz]
    assert len(errors) == 2 and errors[1] < errors[0]  # refining helps mortar
    # the recommendation is the cheapest row within the tolerance
    report = (tmp_path / "report.md").read_text()
    ok = [r for r in rows if r["scene"] == "hertz" and r["error"] <= 0.02]
    best = min(ok, key=lambda r: r["wall_time_s"])
    section = report.split("## hertz")[1].split("## ")[0]
    assert f"**{best['method']}**, refine={best['param.refine']}" in section


def test_steps_list_and_grid_points_are_validated():
    """``steps`` as the CLI's text "5,10,20" or a list; bad counts and a grid point
    whose value the scene refuses fail before any run, naming the parameter."""
    plan = plan_study(["ring"], quick=True, steps="5,10,20")
    assert sorted({r["steps"] for r in plan.runs}) == [5, 10, 20]
    assert study.parse_steps([4, "8"]) == [4, 8]
    for bad in ("0", "5,x", "1e9", ""):
        with pytest.raises(ValueError, match="'steps' must be an int in|steps must list"):
            plan_study(["ring"], quick=True, steps=bad)
    with pytest.raises(ValueError, match=r"parameter 'EA' .* grid point EA=1000000000000.0"):
        plan_study(["ring"], quick=True, sets={"EA": "10,1e12"})


def test_mu_is_an_axis_of_the_friction_scenes():
    """``--set mu=...`` is an axis like any scene parameter: slide (whose mu must
    be > 0: it is a friction scene), ironing and seed (mu = 0: frictionless)."""
    for scene, values in (("slide", "0.1,0.3"), ("ironing", "0,0.1,0.3"), ("seed", "0,0.1,0.3")):
        plan = plan_study([scene], quick=True, methods=["nts"], sets={"mu": values})
        mus = sorted({r["params"]["mu"] for r in plan.runs})
        assert mus == [float(v) for v in values.split(",")]
    with pytest.raises(ValueError, match="'mu'"):
        plan_study(["slide"], quick=True, sets={"mu": "0,0.3"})


def test_friction_cost_pairs_each_friction_row_with_its_frictionless_one():
    from skfem_mortar.app.study_report import friction_cost

    def row(method, mu, its, t, n="10"):
        return {"scene": "seed", "method": method, "steps": "", "solver": "",
                "param.mu": mu, "param.n": n, "status": "ok", "newton_iterations": its,
                "wall_time_s": t}
    rows = [row("nts", 0.0, 40, 2.0), row("nts", "0.3", 60, 6.0),  # a string: read back
            row("mortar", 0.3, 50, 5.0), row("nts", 0.3, 80, 9.0, n="20")]
    cost = friction_cost(rows)
    assert [c["mu"] for c in cost] == [0.3, 0.3, 0.3]
    first = cost[0]
    assert first["partner"] and first["iterations_ratio"] == 60 / 40
    assert first["time_ratio"] == 6.0 / 2.0
    assert first["time_per_iteration_ratio"] == pytest.approx((6.0 / 60) / (2.0 / 40), rel=1e-15)
    # no mu = 0 run of the same method / the same n: listed without ratios
    assert [c["partner"] for c in cost[1:]] == [False, False]
    assert cost[1]["iterations_ratio"] is None


def test_study_over_mu_reports_friction_cost(tmp_path, monkeypatch):
    """A tiny seed grid (mortar-dual, the references' method, the coarse level, mu = 0 and 0.3): every row
    runs, and the report's friction_cost section gives the mu = 0.3 run's
    iterations and times against the mu = 0 one.  The reference run is made at
    the grid's own level (to keep the test short), so each row's reference
    errors are exactly 0 when each mu has its own reference run (against the
    frictionless reference the mu = 0.3 run's contact force is 1.8 % off)."""
    monkeypatch.setitem(study.GRIDS["seed"], "reference_params",
                        {"n_cable": 24, "refine_cushion": 1})
    rows = run_study(["seed"], tmp_path, quick=True, methods=["mortar-dual"], sets={"mu": "0,0.3"},
                     repeat=1)
    assert [r["status"] for r in rows] == ["ok", "ok"]
    report = (tmp_path / "report.md").read_text()
    section = report.split("### friction_cost")[1]
    dry, wet = sorted(rows, key=lambda r: r["param.mu"])
    line = next(l for l in section.splitlines() if l.startswith("| mortar-dual"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[2] == "0.3"
    assert cells[3] == f"{wet['newton_iterations']:.3g}"
    assert cells[4] == f"{dry['newton_iterations']:.3g}"
    assert float(cells[5]) == pytest.approx(wet["newton_iterations"] / dry["newton_iterations"],
                                            rel=1e-2)  # printed to 3 digits
    assert float(cells[8]) == pytest.approx(wet["wall_time_s"] / dry["wall_time_s"], rel=1e-2)
    # each mu against its own reference run (a run like the row's: exactly 0)
    for r in rows:
        for q in ("contact_force", "max_indentation", "contact_length"):
            assert r[f"{q}_error"] == 0.0, (r["param.mu"], q)
    refs = json.loads((tmp_path / "references.json").read_text())
    assert sorted(refs) == ["seed", 'seed {"mu": 0.3}']
    assert refs['seed {"mu": 0.3}']["params"]["mu"] == 0.3
    # the tension's variation along the contact is a metric of the rows
    assert json.loads(wet["metrics"])["tension_variation"] > json.loads(
        dry["metrics"])["tension_variation"]
