"""Load stepping with automatic step cutting.

The load factor goes from ``start`` to 1 in ``n_steps`` equal increments. A step
whose Newton attempt fails (divergence, a non-finite value, an inverted element,
a singular tangent, too many iterations) is retried from the last converged
state with half the increment; after ``easy_steps`` consecutive steps that
converged in at most ``easy_iterations`` iterations the increment grows again
by ``growth`` (never beyond the nominal ``1 / n_steps``). When the increment
falls below ``min_step`` a :class:`ConvergenceError` is raised.  Under a force
or pressure load each converged step records Bergan's current stiffness
parameter (``StepRecord.info["stiffness_parameter"]``), and a failed step at a
limit point stops after at most two cuts with a
:class:`~skfem_mortar.solver.limit_point.LimitPointError` (:mod:`.limit_point`).

The increment in force and its counters are a :class:`Controller`; a
:class:`Restart` (the last converged state, the steps so far, the controller and
every item's :meth:`~skfem_mortar.core.item.Item.state_dict`) continues a run
exactly where a checkpoint left it.
"""
from __future__ import annotations

import logging
import os
import time
from pathlib import Path
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Sequence

import numpy as np

from ..contact import preflight as _preflight  # noqa: F401 (registers its checks: solve runs them)
from ..core.errors import ConvergenceError, warn_at_user
from ..core.item import Item, Output
from ..core.model import Model
from .pardiso import forget_analyses
from .states import MODEL_STATE, restore_items, stateful_items  # noqa: F401 (offered here too)
from .newton import NewtonOptions, NewtonReport
from .newton import newton as newton_step
from .observers import Callback, ContactCsv, Observer, ProgressBar, SeriesObserver, replay
from .diagnosis import failure_causes, round_off_above_load
from .limit_point import LimitWatch
# MAX_STEPS: a name of this module before the checks moved
from .arguments import MAX_STEPS, check_z0, validate as _validate  # noqa: F401

__all__ = ["Controller", "Restart", "StepRecord", "Result", "solve"]

log = logging.getLogger(__name__)


@dataclass
class Controller:
    """The step-size controller between two load steps: all it needs to go on.

    Attributes
    ----------
    increment : float
        Load increment of the next step, in (0, 1].
    n_easy : int
        Consecutive easy steps since the increment last changed.
    cuts : int
        Failed attempts since the last converged step.
    lf_prev : float
        Load factor of the converged step before the last one (the base of
        the ``extrapolate`` predictor), in [0, 1).
    """

    increment: float
    n_easy: int = 0
    cuts: int = 0
    lf_prev: float = 0.0

    def as_dict(self) -> dict:
        return {"increment": float(self.increment), "n_easy": int(self.n_easy),
                "cuts": int(self.cuts), "lf_prev": float(self.lf_prev)}

    @classmethod
    def from_dict(cls, d: dict) -> "Controller":
        """The controller of :meth:`as_dict` (ValueError naming a missing or bad entry)."""
        if not isinstance(d, dict) or set(d) != {"increment", "n_easy", "cuts", "lf_prev"}:
            raise ValueError(f"controller must have the entries increment, n_easy, cuts, "
                             f"lf_prev, got {d!r}")
        for k in ("n_easy", "cuts"):
            if not (isinstance(d[k], int) and not isinstance(d[k], bool) and d[k] >= 0):
                raise ValueError(f"controller {k} must be an integer >= 0, got {d[k]!r}")
        for k in ("increment", "lf_prev"):
            if not (isinstance(d[k], (int, float)) and np.isfinite(d[k])):
                raise ValueError(f"controller {k} must be a finite number, got {d[k]!r}")
        if not 0.0 < d["increment"] <= 1.0:
            raise ValueError(f"controller increment must lie in (0, 1], got {d['increment']!r}")
        if not 0.0 <= d["lf_prev"] < 1.0:
            raise ValueError(f"controller lf_prev must lie in [0, 1), got {d['lf_prev']!r}")
        return cls(float(d["increment"]), d["n_easy"], d["cuts"], float(d["lf_prev"]))


