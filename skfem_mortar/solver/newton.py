"""Block Newton method over displacements and multipliers.

One load step: starting from the last converged unknowns ``z`` and the new
prescribed values, iterate

    K(z) dz = -R(z),      z <- z + alpha dz

on the free unknowns (``K = dR/dz`` holds the bulk, load and contact blocks
``[K_uu  K_ulam; K_lamu  K_lamlam]``). The prescribed increment enters the
first iteration through the consistent predictor ``K_ff dz_f = -(R_f + K_fp dz_p)``,
so that a large boundary displacement does not invert the elements next to
the boundary before the interior has followed.  ``NewtonOptions.linear``
chooses how ``K dz = -R`` is solved: a factorization per iteration
(``"direct"``), or inexactly to a forcing term by FGMRES preconditioned by the
kept factors of an earlier tangent (``"krylov"``, :mod:`.krylov`); the
convergence test below is the same for both.

Convergence (a step is reported converged only when all three hold):

(a) equilibrium: ``|| max(|R_f| - floor, 0) || <= max(rtol * S, atol)`` with the step's force
    scale ``S = max(||R_f(z0, lf1) - R_f(z0, lf0)||, ||K_fp dz_p||)`` (the
    external load increment over the step and the stiffness times the
    prescribed increment, both at the converged start state ``z0``), fixed
    before the first iteration from data only, so a blown-up iterate cannot
    inflate it; ``floor`` is each row's round-off of the stiffness scale,
    ``ROUND_OFF * eps * max_j |K_ij| * L`` (``L`` the largest coordinate), so
    a residual that is round-off in every row passes;
(b) every item is *settled* (no active set change in the last iteration) and
    reports no violation of its own conditions (:meth:`Item.violation`, e.g.
    the contact pair's KKT conditions, to the tolerances it states);
(c) every unknown is finite.

A stalled residual is accepted at round-off only below ``STAGNATION_RESIDUAL * S``
(see :func:`_stagnated_at_round_off`).  An iteration whose residual exceeds
``divergence`` times the step's scale is divergent.

A wandering iterate ends the attempt too (the step is then cut): one that moves a
body node farther from its place at the step's start than ``WANDER`` times the
model's size ``L`` (the diagonal of the box around every body node at the
step's start, or the largest prescribed increment if that is larger;
:func:`wandered`).  From so far away Newton converges, if at all, to whichever
equilibrium lies near the iterate, not to the one the load path leads to:
``cable_flat`` (n = 50, mortar) on another round-off path (``MKL_CBWR=AVX``)
took its first step in 24 iterations with residuals up to 3.9e7 times the
step's scale and an iterate 87 L away, and converged to a looped cable without
contact (contact force error 1.0).  The iterates of the first 13 recorded scene
runs (95 attempts) stay within 0.9 L, and no recorded run is cut by the guard
(``benchmarks/compare_scenes.py``: every step history unchanged).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import InversionError
from ..core.validate import count, flag, real
from .krylov import FORCING_MAX, KRYLOV_MAX_ITER, LINEAR, KrylovSolver, choose_linear, forcing
from .linsolve import solve_linear
from ..core.item import Body
from ..core.model import Model

__all__ = ["NewtonOptions", "NewtonReport", "newton"]

log = logging.getLogger(__name__)


@dataclass
class NewtonOptions:
    """Settings of the Newton iteration.

    Parameters
    ----------
    max_iter : int
        Iterations allowed per load step attempt (>= 1).
    rtol : float
        Relative residual tolerance, in (0, 1).
    atol : float
        Absolute residual tolerance (>= 0, a force): the test is
        ``|| max(|R_f| - floor, 0) || <= max(rtol * S, atol)``; 0 (default)
        means the step's force scale ``S`` and the round-off floor alone.
    line_search : bool
        Backtracking on the residual norm (halving, Armijo factor 1e-4).
    max_backtracks : int
        Halvings per iteration when ``line_search`` is on.
    divergence : float
        An iteration whose residual exceeds ``divergence`` times the step's
        reference scale is declared divergent.
    linear : {"direct", "krylov", "auto"}
        How the Newton system is solved: ``"direct"`` a factorization per
        iteration; ``"krylov"`` inexact Newton, FGMRES to the forcing term
        ``eta_k`` preconditioned by the kept factors of an earlier tangent,
        refactored when it does not reach it (:mod:`~skfem_mortar.solver.krylov`);
        ``"auto"`` "krylov" from
        :data:`~skfem_mortar.solver.krylov.AUTO_KRYLOV_ABOVE` free unknowns on.
    forcing_max : float
        Largest forcing term ``eta_max`` of "krylov", in (0, 1).
    krylov_max_iter : int
        FGMRES iterations with the kept factors before the tangent is
        refactored (>= 1).
    """

    max_iter: int = 25
    rtol: float = 1e-10
    atol: float = 0.0
    line_search: bool = False
    max_backtracks: int = 8
    divergence: float = 1e8
    linear: str = "direct"
    forcing_max: float = FORCING_MAX
    krylov_max_iter: int = KRYLOV_MAX_ITER

    def __post_init__(self):
        # each field checked and stored as its plain type: a bool is no count
        # (max_iter=True), a string no number (rtol="1e-8"), 2.5 no count
        self.max_iter = count("max_iter", self.max_iter, 1)
        self.rtol = real("rtol", self.rtol, 0.0, 1.0, low_open=True, high_open=True)
        self.atol = real("atol", self.atol, 0.0)
        self.line_search = flag("line_search", self.line_search)
        self.max_backtracks = count("max_backtracks", self.max_backtracks, 0)
        self.divergence = real("divergence", self.divergence, 1.0, low_open=True)
        if not isinstance(self.linear, str) or self.linear not in LINEAR:
            raise ValueError(f"linear must be one of {LINEAR}, got {self.linear!r}")
        self.forcing_max = real("forcing_max", self.forcing_max, 0.0, 1.0,
                                low_open=True, high_open=True)
        self.krylov_max_iter = count("krylov_max_iter", self.krylov_max_iter, 1)


@dataclass
class NewtonReport:
    """What one attempt of a load step did."""

    converged: bool
    iterations: int
    residual_norms: list[float] = field(default_factory=list)
    reason: str = ""
    solve_time: float = 0.0
    inversion_cuts: int = 0
    roundoff: bool = False
    #: the step's force scale S, the residual tolerance it gave, and the norm
    #: of the rows' round-off floor
    scale: float = 0.0
    tolerance: float = 0.0
    floor: float = 0.0
    #: the linear solves: ``"direct"`` or ``"krylov"`` (``NewtonOptions.linear``
    #: resolved), fresh factorizations, FGMRES iterations, solves answered by
    #: kept factors, FGMRES runs given up for a factorization (:mod:`.krylov`)
    linear: str = "direct"
    factorizations: int = 0
    krylov_iterations: int = 0
    krylov_solves: int = 0
    fallbacks: int = 0


#: factor of the round-off floor of a row, ``ROUND_OFF * eps * max_j |K_ij| * L``:
#: the force in row i carries a round-off of about ``eps max_j |K_ij| L``
#: (positions x = X + u are known to ``eps L``, and the row's largest stiffness
#: turns that into a force); summed over the few elements at a node, 100 times
#: that is the level below which a row's residual is noise
ROUND_OFF = 1e2


def round_off_floor(model: Model, z: np.ndarray, K, free: np.ndarray) -> np.ndarray:
    """Per free row, ``ROUND_OFF * eps * max_j |K_ij| * L``: the residual below
    which the row's force is round-off (``L`` the largest coordinate of a body
    node at ``z``).  Per row, so that a body 1e6 times stiffer than another
    does not lend its round-off to the soft body's rows.  The bodies give their
    positions through the :class:`~skfem_mortar.core.item.Body` protocol."""
    length = 0.0
    for body in model.bodies:
        if isinstance(body, Body):
            length = max(length, float(np.max(np.abs(body.x(z)), initial=0.0)))
    Kf = abs(K[free][:, free])
    k_row = np.asarray(Kf.max(axis=1).todense()).ravel() if Kf.nnz else np.zeros(free.size)
    return ROUND_OFF * np.finfo(float).eps * length * k_row


def excess_norm(Rf: np.ndarray, floor: np.ndarray) -> float:
    """``|| max(|R_i| - floor_i, 0) ||``: the residual beyond each row's round-off."""
    return float(np.linalg.norm(np.maximum(np.abs(Rf) - floor, 0.0)))


