"""Which items of a model are contact pairs, for the preflight checks and the failure
diagnosis: duck-typed (an item with ``initial_active`` and ``gap_length``, what the
checks call), so that neither imports :mod:`.pair` (the pair imports them)."""
from __future__ import annotations

from typing import Any

__all__ = ["is_contact_pair", "contact_pairs"]


def is_contact_pair(item: Any) -> bool:
    """``item`` is a contact pair: it has the contact pair's ``initial_active`` and
    ``gap_length`` (:class:`~skfem_mortar.contact.pair.ContactPair`)."""
    return hasattr(item, "initial_active") and hasattr(item, "gap_length")


def contact_pairs(model: Any) -> list:
    """The contact pairs among ``model.items``, in their order."""
    return [it for it in model.items if is_contact_pair(it)]