@dataclass
class Restart:
    """Where a resumed solve starts: a checkpoint's last converged step.

    Attributes
    ----------
    z : ndarray
        The converged unknowns.
    load_factor : float
        Their load factor, in (0, 1).
    history : list of StepRecord
        The steps done up to ``z`` (kept in the result).
    controller : Controller
        The step-size controller after the last step.
    previous : ndarray or None
        The converged unknowns before ``z`` (the ``extrapolate`` predictor).
    items : dict
        ``{item name: item.state_dict()}`` after the last step, for every
        item whose state is not empty.
    source : str
        Where it was read from (named in error messages).
    """

    z: np.ndarray
    load_factor: float
    history: list["StepRecord"]
    controller: Controller
    previous: np.ndarray | None = None
    items: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    source: str = "restart"


@dataclass
class StepRecord:
    """One converged load step (``controller``: the step-size controller after
    it, not part of :meth:`as_dict`)."""

    load_factor: float
    newton_iterations: int
    residual_norms: list[float]
    n_active: int = 0
    active_set_changes: int = 0
    cuts: int = 0
    increment: float = 0.0
    info: dict = field(default_factory=dict)
    controller: Controller | None = None
    #: the linear solves of the converged attempt: fresh factorizations and
    #: Krylov iterations (``NewtonOptions.linear="krylov"``; 0 for "direct")
    factorizations: int = 0
    krylov_iterations: int = 0

    @classmethod
    def from_dict(cls, d: dict) -> "StepRecord":
        return cls(d["load_factor"], d["newton_iterations"], list(d["residual_norms"]),
                   d.get("n_active", 0), d.get("active_set_changes", 0), d.get("cuts", 0),
                   d.get("increment", 0.0), factorizations=d.get("factorizations", 0),
                   krylov_iterations=d.get("krylov_iterations", 0))

    def as_dict(self) -> dict:
        return {"load_factor": float(self.load_factor),
                "newton_iterations": int(self.newton_iterations),
                "residual_norms": [float(r) for r in self.residual_norms],
                "n_active": int(self.n_active),
                "active_set_changes": int(self.active_set_changes),
                "cuts": int(self.cuts),
                "increment": float(self.increment),
                "factorizations": int(self.factorizations),
                "krylov_iterations": int(self.krylov_iterations)}


