"""The study's error measures, repeated timings, solver axis, recommendations and
refusals (issue 16, item 5). Timing logic is tested with a stub run and a fake
clock (known times), not the machine."""
import csv
import json
import os

import pytest

from skfem_mortar.app import runner, study, study_measures, study_rows
from skfem_mortar.app.cli import main
from skfem_mortar.app.study import GRIDS, error_measures, plan_study, run_study, timing_stats
from skfem_mortar.app.study_rows import SOLVER_ENV
from skfem_mortar.app.study_report import pareto_figure, recommend, write_report
from skfem_mortar.scenes import list_scenes
from skfem_mortar.solver import linsolve

HERTZ = ("peak_pressure_error", "half_width_error", "pressure_l2_error",
         "peak_pressure_ref_error", "pressure_ref_l2_error")


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# -- error measures -------------------------------------------------------------------

def test_hertz_measures_are_columns_and_metric_picks_the_plotted_one(tmp_path):
    """One real tiny hertz run: a column per measure, each the scene's metric;
    ``metric`` sets ``error_metric``/``error``, the plot's label and title, the report."""
    rows = run_study(["hertz"], tmp_path, methods=["nts"], sets={"refine": "-2"}, repeat=1,
                     metric="half_width_error")
    written = read_rows(tmp_path / "results.csv")
    assert len(rows) == len(written) == 1
    metrics = json.loads(rows[0]["metrics"])
    for name in HERTZ:
        assert name in written[0]
        assert rows[0][name] == metrics[name]
        assert float(written[0][name]) == metrics[name]  # repr round-trips exactly
    assert written[0]["error_metric"] == "half_width_error"
    assert rows[0]["error"] == metrics["half_width_error"]
    fig = pareto_figure(rows, {"hertz": "half_width_error"})
    ax = fig.axes[0]
    assert "half_width_error" in ax.get_ylabel() and "half_width_error" in ax.get_title()
    report = (tmp_path / "report.md").read_text()
    assert "Plotted error measure: `half_width_error`" in report
    for name in HERTZ:  # every measure has its recommendation rows
        assert f"| {name} | 1 % |" in report
    # resuming with another metric re-labels the rows, runs nothing
    rows = run_study(["hertz"], tmp_path, methods=["nts"], sets={"refine": "-2"}, repeat=1,
                     resume=True)
    assert rows[0]["error_metric"] == "peak_pressure_error"
    assert rows[0]["error"] == metrics["peak_pressure_error"]


def test_default_plot_names_the_scene_default():
    rows = [{"scene": "ring", "method": "", "status": "ok", "wall_time_s": "0.1",
             "radius_error": "0.01", "error_metric": "radius_error"}]
    ax = pareto_figure(rows).axes[0]
    assert ax.get_ylabel().startswith("radius_error") and ax.get_title() == "ring: radius_error"


def test_every_scene_declares_its_measures_and_they_exist():
    """Each scene has a GRIDS entry; its declared measures are keys of the metrics
    a run returns (the cheap scenes are run at their first quick point; ironing,
    12 s, is left out), reference quantities likewise."""
    assert {s.name for s in list_scenes()} <= set(GRIDS)
    for name in ("block", "ring", "cable_arc", "cable_flat", "patch", "tied", "seed"):
        plan = plan_study([name], quick=True)
        run = plan.runs[0]
        metrics = runner.run_scene(name, run["params"], method=run["method"])["metrics"]
        for q in GRIDS[name].get("metrics", []) + GRIDS[name].get("reference", []):
            assert q in metrics, (name, q)
        assert error_measures(name)


