"""The states items keep from one load step to the next, by name: what a
checkpoint writes (:func:`stateful_items`, with the model's own under
:data:`MODEL_STATE`) and what a resumed run gives back (:func:`restore_items`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from ..core.model import Model

__all__ = ["MODEL_STATE", "stateful_items", "restore_items"]


#: the key of the model's own state among the item states of a checkpoint
MODEL_STATE = "__model__"


def stateful_items(model: Model) -> dict[str, object]:
    """The items of ``model`` that keep a state (a non-empty ``state_dict``), by
    name, and the model itself under ``MODEL_STATE``.

    Raises
    ------
    ValueError
        When two of them share a name (their states could not be told apart).
    """
    out: dict[str, object] = {MODEL_STATE: model}  # the model's own (tangent pattern)
    for item in model.items:
        if item.state_dict():
            if item.name in out:
                raise ValueError(f"two items with a state share the name {item.name!r}")
            out[item.name] = item
    return out


def restore_items(model: Model, states: dict[str, dict[str, np.ndarray]],
                  source: str = "restart") -> None:
    """``load_state_dict`` of every stateful item of ``model`` from ``states``.

    Raises
    ------
    ValueError
        Naming ``source`` and what does not fit: an unknown item, a missing
        one, or the item's own refusal.
    """
    items = stateful_items(model)
    unknown = sorted(set(states) - set(items))
    if unknown:
        raise ValueError(f"{source}: states of unknown items {unknown}")
    for name, item in items.items():
        if name not in states:
            raise ValueError(f"{source}: no state of item {name!r}")
        try:
            item.load_state_dict(states[name])
        except ValueError as exc:
            raise ValueError(f"{source}: {exc}") from None