def step_scale(model: Model, z0: np.ndarray, lf0: float, lf1: float, free: np.ndarray,
               K_dz_fixed: np.ndarray | None) -> float:
    """The step's force scale ``S = max(||R_f(z0, lf1) - R_f(z0, lf0)||, ||K_fp dz_p||)``.

    The first term is the external load increment at the converged start
    state (the items declared ``loaded``; trial evaluations, so no item's
    state changes), the second the force of the prescribed increment.
    """
    R1 = model.load_residual(z0, lf1)
    R0 = model.load_residual(z0, lf0)
    s = float(np.linalg.norm(R1[free] - R0[free]))
    if K_dz_fixed is not None:
        s = max(s, float(np.linalg.norm(K_dz_fixed)))
    return s if np.isfinite(s) else np.inf


def newton(model: Model, z: np.ndarray, load_factor: float, free: np.ndarray,
           fixed: np.ndarray, dz_fixed: np.ndarray,
           options: NewtonOptions | None = None,
           start: tuple[np.ndarray, float] | None = None) -> NewtonReport:
    """Solve one load step in place on ``z``.

    Parameters
    ----------
    model : Model
    z : ndarray
        Unknowns at the last converged state (prescribed entries still at their
        old values); updated in place.
    load_factor : float
        Target load factor of the step.
    free, fixed : ndarray of int
        Free and prescribed global indices.
    dz_fixed : ndarray
        Increment of the prescribed values over the step.
    options : NewtonOptions
    start : (z, load_factor), optional
        The converged state the step starts from and its load factor (default:
        ``z`` itself at ``load_factor``): the step's force scale is taken there.
    """
    opt = options or NewtonOptions()
    report = NewtonReport(False, 0)
    z0, lf0 = (z.copy(), load_factor) if start is None else start
    ref = tol = 0.0
    floor = np.zeros(free.size)
    symmetric = model.symmetrizable  # symmetric but for the multiplier rows
    report.linear = choose_linear(opt.linear, free.size)
    krylov = KrylovSolver(max_iter=opt.krylov_max_iter) if report.linear == "krylov" else None
    eta: float | None = None
    last: tuple[np.ndarray, float] | None = None  # the last update (dz_f, alpha)
    home = _Home(model, z0, dz_fixed)
    for it in range(opt.max_iter + 1):
        try:
            R, K, _ = _assemble_damped(model, z, load_factor, free, last, opt, report)
        except InversionError as exc:
            report.reason = f"inversion: {exc}"
            return report
        if it > 0:
            report.reason = wandered(model, z, home)
            if report.reason:
                report.iterations = it
                return report
        K_dz = K[free][:, fixed] @ dz_fixed if (it == 0 and fixed.size) else None
        Rf = R[free] + K_dz if K_dz is not None else R[free]
        rnorm = float(np.linalg.norm(Rf))
        report.residual_norms.append(rnorm)
        if not np.isfinite(rnorm):
            report.reason = "non-finite residual"
            return report
        if it == 0:  # the step's yardsticks, from data only (module docstring)
            report.scale = step_scale(model, z0, lf0, load_factor, free, K_dz)
            floor = round_off_floor(model, z0, K, free)
            tol = report.tolerance = max(opt.rtol * report.scale, opt.atol)
            report.floor = float(np.linalg.norm(floor))
            ref = max(rnorm, report.scale, report.floor)
        settled = False
        if it > 0 or not fixed.size:
            settled, done = _test(model, z, free, Rf, floor, tol, last, report, it)
            if done:
                return report
        if it == opt.max_iter:
            report.reason = f"no convergence in {opt.max_iter} iterations"
            report.iterations = it
            return report
        if rnorm > opt.divergence * max(ref, np.finfo(float).tiny):
            report.reason = "divergence"
            report.iterations = it
            return report
        t0 = time.perf_counter()
        dzf, eta = _update(model, z, K, free, Rf, symmetric, krylov, eta, settled, tol, opt,
                           report)
        if dzf is None:
            report.iterations = it
            return report
        report.solve_time += time.perf_counter() - t0
        if it == 0 and fixed.size:
            z[fixed] += dz_fixed
        alpha = 1.0
        if opt.line_search:
            alpha = _backtrack(model, z, load_factor, free, dzf, rnorm, opt)
        z[free] += alpha * dzf
        last = (dzf, alpha)
        report.iterations = it + 1
    return report  # pragma: no cover (loop always returns)


