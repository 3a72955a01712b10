"""SciPy routines imported on first use.

``scipy.optimize`` takes 0.3 s to import on an idle machine (1.3 s on a busy
one, measured with ``python -X importtime``), more than a small run's whole
solve; only start shapes and analytic references need its root finder, so a
run that needs neither does not pay for it.
"""
from __future__ import annotations

from typing import Any

__all__ = ["brentq"]


def brentq(*args: Any, **kwargs: Any) -> float:
    """:func:`scipy.optimize.brentq` (same arguments), imported on the first call."""
    from scipy.optimize import brentq as _brentq

    return _brentq(*args, **kwargs)
