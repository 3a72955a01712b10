"""Run a scene end to end: build, solve, measure, write. Used by the CLI and tests."""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import ConvergenceError
from ..solver.observers import CheckpointObserver, ContactCsv, Observer, SeriesObserver
from ..scenes import Setup, get_scene
from ..solver.newton import NewtonOptions
from ..solver.stepping import Controller, Restart, Result, StepRecord, solve, stateful_items
from .interrupt import check as check_interrupt

__all__ = ["build_scene", "run_scene"]

#: largest checkpoint step file a resume accepts, in states of the model (plus
#: 1 MiB): a step holds one state and the contact state (a few arrays over the
#: contact nodes), far below it; a larger file is refused unread
MAX_STEP_STATES = 16


def build_scene(name: str, params: dict[str, Any] | None = None,
                method: str | None = None) -> tuple[Setup, dict[str, Any], str | None]:
    """Validate ``params`` and ``method`` and build the scene's setup."""
    scene = get_scene(name)
    values = scene.resolve(params)
    method = scene.check_method(method)
    return scene.build(values, method), values, method


def _check_steps(n_steps: Any) -> None:
    """The number of load steps: an integer in [1, MAX_STEPS] (ValueError naming ``steps``)."""
    from ..scenes import MAX_STEPS

    if not (isinstance(n_steps, (int, np.integer)) and not isinstance(n_steps, bool)
            and 1 <= n_steps <= MAX_STEPS):
        raise ValueError(f"steps must be an integer in [1, {MAX_STEPS}], got {n_steps!r}")