def test_reference_measures_against_the_reference_values():
    """``<q>_error`` of a reference scene is |q - q_ref| / |q_ref|; a zero or
    missing reference gives no value (not a division by zero)."""
    row = {"scene": "seed", "status": "ok",
           "metrics": json.dumps({"contact_force": 2.2, "max_indentation": 0.5,
                                  "contact_length": 1.0})}
    refs = {"seed": {"values": {"contact_force": 2.0, "max_indentation": 0.0,
                                "contact_length": None}}}
    out = study_measures._measures(row, refs)
    assert list(out) == ["contact_force_error", "max_indentation_error", "contact_length_error"]
    assert out["contact_force_error"] == pytest.approx(0.1, rel=1e-12)  # round-off of 0.2/2
    assert out["max_indentation_error"] is None and out["contact_length_error"] is None
    ironing = error_measures("ironing")
    assert ironing == ["normal_force_mean_error", "max_penetration"]


# -- repeated timings ---------------------------------------------------------------

def test_timing_stats():
    # dyadic times: every difference and quotient below is exact in binary floats
    assert timing_stats([1.0, 1.0625, 0.9375]) == (1.0, 0.125, False)
    assert timing_stats([1.0, 1.25, 1.0]) == (1.0, 0.25, True)
    assert timing_stats([4.0, 1.0, 2.0, 3.0]) == (2.5, 1.2, True)
    assert timing_stats([2.0]) == (2.0, None, False)  # one run: no spread known


class FakeRuns:
    """A stub ``run_scene`` that advances a fake clock by a known time per call."""

    def __init__(self, durations):
        self.durations = durations  # {n_elements: [time of 1st call, 2nd, ...]}
        self.now = 0.0
        self.calls = []
        self.solvers = []

    def clock(self):
        return self.now

    def run_scene(self, name, params, method=None, steps=None):
        n = params["n_elements"]
        k = sum(c == n for c in self.calls)
        self.calls.append(n)
        self.solvers.append(os.environ.get(SOLVER_ENV))
        self.now += self.durations[n][k]
        return {"n_dofs": 2 * n, "n_multipliers": 0, "steps": [{"newton_iterations": 3}],
                "phase_times_s": {"bulk": 0.1 * k, "solve": None},
                "metrics": {"radius_error": 1.0 / n, "tension_error": 2.0 / n}}


@pytest.fixture
def fake(monkeypatch):
    def make(durations):
        f = FakeRuns(durations)
        monkeypatch.setattr(study_rows, "_clock", f.clock)
        monkeypatch.setattr(runner, "run_scene", f.run_scene)
        return f
    return make


def test_repeat_median_spread_flag_and_interleaving(tmp_path, fake):
    # dyadic times: the fake clock's sums and differences are exact
    f = fake({8: [1.0, 1.0625, 0.9375], 16: [2.0, 3.0, 2.0], 32: [4.0, 4.0, 4.0]})
    rows = run_study(["ring"], tmp_path, quick=True, repeat=3)
    by_n = {int(r["param.n_elements"]): r for r in rows}
    assert by_n[8]["wall_time_s"] == 1.0 and by_n[16]["wall_time_s"] == 2.0
    assert by_n[8]["wall_time_spread"] == 0.125 and by_n[16]["wall_time_spread"] == 0.5
    assert [by_n[n]["timing_unsteady"] for n in (8, 16, 32)] == [False, True, False]
    assert all(by_n[n]["n_timings"] == 3 for n in by_n)
    assert by_n[16]["time.bulk"] == pytest.approx(0.1, rel=1e-12)  # median of 0, 0.1, 0.2
    # round robin: each round runs every point once, before any point runs again
    rounds = [f.calls[i:i + 3] for i in range(0, 9, 3)]
    assert all(sorted(r) == [8, 16, 32] for r in rounds)
    assert len({tuple(r) for r in rounds}) > 1  # shuffled per round (seeded)
    written = read_rows(tmp_path / "results.csv")
    assert [w["timing_unsteady"] for w in written] == ["False", "True", "False"]
    assert json.loads(written[1]["timings"])[1]["wall"] == 3.0
    # the plot draws the unsteady point open (a second line, facecolor none)
    ax = pareto_figure(rows).axes[0]
    open_lines = [ln for ln in ax.get_lines() if ln.get_markerfacecolor() == "none"
                  and len(ln.get_xdata())]
    assert [list(ln.get_xdata()) for ln in open_lines] == [[2.0]]
    assert "⚠" in (tmp_path / "report.md").read_text()


