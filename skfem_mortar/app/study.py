"""The speed-accuracy study: a grid of settings per scene, error against time.

Each grid point is one :func:`~skfem_mortar.app.runner.run_scene` call, a *row* of
``results.csv`` with every setting (method, scene parameters, load steps, solver
backend), the sizes, the wall time per phase, the Newton iterations and every
error measure of the scene, each its own column named after the measure
(:data:`GRIDS`): the scene's analytic errors where it has them (``hertz``:
``peak_pressure_error``, ``half_width_error``, ``pressure_l2_error``,
``peak_pressure_ref_error``, ``pressure_ref_l2_error``), else the relative
deviation ``<q>_error = |q - q_ref| / |q_ref|`` of a scene quantity ``q`` from a
fine mortar reference run computed once and cached in the output directory.
``error_metric`` names the plotted measure (``metric``), ``error`` holds its value.

The friction coefficient is an axis like any scene parameter (``--set
mu=0,0.1,0.3`` for ``ironing`` and ``seed``, where ``mu = 0`` builds no
friction; ``slide`` takes ``mu > 0``). It changes the problem, not its
discretization (:data:`PHYSICS_AXES`), so each of its values gets its own
reference run; the report's ``friction_cost`` section compares each friction
run with the ``mu = 0`` run of the same setting (Newton iterations, wall time,
time per iteration: :func:`~skfem_mortar.app.study_report.friction_cost`).

Timing: each point is run ``repeat`` times (default :data:`SMALL_REPEAT` for a
grid of at most :data:`SMALL_GRID_RUNS` points, else once), in rounds: a round
runs every point that needs another timing once, in an order shuffled per round
(seeded: deterministic), so that a drift of the machine's load spreads over all
points. ``wall_time_s`` and ``time.<phase>`` are medians over the runs;
``wall_time_spread = (max - min) / median``; ``timing_unsteady`` marks a spread
above :data:`UNSTEADY_SPREAD`. Everything but the timings is deterministic.

Rows are written (atomically rewriting the CSV) as each run finishes, so an
interrupted study resumes without redoing finished runs: a row with fewer
timings than ``repeat`` (``timings``, one JSON record per run) gets the missing
ones. A run that fails is a row with its reason (a failed repeat fails its row).
``workers`` runs the grid on a Dask LocalCluster,
``scheduler`` on an existing Dask cluster; serial needs no Dask. A grid point
whose run kills its worker process (a crash, ``os._exit``, the out-of-memory
killer) is retried on a fresh worker ``KILL_RETRIES`` times at most, then it is
a failed row (``failed: worker died ...``) and the other points go on. Each run is
deterministic and independent of where it runs, so the rows are the same.
"""
from __future__ import annotations

import csv
import io as _io
import itertools
import json
import os
import random
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

from ..contact import DEFAULT_METHOD

__all__ = ["StudyPlan", "plan_study", "run_study", "parse_steps", "error_measures",
           "timing_stats", "GRIDS", "KILL_RETRIES", "SMALL_GRID_RUNS", "SMALL_REPEAT",
           "UNSTEADY_SPREAD", "DEFAULT_TOLERANCES", "PHYSICS_AXES"]

#: how many times a grid point that killed its worker is tried again on another
#: worker before it becomes a failed row (dask's ``allowed-failures``)
KILL_RETRIES = 1