def _clean(obj: Any) -> Any:
    """JSON-ready copy: numpy scalars to Python, non-finite floats to None."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_clean(v) for v in obj]
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    return obj


#: significant digits of the load factors in the summary (JSON and console); the
#: checkpoints keep the full precision a resumed run restarts from
LOAD_FACTOR_DIGITS = 12


def load_factor_value(lf: float) -> float:
    """``lf`` rounded to :data:`LOAD_FACTOR_DIGITS` significant digits (``0.1 + 0.2``
    is written ``0.3``, not ``0.30000000000000004``)."""
    return float(f"{float(lf):.{LOAD_FACTOR_DIGITS}g}")


def _step_entry(record: StepRecord) -> dict:
    """A step of the summary: :meth:`StepRecord.as_dict`, its load factor and
    increment at :data:`LOAD_FACTOR_DIGITS` digits."""
    d = record.as_dict()
    return {**d, "load_factor": load_factor_value(d["load_factor"]),
            "increment": load_factor_value(d["increment"])}


def run_scene(name: str, params: dict[str, Any] | None = None, method: str | None = None,
              steps: int | None = None, out: str | Path | None = None,
              progress: bool = False, resume: bool = False, replace: bool = False,
              return_result: bool = False, linear: str | None = None,
              **solve_kwargs) -> dict | tuple[dict, Result, Setup]:
    """Build and solve a scene; return the summary object of the CLI contract.

    Parameters
    ----------
    name : str
        Scene name (``skfem-mortar scenes`` lists them).
    params : dict
        Overrides of the scene parameters (validated; ValueError otherwise).
    method : {"nts", "mortar", "mortar-dual"} or None
    steps : int, optional
        Number of load steps (default: the scene's).
    out : path, optional
        Directory for the result series, ``summary.json``, ``contact.csv`` and
        the ``checkpoint/`` directory (one file added per converged step). It
        holds one run (:mod:`skfem_mortar.output.outdir`): it is locked while the run
        goes on, and a directory that holds another run's files is refused
        (:class:`~skfem_mortar.output.outdir.OutputDirError`, a ValueError) unless
        ``replace``. ``summary.json`` is written only when the run ends:
        ``converged`` true when it finished, false (with the converged steps and
        the ``error``) when a load step did not converge; a run killed or
        interrupted leaves none.
    resume : bool
        Continue from ``out/checkpoint/`` if it belongs to the same scene,
        method, parameters and steps (ValueError if it belongs to another run
        or does not pass validation: a file that is not a step file of this
        run, or a state that is not converged at its load factor,
        :mod:`~skfem_mortar.solver.resume_check`). The resumed run makes the
        same solves as an uninterrupted one from the last checkpointed step on; a finished
        run redoes its last step, so its outputs and metrics come out as they were.
    replace : bool
        Remove the files of the run ``out`` holds before starting (never a file
        that run did not write).
    return_result : bool
        Also return the :class:`Result` and the :class:`Setup`.
    linear : {"direct", "krylov", "auto"}, optional
        How the Newton systems are solved (``NewtonOptions.linear``, in the
        scene's Newton options): a factorization per iteration, or inexact
        Newton with kept factors (:mod:`~skfem_mortar.solver.krylov`).  Default:
        the scene's (``direct``).  The summary's steps count the
        factorizations and Krylov iterations.
    """
    _check_linear(linear)
    if resume and replace:
        raise ValueError("--resume and --replace exclude each other: resume continues the "
                         "run in --out, replace removes it")
    if out is None:
        if resume or replace:
            raise ValueError("--resume and --replace need --out (the run's directory)")
        return _run_scene(name, params, method, steps, None, progress, False, False,
                          return_result, solve_kwargs, linear)
    from ..output.outdir import output_lock

    scene = get_scene(name)  # bad input is refused before --out is made or locked
    scene.resolve(params)
    scene.check_method(method)
    with output_lock(out, "run") as out:
        return _run_scene(name, params, method, steps, out, progress, resume, replace,
                          return_result, solve_kwargs, linear)


def _check_linear(linear: str | None) -> None:
    """ValueError naming ``linear`` and its allowed values (before anything is built)."""
    from ..solver.krylov import LINEAR

    if linear is not None and linear not in LINEAR:
        raise ValueError(f"linear must be one of {', '.join(LINEAR)}, got {linear!r}")


def _newton_with(kwargs: dict, linear: str) -> dict:
    """The solve options with ``NewtonOptions.linear = linear`` (the scene's other
    Newton settings kept)."""
    from dataclasses import replace as _replace

    opts = kwargs.pop("newton_options", None) or kwargs.get("newton") or NewtonOptions()
    return {**kwargs, "newton": _replace(opts, linear=linear)}


def _run_scene(name: str, params: dict[str, Any] | None, method: str | None,
               steps: int | None, out: Path | None, progress: bool, resume: bool,
               replace: bool, return_result: bool, solve_kwargs: dict,
               linear: str | None = None) -> dict | tuple[dict, Result, Setup]:
    """:func:`run_scene` once ``out`` (if any) is locked."""
    t0 = time.perf_counter()
    scene = get_scene(name)
    if steps is not None:
        _check_steps(steps)  # before the scene is built
    setup, values, method = build_scene(name, params, method)
    n_steps = steps if steps is not None else (setup.n_steps or scene.steps(values, method))
    _check_steps(n_steps)
    model = setup.model
    model.timers.clear()
    from ..core.timing import reset
    reset()
    kwargs = {**setup.solve_options, **solve_kwargs}
    if linear is not None:  # the scene's other Newton settings kept
        kwargs = _newton_with(kwargs, linear)
    meta = _clean({"scene": name, "method": method, "parameters": values, "steps": n_steps})
    recorder = _Recorder(out, setup, meta) if out is not None else None
    earlier: list[np.ndarray] = []
    if recorder is not None:
        restart = recorder.restart(kwargs.get("newton") or kwargs.get("newton_options")
                                   ) if resume else None
        if restart is not None:
            earlier = list(recorder.earlier)
            kwargs["restart"] = restart
        recorder.claim(resumed=restart is not None, replace=replace, own=resume)
        recorder.begin(earlier)
        kwargs["callback"] = recorder.step
    try:
        result = solve(model, n_steps, progress=progress, **kwargs)
    except ConvergenceError as exc:
        if recorder is not None:
            recorder.fail(_summary(name, method, values, setup, t0, recorder.records, {},
                                   None, recorder.time, error=str(exc)))
        raise
    if earlier:
        result.states = earlier[:-1] + result.states
    metrics = setup.metrics(result)
    t_out = time.perf_counter()
    if recorder is not None:
        recorder.finish(result, metrics)
    t_out = time.perf_counter() - t_out + (recorder.time if recorder else 0.0)
    summary = _summary(name, method, values, setup, t0, result.steps, metrics,
                       result.solve_time, t_out, converged=bool(result.converged))
    if recorder is not None:
        from ..output.io import write_json
        write_json(out / "summary.json", summary)
    if return_result:
        return summary, result, setup
    return summary


def _summary(name: str, method: str | None, values: dict, setup: Setup, t0: float,
             steps: list[StepRecord], metrics: dict, solve_time: float | None,
             t_out: float, converged: bool = False, error: str | None = None) -> dict:
    """The summary object: ``converged`` true only for a run that finished; a
    failed one adds its ``error`` (its ``steps`` are the converged ones)."""
    from ..core.timing import TIMERS

    model = setup.model
    timers = dict(model.timers)
    summary = {
        "scene": name,
        "method": method,
        "parameters": values,
        "geometry": model.geometry,
        "n_dofs": int(model.n_u),
        "n_multipliers": int(model.n_lam),
        "converged": converged,
        "wall_time_s": time.perf_counter() - t0,
        "phase_times_s": {"bulk": timers.get("bulk", 0.0) + timers.get("loads", 0.0),
                          "contact": timers.get("contact", 0.0),
                          "search": TIMERS.get("search", 0.0),
                          "solve": solve_time, "output": t_out},
        "steps": [_step_entry(s) for s in steps],
        "metrics": metrics,
    }
    if error is not None:
        summary["error"] = error
    return _clean(summary)


class _Recorder(Observer):
    """The observer of a run in ``--out``: one frame per output
    (:class:`~skfem_mortar.solver.observers.SeriesObserver`) and a checkpoint step
    (:class:`~skfem_mortar.solver.observers.CheckpointObserver`) after every converged
    step, plus the bookkeeping of the output directory (claim, resume, the
    summary of a failed run).

    See :mod:`skfem_mortar.output.checkpoint` for the checkpoint layout: a step's file is
    written before the index that lists it, so a kill leaves a valid checkpoint.
    It is started by :meth:`begin` before the solve (a resumed run's frames are
    checked and completed there), so its :meth:`on_start` has nothing to do.
    """

    def __init__(self, out: Path, setup: Setup, meta: dict):
        self.out = out
        self.setup = setup
        self.meta = meta
        self.series = SeriesObserver(out, setup.outputs)
        self.checkpoints = CheckpointObserver(out / "checkpoint", meta,
                                              stateful_items(setup.model))
        self.earlier: list[np.ndarray] = []
        self.lfs: list[float] = [0.0]
        self.time = 0.0
        self.records: list[StepRecord] = []  # the converged steps, resumed ones included

    @property
    def run(self) -> str:
        return self.checkpoints.run

    @property
    def bytes_written(self) -> list[int]:
        """Bytes per checkpoint write."""
        return self.checkpoints.bytes_written

    @property
    def files(self) -> list[str]:
        """The top-level entries this run writes (its manifest lists them)."""
        series = [f for item in self.setup.outputs for f in (f"{item.name}.pvd", item.name)]
        return ["checkpoint", "summary.json", "contact.csv", *series]

    def claim(self, resumed: bool, replace: bool, own: bool) -> None:
        """Make ``out`` this run's: adopt it (resumed from its checkpoint) or claim
        it for a fresh start (``replace``: the old run's files go first; ``own``: a
        resume with nothing to resume from may remove its own run's files)."""
        from ..output.outdir import adopt, claim

        if resumed:
            adopt(self.out, self.meta, self.files)
        else:
            claim(self.out, self.meta, self.files, replace=replace, own=own)

    @property
    def checkpoint(self) -> Path:
        return self.checkpoints.directory

    @property
    def legacy(self) -> Path:
        return self.checkpoints.legacy

    def restart(self, newton: NewtonOptions | None = None) -> Restart | None:
        """The :class:`Restart` of a validated checkpoint of this run (None: none there,
        or nothing to resume). A finished run restarts before its last step, from
        a state that is converged at its load factor (re-checked with the run's
        Newton settings ``newton``, :mod:`~skfem_mortar.solver.resume_check`).

        Raises
        ------
        ValueError
            For a checkpoint of another run or one that fails validation,
            naming the file and what is wrong.
        """
        from ..output.checkpoint import read_checkpoint
        from ..solver.resume_check import check_restart

        model = self.setup.model
        ck = read_checkpoint(self.checkpoint, self.meta, n=model.n,
                             max_bytes=(1 << 20) + MAX_STEP_STATES * 8 * model.n)
        if ck is None:
            if self.legacy.exists():
                raise ValueError(f"resume: {self.legacy} was written by an older version "
                                 "(no step-size controller, no item states); run without "
                                 "--resume")
            return None
        k = len(ck.history)
        r = k - 1 if k and ck.history[-1]["load_factor"] >= 1.0 else k
        if r == 0:
            return None
        history = [StepRecord.from_dict(h) for h in ck.history[:r]]
        source = str(ck.step_path(r))
        try:
            ctl = Controller.from_dict(ck.controllers[r])
        except ValueError as exc:
            raise ValueError(f"checkpoint {source}: {exc}") from None
        lfs = ck.load_factors
        if ctl.lf_prev != lfs[r - 1] or ctl.increment != history[-1].increment:
            raise ValueError(f"checkpoint {source}: controller {ck.controllers[r]} does not "
                             f"fit the step records (load factor before {lfs[r - 1]!r}, "
                             f"increment {history[-1].increment!r})")
        restart = Restart(ck.states[r].copy(), float(lfs[r]), history, ctl,
                          previous=ck.states[r - 1].copy(), items=ck.items[r],
                          source=f"checkpoint {source}")
        check_restart(model, restart, ck.items[r - 1], newton)
        self.checkpoints.run, self.checkpoints.k = ck.run, r + 1
        self.records = list(history)
        self.earlier, self.lfs = list(ck.states[:r + 1]), list(lfs[:r + 1])
        return restart

    def begin(self, earlier: list[np.ndarray]) -> None:
        """Start the outputs: a fresh checkpoint and series, or (resumed) keep the
        frames already written for ``earlier`` and write those that are missing."""
        t0 = time.perf_counter()
        self.series.open()
        if not earlier:
            earlier, self.lfs = [self._initial_state(self.setup.model)], [0.0]
            self.checkpoints.start(earlier[0])
        self.series.resume(self.lfs, earlier)
        self.time += time.perf_counter() - t0

    @staticmethod
    def _initial_state(model) -> np.ndarray:
        z = model.zeros()
        fixed, values = model.prescribed(0.0)
        z[fixed] = values
        return z

    def on_step(self, record: StepRecord, z: np.ndarray) -> None:
        """After a converged step: its frames, then its checkpoint step; then a Ctrl-C
        that Python dropped ends the run (:func:`~.interrupt.check`)."""
        t0 = time.perf_counter()
        self.series.on_step(record, z)
        self.checkpoints.on_step(record, z)
        self.lfs.append(record.load_factor)
        self.records.append(record)
        self.time += time.perf_counter() - t0
        check_interrupt()

    #: the name ``solve(callback=...)`` is given (the runner's one observer)
    step = on_step

    def finish(self, result: Result, metrics: dict) -> None:
        """After the last step: ``contact.csv``, a 3D model's ``figure.png`` (the
        final state by von Mises beside the slave surfaces by pressure,
        :meth:`Result.plot`) and the scene's pictures (listed in the manifest once
        written; ``summary.json`` comes last, from the caller)."""
        from ..output.outdir import add_to_manifest, entries

        if self.setup.contact is not None:
            ContactCsv(self.out / "contact.csv", self.setup.contact).on_end(result)
        before = entries(self.out)
        try:
            if result.model.geometry == "3d":
                self._picture3d(result)
            if self.setup.plots is not None:
                self.setup.plots(metrics, self.out)
        finally:
            add_to_manifest(self.out, sorted(entries(self.out) - before))

    def _picture3d(self, result: Result) -> None:
        """``figure.png`` of a 3D model, or one line on stderr saying why not where VTK
        cannot draw (a bare Linux without a display, EGL or OSMesa)."""
        from ..output.views import can_render

        if can_render():
            result.plot(self.out / "figure.png")
        else:
            print("figure.png not drawn: no display, and neither EGL nor OSMesa for "
                  "off-screen rendering (Debian: apt-get install -y libegl1 "
                  "libgl1-mesa-dri)", file=sys.stderr)

    def fail(self, summary: dict) -> None:
        """A load step did not converge: the summary says so (``converged`` false,
        the converged steps, the error); the frames and checkpoint stay."""
        from ..output.io import write_json

        write_json(self.out / "summary.json", summary)
