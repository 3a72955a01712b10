"""Run a scene end to end: build, solve, measure, write. Used by the CLI and tests."""
from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from .scenes import Setup, get_scene
from .stepping import Result, solve

__all__ = ["build_scene", "run_scene"]


def build_scene(name: str, params: dict[str, Any] | None = None,
                method: str | None = None) -> tuple[Setup, dict[str, Any], str | None]:
    """Validate ``params`` and ``method`` and build the scene's setup."""
    scene = get_scene(name)
    values = scene.resolve(params)
    method = scene.check_method(method)
    return scene.build(values, method), values, method


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


def run_scene(name: str, params: dict[str, Any] | None = None, method: str | None = None,
              steps: int | None = None, out: str | Path | None = None,
              progress: bool = False, resume: bool = False, return_result: bool = False,
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
        ``checkpoint.npz`` (rewritten after every converged step).
    resume : bool
        Continue from ``out/checkpoint.npz`` if it belongs to the same scene,
        method, parameters and steps (ValueError if it belongs to another run).
    return_result : bool
        Also return the :class:`Result` and the :class:`Setup`.
    """
    t0 = time.perf_counter()
    scene = get_scene(name)
    setup, values, method = build_scene(name, params, method)
    n_steps = steps if steps is not None else (setup.n_steps or scene.default_steps)
    if not (isinstance(n_steps, int) and n_steps >= 1):
        raise ValueError(f"steps must be an integer >= 1, got {n_steps!r}")
    model = setup.model
    model.timers.clear()
    from .timing import TIMERS, reset
    reset()
    kwargs = {**setup.solve_options, **solve_kwargs}
    meta = _clean({"scene": name, "method": method, "parameters": values, "steps": n_steps})
    recorder = _Recorder(Path(out), setup, meta) if out is not None else None
    earlier: list[np.ndarray] = []
    if recorder is not None and resume:
        restart = recorder.restart()
        if restart is not None:
            earlier, history = restart
            kwargs.update(z0=earlier[-1], start=history[-1].load_factor, history=history,
                          increment=history[-1].increment or None)
    if recorder is not None:
        recorder.begin(earlier)
        kwargs["callback"] = recorder.step
    if kwargs.get("start", 0.0) >= 1.0 - 1e-14:  # the checkpoint is already final
        result = Result(model, steps=kwargs["history"], states=[kwargs["z0"]],
                        converged=True)
    else:
        result = solve(model, n_steps, progress=progress, **kwargs)
    if earlier:
        result.states = earlier[:-1] + result.states
    metrics = setup.metrics(result)
    t_out = time.perf_counter()
    if recorder is not None:
        recorder.finish(result)
        if setup.plots is not None:
            setup.plots(metrics, Path(out))
    t_out = time.perf_counter() - t_out + (recorder.time if recorder else 0.0)
    timers = dict(model.timers)
    summary = {
        "scene": name,
        "method": method,
        "parameters": values,
        "n_dofs": int(model.n_u),
        "n_multipliers": int(model.n_lam),
        "converged": bool(result.converged),
        "wall_time_s": time.perf_counter() - t0,
        "phase_times_s": {"bulk": timers.get("bulk", 0.0) + timers.get("loads", 0.0),
                          "contact": timers.get("contact", 0.0),
                          "search": TIMERS.get("search", 0.0),
                          "solve": result.solve_time, "output": t_out},
        "steps": [s.as_dict() for s in result.steps],
        "metrics": metrics,
    }
    summary = _clean(summary)
    if out is not None:
        from .io import write_json
        write_json(Path(out) / "summary.json", summary)
    if return_result:
        return summary, result, setup
    return summary


class _Recorder:
    """Writes one frame per output item and a checkpoint after every converged step."""

    def __init__(self, out: Path, setup: Setup, meta: dict):
        self.out = out
        self.setup = setup
        self.meta = meta
        self.states: list[np.ndarray] = []
        self.history: list[dict] = []
        self.writers: list = []
        self.time = 0.0

    @property
    def checkpoint(self) -> Path:
        return self.out / "checkpoint.npz"

    def restart(self):
        from .io import read_checkpoint
        from .stepping import StepRecord

        if not self.checkpoint.exists():
            return None
        meta, states, history = read_checkpoint(self.checkpoint)
        if meta != self.meta:
            raise ValueError(f"resume: {self.checkpoint} belongs to another run "
                             f"({meta}); use another --out or drop --resume")
        if not history:
            return None
        self.history = history
        return list(states), [StepRecord.from_dict(h) for h in history]

    def begin(self, earlier: list[np.ndarray]) -> None:
        from .io import SeriesWriter

        t0 = time.perf_counter()
        self.out.mkdir(parents=True, exist_ok=True)
        model = self.setup.model
        self.writers = [SeriesWriter(self.out, item.name, item.output_mesh())
                        for item in self.setup.outputs]
        self.states = list(earlier) or [self._initial_state(model)]
        lfs = [0.0] + [h["load_factor"] for h in self.history]
        for lf, z in zip(lfs, self.states):  # (re)write the frames done so far
            self._frame(lf, z)
        self.time += time.perf_counter() - t0

    @staticmethod
    def _initial_state(model) -> np.ndarray:
        z = model.zeros()
        fixed, values = model.prescribed(0.0)
        z[fixed] = values
        return z

    def _frame(self, lf: float, z: np.ndarray) -> None:
        for item, writer in zip(self.setup.outputs, self.writers):
            pdata, cdata = item.output_data(z)
            writer.write(lf, pdata, cdata)

    def step(self, record, z: np.ndarray) -> None:
        from .io import write_checkpoint

        t0 = time.perf_counter()
        self._frame(record.load_factor, z)
        self.states.append(z.copy())
        self.history.append(record.as_dict())
        write_checkpoint(self.checkpoint, self.meta, np.array(self.states), self.history)
        self.time += time.perf_counter() - t0

    def finish(self, result: Result) -> None:
        from .io import write_contact_csv

        if self.setup.contact is not None:
            write_contact_csv(self.out / "contact.csv", self.setup.contact(result.z))