@dataclass
class Result:
    """Everything a solve produced: data only (the states and the step records).

    Writing and drawing go through the output layer: :meth:`save` replays the
    result to the observers of :mod:`skfem_mortar.solver.observers`, :meth:`plot`
    calls :func:`skfem_mortar.output.plot.draw`; both import it when called.

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

    def outputs(self) -> list[Output]:
        """What can be written or drawn: the bodies, then the slave surface of each
        contact pair (pressure and gap), by the items' :meth:`~skfem_mortar.core.item.Item.outputs`."""
        outs = self.model.outputs()
        return ([o for o in outs if isinstance(o, Item)]
                + [o for o in outs if not isinstance(o, Item)])

    def fields(self, k: int = -1) -> dict[str, tuple[dict, dict]]:
        """Per output (by name): ``(point_data, cell_data)`` at state ``k``."""
        return {o.name: o.output_data(self.states[k]) for o in self.outputs()}

    def save(self, out: str | os.PathLike) -> Path:
        """Write one PVD/VTU series per output, one frame per state, into ``out``;
        for a contact model also ``contact.csv`` (final state) of the first pair."""
        out = Path(out)
        tables = self.model.contact_tables()
        observers: list[Observer] = [SeriesObserver(out, self.outputs())]
        if tables:
            observers.append(ContactCsv(out / "contact.csv", tables[0]))
        replay(self, observers)
        return out

    def plot(self, path: str | os.PathLike, title: str = "", revolved: bool = False, *,
             cut: Any = None) -> Path:
        """The initial and the final configuration side by side, as a PNG, with
        every contact pair's pressure and the model's supports and loads
        (see :func:`skfem_mortar.output.plot.draw`); ``revolved`` (an axisymmetric
        model): the final state revolved into 3D, a quarter cut away
        (:func:`skfem_mortar.output.views.render_revolved`).  A 3D model is
        rendered by pyvista off screen (:func:`skfem_mortar.output.render3d.render3d`:
        the final state coloured by von Mises over the undeformed outline,
        supports and loads marked; ``cut`` a clipping plane, "x", "y", "z" or
        ``(normal, origin)``).  A notebook shows the PNG inline either way."""
        bodies = [it for it in self.model.items if isinstance(it, Output)]
        lf = float(self.load_factors[-1])
        if self.model.geometry == "3d":
            from ..output.render3d import render3d

            return render3d(bodies, self.states[0], self.z, path, items=self.model.items,
                            load_factor=lf, cut=cut, title=title)
        if cut is not None:
            raise ValueError(f"cut is for 3D models (a clipping plane), got {cut!r} for a "
                             f"{self.model.geometry} model")
        if revolved:
            from ..output.views import render_revolved

            return render_revolved(self, path)
        from ..output.plot import draw

        return draw(bodies, self.states[0], self.z, path, title=title,
                    contact=self.model.contact_tables(), items=self.model.items,
                    load_factor=lf)

    def residual(self, k: int = -1) -> np.ndarray:
        """Global residual at state ``k`` (reactions at prescribed dofs)."""
        lf = self.load_factors[k]
        R, _, _ = self.model.assemble(self.states[k], lf, tangent=False)
        return R

    #: the steps the HTML table lists at each end of a longer result
    HTML_ROWS = 10

    def _headline(self) -> str:
        """``converged, 10 steps, 52 Newton iterations, load factor 1, ...``."""
        its = sum(s.newton_iterations for s in self.steps)
        cuts = sum(s.cuts for s in self.steps)
        lf = self.steps[-1].load_factor if self.steps else 0.0
        return (f"{'converged' if self.converged else 'not converged'}, {len(self.steps)} steps, "
                f"{its} Newton iterations{f', {cuts} cuts' if cuts else ''}, load factor {lf:.12g}, "
                f"{self.model.n} unknowns, {self.wall_time:.3g} s")

    def __repr__(self) -> str:
        """One line (the states and records stay out of it): :meth:`_headline`."""
        return f"Result({self._headline()})"

    def _repr_html_(self) -> str:
        """The headline and a table of the steps (load factor, Newton iterations,
        final residual, active nodes, active-set changes, cuts); a result of more
        than ``2 HTML_ROWS`` steps lists the first and the last ``HTML_ROWS``."""
        from html import escape

        head = ("step", "load factor", "Newton iterations", "final residual",
                "active nodes", "active-set changes", "cuts")
        rows = [(k + 1, f"{s.load_factor:.12g}", s.newton_iterations,
                 f"{s.residual_norms[-1]:.2e}" if s.residual_norms else "",
                 s.n_active, s.active_set_changes, s.cuts) for k, s in enumerate(self.steps)]
        n = self.HTML_ROWS
        if len(rows) > 2 * n:
            rows = rows[:n] + [("\u2026",) * len(head)] + rows[-n:]
        cell = "".join
        body = cell(f"<tr>{cell(f'<td>{escape(str(v))}</td>' for v in r)}</tr>" for r in rows)
        return (f"<div><p><b>Result</b>: {escape(self._headline())}; linear solves "
                f"{self.solve_time:.3g} s</p><table><thead><tr>"
                f"{cell(f'<th>{h}</th>' for h in head)}</tr></thead><tbody>{body}</tbody>"
                f"</table></div>")


