"""A resumed run's starting state re-checked: converged at its load factor.

A checkpoint's step file holds a state ``z`` the run says is converged at the
load factor of its record.  Before a resume starts from it, the state is
judged by the test Newton passed it with (:mod:`skfem_mortar.solver.newton`,
module docstring), on a copy of the model with the items' checkpointed states
restored; the tangent, the force scale and the round-off floor are taken at the
state before the step (Newton took them at its predictor: the margin measured
on every checkpoint of the suite, 7e-5 of the tolerance at most, is far from
that difference):

(a) equilibrium: ``|| max(|R_f(z)| - floor, 0) || <= max(rtol * S, atol,
    STAGNATION_RESIDUAL * S)``, the last term the loosest residual Newton
    accepts (a residual stalled at round-off); ``S`` is the step's force scale
    (:func:`~skfem_mortar.solver.newton.step_scale`, at the state before it and
    its load factor) and ``floor`` the rows' round-off;
(b) every item's own conditions (:meth:`~skfem_mortar.core.item.Item.violation`,
    e.g. a contact pair's KKT conditions) at that scale;
(c) no inverted element at the state or the one before it.

The step's residual depends on the discrete choices it ended with (the items'
states after it: active sets, segment choices) and, with friction, on the slip
measured from where it started (the items' states before it); the checkpoint
holds both states, but no one of them both parts, so the state is judged with
each (the first alone when it passes) and accepted if it passes with either.
Measured on every scene and method of the kill-and-resume tests, with and
without friction: every checkpointed state passes with a residual at most
7e-5 of the tolerance; each state moved by 1e-3 of its size fails by a factor
of 4e3 or more, or inverts elements.

A state that fails is refused as a bad checkpoint (ValueError naming the
file), never resumed from: a resume starts only from what a solve could have
converged to.  The copy keeps the model as it was, so the resumed solve repeats
the uninterrupted run's solves to the last bit.
"""
from __future__ import annotations

import copy

import numpy as np

from ..core.errors import InversionError
from ..core.model import Model
from .newton import (STAGNATION_RESIDUAL, NewtonOptions, _violations, excess_norm,
                     round_off_floor, step_scale)
from .states import restore_items
from .stepping import Restart

__all__ = ["check_restart", "measure"]

#: assemblies at the state until the items' discrete state (active sets,
#: segment choices) stops changing, as over Newton's last iterations
SETTLE_ASSEMBLIES = 5


def check_restart(model: Model, restart: Restart, before: dict[str, dict[str, np.ndarray]],
                  newton: NewtonOptions | None = None) -> None:
    """Refuse a restart whose state is not converged at its load factor.

    The step's residual depends on the discrete choices it ended with (the
    items' states after it, ``restart.items``: active sets, segment choices)
    and, with friction, on the slip measured from where it started (the items'
    states before it, ``before``); no one state holds both, so the state is
    judged with each and accepted if it passes with either (a state no solve
    converged to passes with neither).

    Parameters
    ----------
    model : Model
        The model the run solves, as built (left unchanged: the check works on
        copies).
    restart : Restart
        The checkpoint's state, load factor and item states, the state before
        it (``previous``) and the load factor before (``controller.lf_prev``).
    before : dict
        The items' states after the step before (``{}`` for the initial state:
        the model's own as built).
    newton : NewtonOptions, optional
        The run's Newton settings (``rtol``, ``atol``).

    Raises
    ------
    ValueError
        Naming ``restart.source``: the state is not in equilibrium at its load
        factor, violates an item's conditions, or inverts an element.
    """
    lf = float(restart.load_factor)
    where = f"{restart.source}: its state"
    tail = "; remove the checkpoint or run without --resume"
    found = []
    for items, reset in ((restart.items, True), (before, False)):
        try:
            r, tol, why = measure(model, restart, items, newton, reset=reset)
        except InversionError as exc:
            raise ValueError(f"{where} (or the one before it) inverts elements: {exc}{tail}"
                             ) from None
        if r <= tol and not why:
            return
        found.append((r, tol, why))
    r, tol, why = min(found, key=lambda f: f[0] / max(f[1], np.finfo(float).tiny))
    if not r <= tol:
        raise ValueError(f"{where} is not converged at load factor {lf!r} (residual "
                         f"{r:.3e} > tolerance {tol:.3e}){tail}")
    raise ValueError(f"{where} at load factor {lf!r} is no solution: {why}{tail}")


def measure(model: Model, restart: Restart, items: dict[str, dict[str, np.ndarray]],
            newton: NewtonOptions | None = None, reset: bool = False
            ) -> tuple[float, float, str]:
    """The restart's residual beyond round-off, the tolerance it must meet and
    the items' violations ("" if none), as Newton judged its last step, on a
    copy of ``model`` with the items' states ``items`` (``{}``: as built): the
    step begun at the state before and assembled there (its force scale, the
    rows' round-off), then the state assembled until the items' discrete state
    settles (module docstring).  ``reset``: the step begun again in between
    (``items`` are the states after the step: its own discrete choices, not
    those the assembly at the state before makes).

    Raises
    ------
    InversionError
        If the state or the one before it inverts an element.
    """
    opts = newton or NewtonOptions()
    m = copy.deepcopy(model)
    if items:
        restore_items(m, items, restart.source)
    lf, lf0 = float(restart.load_factor), float(restart.controller.lf_prev)
    fixed, values = m.prescribed(lf)
    free = np.setdiff1d(np.arange(m.n), fixed, assume_unique=True)
    z = np.array(restart.z, dtype=float)
    z[fixed] = values
    z0 = np.array(restart.z if restart.previous is None else restart.previous, dtype=float)
    _begin(m, z0, lf, fixed)
    _, K0, _ = m.assemble(z0, lf, tangent=True)
    dz_p = values - z0[fixed]
    S = step_scale(m, z0, lf0, lf, free, K0[free][:, fixed] @ dz_p if fixed.size else None)
    floor = round_off_floor(m, z0, K0, free)
    if reset:
        _begin(m, z0, lf, fixed)
    for _ in range(SETTLE_ASSEMBLIES):
        R, _, _ = m.assemble(z, lf, tangent=True)
        if all(item.settled() for item in m.items):
            break
    tol = max(opts.rtol * S, opts.atol, STAGNATION_RESIDUAL * S)
    return (excess_norm(R[free], floor), tol,
            _violations(m, z, max(S, float(np.linalg.norm(floor)))))


def _begin(model: Model, z0: np.ndarray, lf: float, fixed: np.ndarray) -> None:
    """The items' hooks before an attempt of the step to ``lf`` from ``z0``
    (:func:`~skfem_mortar.solver.stepping.solve`): the fixed dofs, the step's
    start (the active sets back to the items' converged ones)."""
    for item in model.items:
        item.set_fixed(fixed)
        item.begin_step(z0, lf)
