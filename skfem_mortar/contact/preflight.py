"""Checks before the first load step: refuse a model that cannot work.

:meth:`Model.preflight <skfem_mortar.core.model.Model.preflight>` calls :func:`run`
once, on the initial state, before :func:`~skfem_mortar.solver.stepping.solve` takes
its first load step.  Each check either passes silently or raises a
ValueError that names the item and the fix (issue 13: a converged answer is a
right answer; a model that cannot give one is refused before any work):

1. :func:`check_surface` / :func:`check_orientation`: the surfaces of a contact
   pair face each other (a pair pointing the same way converges to a
   penetration).
2. :func:`check_rigid_modes`: every rigid mode of every body is held by the
   Dirichlet data, the normals of the touching contact nodes, or a stiffness
   other than the solids' and cables' own (a spring); otherwise the tangent
   is singular or the answer drifts.
3. :func:`warn_methods`: where a method is known not to work for the
   configuration (NTS with a slave coarser than the master, NTS on
   non-matching deformable meshes: off the patch test) or two bodies in
   contact lie beyond the measured stiffness ratio, a
   :class:`PreflightWarning` before the solve, naming the fix.

The checks live in :mod:`.preflight_orientation` (1., tolerance ``FACING``),
:mod:`.preflight_rigid` (2., ``HOLD``, ``SPRING``) and :mod:`.preflight_methods` (3.);
this module runs them and registers :func:`run` with the model.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..core.checks import register_check
from .preflight_methods import PreflightWarning, warn_methods
from .preflight_orientation import FACING, check_orientation, check_surface
from .preflight_pairs import contact_pairs
from .preflight_rigid import HOLD, SPRING, check_rigid_modes

__all__ = ["PreflightWarning", "run", "check_surface", "check_orientation",
           "check_rigid_modes", "warn_methods", "FACING", "HOLD", "SPRING"]


def run(model: Any, z: np.ndarray, load_factor: float, fixed: np.ndarray) -> None:
    """All checks on the initial state ``z`` (ValueError on the first failing one)."""
    pairs = contact_pairs(model)
    for pair in pairs:
        check_surface(pair.slave)
        check_surface(pair.master)
    for pair in pairs:
        check_orientation(pair, z)
    check_rigid_modes(model, z, load_factor, fixed)
    warn_methods(model, z, load_factor)


register_check(run)  # Model.preflight runs it (the core names no layer below it)