def solve(model: Model, n_steps: int = 1, *, newton_options: NewtonOptions | None = None,
          newton: NewtonOptions | None = None, min_step: float = 1e-4,
          growth: float = 2.0, easy_iterations: int = 4, easy_steps: int = 2,
          z0: np.ndarray | None = None, start: float = 0.0, progress: bool = False,
          callback: Callable[[StepRecord, np.ndarray], None] | None = None,
          history: list[StepRecord] | None = None,
          increment: float | None = None, extrapolate: bool = False,
          restart: Restart | None = None,
          observers: Sequence[Observer] = ()) -> Result:
    """Solve the model from load factor ``start`` to 1.

    Parameters
    ----------
    model : Model
    n_steps : int
        Nominal number of equal load increments (>= 1).
    newton : NewtonOptions
        Newton settings.
    newton_options : NewtonOptions
        Deprecated name of ``newton`` (a DeprecationWarning; it still works).

    The step-size controller:

    min_step : float
        Smallest load increment allowed by step cutting, in (0, 1].
    growth : float
        Factor by which the increment grows back after easy steps.
    easy_iterations, easy_steps : int
        A step converged in at most ``easy_iterations`` iterations is easy;
        after ``easy_steps`` easy steps in a row the increment grows.
    increment : float, optional
        First load increment (default ``1 / n_steps``).
    extrapolate : bool
        Start each step from the linear extrapolation of the last two converged
        states instead of the last one.

    Where the solve starts (either ``restart`` or ``z0``, ``start``, ``history``,
    ``increment``):

    z0 : ndarray, optional
        Initial unknowns (default zeros).
    start : float
        Load factor of ``z0``.
    history : list of StepRecord, optional
        Steps already done before ``z0`` (kept in the result).
    restart : Restart, optional
        Continue a checkpointed run exactly: its state, steps, step-size
        controller and item states (instead of ``z0``, ``start``, ``history``
        and ``increment``). The steps that follow are the same solves as those
        of the uninterrupted run.
    What is done with the states as they come (:mod:`skfem_mortar.solver.observers`):

    observers : sequence of Observer
        Told ``on_start(model, z, load_factor)`` once the preflight has passed,
        ``on_step(record, z)`` after each converged step and ``on_end(result)``
        when the solve returns or raises, in the order given (after the
        progress bar and before the callback).
    progress : bool
        Show a tqdm progress bar on stderr (a :class:`~skfem_mortar.solver.observers.ProgressBar`).
    callback : callable(StepRecord, z)
        Called after each converged step (a :class:`~skfem_mortar.solver.observers.Callback`);
        the record's ``controller`` holds the step-size controller after the step.

    Raises
    ------
    ConvergenceError
        When a step cannot converge even at ``min_step``.
    ValueError
        Bad arguments, or a ``restart`` that does not fit the model (naming
        its ``source``).
    """
    if restart is not None:
        if z0 is not None or start or history or increment:
            raise ValueError("give either restart or z0, start, history, increment")
        z0, start, history = restart.z, restart.load_factor, restart.history
    _validate(n_steps, min_step, start, growth, easy_iterations, easy_steps, increment)
    if newton_options is not None:
        warn_at_user("solve(newton_options=...) is deprecated, use solve(newton=...)",
                     DeprecationWarning)
    opts = newton_options or newton or NewtonOptions()
    watchers = _observers(observers, progress, callback)
    t_start = time.perf_counter()
    z = model.zeros() if z0 is None else check_z0(z0, model.n,
                                                  "z0" if restart is None else "restart.z")
    fixed, values = model.prescribed(start)
    z[fixed] = values
    nominal = 1.0 / n_steps
    if restart is None:
        ctl, z_prev = Controller(increment or nominal, lf_prev=start), None
    else:
        restore_items(model, restart.items, restart.source)
        ctl, z_prev = replace(restart.controller), restart.previous
    # refuse what cannot work before the first step (a resumed run: with its
    # items' states restored, e.g. the converged active set)
    model.preflight(z, start, fixed)
    result = Result(model, steps=list(history or []), states=[z.copy()])
    watch = LimitWatch(model)   # a limit point under load control (.limit_point)
    lf = start
    step_no = len(result.steps) + 1
    started: list[Observer] = []
    try:
        for o in watchers:
            started.append(o)
            o.on_start(model, z, start)
        while lf < 1.0 - 1e-14:
            target = min(lf + ctl.increment, 1.0)
            if 1.0 - target < 1e-12:
                target = 1.0
            predictor = z_prev if extrapolate and lf > ctl.lf_prev else None
            trial, rep = _attempt(model, z, lf, target, opts, predictor, ctl.lf_prev)
            result.solve_time += rep.solve_time
            if rep.converged:  # a residual above the load is no answer, at any increment
                rep.reason = round_off_above_load(model, trial, target, rep)
                if rep.reason:
                    _give_up(model, step_no, target, rep, (z, lf))
            if rep.converged:
                z_prev, z = z, trial
                rec = _converged(model, z, target, rep, ctl)
                s_p = watch.converged(z, target)
                if s_p is not None:
                    rec.info["stiffness_parameter"] = s_p
                ctl.lf_prev, lf = lf, target
                _grow(ctl, rep.iterations, nominal, growth, easy_iterations, easy_steps)
                rec.increment, rec.controller = ctl.increment, replace(ctl)
                result.steps.append(rec)
                result.states.append(z.copy())
                step_no += 1
                for o in watchers:
                    o.on_step(rec, z)
                continue
            # failed attempt: cut the increment and retry from the last converged state
            log.info("step %d to load factor %.6g failed (%s); cutting the step",
                     step_no, target, rep.reason)
            watch.failed(step_no, target, rep.iterations, rep.residual_norms)
            ctl.increment *= 0.5
            ctl.cuts += 1
            ctl.n_easy = 0
            if ctl.increment < min_step * (1.0 - 1e-12):
                _give_up(model, step_no, target, rep, (z, lf))
        result.converged = True
        result.wall_time = time.perf_counter() - t_start
    finally:
        for o in started:
            o.on_end(result)
    return result


