"""Load stepping with automatic step cutting.

The load factor goes from ``start`` to 1 in ``n_steps`` equal increments. A step
whose Newton attempt fails (divergence, a non-finite value, an inverted element,
a singular tangent, too many iterations) is retried from the last converged
state with half the increment; after ``easy_steps`` consecutive steps that
converged in at most ``easy_iterations`` iterations the increment grows again
by ``growth`` (never beyond the nominal ``1 / n_steps``). When the increment
falls below ``min_step`` a :class:`ConvergenceError` is raised.
"""
from __future__ import annotations

import logging
import os
import time
from pathlib import Path
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .errors import ConvergenceError
from .model import Model
from .newton import NewtonOptions, NewtonReport
from .newton import newton as newton_step

__all__ = ["StepRecord", "Result", "solve"]

log = logging.getLogger(__name__)


@dataclass
class StepRecord:
    """One converged load step."""

    load_factor: float
    newton_iterations: int
    residual_norms: list[float]
    n_active: int = 0
    active_set_changes: int = 0
    cuts: int = 0
    increment: float = 0.0
    info: dict = field(default_factory=dict)

    @classmethod
    def from_dict(cls, d: dict) -> "StepRecord":
        return cls(d["load_factor"], d["newton_iterations"], list(d["residual_norms"]),
                   d.get("n_active", 0), d.get("active_set_changes", 0), d.get("cuts", 0),
                   d.get("increment", 0.0))

    def as_dict(self) -> dict:
        return {"load_factor": float(self.load_factor),
                "newton_iterations": int(self.newton_iterations),
                "residual_norms": [float(r) for r in self.residual_norms],
                "n_active": int(self.n_active),
                "active_set_changes": int(self.active_set_changes),
                "cuts": int(self.cuts),
                "increment": float(self.increment)}


@dataclass
class Result:
    """Everything a solve produced.

    Attributes
    ----------
    model : Model
    steps : list of StepRecord
        Converged steps, in order.
    states : list of ndarray
        ``states[0]`` the initial unknowns, ``states[k]`` after step ``k``
        (for a resumed run: the states from the restart on, unless the caller
        puts the earlier ones back).
    converged : bool
    solve_time : float
        Time spent in linear solves (s).
    """

    model: Model
    steps: list[StepRecord] = field(default_factory=list)
    states: list[np.ndarray] = field(default_factory=list)
    converged: bool = False
    solve_time: float = 0.0
    wall_time: float = 0.0

    @property
    def z(self) -> np.ndarray:
        return self.states[-1]

    @property
    def load_factors(self) -> np.ndarray:
        return np.array([0.0] + [s.load_factor for s in self.steps])

    def outputs(self) -> list:
        """What can be written or drawn: the bodies, and the slave surface of each
        contact pair (pressure and gap)."""
        from .contact_output import ContactOutput

        outs = [it for it in self.model.items if hasattr(it, "output_mesh")]
        outs += [ContactOutput(it) for it in self.model.items if hasattr(it, "contact_data")]
        return outs

    def fields(self, k: int = -1) -> dict[str, tuple[dict, dict]]:
        """Per output (by name): ``(point_data, cell_data)`` at state ``k``."""
        return {o.name: o.output_data(self.states[k]) for o in self.outputs()}

    def save(self, out: str | os.PathLike) -> Path:
        """Write one PVD/VTU series per output, one frame per state, into ``out``;
        for a contact model also ``contact.csv`` (final state) of the first pair."""
        from .io import SeriesWriter, write_contact_csv

        out = Path(out)
        for o in self.outputs():
            writer = SeriesWriter(out, o.name, o.output_mesh())
            for lf, z in zip(self.load_factors, self.states):
                writer.write(lf, *o.output_data(z))
        pairs = [it for it in self.model.items if hasattr(it, "contact_data")]
        if pairs:
            write_contact_csv(out / "contact.csv", pairs[0].contact_data(self.z))
        return out

    def plot(self, path: str | os.PathLike, title: str = "") -> Path:
        """The initial and the final configuration side by side, as a PNG
        (see :func:`skfem_mortar.plot.figure`)."""
        from types import SimpleNamespace

        from .plot import figure

        pairs = [it for it in self.model.items if hasattr(it, "contact_data")]
        view = SimpleNamespace(outputs=[it for it in self.model.items
                                        if hasattr(it, "output_mesh")],
                               contact=pairs[0].contact_data if pairs else None)
        return figure(view, self, path, title=title)

    def residual(self, k: int = -1) -> np.ndarray:
        """Global residual at state ``k`` (reactions at prescribed dofs)."""
        lf = self.load_factors[k]
        R, _, _ = self.model.assemble(self.states[k], lf, tangent=False)
        return R


def _validate(n_steps: int, min_step: float, start: float) -> None:
    if not (isinstance(n_steps, (int, np.integer)) and n_steps >= 1):
        raise ValueError(f"n_steps must be an integer >= 1, got {n_steps!r}")
    if not (0.0 < min_step <= 1.0):
        raise ValueError(f"min_step must lie in (0, 1], got {min_step!r}")
    if not (0.0 <= start < 1.0):
        raise ValueError(f"start must lie in [0, 1), got {start!r}")