def test_default_repeat_depends_on_the_grid_size(tmp_path, fake):
    f = fake({n: [1.0] * 3 for n in (8, 16, 32)})
    run_study(["ring"], tmp_path / "a", quick=True)
    assert len(f.calls) == 3 * 3  # 3 points <= SMALL_GRID_RUNS: 3 runs each
    assert study.check_repeat(None, study.SMALL_GRID_RUNS + 1) == 1


def test_resume_completes_missing_timings(tmp_path, fake):
    f = fake({n: [1.0, 2.0, 3.0, 4.0] for n in (8, 16, 32)})
    run_study(["ring"], tmp_path, quick=True, repeat=1)
    rows = run_study(["ring"], tmp_path, quick=True, repeat=3, resume=True)
    assert sorted(f.calls) == [8] * 3 + [16] * 3 + [32] * 3
    assert all(r["n_timings"] == 3 and r["wall_time_s"] == 2.0 for r in rows)
    rows = run_study(["ring"], tmp_path, quick=True, repeat=3, resume=True)
    assert len(f.calls) == 9  # nothing left to do


def test_a_failed_repeat_fails_its_row(tmp_path, fake):
    f = fake({8: [1.0, 1.0], 16: [1.0], 32: [1.0, 1.0]})  # a second run of 16 raises
    rows = run_study(["ring"], tmp_path, quick=True, repeat=2)
    by_n = {int(r["param.n_elements"]): r for r in rows}
    assert by_n[8]["status"] == "ok"
    assert by_n[16]["status"].startswith("failed: timing run 2 of 2: IndexError")
    assert len(f.calls) == 6


def test_solver_axis_runs_each_point_with_its_backend(tmp_path, fake, monkeypatch):
    monkeypatch.setattr(linsolve, "available_backends", lambda: ["superlu", "pardiso"])
    monkeypatch.delenv(SOLVER_ENV, raising=False)
    f = fake({8: [1.0, 1.0], 16: [1.0, 1.0], 32: [1.0, 1.0]})
    rows = run_study(["ring"], tmp_path, quick=True, repeat=1, solvers=["superlu", "pardiso"])
    assert sorted((int(r["param.n_elements"]), r["solver"]) for r in rows) == sorted(
        (n, s) for n in (8, 16, 32) for s in ("superlu", "pardiso"))
    assert sorted(f.solvers) == ["pardiso"] * 3 + ["superlu"] * 3
    assert SOLVER_ENV not in os.environ  # restored after each run
    assert len({r["key"] for r in rows}) == 6  # the backend is part of a point's identity


# -- recommendations ----------------------------------------------------------------

def synthetic(time, error, **kw):
    return {"scene": "s", "method": "m", "status": "ok", "wall_time_s": str(time),
            "peak": str(error), "key": f"{time}-{error}", **kw}


def test_recommendation_is_the_cheapest_passing_row():
    rows = [synthetic(3.0, 0.001), synthetic(1.0, 0.05), synthetic(2.0, 0.02),
            synthetic(0.5, 0.2), {**synthetic(0.1, 0.0001), "status": "failed: x"},
            synthetic(0.2, "")]  # a run without the measure never passes
    recs = dict(recommend(rows, "peak", [0.1, 0.03, 0.01, 0.0001]))
    assert recs[0.1]["wall_time_s"] == "1.0"
    assert recs[0.03]["wall_time_s"] == "2.0"
    assert recs[0.01]["wall_time_s"] == "3.0"
    assert recs[0.0001] is None