#: per scene: its error measures (``metrics``: keys of the scene's metrics, the
#: first plotted by default), the full grid, the quick grid, and for scenes
#: without an analytic answer the quantities (``reference``) compared with a fine
#: mortar reference run (``reference_params``), each the measure ``<q>_error``.
GRIDS: dict[str, dict[str, Any]] = {
    "block": {"metrics": ["nominal_stress_error", "lateral_stretch_error", "max_stress_error"],
              "grid": {"refine": [1, 2, 3, 4], "element": ["tri1", "quad1", "tri2"]},
              "quick": {"refine": [1, 2]}},
    "ring": {"metrics": ["radius_error", "tension_error"],
             "grid": {"n_elements": [8, 16, 32, 64, 128, 256]},
             "quick": {"n_elements": [8, 16, 32]}},
    "cable_arc": {"metrics": ["apex_height_error", "tension_error"],
                  "grid": {"n_elements": [8, 16, 32, 64, 128]},
                  "quick": {"n_elements": [8, 16]}},
    "cable_flat": {"metrics": ["contact_force_error", "contact_half_width_error",
                               "tension_error"],
                   "grid": {"n_elements": [25, 50, 100, 200, 400]},
                   "quick": {"n_elements": [20, 40]}},
    "patch": {"metrics": ["pressure_error", "contact_force_error", "support_reaction_error"],
              "grid": {"n_top": [3, 7, 13], "n_bottom": [4, 10]},
              "quick": {"n_top": [3], "n_bottom": [4]}},
    # the *_ref_* measures read the pressure as linear theory does (reference
    # positions and lengths): with kinematics=small they hold the discretization error
    "hertz": {"metrics": ["peak_pressure_error", "half_width_error", "pressure_l2_error",
                          "peak_pressure_ref_error", "pressure_ref_l2_error"],
              "grid": {"refine": [-2, -1, 0, 1]},
              "quick": {"refine": [-2, -1]}},
    # seed refines both meshes together (a "levels" axis: zipped parameter sets)
    "seed": {"reference": ["contact_force", "max_indentation", "contact_length"],
             "reference_params": {"n_cable": 192, "refine_cushion": 4},
             "grid": {"levels": [{"n_cable": 24, "refine_cushion": 1},
                                 {"n_cable": 48, "refine_cushion": 2},
                                 {"n_cable": 96, "refine_cushion": 3}]},
             "quick": {"levels": [{"n_cable": 24, "refine_cushion": 1}]}},
    # max_penetration: the largest penetration of an active node over the die radius
    "ironing": {"reference": ["normal_force_mean"], "metrics": ["max_penetration"],
                "grid": {}, "quick": {}},
    # slide: the contact's tangential resultant against mu N (gross sliding at the end)
    "slide": {"metrics": ["tangential_ratio_error"], "grid": {"n": [10, 20, 40]},
              "quick": {"n": [10]}},
    # mindlin: the Cattaneo-Mindlin shear and stick zone (the pressure: the floor)
    "mindlin": {"metrics": ["shear_l2_error", "stick_half_width_error", "shear_core_error",
                            "pressure_l2_error"],
                "grid": {"n_a": [6, 12, 24]}, "quick": {"n_a": [6]}},
    "tied": {"metrics": ["tip_deflection_error", "energy_error", "traction_max_error",
                         "traction_error"],
             "grid": {"refine": [1, 2, 3, 4]}, "quick": {"refine": [1, 2]}},
}

#: a study of at most this many grid points is *small*: each point is timed
#: ``SMALL_REPEAT`` times unless ``repeat`` says otherwise (larger grids once)
SMALL_GRID_RUNS = 12
SMALL_REPEAT = 3
#: a point whose timing spread ``(max - min) / median`` exceeds this is marked
#: ``timing_unsteady``
UNSTEADY_SPREAD = 0.2
#: the tolerances (relative errors) the report recommends a setting for
DEFAULT_TOLERANCES = (0.1, 0.03, 0.01, 0.003)
#: the environment variable a run's solver backend is set through
SOLVER_ENV = "SKFEM_MORTAR_SOLVER"

#: the study's clock (a module attribute, so that tests can give known times)
_clock = time.perf_counter


#: settings that only mortar methods have (an NTS run ignores them)
MORTAR_ONLY = ("n_gauss", "segmentation")

#: axes that change the problem, not its discretization (the friction
#: coefficient): each value of such an axis a grid sets gets its own reference
#: run (the reference parameters with that value), so that ``<q>_error`` of a
#: friction run is measured against a fine run with the same friction
PHYSICS_AXES = ("mu",)


@dataclass
class StudyPlan:
    """The list of runs of a study and how to measure each.

    ``measures`` lists each scene's error measures (CSV columns), ``plotted``
    the one plotted and reported first, ``references`` the reference runs.
    """

    runs: list[dict] = field(default_factory=list)
    references: dict[str, dict] = field(default_factory=dict)
    measures: dict[str, list[str]] = field(default_factory=dict)
    plotted: dict[str, str | None] = field(default_factory=dict)


def _parse_values(text: str) -> list[str]:
    return [v.strip() for v in text.split(",") if v.strip()]