def _test(model: Model, z: np.ndarray, free: np.ndarray, Rf: np.ndarray, floor: np.ndarray,
          tol: float, last: tuple[np.ndarray, float] | None, report: NewtonReport,
          it: int) -> tuple[bool, bool]:
    """The convergence test of iteration ``it`` (module docstring): whether every
    item is settled, and whether the step is done (then ``report`` says how)."""
    rnorm = report.residual_norms[-1]
    settled = all(item.settled() for item in model.items)
    done = settled and excess_norm(Rf, floor) <= tol
    if not done and settled and _stagnated_at_round_off(model, z, free, last, report,
                                                        report.scale):
        log.info("residual %.3e stagnates at round-off (tolerance %.3e)", rnorm, tol)
        report.roundoff = done = True
    if done:
        report.iterations = it
        report.reason = _violations(model, z, max(report.scale, report.floor))
        report.converged = not report.reason
        if report.reason:
            report.roundoff = False
            log.info("residual converged, but %s", report.reason)
    return settled, done


def _update(model: Model, z: np.ndarray, K, free: np.ndarray, Rf: np.ndarray,
            symmetric: bool, krylov: KrylovSolver | None, eta: float | None, settled: bool,
            tol: float, opt: NewtonOptions, report: NewtonReport
            ) -> tuple[np.ndarray | None, float | None]:
    """The Newton update of the free unknowns, ``K_ff dz_f = -R_f`` (direct, or
    Krylov to the forcing term, which is returned too); None when the linear
    solve fails (``report.reason`` says why)."""
    mult = (free >= model.n_u) if symmetric else None
    hint = (lambda z=z: model.analysis_coupling(z, free)) if symmetric else None
    try:
        if krylov is None:
            dzf = solve_linear(model.free_block(K, free), -Rf, multipliers=mult, hint=hint)
            report.factorizations += 1
        else:
            eta = forcing(report.residual_norms, eta, report.scale, tol, opt.forcing_max)
            dzf = krylov.solve(model.free_block(K, free), -Rf, eta, multipliers=mult,
                               reuse=settled, hint=hint)
    except InversionError as exc:
        report.reason = str(exc)
        return None, eta
    finally:
        if krylov is not None:
            c = krylov.counts
            report.factorizations, report.krylov_iterations = (c.factorizations,
                                                               c.krylov_iterations)
            report.krylov_solves, report.fallbacks = c.krylov_solves, c.fallbacks
    return dzf, eta


