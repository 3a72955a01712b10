"""Checks of the values a user hands to a public constructor.

Each check returns the value converted to its plain Python type, or raises a
ValueError that names the parameter, the allowed range and the value given.
A number must be a real number (``int``, ``float`` or a NumPy real scalar: a
string such as ``"100"`` or a ``bool`` is refused, not converted); a count must
be an integer (``2.5`` is refused, not truncated); a flag must be a ``bool``.
"""
from __future__ import annotations

import math
from numbers import Integral, Real
from typing import Any

import numpy as np

__all__ = ["real", "count", "flag", "is_real"]


def is_real(value: Any) -> bool:
    """Whether ``value`` is a real number: not a bool, not a string, not complex."""
    return isinstance(value, (Real, np.floating, np.integer)) and not isinstance(value, (bool, np.bool_))


def _bounds(low: float | None, high: float | None, low_open: bool, high_open: bool) -> str:
    if low is not None and high is not None:
        return f"in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
    if low is not None:
        return f"{'>' if low_open else '>='} {low:g}"
    if high is not None:
        return f"{'<' if high_open else '<='} {high:g}"
    return ""


def real(name: str, value: Any, low: float | None = None, high: float | None = None, *,
         low_open: bool = False, high_open: bool = False, finite: bool = True) -> float:
    """``value`` as a float, checked against ``[low, high]`` (open ends on request).

    Raises
    ------
    ValueError
        Naming ``name`` when ``value`` is not a real number (a string, a bool, None),
        is NaN, is infinite while ``finite``, or lies outside the range.
    """
    what = (f"{name} must be a {'finite ' if finite else ''}real number "
            f"{_bounds(low, high, low_open, high_open)}").rstrip()
    if not is_real(value):
        raise ValueError(f"{what}, got {value!r} ({type(value).__name__})")
    try:
        v = float(value)
    except OverflowError:  # an int beyond float's range (10**400)
        raise ValueError(f"{what}, got an integer of {len(str(int(value)))} digits") from None
    if math.isnan(v) or (finite and math.isinf(v)):
        raise ValueError(f"{what}, got {value!r}")
    if low is not None and (v < low or (low_open and v == low)):
        raise ValueError(f"{what}, got {value!r}")
    if high is not None and (v > high or (high_open and v == high)):
        raise ValueError(f"{what}, got {value!r}")
    return v


def count(name: str, value: Any, low: int = 0, high: int | None = None) -> int:
    """``value`` as an int in ``[low, high]``; a float (even ``2.0``) or a bool is refused.

    Raises
    ------
    ValueError
        Naming ``name``, the range and the value.
    """
    rng = f">= {low}" if high is None else f"in [{low}, {high}]"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (Integral, np.integer)):
        raise ValueError(f"{name} must be an integer {rng}, got {value!r} ({type(value).__name__})")
    v = int(value)
    if v < low or (high is not None and v > high):
        raise ValueError(f"{name} must be an integer {rng}, got {v}")
    return v


def flag(name: str, value: Any) -> bool:
    """``value`` if it is a bool (``True``/``False`` or a NumPy bool), else ValueError naming ``name``."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {value!r} ({type(value).__name__})")
    return bool(value)