def parse_steps(steps: str | int | Sequence[int | str] | None) -> list[int] | None:
    """Load step counts from ``"5,10,20"``, an int or a sequence (None: the scenes').

    Raises
    ------
    ValueError
        Naming ``steps`` and the allowed range, for a value that is not an
        integer in ``[1, MAX_STEPS]`` or an empty list.
    """
    from ..scenes import MAX_STEPS, Param

    if steps is None:
        return None
    items = _parse_values(steps) if isinstance(steps, str) else (
        [steps] if isinstance(steps, int) else list(steps))
    if not items:
        raise ValueError(f"steps must list integers in [1, {MAX_STEPS}], got {steps!r}")
    param = Param("steps", 1, kind=int, low=1, high=MAX_STEPS)
    return [param.parse(v) for v in items]


def error_measures(scene: str) -> list[str]:
    """The error measures (CSV columns) of a scene, the default plotted one first.

    The reference quantities ``q`` of :data:`GRIDS` give ``<q>_error`` (against
    the reference run), then come the scene's own metrics. Empty for a scene
    :data:`GRIDS` does not declare: its rows take every ``*_error`` metric.
    """
    conf = GRIDS.get(scene, {})
    return [f"{q}_error" for q in conf.get("reference", [])] + list(conf.get("metrics", []))


def solver_path(path: str) -> tuple[str, str | None]:
    """``(backend, linear)`` of a solver path ``"backend"`` or ``"backend+linear"``
    (``linear`` one of ``NewtonOptions.linear``'s; None for the bare backend)."""
    backend, _, linear = str(path).partition("+")
    return backend.strip(), (linear.strip() or None)


def parse_solvers(solvers: str | Sequence[str] | None) -> list[str]:
    """The solver paths of the ``solver`` axis (None: the default backend only).

    A path is a backend, optionally with the Newton systems' linear solves
    (``NewtonOptions.linear``): ``pardiso``, ``pardiso+krylov``, ``superlu+auto``;
    ``+direct`` is the bare backend.

    Raises
    ------
    ValueError
        Naming ``--solver`` and the backends available here (or the linear
        solves allowed), for any other name.
    """
    from ..solver.krylov import LINEAR
    from ..solver.linsolve import BACKENDS, available_backends, default_backend

    if solvers is None or (not isinstance(solvers, str) and not list(solvers)):
        return [default_backend()]
    items = _parse_values(solvers) if isinstance(solvers, str) else [
        str(s).strip() for s in solvers]
    available = available_backends()
    paths = []
    for name in items:
        backend, linear = solver_path(name)
        if backend not in available:
            why = (" (a backend of the package, but not installed here)"
                   if backend in BACKENDS else "")
            raise ValueError(f"solver {name!r} is not available{why}; allowed (--solver): "
                             f"{', '.join(available)}, each optionally +krylov or +auto")
        if linear is not None and linear not in LINEAR:
            raise ValueError(f"solver {name!r}: the linear solves after '+' must be one of "
                             f"{', '.join(LINEAR)} (--solver), got {linear!r}")
        paths.append(backend if linear in (None, "direct") else f"{backend}+{linear}")
    return list(dict.fromkeys(paths))


def _plotted(scenes: Sequence[str], metric: str | Sequence[str] | None) -> dict[str, str | None]:
    """Per scene, the plotted measure: the first of ``metric`` the scene has (default:
    its first measure). ValueError naming ``--metric`` and a scene's allowed names."""
    names = [metric] if isinstance(metric, str) else list(metric or [])
    allowed = {scene: error_measures(scene) for scene in scenes}
    for name in names:
        if not any(name in a for a in allowed.values()):
            listing = "; ".join(f"{s}: {', '.join(a) or '(none declared)'}"
                                for s, a in allowed.items())
            raise ValueError(f"metric {name!r} is not an error measure of the studied "
                             f"scenes; allowed (--metric): {listing}")
    out: dict[str, str | None] = {}
    for scene, names_here in allowed.items():
        pick = next((n for n in names if n in names_here), None)
        if names and pick is None:
            raise ValueError(f"metric {names} names no error measure of scene {scene!r}; "
                             f"allowed for {scene} (--metric): "
                             f"{', '.join(names_here) or '(none declared)'}")
        out[scene] = pick or (names_here[0] if names_here else None)
    return out