def _violations(model: Model, z: np.ndarray, scale: float) -> str:
    """Why a state whose residual passed is still not a solution ("" if none):
    a non-finite unknown, or an item's own conditions (:meth:`Item.violation`)."""
    if not np.all(np.isfinite(z)):
        return "non-finite unknowns"
    # the items see the force scale per unit thickness, as their own forces are
    H = getattr(model, "thickness", 1.0)
    return "; ".join(m for m in (item.violation(z, scale / H if item.per_thickness else scale)
                                 for item in model.items) if m)


#: an iterate that moves a body node farther than ``WANDER`` times the model's size
#: from the step's start ends the attempt (module docstring)
WANDER = 10.0


class _Home:
    """The body nodes' places at the step's start and the model's size ``L`` there
    (:func:`wandered`)."""

    def __init__(self, model: Model, z0: np.ndarray, dz_fixed: np.ndarray):
        self.x0 = [body.x(z0) for body in model.bodies if isinstance(body, Body)]
        size = 0.0
        if self.x0:
            x = np.hstack([np.asarray(x, dtype=float).reshape(len(x), -1) for x in self.x0])
            size = float(np.linalg.norm(x.max(axis=1) - x.min(axis=1))) if x.size else 0.0
        moved = float(np.max(np.abs(dz_fixed), initial=0.0))
        self.size = max(size, moved)


