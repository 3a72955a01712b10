"""The speed-accuracy study: a grid of settings per scene, error against time.

Each grid point is one :func:`~skfem_mortar.app.runner.run_scene` call, a *row* of
``results.csv`` with every setting, the sizes, the wall time per phase, the
Newton iterations and the error. The error is the scene's analytic error metric
where it has one, else the relative deviation of a scene quantity from a fine
mortar reference computed once and cached in the output directory.

Rows are appended (atomically rewriting the CSV) as they finish, so an
interrupted study resumes without redoing finished rows. A run that fails is a
row with its reason. ``workers`` runs the grid on a Dask LocalCluster,
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
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

__all__ = ["StudyPlan", "plan_study", "run_study", "parse_steps", "GRIDS", "KILL_RETRIES"]

#: how many times a grid point that killed its worker is tried again on another
#: worker before it becomes a failed row (dask's ``allowed-failures``)
KILL_RETRIES = 1

#: per scene: the error metric, the full grid, the quick grid, and (for scenes
#: without an analytic answer) the metric compared with a fine reference run.
GRIDS: dict[str, dict[str, Any]] = {
    "block": {"error": "nominal_stress_error",
              "grid": {"refine": [1, 2, 3, 4], "element": ["tri1", "quad1", "tri2"]},
              "quick": {"refine": [1, 2]}},
    "ring": {"error": "radius_error",
             "grid": {"n_elements": [8, 16, 32, 64, 128, 256]},
             "quick": {"n_elements": [8, 16, 32]}},
    "cable_arc": {"error": "apex_height_error",
                  "grid": {"n_elements": [8, 16, 32, 64, 128]},
                  "quick": {"n_elements": [8, 16]}},
    "cable_flat": {"error": "contact_force_error",
                   "grid": {"n_elements": [25, 50, 100, 200, 400]},
                   "quick": {"n_elements": [20, 40]}},
    "patch": {"error": "pressure_error",
              "grid": {"n_top": [3, 7, 13], "n_bottom": [4, 10]},
              "quick": {"n_top": [3], "n_bottom": [4]}},
    "hertz": {"error": "peak_pressure_error",
              "grid": {"refine": [-2, -1, 0, 1]},
              "quick": {"refine": [-2, -1]}},
    # seed refines both meshes together (a "levels" axis: zipped parameter sets)
    "seed": {"reference": "contact_force", "reference_params": {"n_cable": 192,
                                                                "refine_cushion": 4},
             "grid": {"levels": [{"n_cable": 24, "refine_cushion": 1},
                                 {"n_cable": 48, "refine_cushion": 2},
                                 {"n_cable": 96, "refine_cushion": 3}]},
             "quick": {"levels": [{"n_cable": 24, "refine_cushion": 1}]}},
    "ironing": {"reference": "normal_force_mean",
                "grid": {}, "quick": {}},
}


#: settings that only mortar methods have (an NTS run ignores them)
MORTAR_ONLY = ("n_gauss", "segmentation")


@dataclass
class StudyPlan:
    """The list of runs of a study and how to measure each."""

    runs: list[dict] = field(default_factory=list)
    references: dict[str, dict] = field(default_factory=dict)


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


def plan_study(scenes: Sequence[str], *, methods: Sequence[str] | None = None,
               sets: dict[str, str] | None = None, steps: Sequence[int] | None = None,
               quick: bool = False) -> StudyPlan:
    """Expand the grid.

    Parameters
    ----------
    scenes : names of scenes.
    methods : contact methods to compare (default: every method of the scene).
    sets : ``{name: "v1,v2,..."}`` axes that override or extend the scene's grid.
        A name that no scene knows is an error.
    steps : load step counts to compare (default: the scene's).
    quick : use the small grid (for CI).
    """
    from ..scenes import get_scene

    plan = StudyPlan()
    steps = parse_steps(steps)
    sets = dict(sets or {})
    used = set()
    for name in scenes:
        scene = get_scene(name)
        conf = GRIDS.get(name, {})
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
        for method, step, level, combo in itertools.product(
                scene_methods, list(steps or [None]), levels,
                itertools.product(*(axes[k] for k in keys)) if keys else [()]):
            params = {**{k: scene.param(k).parse(v) for k, v in level.items()},
                      **{k: scene.param(k).parse(v) for k, v in zip(keys, combo)}}
            params = {k: v for k, v in params.items()
                      if not (method == "nts" and k in MORTAR_ONLY)}
            _check_point(scene, params)
            run = {"scene": name, "method": method, "steps": step, "params": params}
            if run not in plan.runs:  # NTS ignores the mortar axes: run it once
                plan.runs.append(run)
        if "reference" in conf:
            plan.references[name] = {"metric": conf["reference"],
                                     "params": conf.get("reference_params", {})}
    unknown = set(sets) - used
    if unknown:
        raise ValueError(f"--set names no parameter of the studied scenes: {sorted(unknown)}")
    return plan


def _check_point(scene, params: dict) -> None:
    """Validate one grid point as a run would (sizes, derived quantities), naming
    the grid point in the message."""
    try:
        scene.resolve(params)
    except ValueError as exc:
        point = ", ".join(f"{k}={v}" for k, v in params.items())
        raise ValueError(f"{exc} [scene {scene.name}, grid point {point}]") from None


def run_key(run: dict) -> str:
    """A stable identity of a run (to resume without redoing rows)."""
    return json.dumps({"scene": run["scene"], "method": run["method"], "steps": run["steps"],
                       "params": run["params"]}, sort_keys=True)


def execute(run: dict) -> dict:
    """Run one grid point; never raises (a failure is a row with its reason)."""
    from .runner import run_scene

    row = _base_row(run)
    try:
        summary = run_scene(run["scene"], run["params"], method=run["method"],
                            steps=run["steps"])
    except Exception as exc:  # noqa: BLE001 - the study reports, it does not crash
        return failed_row(run, f"{type(exc).__name__}: {exc}")
    iters = [s["newton_iterations"] for s in summary["steps"]]
    row.update(status="ok", n_dofs=summary["n_dofs"], n_multipliers=summary["n_multipliers"],
               wall_time_s=summary["wall_time_s"], n_steps=len(iters),
               newton_iterations=sum(iters), max_newton_iterations=max(iters or [0]),
               **{f"time.{k}": v for k, v in summary["phase_times_s"].items()},
               metrics=json.dumps(summary["metrics"]))
    return row


def _base_row(run: dict) -> dict[str, Any]:
    """The settings columns of a run's row."""
    return {"key": run_key(run), "scene": run["scene"], "method": run["method"] or "",
            "steps": run["steps"] or "",
            **{f"param.{k}": v for k, v in run["params"].items()}}


def failed_row(run: dict, reason: str) -> dict[str, Any]:
    """The row of a run that failed, with its reason on one line."""
    return {**_base_row(run), "status": f"failed: {reason}".replace("\n", " ")}


def _error(row: dict, refs: dict[str, dict]) -> float | None:
    if row.get("status") != "ok":
        return None
    metrics = json.loads(row["metrics"])
    conf = GRIDS.get(row["scene"], {})
    if row["scene"] in refs:
        ref = refs[row["scene"]]
        q, q_ref = metrics.get(ref["metric"]), ref.get("value")
        if q is None or q_ref in (None, 0):
            return None
        return abs(q - q_ref) / abs(q_ref)
    name = conf.get("error") or next((k for k in metrics if k.endswith("_error")), None)
    val = metrics.get(name) if name else None
    return None if val is None else float(val)


def _write_csv(path: Path, rows: list[dict]) -> None:
    from ..output.io import atomic_path

    cols: list[str] = []
    for r in rows:
        cols += [k for k in r if k not in cols]
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


def _map(runs: list[dict], workers: int, scheduler: str | None) -> Iterable[dict]:
    """Yield rows as they finish: serially, or on a Dask cluster."""
    if not workers and not scheduler:
        for run in runs:
            yield execute(run)
        return
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as exc:  # pragma: no cover - depends on the extra
        raise ValueError("workers/scheduler need the 'distributed' extra: "
                         "pip install 'skfem-mortar[distributed]'") from exc
    import dask

    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        import logging

        # the scheduler runs in this process: a point that kills its worker is
        # given up (KilledWorker) after KILL_RETRIES retries on fresh workers
        with dask.config.set({"distributed.scheduler.allowed-failures": KILL_RETRIES}):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.CRITICAL)
        client = Client(cluster)
    try:
        futures = {client.submit(execute, run, pure=False): run for run in runs}
        for fut in as_completed(list(futures)):
            yield _result_row(fut, futures[fut])
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


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