def plan_study(scenes: Sequence[str], *, methods: Sequence[str] | None = None,
               sets: dict[str, str] | None = None, steps: Sequence[int] | None = None,
               solvers: str | Sequence[str] | None = None,
               metric: str | Sequence[str] | None = None, quick: bool = False) -> StudyPlan:
    """Expand the grid and check every option (nothing runs, nothing is written).

    Parameters
    ----------
    scenes : names of scenes.
    methods : contact methods to compare (default: every method of the scene).
    sets : ``{name: "v1,v2,..."}`` axes that override or extend the scene's grid.
        A name that no scene knows is an error.
    steps : load step counts to compare (default: the scene's).
    solvers : solver paths to compare (:func:`parse_solvers`; default: the
        default backend only).
    metric : the plotted error measure, or several (each scene plots the first
        it has; default: the scene's first, :func:`error_measures`).
    quick : use the small grid (for CI).

    Raises
    ------
    ValueError
        For an unknown scene, method, axis, value, metric or solver.
    """
    from ..scenes import get_scene

    plan = StudyPlan()
    steps = parse_steps(steps)
    solvers = parse_solvers(solvers)
    sets = dict(sets or {})
    used = set()
    for name in scenes:
        get_scene(name)  # an unknown scene before an unknown metric
    plan.plotted = _plotted(scenes, metric)
    for name in scenes:
        scene = get_scene(name)
        conf = GRIDS.get(name, {})
        plan.measures[name] = error_measures(name)
        axes = dict(conf.get("quick" if quick else "grid", {}))
        levels = axes.pop("levels", [{}])
        known = {p.name for p in scene.params}
        for key, text in sets.items():
            if key in known:
                axes[key] = _parse_values(text)
                used.add(key)
                levels = [{k: v for k, v in lv.items() if k != key} for lv in levels]
        for key, vals in axes.items():  # validate now: a bad value is a clear error
            for v in vals:
                scene.param(key).parse(v)
        scene_methods = [m for m in scene.methods]
        if methods:
            bad = [m for m in methods if m not in scene.methods]
            scene_methods = [m for m in methods if m in scene.methods] or [None]
            if bad and scene.methods != (None,):
                raise ValueError(f"method(s) {bad} are not available for scene {name!r}; "
                                 f"allowed: {[m for m in scene.methods if m]}")
        keys = sorted(axes)
        for method, step, solver, level, combo in itertools.product(
                scene_methods, list(steps or [None]), solvers, levels,
                itertools.product(*(axes[k] for k in keys)) if keys else [()]):
            params = {**{k: scene.param(k).parse(v) for k, v in level.items()},
                      **{k: scene.param(k).parse(v) for k, v in zip(keys, combo)}}
            params = {k: v for k, v in params.items()
                      if not (method == "nts" and k in MORTAR_ONLY)}
            _check_point(scene, params)
            run = {"scene": name, "method": method, "steps": step, "solver": solver,
                   "params": params}
            if run not in plan.runs:  # NTS ignores the mortar axes: run it once
                plan.runs.append(run)
        if "reference" in conf:
            plan.references[name] = {"metrics": list(conf["reference"]),
                                     "params": conf.get("reference_params", {}),
                                     "variants": _variants(scene, plan.runs)}
    unknown = set(sets) - used
    if unknown:
        raise ValueError(f"--set names no parameter of the studied scenes: {sorted(unknown)}")
    return plan


def _variants(scene, runs: list[dict]) -> list[dict]:
    """The settings of :data:`PHYSICS_AXES` the scene's runs use other than the
    scene's defaults (each wants its own reference run), in order of appearance."""
    out: list[dict] = []
    for run in runs:
        if run["scene"] != scene.name:
            continue
        variant = {k: run["params"][k] for k in PHYSICS_AXES
                   if k in run["params"] and run["params"][k] != scene.param(k).default}
        if variant and variant not in out:
            out.append(variant)
    return out


def variant_key(values: dict) -> str:
    """The key of a reference variant (its physics-axis values, as floats)."""
    return json.dumps({k: float(v) for k, v in values.items()}, sort_keys=True)


def _check_point(scene, params: dict) -> None:
    """Validate one grid point as a run would (sizes, derived quantities), naming
    the grid point in the message."""
    try:
        scene.resolve(params)
    except ValueError as exc:
        point = ", ".join(f"{k}={v}" for k, v in params.items())
        raise ValueError(f"{exc} [scene {scene.name}, grid point {point}]") from None


