"""Which model's unknown layout an item reads: an item in several models.

A :class:`~skfem_mortar.core.model.Model` writes its layout into its items:
each body's and contact pair's ``offset`` (its first global unknown) and every
item's ``thickness``.  A body without history may be in several models (one
model per contact method on the same bodies); each model then keeps its own
layout and writes it again into its items whenever it is used
(:func:`bind`: every read of ``Model.items``), which costs one identity check
per item while the layout is already there.

An item with a history (:attr:`~skfem_mortar.core.item.Item.has_history`: a
contact pair's active set, friction state) belongs to one model at a time: the
one built last with it (:func:`claim`).  An earlier model that holds it is
refused from then on (ValueError at its next use, :func:`bind`): two models
would share, and overwrite, its state.  Building a new model around a pair that
is done with the old one (a step continued in another model) is allowed.

An item's own helpers (``pair.contact_data(z)``, ``body.x(z)``) read the
layout of the model used last; :func:`rebind` makes that the layout of the
one live model the item is in (nothing for a body in several models: then
``model.bind()`` says which).
"""
from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from .item import Item  # (Model: a name in the annotations only, no import)

__all__ = ["claim", "layout", "bind", "rebind"]

#: the attributes a model writes into its items (in their ``__dict__``)
_BOUND = "_model_bound"    # weakref of the model whose layout the item holds now
_MODELS = "_model_refs"    # weakrefs of every model the item was put in
_OWNER = "_model_owner"    # an item with a history: weakref of the model built last with it


def _models(item: "Item") -> list["Model"]:
    """The live models ``item`` was put in, oldest first (dead references dropped)."""
    refs = [r for r in item.__dict__.get(_MODELS, []) if r() is not None]
    item.__dict__[_MODELS] = refs
    return [r() for r in refs]


def claim(ref: "weakref.ref[Model]", items: list["Item"]) -> None:
    """Record the model of weak reference ``ref`` in each of its items; an item
    with a history belongs to that model from now on (module docstring)."""
    for it in items:
        it.__dict__.setdefault(_MODELS, []).append(ref)
        if it.has_history:
            it.__dict__[_OWNER] = ref


def layout(items: list["Item"], thickness: float, geometry: str = "plane"
           ) -> tuple[list[tuple[Any, ...]], int, int]:
    """Each item's ``(item, offset or None, thickness, geometry)`` in a model of these
    items (displacement blocks first, in order, then the multiplier blocks),
    the number of displacement unknowns and of all unknowns."""
    offsets: dict[int, int] = {}
    n, n_u = 0, 0
    for kind in ("u", "lam"):
        for it in items:
            if it.dof_kind == kind:
                offsets[id(it)] = n
                n += int(it.n_dofs)
        if kind == "u":
            n_u = n
    rows = [(it, offsets.get(id(it)), thickness if it.per_thickness else 1.0, geometry)
            for it in items]
    return rows, n_u, n


def bind(model: "Model", ref: "weakref.ref[Model]", rows: list[tuple[Any, ...]]) -> None:
    """Write the layout ``rows`` of :func:`layout` into the items unless every
    item holds it already (``ref``: the model's weak reference, the token)."""
    for it, *_ in rows:
        if it.__dict__.get(_BOUND) is not ref:
            break
    else:
        return
    for it, *_ in rows:
        if it.has_history and it.__dict__.get(_OWNER) is not ref:
            raise ValueError(
                f"item {it.name!r} ({type(it).__name__}) keeps a state from step to step "
                f"and was put in a model built after this one ({model!r}): it belongs to "
                f"that model now, so this one can no longer be used; build a new "
                f"{type(it).__name__} for each model (bodies, loads and boundary "
                f"conditions may be shared)")
    for it, offset, H, geometry in rows:
        if offset is not None:
            it.offset = offset
        it.thickness = H
        if it.geometry != geometry:   # a body rebuilds its geometry's kernel data
            it.geometry = geometry
        it.__dict__[_BOUND] = ref


def rebind(item: "Item") -> None:
    """Give ``item`` (and the other items of its model) the layout of its
    model: the one it belongs to (an item with a history), or the one live
    model it is in; nothing when it is in none or in several (a shared body)."""
    owner = item.__dict__.get(_OWNER)
    models = [owner()] if owner is not None and owner() is not None else _models(item)
    if len(models) == 1:
        models[0].bind()