def solve(model: Model, n_steps: int = 1, *, newton_options: NewtonOptions | None = None,
          newton: NewtonOptions | None = None, min_step: float = 1e-4,
          growth: float = 2.0, easy_iterations: int = 4, easy_steps: int = 2,
          z0: np.ndarray | None = None, start: float = 0.0, progress: bool = False,
          callback: Callable[[StepRecord, np.ndarray], None] | None = None,
          history: list[StepRecord] | None = None,
          increment: float | None = None, extrapolate: bool = False) -> Result:
    """Solve the model from load factor ``start`` to 1.

    Parameters
    ----------
    model : Model
    n_steps : int
        Nominal number of equal load increments (>= 1).
    newton_options, newton : NewtonOptions
        Newton settings (either name works).
    min_step : float
        Smallest load increment allowed by step cutting, in (0, 1].
    growth : float
        Factor by which the increment grows back after easy steps.
    z0 : ndarray, optional
        Initial unknowns (default zeros), e.g. a checkpoint to resume from.
    start : float
        Load factor of ``z0``.
    history : list of StepRecord, optional
        Steps already done before ``z0`` (a resumed run keeps them in the result).
    increment : float, optional
        First load increment (a resumed run continues with the one in force).
    extrapolate : bool
        Start each step from the linear extrapolation of the last two converged
        states instead of the last one.
    progress : bool
        Show a tqdm progress bar on stderr.
    callback : callable(StepRecord, z)
        Called after each converged step (output, checkpoints).

    Raises
    ------
    ConvergenceError
        When a step cannot converge even at ``min_step``.
    """
    _validate(n_steps, min_step, start)
    opts = newton_options or newton or NewtonOptions()
    t_start = time.perf_counter()
    z = model.zeros() if z0 is None else np.array(z0, dtype=float)
    if z.shape != (model.n,):
        raise ValueError(f"z0 must have shape ({model.n},), got {z.shape}")
    fixed, values = model.prescribed(start)
    z[fixed] = values
    model.preflight(z, start, fixed)  # refuse what cannot work before the first step
    result = Result(model, steps=list(history or []), states=[z.copy()])
    nominal = 1.0 / n_steps
    lf, dlf = start, (increment or nominal)
    lf_prev = start
    n_easy, cuts, step_no = 0, 0, len(result.steps) + 1
    bar = _progress_bar(progress)
    try:
        while lf < 1.0 - 1e-14:
            target = min(lf + dlf, 1.0)
            if 1.0 - target < 1e-12:
                target = 1.0
            fixed, values = model.prescribed(target)
            free = np.setdiff1d(np.arange(model.n), fixed, assume_unique=True)
            trial = z.copy()
            if extrapolate and len(result.states) >= 2 and lf > lf_prev:
                # linear predictor along the last increment (free unknowns only;
                # the prescribed ones follow the consistent predictor of newton)
                scale = (target - lf) / (lf - lf_prev)
                step_dir = z - result.states[-2]
                trial[free] += scale * step_dir[free]
            dz_fixed = values - trial[fixed]
            for item in model.items:
                if hasattr(item, "set_fixed"):  # e.g. contact pairs drop pinned slave nodes
                    item.set_fixed(fixed)
                item.begin_step(trial, target)
            rep: NewtonReport = newton_step(model, trial, target, free, fixed, dz_fixed, opts,
                                            start=(z, lf))
            result.solve_time += rep.solve_time
            if rep.converged:
                z = trial
                for item in model.items:
                    item.end_step(z, target)
                info: dict = {}
                for item in model.items:
                    for k, v in item.step_info().items():
                        info[k] = info.get(k, 0) + v
                rec = StepRecord(target, rep.iterations, rep.residual_norms,
                                 int(info.get("n_active", 0)),
                                 int(info.get("active_set_changes", 0)), cuts, 0.0, info)
                result.steps.append(rec)
                result.states.append(z.copy())
                lf_prev, lf = lf, target
                step_no += 1
                cuts = 0
                n_easy = n_easy + 1 if rep.iterations <= easy_iterations else 0
                if n_easy >= easy_steps and dlf < nominal:
                    dlf = min(nominal, dlf * growth)
                    n_easy = 0
                rec.increment = dlf
                if bar is not None:
                    bar.update(1)
                    bar.set_postfix_str(f"lf={lf:.3g} it={rep.iterations} "
                                        f"active={rec.n_active} "
                                        f"r={rep.residual_norms[-1]:.1e}")
                if callback is not None:
                    callback(rec, z)
                continue
            # failed attempt: cut the increment and retry from the last converged state
            log.info("step %d to load factor %.6g failed (%s); cutting the step",
                     step_no, target, rep.reason)
            dlf *= 0.5
            cuts += 1
            n_easy = 0
            if dlf < min_step * (1.0 - 1e-12):
                hints = [h for h in (getattr(it, "failure_hint", lambda: "")()
                                     for it in model.items) if h]
                reason = "; ".join([rep.reason] + hints)
                raise ConvergenceError(step_no, target, rep.iterations,
                                       rep.residual_norms, reason)
    finally:
        if bar is not None:
            bar.close()
    result.converged = True
    result.wall_time = time.perf_counter() - t_start
    return result


def _progress_bar(enabled: bool):
    if not enabled:
        return None
    from tqdm.auto import tqdm  # imported lazily: the command line starts fast

    return tqdm(desc="load steps", unit="step", leave=False)