def check_repeat(repeat: int | None, n_points: int) -> int:
    """The number of timed runs per point: ``repeat``, or by default
    :data:`SMALL_REPEAT` for at most :data:`SMALL_GRID_RUNS` points, else 1.

    Raises
    ------
    ValueError
        Naming ``--repeat`` for anything but an integer >= 1.
    """
    if repeat is None:
        return SMALL_REPEAT if n_points <= SMALL_GRID_RUNS else 1
    if isinstance(repeat, bool) or not isinstance(repeat, (int, np.integer)) or repeat < 1:
        raise ValueError(f"repeat (--repeat) must be an integer >= 1, got {repeat!r}")
    return int(repeat)


def check_tolerances(tolerance: float | Sequence[float] | None) -> list[float]:
    """The report's tolerances, largest first (None: :data:`DEFAULT_TOLERANCES`).

    Raises
    ------
    ValueError
        Naming ``tolerance`` for a value outside (0, 1).
    """
    if tolerance is None:
        return list(DEFAULT_TOLERANCES)
    values = [tolerance] if isinstance(tolerance, (int, float)) else list(tolerance)
    if not values:
        return list(DEFAULT_TOLERANCES)
    for t in values:
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not (0.0 < t < 1.0):
            raise ValueError(f"tolerance must lie in (0, 1), got {t!r}")
    return sorted({float(t) for t in values}, reverse=True)


def run_key(run: dict) -> str:
    """A stable identity of a run (to resume without redoing rows)."""
    return json.dumps({"scene": run["scene"], "method": run["method"], "steps": run["steps"],
                       "solver": run.get("solver"), "params": run["params"]}, sort_keys=True)


def execute(run: dict) -> dict:
    """Run one grid point with its solver path; never raises (a failure is a row
    with its reason). The row's ``timings`` holds this run's wall and phase times."""
    from .runner import run_scene

    row = _base_row(run)
    solver, linear = solver_path(run["solver"]) if run.get("solver") else (None, None)
    previous = os.environ.get(SOLVER_ENV)
    if solver:
        os.environ[SOLVER_ENV] = solver
    try:
        t0 = _clock()
        summary = run_scene(run["scene"], run["params"], method=run["method"],
                            steps=run["steps"], **({"linear": linear} if linear else {}))
        wall = _clock() - t0
    except Exception as exc:  # noqa: BLE001 - the study reports, it does not crash
        return failed_row(run, f"{type(exc).__name__}: {exc}")
    finally:
        if solver:
            if previous is None:
                os.environ.pop(SOLVER_ENV, None)
            else:
                os.environ[SOLVER_ENV] = previous
    iters = [s["newton_iterations"] for s in summary["steps"]]
    row.update(status="ok", n_dofs=summary["n_dofs"], n_multipliers=summary["n_multipliers"],
               n_steps=len(iters), newton_iterations=sum(iters),
               max_newton_iterations=max(iters or [0]),
               metrics=json.dumps(summary["metrics"]),
               timings=json.dumps([{"wall": wall, **summary["phase_times_s"]}]))
    _apply_timings(row)
    return row


def _base_row(run: dict) -> dict[str, Any]:
    """The settings columns of a run's row."""
    return {"key": run_key(run), "scene": run["scene"], "method": run["method"] or "",
            "steps": run["steps"] or "", "solver": run.get("solver") or "",
            **{f"param.{k}": v for k, v in run["params"].items()}}


def failed_row(run: dict, reason: str) -> dict[str, Any]:
    """The row of a run that failed, with its reason on one line."""
    return {**_base_row(run), "status": f"failed: {reason}".replace("\n", " ")}


def timing_stats(times: Sequence[float]) -> tuple[float, float | None, bool]:
    """Median, spread and steadiness of the wall times of one point.

    ``spread = (max - min) / median`` (None for a single run, which has none);
    ``unsteady = spread > UNSTEADY_SPREAD``.
    """
    t = np.asarray(times, dtype=float)
    if t.size == 0:
        raise ValueError("times must hold at least one wall time")
    median = float(np.median(t))
    if t.size < 2:
        return median, None, False
    spread = float((t.max() - t.min()) / median) if median > 0 else 0.0
    return median, spread, spread > UNSTEADY_SPREAD


