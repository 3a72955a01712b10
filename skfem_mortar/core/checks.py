"""The model-wide checks: what :class:`~skfem_mortar.core.model.Model` refuses
when it is built (its items and thickness) and the checks its
:meth:`~skfem_mortar.core.model.Model.preflight` runs before the first step,
registered by the layers that know them (:func:`register_check`).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from .item import Item
from .validate import real

__all__ = ["register_check", "check_thickness"]


def _check_items(items: list[Item]) -> None:
    """Every entry an Item, none listed twice (its load or stiffness would count
    twice), every body an item refers to in the list."""
    for k, it in enumerate(items):
        if not isinstance(it, Item):
            raise ValueError(f"items[{k}] is not a model item (a body, load, boundary "
                             f"condition or contact pair), got {type(it).__name__}")
    seen: dict[int, int] = {}
    for k, it in enumerate(items):
        if id(it) in seen:
            raise ValueError(f"items[{seen[id(it)]}] and items[{k}] are the same item "
                             f"{it.name!r}: list each item once (twice would count it twice)")
        seen[id(it)] = k
    for it in items:
        for body in it.referenced_bodies():
            if id(body) not in seen:
                raise ValueError(f"item {it.name!r} acts on body {body.name!r}, which is not "
                                 f"in the model: add the body to the items")


#: the model-wide checks :meth:`Model.preflight` runs (see :func:`register_check`)
_MODEL_CHECKS: list[Callable[["Model", np.ndarray, float, np.ndarray], None]] = []


def register_check(check: Callable[["Model", np.ndarray, float, np.ndarray], None]) -> None:
    """Add ``check(model, z, load_factor, fixed)`` to what :meth:`Model.preflight`
    runs (once: registering the same function again does nothing).  A check
    raises ValueError to refuse the model and may warn."""
    if check not in _MODEL_CHECKS:
        _MODEL_CHECKS.append(check)


def check_thickness(thickness: float) -> float:
    """``thickness`` as a float, ValueError unless a finite real number > 0 (a
    string such as ``"2"`` or a bool is refused, not converted)."""
    return real("thickness", thickness, 0.0, low_open=True)