def run_study(scenes: Sequence[str], out: str | Path, *, methods: Sequence[str] | None = None,
              sets: dict[str, str] | None = None, steps: Sequence[int] | None = None,
              quick: bool = False, tolerance: float = 1e-2, resume: bool = False,
              workers: int = 0, scheduler: str | None = None, progress: bool = False
              ) -> list[dict]:
    """Run the grid and write ``results.csv``, ``pareto.png`` and ``report.md``.

    Returns the rows (dicts), including an ``error`` column.
    """
    if not (0.0 < tolerance < 1.0):
        raise ValueError(f"tolerance must lie in (0, 1), got {tolerance!r}")
    if workers < 0:
        raise ValueError(f"workers must be >= 0, got {workers!r}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    plan = plan_study(scenes, methods=methods, sets=sets, steps=steps, quick=quick)
    csv_path = out / "results.csv"
    rows = _read_csv(csv_path) if resume else []
    done = {r["key"] for r in rows}
    todo = [r for r in plan.runs if run_key(r) not in done]
    refs = _references(plan, out)
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=len(plan.runs), initial=len(plan.runs) - len(todo), desc="study",
                   unit="run")
    try:
        for row in _map(todo, workers, scheduler):
            err = _error(row, refs)
            row["error"] = "" if err is None else err
            rows.append(row)
            _write_csv(csv_path, rows)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    order = {run_key(r): i for i, r in enumerate(plan.runs)}
    rows.sort(key=lambda r: order.get(r["key"], len(order)))
    _write_csv(csv_path, rows)
    from .study_report import pareto_plot, write_report

    pareto_plot(rows, out / "pareto.png")
    write_report(rows, out / "report.md", tolerance)
    return rows


def _references(plan: StudyPlan, out: Path) -> dict[str, dict]:
    """Fine mortar reference values, computed once and cached in ``references.json``."""
    from ..output.io import write_json
    from .runner import run_scene

    path = out / "references.json"
    cache = json.loads(path.read_text()) if path.exists() else {}
    for scene, ref in plan.references.items():
        key = json.dumps(ref, sort_keys=True)
        if cache.get(scene, {}).get("key") != key:
            summary = run_scene(scene, ref["params"], method="mortar")
            value = summary["metrics"].get(ref["metric"])
            cache[scene] = {"key": key, "metric": ref["metric"], "value": value,
                            "params": ref["params"]}
            write_json(path, cache)
        plan.references[scene]["value"] = cache[scene]["value"]
    return plan.references