def _timings(row: dict) -> list[dict]:
    """The per-run time records of a row (a row of an older CSV: its one time)."""
    if row.get("status") != "ok":
        return []
    if row.get("timings"):
        return json.loads(row["timings"])
    phases = {k[5:]: _float(v) for k, v in row.items() if k.startswith("time.")}
    return [{"wall": _float(row.get("wall_time_s")), **phases}]


def _float(v) -> float | None:
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def _apply_timings(row: dict) -> None:
    """Set the median times, spread and flag of a row from its ``timings``."""
    runs = _timings(row)
    median, spread, unsteady = timing_stats([r["wall"] for r in runs])
    row.update(wall_time_s=median, wall_time_spread="" if spread is None else spread,
               timing_unsteady=unsteady, n_timings=len(runs))
    for phase in dict.fromkeys(k for r in runs for k in r if k != "wall"):
        vals = [r[phase] for r in runs if r.get(phase) is not None]
        row[f"time.{phase}"] = float(np.median(vals)) if vals else None
    row["timings"] = json.dumps(runs)


def _add_repeat(row: dict, new: dict, repeat: int) -> None:
    """Merge one more timed run of a point into its row (a failed one fails the row)."""
    done = len(_timings(row))
    if new.get("status") != "ok":
        reason = new["status"].removeprefix("failed: ")
        row["status"] = f"failed: timing run {done + 1} of {repeat}: {reason}"
        return
    row["timings"] = json.dumps(_timings(row) + _timings(new))
    _apply_timings(row)


def _measures(row: dict, refs: dict[str, dict]) -> dict[str, float | None]:
    """Every error measure of a row (None where the run failed or lacks it)."""
    names = error_measures(row["scene"])
    if row.get("status") != "ok":
        return {n: None for n in names}
    metrics = json.loads(row["metrics"])
    if not names:  # a scene GRIDS does not declare: its own *_error metrics
        names = [k for k in metrics if k.endswith("_error")]
    ref = refs.get(row["scene"], {}).get("values", {})
    variant = {k: row[f"param.{k}"] for k in PHYSICS_AXES
               if row.get(f"param.{k}") not in ("", None)}
    ref = refs.get(row["scene"], {}).get("variant_values", {}).get(variant_key(variant), ref) \
        if variant else ref
    out: dict[str, float | None] = {}
    for name in names:
        q = name.removesuffix("_error")
        if q in ref:  # against the reference run
            val, val_ref = metrics.get(q), ref[q]
            out[name] = (None if val is None or val_ref in (None, 0)
                         else abs(val - val_ref) / abs(val_ref))
        else:
            val = metrics.get(name)
            out[name] = None if val is None else float(val)
    return out


def _finish(row: dict, refs: dict[str, dict], plotted: dict[str, str | None]) -> None:
    """Add the measure columns, ``error_metric`` and ``error`` to a row."""
    measures = _measures(row, refs)
    row.update({k: ("" if v is None else v) for k, v in measures.items()})
    scene = row["scene"]
    name = plotted.get(scene) if scene in plotted else (error_measures(scene) or [None])[0]
    name = name or next(iter(measures), None)
    row["error_metric"] = name or ""
    val = measures.get(name) if name else None
    row["error"] = "" if val is None else val


#: the column groups of results.csv, in order (a column's group: its first match)
_COLUMN_ORDER = ("key", "scene", "method", "steps", "solver", "param.", "status", "n_dofs",
                 "n_multipliers", "wall_time_s", "wall_time_spread", "timing_unsteady",
                 "n_timings", "time.", "n_steps", "newton_iterations",
                 "max_newton_iterations", "error_metric", "error", None, "metrics", "timings")


def _column_rank(col: str) -> int:
    for i, c in enumerate(_COLUMN_ORDER):
        if c is not None and (col == c or (c.endswith(".") and col.startswith(c))):
            return i
    return _COLUMN_ORDER.index(None)  # the error measures


def _write_csv(path: Path, rows: list[dict]) -> None:
    from ..output.io import atomic_path

    cols: list[str] = []
    for r in rows:
        cols += [k for k in r if k not in cols]
    cols.sort(key=_column_rank)  # stable: first appearance within a group
    buf = _io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols)
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if v is None else v) for k, v in r.items()})
    with atomic_path(path) as tmp:
        tmp.write_text(buf.getvalue())


