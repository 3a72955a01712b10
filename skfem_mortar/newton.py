"""Block Newton method over displacements and multipliers.

One load step: starting from the last converged unknowns ``z`` and the new
prescribed values, iterate

    K(z) dz = -R(z),      z <- z + alpha dz

on the free unknowns (``K = dR/dz`` holds the bulk, load and contact blocks
``[K_uu  K_ulam; K_lamu  K_lamlam]``). The prescribed increment enters the
first iteration through the consistent predictor ``K_ff dz_f = -(R_f + K_fp dz_p)``,
so that a large boundary displacement does not invert the elements next to
the boundary before the interior has followed.

Convergence: ``||R_f|| <= rtol * scale`` where ``scale`` is the largest of the
first residual norm of the step and the current largest single item's residual
norm (a force scale of the problem, so the test is unit-free), and every item is
*settled* (no active set change in the last iteration). An iteration whose
residual exceeds ``divergence`` times the step's first scale is divergent.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from .errors import InversionError
from .linsolve import solve_linear
from .model import Model

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
        Absolute residual tolerance (>= 0); 0 means unit-free, relative only.
    line_search : bool
        Backtracking on the residual norm (halving, Armijo factor 1e-4).
    max_backtracks : int
        Halvings per iteration when ``line_search`` is on.
    divergence : float
        An iteration whose residual exceeds ``divergence`` times the step's
        reference scale is declared divergent.
    """

    max_iter: int = 25
    rtol: float = 1e-10
    atol: float = 0.0
    line_search: bool = False
    max_backtracks: int = 8
    divergence: float = 1e8

    def __post_init__(self):
        if not (isinstance(self.max_iter, (int, np.integer)) and self.max_iter >= 1):
            raise ValueError(f"max_iter must be an integer >= 1, got {self.max_iter!r}")
        if not (0.0 < self.rtol < 1.0):
            raise ValueError(f"rtol must lie in (0, 1), got {self.rtol!r}")
        if not self.atol >= 0.0:
            raise ValueError(f"atol must be >= 0, got {self.atol!r}")


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


def _round_off_floor(scale: float) -> float:
    # residuals summed from O(n) terms of size `scale` cannot be trusted below this
    return 1e3 * np.finfo(float).eps * scale


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
        ``z`` itself at ``load_factor``).
    """
    opt = options or NewtonOptions()
    report = NewtonReport(False, 0)
    ref = 0.0
    last: tuple[np.ndarray, float] | None = None  # the last update (dz_f, alpha)
    for it in range(opt.max_iter + 1):
        try:
            R, K, scale = _assemble_damped(model, z, load_factor, free, last, opt, report)
        except InversionError as exc:
            report.reason = f"inversion: {exc}"
            return report
        if it == 0 and fixed.size:
            Rf = R[free] + K[free][:, fixed] @ dz_fixed
        else:
            Rf = R[free]
        rnorm = float(np.linalg.norm(Rf))
        report.residual_norms.append(rnorm)
        if not np.isfinite(rnorm):
            report.reason = "non-finite residual"
            return report
        if it == 0:
            ref = max(rnorm, scale)  # fixed for the step: the divergence yardstick
        current = max(ref, scale)
        settled = all(item.settled() for item in model.items)
        tol = max(opt.rtol * current, opt.atol, _round_off_floor(current))
        if it > 0 or not fixed.size:
            if rnorm <= tol and settled:
                report.converged = True
                report.iterations = it
                return report
            if settled and _stagnated_at_round_off(model, z, free, last, report, current):
                log.info("residual %.3e stagnates at round-off (tolerance %.3e): converged",
                         rnorm, tol)
                report.converged = True
                report.roundoff = True
                report.iterations = it
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
        try:
            dzf = solve_linear(K[free][:, free], -Rf)
        except InversionError as exc:
            report.reason = str(exc)
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


#: relative size of the last Newton update below which it is round-off (both blocks)
STAGNATION_UPDATE = 1e-7
#: a stagnating residual is accepted only below this fraction of the force scale
STAGNATION_RESIDUAL = 1e-6


def _stagnated_at_round_off(model: Model, z: np.ndarray, free: np.ndarray,
                            last: tuple[np.ndarray, float] | None, report: NewtonReport,
                            current: float) -> bool:
    """Round-off safeguard: the residual no longer decreases and the iterate no longer moves.

    The floor :func:`_round_off_floor` is relative to the force scale; with
    a body ``1e6`` times stiffer than the other (the patch test at a stiffness
    ratio of 1e6) the internal forces carry a round-off of ``eps E h``, far
    above it, and the residual stalls there.  Accepted as converged when
    (all of) the active set is settled, the residual is below
    ``STAGNATION_RESIDUAL`` times the force scale and did not halve over the
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
