"""Checks of the arrays a user hands to a public constructor (the array
counterparts of :mod:`skfem_mortar.core.validate`).

``np.asarray(value, dtype=float)`` converts what it should refuse: an array of
strings (``["1", "2"]``), of bools, of objects.  These checks look at the dtype
first: an array of real numbers must hold integers or floats, an index array
integers (``1.5`` is refused, not truncated).  Each raises a ValueError naming
the parameter, the allowed range and the first offending entry.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .validate import _bounds

__all__ = ["real_array", "index_array"]

#: what an array of each refused dtype kind holds, for the message
_KINDS = {"U": "strings", "S": "bytes", "b": "booleans", "c": "complex numbers",
          "O": "objects", "f": "floats", "M": "dates", "m": "time spans"}


def _as_array(name: str, value: Any, kinds: str, what: str) -> np.ndarray:
    """``value`` as an array whose dtype kind is one of ``kinds`` (an empty array passes);
    ``what`` (plural: "finite real numbers") says what it must be."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):        # ragged nested lists
        raise ValueError(f"{name} must be {what}, got {value!r}") from None
    if a.size and isinstance(value, (list, tuple)) and a.dtype.kind in kinds:
        # a list such as (0.0, True) or [1, "2"] is converted by NumPy: look at its items
        odd = next((x for x in np.array(value, dtype=object).ravel()
                    if isinstance(x, (bool, np.bool_, str, bytes))), None)
        if odd is not None:
            raise ValueError(f"{name} must be {what}, got {odd!r} ({type(odd).__name__}) "
                             f"in {value!r}")
    if a.size and a.dtype.kind not in kinds:
        example = a.ravel()[:1].tolist()[0]
        got = f"{example!r} ({type(example).__name__})" if a.ndim == 0 else \
            f"{_KINDS.get(a.dtype.kind, a.dtype.name)} (e.g. {example!r})"
        raise ValueError(f"{name} must be {_singular(what) if a.ndim == 0 else what}, "
                         f"got {got}")
    return a


def _singular(what: str) -> str:
    """"finite real numbers > 0" -> "a finite real number > 0" (the message of a scalar)."""
    if what.startswith("integers"):
        return "an " + what.replace("integers", "integer", 1)
    return "a " + what.replace("numbers", "number", 1)


def real_array(name: str, value: Any, low: float | None = None, high: float | None = None,
               *, low_open: bool = False, high_open: bool = False) -> np.ndarray:
    """``value`` as a float array of finite real numbers in ``[low, high]`` (open ends on
    request); a scalar gives a 0-d array.

    Raises
    ------
    ValueError
        Naming ``name``: an array of strings, bools, complex numbers or objects, or
        an entry that is NaN, infinite or outside the range (the first one and how
        many).
    """
    what = f"finite real numbers {_bounds(low, high, low_open, high_open)}".rstrip()
    a = _as_array(name, value, "iuf", what).astype(float)
    bad = ~np.isfinite(a)
    if low is not None:
        bad |= (a <= low) if low_open else (a < low)
    if high is not None:
        bad |= (a >= high) if high_open else (a > high)
    if bad.any():
        k = int(np.flatnonzero(bad.ravel())[0])
        if a.ndim == 0:
            raise ValueError(f"{name} must be {_singular(what)}, got {a.item()!r}")
        raise ValueError(f"{name} must be {what}, got {float(a.flat[k])!r} at index "
                         f"{tuple(int(i) for i in np.unravel_index(k, a.shape))} "
                         f"({int(bad.sum())} such)")
    return a


def index_array(name: str, value: Any, n: int) -> np.ndarray:
    """``value`` as an int64 array of indices in ``[0, n)`` (floats, even ``2.0``, and
    bools refused, not truncated).

    Raises
    ------
    ValueError
        Naming ``name``, the range and the first offending entry.
    """
    what = f"integers in [0, {n})"
    a = _as_array(name, value, "iu", what).astype(np.int64)
    bad = (a < 0) | (a >= n)
    if bad.any():
        k = int(np.flatnonzero(bad.ravel())[0])
        raise ValueError(f"{name} must be {what if a.ndim else _singular(what)}, got "
                         f"{int(a.flat[k])} ({int(bad.sum())} such)")
    return a
