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
              progress: bool = False, return_result: bool = False, **solve_kwargs
              ) -> dict | tuple[dict, Result, Setup]:
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
        Directory for the result series, ``summary.json`` and ``contact.csv``.
    return_result : bool
        Also return the :class:`Result` and the :class:`Setup`.
    """
    t0 = time.perf_counter()
    scene = get_scene(name)
    setup, values, method = build_scene(name, params, method)
    n_steps = steps if steps is not None else (setup.n_steps or scene.default_steps)
    model = setup.model
    model.timers.clear()
    kwargs = {**setup.solve_options, **solve_kwargs}
    result = solve(model, n_steps, progress=progress, **kwargs)
    metrics = setup.metrics(result)
    t_out = time.perf_counter()
    if out is not None:
        write_outputs(Path(out), setup, result)
    t_out = time.perf_counter() - t_out
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


def write_outputs(out: Path, setup: Setup, result: Result) -> None:
    """Result series per output item and, for contact scenes, contact.csv."""
    from .io import write_contact_csv, write_series

    out.mkdir(parents=True, exist_ok=True)
    lfs = result.load_factors
    for item in setup.outputs:
        mesh = item.output_mesh()
        frames = []
        for lf, z in zip(lfs, result.states):
            pdata, cdata = item.output_data(z)
            frames.append((lf, pdata, cdata))
        write_series(out / f"{item.name}.xdmf", mesh, frames)
    if setup.contact is not None:
        write_contact_csv(out / "contact.csv", setup.contact(result.z))