def _attempt(model: Model, z: np.ndarray, lf: float, target: float, opts: NewtonOptions,
             z_prev: np.ndarray | None, lf_prev: float) -> tuple[np.ndarray, NewtonReport]:
    """One Newton solve from the converged ``z`` at ``lf`` to the load factor
    ``target``: the prescribed values of ``target``, the items' step hooks, and
    with ``z_prev`` (the state at ``lf_prev``) the linear predictor
    ``z + (target - lf) / (lf - lf_prev) (z - z_prev)`` on the free unknowns (the
    prescribed ones follow the consistent predictor of newton).  Returns the
    trial state (converged or not) and Newton's report."""
    fixed, values = model.prescribed(target)
    free = np.setdiff1d(np.arange(model.n), fixed, assume_unique=True)
    trial = z.copy()
    if z_prev is not None:
        scale = (target - lf) / (lf - lf_prev)
        trial[free] += scale * (z - z_prev)[free]
    dz_fixed = values - trial[fixed]
    for item in model.items:
        item.set_fixed(fixed)  # e.g. contact pairs drop pinned slave nodes
        item.begin_step(trial, target)
    forget_analyses()  # the step's solves depend on the step alone (resume to the bit)
    rep = newton_step(model, trial, target, free, fixed, dz_fixed, opts, start=(z, lf))
    return trial, rep


def _observers(observers: Sequence[Observer], progress: bool,
               callback: Callable[[StepRecord, np.ndarray], None] | None) -> list[Observer]:
    """The observers of a solve: the progress bar, the given ones, the callback."""
    observers = list(observers)
    for k, o in enumerate(observers):
        if not isinstance(o, Observer):
            raise ValueError(f"observers[{k}] must be an Observer (skfem_mortar.solver.observers), "
                             f"got {type(o).__name__}")
    return (([ProgressBar()] if progress else []) + observers
            + ([Callback(callback)] if callback is not None else []))


def _converged(model: Model, z: np.ndarray, target: float, rep: NewtonReport,
               ctl: Controller) -> StepRecord:
    """Close a converged step: the items' ``end_step`` and the step's record."""
    for item in model.items:
        item.end_step(z, target)
    info: dict = {}
    for item in model.items:
        for k, v in item.step_info().items():
            info[k] = info.get(k, 0) + v
    rec = StepRecord(target, rep.iterations, rep.residual_norms,
                     int(info.get("n_active", 0)),
                     int(info.get("active_set_changes", 0)), ctl.cuts, 0.0, info,
                     factorizations=rep.factorizations, krylov_iterations=rep.krylov_iterations)
    ctl.cuts = 0
    return rec


def _grow(ctl: Controller, iterations: int, nominal: float, growth: float,
          easy_iterations: int, easy_steps: int) -> None:
    """Count an easy step; after ``easy_steps`` of them grow the increment."""
    ctl.n_easy = ctl.n_easy + 1 if iterations <= easy_iterations else 0
    if ctl.n_easy >= easy_steps and ctl.increment < nominal:
        ctl.increment = min(nominal, ctl.increment * growth)
        ctl.n_easy = 0


def _give_up(model: Model, step_no: int, target: float, rep: NewtonReport,
             last: tuple[np.ndarray, float]) -> None:
    """Raise the step's ConvergenceError: Newton's reason, then the physical causes
    the last converged state ``last = (z, load factor)`` and the target load
    show (:func:`~skfem_mortar.solver.diagnosis.failure_causes`), then the items'
    failure hints."""
    causes = failure_causes(model, last[0], last[1], target)
    hints = [h for h in (it.failure_hint() for it in model.items) if h]
    reason = "; ".join([rep.reason] + causes + hints)
    raise ConvergenceError(step_no, target, rep.iterations, rep.residual_norms, reason)
