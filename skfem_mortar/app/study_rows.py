"""One grid point of the study as a row of ``results.csv``: its run (:func:`execute`,
never raising: a failure is a row with its reason), its repeated timings (medians,
spread, :data:`UNSTEADY_SPREAD`) and the CSV, rewritten atomically.
"""
from __future__ import annotations

import csv
import io as _io
import json
import os
import time
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .study_plan import run_key, solver_path

__all__ = ["execute", "failed_row", "timing_stats", "UNSTEADY_SPREAD", "SOLVER_ENV"]

#: a point whose timing spread ``(max - min) / median`` exceeds this is marked
#: ``timing_unsteady``
UNSTEADY_SPREAD = 0.2
#: the environment variable a run's solver backend is set through
SOLVER_ENV = "SKFEM_MORTAR_SOLVER"
#: the study's clock (a module attribute, so that tests can give known times)
_clock = time.perf_counter


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
