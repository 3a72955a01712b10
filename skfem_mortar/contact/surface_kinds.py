"""The kind of a contact surface's cells: curves or faces (the one place that reads a cell's dimension for them).

What differs between the line cells of 2D bodies and cables (curves) and the
faces of 3D bodies (faces) -- the NTS projection and gap, the touching test, the
inward and facing preflight checks, the cell sizes, the failure hints -- is
picked by the surface kind of a cell, never by comparing its dimension:

* :func:`surface_kind` gives a cell's kind: the one registered for its name
  (:func:`register_kind`), else the kind of its reference dimension
  (:data:`BY_DIM`: 1 -> :data:`CURVE`, 2 -> :data:`FACE`);
* each module keeps a table ``{kind: entry}`` of its entries and asks
  :func:`entry` for the one of a cell.

A new cell type is a new row of :mod:`.cells` (and a segmentation); it is
treated as its dimension's kind, or registers another with :func:`register_kind`
(a new kind then brings its entries to every table).
"""
from __future__ import annotations

from typing import Mapping, TypeVar

from .cells import CellType, cell_type

#: line cells of 2D bodies and cables (reference dimension 1)
CURVE = "curve"
#: faces of 3D bodies (reference dimension 2)
FACE = "face"
#: the kind of a cell of each reference dimension (no registered kind)
BY_DIM: dict[int, str] = {1: CURVE, 2: FACE}
#: kinds registered by cell name (:func:`register_kind`)
KINDS: dict[str, str] = {}

T = TypeVar("T")


def register_kind(cell: "str | CellType", kind: str) -> None:
    """Treat contact surfaces of cell type ``cell`` as ``kind`` (:data:`CURVE`, :data:`FACE`
    or a new kind whose entries the tables then hold).

    Raises
    ------
    ValueError
        When ``cell`` is not a registered cell type or ``kind`` is not a non-empty string.
    """
    name = cell_type(cell).name
    if not isinstance(kind, str) or not kind:
        raise ValueError(f"kind must be a non-empty string, got {kind!r}")
    KINDS[name] = kind


def surface_kind(cell: "str | CellType") -> str:
    """The kind of ``cell``: registered (:func:`register_kind`), else by its dimension.

    Raises
    ------
    ValueError
        When the cell has no registered kind and its dimension is not in :data:`BY_DIM`.
    """
    c = cell_type(cell)
    found = KINDS.get(c.name)
    if found is None:
        found = BY_DIM.get(c.dim)
    if found is None:
        raise ValueError(f"cell {c.name!r} (dim {c.dim}) has no surface kind: dimension must "
                         f"be one of {sorted(BY_DIM)} or the kind registered (register_kind)")
    return found


def entry(table: Mapping[str, T], cell: "str | CellType", what: str) -> T:
    """The entry of ``cell``'s kind in ``table`` (``what`` names the table in the error).

    Raises
    ------
    ValueError
        When the table has no entry for the cell's kind.
    """
    kind = surface_kind(cell)
    if kind not in table:
        raise ValueError(f"{what} has no entry for surfaces of kind {kind!r} (cell "
                         f"{cell_type(cell).name!r}); it has {sorted(table)}")
    return table[kind]