def test_report_table_and_csv_name_method_steps_solver(tmp_path):
    rows = [synthetic(1.0, 0.05, **{"param.refine": "1", "steps": "", "n_steps": "4",
                                     "solver": "superlu"}),
            synthetic(2.0, 0.005, method="mortar", **{"param.refine": "2", "steps": "8",
                                                      "n_steps": "8", "solver": "pardiso",
                                                      "timing_unsteady": "True"})]
    write_report(rows, tmp_path / "report.md", [0.1, 0.01, 0.001], plotted={"s": "peak"},
                 csv_path=tmp_path / "rec.csv")
    text = (tmp_path / "report.md").read_text()
    assert "| peak | 10 % | m | refine=1 | 4 (scene default) | superlu | 1 | 0.05 |" in text
    assert "| peak | 1 % | mortar | refine=2 | 8 | pardiso | 2 ⚠ | 0.005 |" in text
    assert "No setting reached tolerance 0.1 % on `peak`." in text
    recs = read_rows(tmp_path / "rec.csv")
    assert [(r["tolerance"], r["status"], r["method"], r["steps"], r["solver"]) for r in recs] == [
        ("0.1", "ok", "m", "4 (scene default)", "superlu"),
        ("0.01", "ok", "mortar", "8", "pardiso"), ("0.001", "not reached", "", "", "")]


# -- refusals -----------------------------------------------------------------------

def test_api_refusals_name_the_option_and_allowed_values(tmp_path):
    with pytest.raises(ValueError, match=r"'no_such'.*--metric.*hertz: peak_pressure_error"):
        plan_study(["hertz"], metric="no_such")
    with pytest.raises(ValueError, match=r"scene 'ring'.*allowed for ring \(--metric\): "
                                         r"radius_error, tension_error"):
        plan_study(["hertz", "ring"], metric="peak_pressure_error")
    with pytest.raises(ValueError, match=r"solver 'mumps' is not available; allowed "
                                         r"\(--solver\): superlu"):
        plan_study(["ring"], solvers=["mumps"])
    for bad in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match=r"--repeat\) must be an integer >= 1"):
            run_study(["ring"], tmp_path / "x", repeat=bad)
    with pytest.raises(ValueError, match=r"tolerance must lie in \(0, 1\)"):
        run_study(["ring"], tmp_path / "x", tolerance=[0.1, 1.5])
    assert not (tmp_path / "x").exists()  # refused before the directory is made


@pytest.mark.parametrize("argv, says", [
    (["--repeat", "0"], "--repeat: must be an integer >= 1"),
    (["--metric", "no_such"], "allowed (--metric): ring: radius_error, tension_error"),
    (["--solver", "mumps"], "allowed (--solver): superlu"),
])
def test_cli_refusals_exit_2_before_any_run(argv, says, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(linsolve, "available_backends", lambda: ["superlu"])
    calls = []
    monkeypatch.setattr(runner, "run_scene", lambda *a, **k: calls.append(a))
    out = tmp_path / "study"
    try:
        code = main(["study", "--scene", "ring", "--quick", "--out", str(out), *argv])
    except SystemExit as exc:  # argparse's refusals
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and says in err[0], err
    assert not calls and not out.exists()


def test_each_point_of_the_pareto_plot_names_its_setting():
    """Every drawn point carries its setting (parameters, load steps, solver)."""
    rows = [{"scene": "hertz", "method": m, "status": "ok", "wall_time_s": str(t),
             "peak_pressure_error": str(e), "error_metric": "peak_pressure_error",
             "param.refine": str(r), "steps": s, "solver": "superlu"}
            for m, t, e, r, s in (("mortar", 0.5, 0.02, -1, "1"), ("mortar", 1.1, 0.01, 0, "1"),
                                  ("nts", 0.3, 0.03, -1, ""))]
    ax = pareto_figure(rows).axes[0]
    texts = sorted(t.get_text() for t in ax.texts)
    assert texts == sorted(["refine=-1 steps=1 superlu", "refine=0 steps=1 superlu",
                            "refine=-1 superlu"])