def _read_csv(path: Path) -> list[dict]:
    if not path.exists():
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


class _Pool:
    """Runs grid points and yields their rows as they finish: serially, or on a
    Dask cluster started at the first :meth:`map` and kept for the later rounds."""

    def __init__(self, workers: int, scheduler: str | None):
        self.workers, self.scheduler = workers, scheduler
        self.client = self.cluster = None

    def _start(self) -> None:
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError as exc:  # pragma: no cover - depends on the extra
            raise ValueError("workers/scheduler need the 'distributed' extra: "
                             "pip install 'skfem-mortar[distributed]'") from exc
        import dask

        if self.scheduler:
            self.client = Client(self.scheduler)
            return
        import logging

        # dask's own config sets its loggers to INFO, and their records reach the
        # command line's handler whatever its level: the scheduler's and nanny's
        # start/stop chatter is kept to warnings unless -v asked for DEBUG
        if logging.getLogger().getEffectiveLevel() > logging.DEBUG:
            logging.getLogger("distributed").setLevel(logging.WARNING)
        # the scheduler runs in this process: a point that kills its worker is
        # given up (KilledWorker) after KILL_RETRIES retries on fresh workers.
        # worker-saturation 1: a worker holds only the point it runs (dask's
        # default 1.1 queues a second one on a one-thread worker, which then
        # dies with it and is counted against that innocent point)
        with dask.config.set({"distributed.scheduler.allowed-failures": KILL_RETRIES,
                              "distributed.scheduler.worker-saturation": 1.0}):
            self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                        processes=True, dashboard_address=None,
                                        silence_logs=logging.CRITICAL)
        self.client = Client(self.cluster)

    def map(self, runs: list[dict]) -> Iterator[dict]:
        if not self.workers and not self.scheduler:
            for run in runs:
                yield execute(run)
            return
        from dask.distributed import as_completed

        if self.client is None:
            self._start()
        futures = {self.client.submit(execute, run, pure=False): run for run in runs}
        for fut in as_completed(list(futures)):
            yield _result_row(fut, futures[fut])

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _result_row(fut, run: dict) -> dict:
    """The row a finished future holds, or a failed row when its worker died (each
    of its tries killed the worker process that ran it) or the cluster lost it."""
    from dask.distributed import KilledWorker

    try:
        return fut.result()
    except KilledWorker:
        return failed_row(run, f"worker died running this point ({KILL_RETRIES + 1} "
                               "tries: a crash, os._exit or the out-of-memory killer)")
    except Exception as exc:  # noqa: BLE001 - a lost task is a row, not a crash
        return failed_row(run, f"{type(exc).__name__}: {exc}")


def _rounds(runs: list[dict], by_key: dict[str, dict], repeat: int, pool: _Pool
            ) -> Iterator[dict]:
    """Run the points in rounds until each ok row has ``repeat`` timings; yield
    the row of each finished run (the caller merges it into ``by_key``). A round
    runs every point that needs another timing once, in an order shuffled with
    the round's number as the seed."""
    for number in itertools.count():
        batch = [r for r in runs if _needs(by_key.get(run_key(r)), repeat)]
        if not batch:
            return
        random.Random(number).shuffle(batch)
        yield from pool.map(batch)


def _needs(row: dict | None, repeat: int) -> bool:
    """Whether a point needs another run: never run, or ok with too few timings."""
    return row is None or (row.get("status") == "ok" and len(_timings(row)) < repeat)


def _pending(runs: list[dict], by_key: dict[str, dict], repeat: int) -> int:
    """How many runs the study still makes."""
    total = 0
    for run in runs:
        row = by_key.get(run_key(run))
        total += repeat if row is None else (
            max(repeat - len(_timings(row)), 0) if row.get("status") == "ok" else 0)
    return total


