"""Exceptions raised by skfem-mortar."""
from __future__ import annotations

import os
import sys
import warnings
from typing import Any

#: the package's directory (``.../skfem_mortar/``): frames in files under it are not the user's
_PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep


class SkfemMortarError(Exception):
    """Base class of the package's own errors."""


class InversionError(SkfemMortarError, FloatingPointError):
    """An element was inverted (det F <= 0) or a kernel produced a non-finite value.

    The Newton solver treats it as a failed iteration: the load step is cut.
    """


class ContactSizeError(InversionError):
    """A contact evaluation would hold more than its bound in the jets of one slave
    cell: a slave cell under thousands of master cells (a wild Newton iterate, or a
    slave surface far coarser than its master).

    The Newton solver treats it as a failed iteration, as an inversion: the update
    is taken back by halves, else the load step is cut.  Where it is not an
    iterate's, make the finer surface the slave (or refine the slave).
    """


class ConvergenceError(SkfemMortarError):
    """A load step could not be solved, even after cutting it to the minimum size.

    Attributes
    ----------
    step : int
        Index of the load step (counted from 1) that failed.
    load_factor : float
        The load factor the failed attempt aimed at.
    iteration : int
        The Newton iteration at which the last attempt stopped.
    residual_history : list of float
        Residual norms of the last attempt.
    reason : str
        Why the last attempt stopped.
    """

    def __init__(self, step: int, load_factor: float, iteration: int,
                 residual_history: list[float], reason: str,
                 attempts: list[dict[str, Any]] | None = None):
        self.step = step
        self.load_factor = load_factor
        self.iteration = iteration
        self.residual_history = list(residual_history)
        self.reason = reason
        self.attempts = attempts or []
        hist = ", ".join(f"{r:.3e}" for r in self.residual_history[-8:])
        super().__init__(
            f"no convergence in load step {step} at load factor {load_factor:.6g} "
            f"(iteration {iteration}: {reason}); residual history [{hist}]")


def user_stacklevel() -> int:
    """The ``stacklevel`` for a ``warnings.warn`` made by the caller of this function
    that points at the first frame outside the package (the user's ``solve(...)``
    or ``Model(...)``).  When every frame is the package's (its command line), the
    outermost of them."""
    frame, level = sys._getframe(1), 1  # the caller: stacklevel 1 of its warnings.warn
    while frame.f_back is not None and _in_package(frame.f_code.co_filename):
        frame, level = frame.f_back, level + 1
    return level


def _in_package(filename: str) -> bool:
    return os.path.abspath(filename).startswith(_PACKAGE)


def warn_at_user(message: str, category: type[Warning] = UserWarning) -> None:
    """``warnings.warn(message, category)`` pointing at the user's line: the first
    frame outside the package (:func:`user_stacklevel`), whatever the depth of
    the package code that warns."""
    warnings.warn(message, category, stacklevel=user_stacklevel())
