"""The arguments of :func:`~skfem_mortar.solver.stepping.solve` checked before any work:
each bad one refused with a ValueError naming it, its allowed range and the value."""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["MAX_STEPS", "validate", "check_z0"]

#: the largest number of nominal load steps a solve accepts (a 1e6-step run of
#: the smallest scene would take days; more is a typo)
MAX_STEPS = 1_000_000


def _number(v: Any) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool)


def validate(n_steps: int, min_step: float, start: float, growth: float = 2.0,
             easy_iterations: int = 4, easy_steps: int = 2,
             increment: float | None = None) -> None:
    """Refuse stepping arguments out of range (ValueError naming the argument)."""
    if not (isinstance(n_steps, (int, np.integer)) and not isinstance(n_steps, bool)
            and 1 <= n_steps <= MAX_STEPS):
        raise ValueError(f"n_steps must be an integer in [1, {MAX_STEPS}], got {n_steps!r}")
    if not (_number(min_step) and 0.0 < min_step <= 1.0):
        raise ValueError(f"min_step must lie in (0, 1], got {min_step!r}")
    if not (_number(start) and 0.0 <= start < 1.0):
        raise ValueError(f"start must lie in [0, 1), got {start!r}")
    if not (_number(growth) and 1.0 <= growth <= 1e3):
        raise ValueError(f"growth must be a number in [1, 1000], got {growth!r}")
    for name, v, lo in (("easy_iterations", easy_iterations, 0), ("easy_steps", easy_steps, 1)):
        if not (isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= lo):
            raise ValueError(f"{name} must be an integer >= {lo}, got {v!r}")
    if increment is not None and not (_number(increment) and 0.0 < increment <= 1.0):
        raise ValueError(f"increment must lie in (0, 1], got {increment!r}")


def check_z0(z0: Any, n: int, name: str = "z0") -> np.ndarray:
    """``z0`` as a new float array of shape ``(n,)``, refused unless it is one.

    Raises
    ------
    ValueError
        Naming ``name`` (the solve's argument) when ``z0`` is not an array of
        ``n`` real numbers (a string, a bool or complex array, another shape) or
        holds a NaN or an infinity (a non-finite start is no state: Newton would
        fail on it with a ConvergenceError that hides the cause), before anything
        is assembled.
    """
    try:
        arr = np.asarray(z0) if not isinstance(z0, (str, bytes)) else np.asarray(None)
    except ValueError:  # a ragged sequence
        arr = np.asarray(None)
    if arr.dtype.kind not in "iuf":
        raise ValueError(f"{name} must be an array of {n} finite real numbers (the model's "
                         f"unknowns), got {_kind(z0, arr)}")
    if arr.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},) (the model's unknowns), got "
                         f"shape {arr.shape}")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ValueError(f"{name} must be finite, got {bad.size} non-finite entries (the "
                         f"first at index {int(bad[0])}: {float(arr[bad[0]])!r})")
    return np.array(arr, dtype=float)


def _kind(value: Any, arr: np.ndarray) -> str:
    """What was given, for a message: ``str``, ``list``, ``ndarray of dtype complex128``."""
    what = type(value).__name__
    return f"{what} of dtype {arr.dtype}" if isinstance(value, np.ndarray) else what
