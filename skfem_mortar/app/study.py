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

import itertools
import random
from pathlib import Path
from typing import Iterator, Sequence

from .study_measures import _finish, _references
from .study_plan import (DEFAULT_TOLERANCES, GRIDS, PHYSICS_AXES, SMALL_GRID_RUNS, SMALL_REPEAT,
                         StudyPlan, check_repeat, check_tolerances, error_measures, parse_steps,
                         plan_study, run_key)
from .study_rows import (UNSTEADY_SPREAD, _add_repeat, _read_csv, _timings, _write_csv, execute,
                         failed_row, timing_stats)

__all__ = ["StudyPlan", "plan_study", "run_study", "parse_steps", "error_measures",
           "timing_stats", "GRIDS", "KILL_RETRIES", "SMALL_GRID_RUNS", "SMALL_REPEAT",
           "UNSTEADY_SPREAD", "DEFAULT_TOLERANCES", "PHYSICS_AXES"]

#: how many times a grid point that killed its worker is tried again on another
#: worker before it becomes a failed row (dask's ``allowed-failures``)
KILL_RETRIES = 1


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