def wandered(model: Model, z: np.ndarray, home: _Home) -> str:
    """Why the iterate ``z`` is no longer on the way to the step's equilibrium ("" if
    it is): a body node moved from its place at the step's start by more than
    ``WANDER`` times the model's size (module docstring).  A model without body
    positions (:class:`~skfem_mortar.core.item.Body`) or of size 0 is never told so."""
    if not home.x0 or not home.size > 0.0:
        return ""
    bodies = [body for body in model.bodies if isinstance(body, Body)]
    far = max(float(np.max(np.linalg.norm(np.asarray(body.x(z)) - x0, axis=0), initial=0.0))
              for body, x0 in zip(bodies, home.x0))
    if not np.isfinite(far) or far <= WANDER * home.size:
        return ""                   # (a non-finite iterate is reported as such)
    return (f"wandering iterate: a node moved {far:.3g} from the step's start, more than "
            f"{WANDER:g} times the model's size {home.size:.3g}; from there Newton finds "
            f"some equilibrium, not the load path's")


#: relative size of the last Newton update below which it is round-off (both blocks)
STAGNATION_UPDATE = 1e-7
#: a stagnating residual is accepted only below this fraction of the force scale
STAGNATION_RESIDUAL = 1e-6


def _stagnated_at_round_off(model: Model, z: np.ndarray, free: np.ndarray,
                            last: tuple[np.ndarray, float] | None, report: NewtonReport,
                            current: float) -> bool:
    """Round-off safeguard: the residual no longer decreases and the iterate no longer moves.

    The floor :func:`round_off_floor` holds the stiffness scale; with
    a body ``1e6`` times stiffer than the other (the patch test at a stiffness
    ratio of 1e6) the internal forces carry a round-off of ``eps E h``, far
    above it, and the residual stalls there.  Accepted as converged when
    (all of) the active set is settled, the residual is below
    ``STAGNATION_RESIDUAL`` times the step's force scale and did not halve over the
    last two iterations, and the last update was below ``STAGNATION_UPDATE``
    of the current unknowns, separately for the displacements and the
    multipliers (each block relative to itself: unit-free).
    """
    r = report.residual_norms
    if last is None or len(r) < 3 or r[-1] > STAGNATION_RESIDUAL * current:
        return False
    if r[-1] < 0.5 * min(r[-3], r[-2]):
        return False
    dzf, alpha = last
    is_u = free < model.n_u
    for blk in (is_u, ~is_u):
        if not blk.any():
            continue
        zb = float(np.max(np.abs(z[free[blk]])))
        db = float(np.max(np.abs(alpha * dzf[blk])))
        if db > STAGNATION_UPDATE * zb:
            return False
    return True


def _assemble_damped(model: Model, z: np.ndarray, load_factor: float, free: np.ndarray,
                     last: tuple[np.ndarray, float] | None, opt: NewtonOptions,
                     report: NewtonReport):
    """Assemble at ``z``; if an element is inverted there, halve the last update.

    Inversion safeguard: a Newton update that inverts an element (a contact
    node pushed through a soft element by a linearized step, e.g. ``seed``
    with nts at ``refine_cushion=3``) is taken back by halves (at most
    ``max_backtracks`` times) before the step is given up and cut; a
    converged answer does not depend on it.  The first iteration (no update
    yet) raises at once.
    """
    while True:
        try:
            return model.assemble(z, load_factor, tangent=True)
        except InversionError:
            if last is None or report.inversion_cuts >= opt.max_backtracks:
                raise
            dzf, alpha = last
            z[free] -= 0.5 * alpha * dzf
            last = (dzf, 0.5 * alpha)
            report.inversion_cuts += 1
            log.debug("inversion: update halved to alpha = %.3g", 0.5 * alpha)


def _backtrack(model: Model, z: np.ndarray, load_factor: float, free: np.ndarray,
               dzf: np.ndarray, rnorm: float, opt: NewtonOptions) -> float:
    """Largest alpha in {1, 1/2, 1/4, ...} with ||R(z + alpha dz)|| <= (1 - 1e-4 alpha) ||R||."""
    alpha = 1.0
    for _ in range(opt.max_backtracks):
        trial = z.copy()
        trial[free] += alpha * dzf
        try:
            R, _, _ = model.assemble(trial, load_factor, tangent=False)
            r = float(np.linalg.norm(R[free]))
        except InversionError:
            r = np.inf
        if np.isfinite(r) and r <= (1.0 - 1e-4 * alpha) * rnorm:
            return alpha
        alpha *= 0.5
    log.debug("line search: no decrease after %d halvings, taking the full step",
              opt.max_backtracks)
    return 1.0