def run_study(scenes: Sequence[str], out: str | Path, *, methods: Sequence[str] | None = None,
              sets: dict[str, str] | None = None, steps: Sequence[int] | None = None,
              solvers: str | Sequence[str] | None = None,
              metric: str | Sequence[str] | None = None, repeat: int | None = None,
              quick: bool = False, tolerance: float | Sequence[float] | None = None,
              resume: bool = False, workers: int = 0, scheduler: str | None = None,
              progress: bool = False) -> list[dict]:
    """Run the grid and write ``results.csv``, ``pareto.png``, ``report.md`` and
    ``recommendations.csv``.

    Parameters
    ----------
    scenes, methods, sets, steps, solvers, metric, quick
        The grid and the plotted measure (:func:`plan_study`).
    repeat : int >= 1, optional
        Timed runs per point (:func:`check_repeat`; default 3 for at most
        ``SMALL_GRID_RUNS`` points, else 1).
    tolerance : float or sequence of floats in (0, 1), optional
        The relative errors the report recommends the cheapest setting for
        (default :data:`DEFAULT_TOLERANCES`).
    resume : bool
        Keep the rows of ``results.csv`` and make only the missing runs.
    workers, scheduler
        A Dask LocalCluster of ``workers`` processes, or an existing scheduler.

    Returns
    -------
    list of dict
        The rows, each with its measure columns, ``error_metric`` and ``error``.

    Raises
    ------
    ValueError
        Before any run, for a bad option (the message names it).
    """
    tolerances = check_tolerances(tolerance)
    if workers < 0:
        raise ValueError(f"workers must be >= 0, got {workers!r}")
    plan = plan_study(scenes, methods=methods, sets=sets, steps=steps, solvers=solvers,
                      metric=metric, quick=quick)
    repeat = check_repeat(repeat, len(plan.runs))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "results.csv"
    rows = _read_csv(csv_path) if resume else []
    by_key = {r["key"]: r for r in rows}
    refs = _references(plan, out)
    bar = None
    if progress:
        from tqdm.auto import tqdm
        todo = _pending(plan.runs, by_key, repeat)
        total = len(plan.runs) * repeat
        bar = tqdm(total=total, initial=total - todo, desc="study", unit="run")
    pool = _Pool(workers, scheduler)
    try:
        for new in _rounds(plan.runs, by_key, repeat, pool):
            row = by_key.get(new["key"])
            before = len(_timings(row)) if row is not None else 0
            if row is None:
                row = by_key[new["key"]] = new
                rows.append(row)
            else:
                _add_repeat(row, new, repeat)
            _finish(row, refs, plan.plotted)
            _write_csv(csv_path, rows)
            if bar is not None:  # a failed run also skips the point's remaining runs
                bar.update(1 if row.get("status") == "ok" else repeat - before)
    finally:
        pool.close()
        if bar is not None:
            bar.close()
    order = {run_key(r): i for i, r in enumerate(plan.runs)}
    rows.sort(key=lambda r: order.get(r["key"], len(order)))
    for row in rows:
        _finish(row, refs, plan.plotted)
    _write_csv(csv_path, rows)
    from .study_report import pareto_plot, write_report

    pareto_plot(rows, out / "pareto.png", plan.plotted)
    write_report(rows, out / "report.md", tolerances, plotted=plan.plotted,
                 measures={s: m for s, m in plan.measures.items() if m}, repeat=repeat,
                 csv_path=out / "recommendations.csv")
    return rows


def _references(plan: StudyPlan, out: Path) -> dict[str, dict]:
    """Fine mortar reference values, computed once and cached in ``references.json``:
    one per scene at its reference parameters, and one per variant of the
    :data:`PHYSICS_AXES` the grid sets (the reference parameters with it, cached
    as ``"<scene> <variant>"``, e.g. ``seed {"mu": 0.3}``)."""
    from ..output.io import write_json
    from .runner import run_scene

    path = out / "references.json"
    cache = json.loads(path.read_text()) if path.exists() else {}
    for scene, ref in plan.references.items():
        variants = ref.get("variants", [])
        for variant in [{}] + list(variants):
            name = scene if not variant else f"{scene} {variant_key(variant)}"
            params = {**ref["params"], **variant}
            key = json.dumps({"metrics": ref["metrics"], "params": params}, sort_keys=True) \
                if variant else json.dumps({k: ref[k] for k in ("metrics", "params")},
                                           sort_keys=True)
            if cache.get(name, {}).get("key") != key:
                summary = run_scene(scene, params, method=DEFAULT_METHOD)
                values = {q: summary["metrics"].get(q) for q in ref["metrics"]}
                cache[name] = {"key": key, "values": values, "params": params}
                write_json(path, cache)
            if variant:
                ref.setdefault("variant_values", {})[variant_key(variant)] = cache[name]["values"]
            else:
                ref["values"] = cache[name]["values"]
    return plan.references
