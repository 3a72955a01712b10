"""A limit point under load control is named, not cut to death.

After each converged step of a model under a force or pressure load (module
:func:`load_controlled`), :class:`LimitWatch` computes Bergan's current
stiffness parameter

    S_p = (f^T K^-1 f)_0 / (f^T K^-1 f)_k ,

with ``f = -(R_load(z, 1) - R_load(z, 0))`` the current load pattern on the
free unknowns (the items declared ``loaded``; followers at the current
configuration), ``K`` the tangent at the converged state and ``0`` the first
converged step of the solve.  ``S_p`` is 1 while the response is as stiff
as at the start, falls to 0 at a limit point and is negative beyond it.

When a step fails and ``S_p`` at the last converged step is below
:data:`STIFFNESS_LIMIT`, or the linear extrapolation of the last two values
crosses zero inside the failed increment, the solve is cut at most
:data:`MAX_LIMIT_CUTS` more times and then stops with a
:class:`LimitPointError`: "limit point near load factor X (pressure P):
pressure control cannot pass it; prescribe the enclosed volume instead"
(``X`` the extrapolated zero, or the last converged load factor).

Not computed (``S_p`` is None, nothing changes): a model with multiplier
unknowns or items with a history (contact pairs, volume control: their Newton
matrix is not a stiffness), with a prescribed displacement that moves with the
load factor (displacement control has no limit point in the load), or with no
load pattern.  The extra cost is one assembly and one factorization per
converged step of the models it is computed for.  The reference ``(.)_0``
belongs to the solve: a run resumed from a checkpoint takes it again at its
first converged step (the watch keeps no checkpointed state).
"""
from __future__ import annotations

import numpy as np

from ..core.errors import ConvergenceError, InversionError
from ..core.model import Model
from .linsolve import solve_linear

__all__ = ["STIFFNESS_LIMIT", "MAX_LIMIT_CUTS", "LimitPointError", "LimitWatch",
           "load_controlled"]

#: ``S_p`` below this at the last converged step marks a failed step as a limit point
STIFFNESS_LIMIT = 0.05
#: the cuts allowed once a limit point is suspected
MAX_LIMIT_CUTS = 2


class LimitPointError(ConvergenceError):
    """The load passes a limit point that load control cannot follow.

    Besides :class:`~skfem_mortar.core.errors.ConvergenceError`'s attributes:

    Attributes
    ----------
    estimate : float
        The load factor of the limit point, estimated from ``S_p``.
    last_load_factor : float
        The last converged load factor.
    pressure : float or None
        The pressure of the model's follower pressures at ``estimate``.
    """

    def __init__(self, step: int, target: float, iteration: int, residual_history: list[float],
                 estimate: float, last_load_factor: float, pressure: float | None):
        self.estimate, self.last_load_factor, self.pressure = estimate, last_load_factor, pressure
        where = "" if pressure is None else f" (pressure {pressure:.6g})"
        super().__init__(step, target, iteration, residual_history,
                         f"limit point near load factor {estimate:.6g}{where}: pressure "
                         f"control cannot pass it; prescribe the enclosed volume instead")


def load_controlled(model: Model) -> bool:
    """Whether ``S_p`` is defined for ``model`` (module docstring)."""
    if model.n_lam or any(it.has_history for it in model.items):
        return False
    d0, v0 = model.prescribed(0.0)
    d1, v1 = model.prescribed(1.0)
    return d0.shape == d1.shape and bool(np.all(d0 == d1)) and bool(np.allclose(v0, v1))


class LimitWatch:
    """``S_p`` over the converged steps of one solve, and the limit-point verdict.

    ``history``: ``(load factor, S_p)`` of the converged steps where it was computed.
    """

    def __init__(self, model: Model):
        self.model = model
        self.active = load_controlled(model)
        self.reference: float | None = None
        self.history: list[tuple[float, float]] = []
        self.cuts = 0

    def converged(self, z: np.ndarray, load_factor: float) -> float | None:
        """``S_p`` at the converged ``z`` (None where it is not defined)."""
        if not self.active:
            return None
        model = self.model
        fixed = model.prescribed(load_factor)[0]
        free = np.setdiff1d(np.arange(model.n), fixed, assume_unique=True)
        f = (model.load_residual(z, 0.0) - model.load_residual(z, 1.0))[free]
        if not np.any(f):
            return None
        _, K, _ = model.assemble(z, load_factor, tangent=True)
        try:
            q = float(f @ solve_linear(model.free_block(K, free), f))
        except InversionError:
            return None
        if self.reference is None:
            self.reference = q
        s = self.reference / q if q != 0.0 else 0.0
        self.history.append((load_factor, s))
        return s

    def estimate(self, target: float) -> float | None:
        """The load factor of a suspected limit point in the failed increment up
        to ``target``, or None (module docstring)."""
        if not self.history:
            return None
        lf1, s1 = self.history[-1]
        crossing = None
        if len(self.history) > 1:
            lf0, s0 = self.history[-2]
            if s1 < s0 and lf1 > lf0:
                zero = lf1 + s1 * (lf1 - lf0) / (s0 - s1)
                if zero <= target:
                    crossing = max(zero, lf1)
        if crossing is None and s1 < STIFFNESS_LIMIT:
            crossing = lf1
        return crossing

    def failed(self, step: int, target: float, iterations: int,
               norms: list[float]) -> None:
        """A step to ``target`` failed: count a cut under a suspected limit
        point, and raise :class:`LimitPointError` once :data:`MAX_LIMIT_CUTS`
        are spent."""
        estimate = self.estimate(target)
        if estimate is None:
            return
        if self.cuts >= MAX_LIMIT_CUTS:
            raise LimitPointError(step, target, iterations, norms, estimate,
                                  self.history[-1][0], self._pressure(estimate))
        self.cuts += 1

    def _pressure(self, load_factor: float) -> float | None:
        """The pressure of the model's first follower pressure at ``load_factor``."""
        for it in self.model.items:
            if hasattr(it, "current_pressure"):
                return float(it.current_pressure(load_factor))
        return None
