"""Interface geometry behind one protocol: candidate cell pairs into integration cells.

A segmentation turns the candidate slave/master cell pairs of a search into
*integration cells*: the parts of a slave cell where one master cell lies
opposite, the domain of the mortar integrals.  Each integration cell records

* its two parent cells (``e_s``, ``e_m``);
* its vertices in the slave cell's coordinates (``xi``; in 2D a segment
  ``[xi_a, xi_b]`` of the slave line) and in the master cell's (``xi_m``);
* where each vertex came from (``origin``): a slave vertex (:data:`SLAVE_VERTEX`),
  a master vertex projected onto the slave cell (:data:`MASTER_VERTEX`), or an
  edge intersection (:data:`EDGE_INTERSECTION`, the 3D clipping's); ``src``
  names the vertex: -1 a slave end, 0 or 1 the master cell's start or end.

The origin is what the kernels differentiate: a projected master vertex moves
with the master nodes and the slave normal field, a slave vertex is fixed in
the slave coordinates (:func:`~skfem_mortar.contact.mortar_kernel.evaluate`).

The protocol (:class:`Segmenter`) is one callable per cell type, registered by
the slave cell's name (:func:`register_segmentation`); :func:`segmentation_for`
finds it, falling back to the built-in one of the cell's dimension
(:func:`register_default`): for lines (``dim`` 1, the 2D surfaces)
:func:`~skfem_mortar.contact.mortar_quadratic_segmentation.segment_lines`, which
handles any order (the projections and the slave normal field of the cells'
geometry).  The 3D one
(auxiliary plane, clipping, triangulation) will be the second implementation of
the same protocol.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

from .cells import CellType, cell_type

__all__ = ["Segmentation", "Segmenter", "SEGMENTATIONS", "register_segmentation",
           "segmentation_for", "register_default", "DEFAULTS", "line_cells", "surface_cell",
           "check_kernel_cells", "SLAVE_VERTEX", "MASTER_VERTEX", "EDGE_INTERSECTION"]

#: ``origin`` codes of an integration cell's vertices
SLAVE_VERTEX, MASTER_VERTEX, EDGE_INTERSECTION = 0, 1, 2


@dataclass
class Segmentation:
    """Integration cells of a slave/master surface pair (values, no derivatives).

    Attributes
    ----------
    e_s, e_m : int ndarray (n,)
        Slave and master parent cell of each integration cell.
    xi : ndarray (n, 2)
        Slave coordinates ``xi_a < xi_b`` of the cell's end points on ``e_s``.
    src : int ndarray (n, 2)
        Where each end point comes from: -1 a slave vertex (``xi = -+1``), 0 or
        1 the projection of the first or second master vertex of ``e_m``.
    elem_xi : ndarray (n_seg_s, 2)
        Projectable part ``[l, h]`` of each slave cell (union of its
        integration cells, assumed connected); ``[1, -1]`` where it has none.
    elem_node : int ndarray (n_seg_s, 2)
        The master node whose projection gives ``l`` (resp. ``h``), -1 for a
        slave end.
    frozen : bool
        When passed to ``evaluate``, whether end points are frozen (policy
        ``step``) or only the pair list is reused and end points are recomputed.
    candidates : (i_s, i_m) or None
        The candidate cell pairs of the search the integration cells were found
        among (before degenerate cells are dropped), None when the pairs were
        given: the method's reserved pattern reads them instead of searching
        again (:meth:`~skfem_mortar.contact.mortar_method.Mortar.pattern`).
    xi_m : ndarray (n, 2) or None
        Master coordinates (in [-1, 1]) of the end points: -1 or 1 at a master
        vertex, the slave vertex projected onto the master cell along its nodal
        normal at a slave vertex.
    """

    e_s: np.ndarray
    e_m: np.ndarray
    xi: np.ndarray
    src: np.ndarray
    elem_xi: np.ndarray
    elem_node: np.ndarray
    frozen: bool = True
    candidates: tuple[np.ndarray, np.ndarray] | None = None
    xi_m: np.ndarray | None = None

    @property
    def n(self) -> int:
        """Number of integration cells."""
        return int(self.e_s.size)

    @property
    def origin(self) -> np.ndarray:
        """(n, 2) :data:`SLAVE_VERTEX` or :data:`MASTER_VERTEX` of each end point."""
        return np.where(self.src < 0, SLAVE_VERTEX, MASTER_VERTEX)

    def vertices(self) -> tuple[np.ndarray, np.ndarray | None]:
        """The vertices in slave and in master coordinates, (n, 2 vertices, dim 1)."""
        return self.xi[:, :, None], None if self.xi_m is None else self.xi_m[:, :, None]


class Segmenter(Protocol):
    """A segmentation: candidate cell pairs into :class:`Segmentation` (integration cells).

    ``xs``, ``xm`` (d, n) node coordinates, ``seg_s``, ``seg_m`` the connectivity,
    ``cells`` the two :class:`~skfem_mortar.contact.cells.CellType`; ``pairs`` given
    candidates (else searched with ``margin`` or the local margin plus ``reach``).
    In an axisymmetric model the mortar method also passes ``mirror``, the symmetry
    lines of the slave normals (:func:`~skfem_mortar.contact.normals.mirror_of_axis`);
    a segmentation used there takes that keyword.
    """

    def __call__(self, xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                 cells: tuple[CellType, CellType],
                 pairs: tuple[np.ndarray, np.ndarray] | None = None,
                 margin: float | None = None, frozen: bool = True,
                 reach: float = 0.0) -> Segmentation: ...


#: registered segmentations by the slave cell's name (:func:`register_segmentation`)
SEGMENTATIONS: dict[str, Callable[..., Segmentation]] = {}


def register_segmentation(cell: "str | CellType", segmenter: Callable[..., Segmentation]
                          ) -> None:
    """Segment slave surfaces of cell type ``cell`` with ``segmenter`` (a :class:`Segmenter`).

    Raises
    ------
    ValueError
        When ``cell`` is not a registered cell type or ``segmenter`` is not callable.
    """
    name = cell_type(cell).name
    if not callable(segmenter):
        raise ValueError(f"segmenter must be callable, got {type(segmenter).__name__}")
    SEGMENTATIONS[name] = segmenter


#: the built-in segmentation of each cell dimension (:func:`register_default`)
DEFAULTS: dict[int, Callable[..., Segmentation]] = {}


def register_default(dim: int, segmenter: Callable[..., Segmentation]) -> None:
    """The segmentation of cells of dimension ``dim`` that have none registered
    (lines: :func:`~skfem_mortar.contact.mortar_quadratic_segmentation.segment_lines`,
    registered where it is defined)."""
    DEFAULTS[int(dim)] = segmenter


def segmentation_for(cells: tuple[CellType, CellType]) -> Callable[..., Segmentation]:
    """The segmentation of a slave/master cell pair: the one registered for the
    slave cell, else the built-in one of its dimension.

    Raises
    ------
    ValueError
        When the cells differ in dimension or none handles their dimension.
    """
    cs, cm = cells
    found = SEGMENTATIONS.get(cs.name)
    if found is not None:
        return found
    if cs.dim != cm.dim:
        raise ValueError(f"cells must have one dimension, got {cs.name} ({cs.dim}) and "
                         f"{cm.name} ({cm.dim})")
    found = DEFAULTS.get(cs.dim)
    if found is None:
        raise ValueError(f"no segmentation for cells of dimension {cs.dim} (registered: "
                         f"{sorted(SEGMENTATIONS)})")
    return found


#: the cell of connectivity arrays handed to a 2D kernel without cells (by columns)
_ARRAY_LINES = {2: "line2", 3: "line3"}


def line_cells(seg_s: np.ndarray, seg_m: np.ndarray,
               cells: "tuple[str | CellType, str | CellType] | None" = None
               ) -> tuple[CellType, CellType]:
    """The cell types of a kernel call: ``cells`` when given (surfaces always give
    them); for bare connectivity arrays (the kernels' array interface) the 2D
    lines of their column count, line2 (start, end) or line3 (start, end, mid).

    Raises
    ------
    ValueError
        When a connectivity is not (n, 2) or (n, 3) without ``cells``, or does not
        have its cell's node count.
    """
    out = []
    for name, seg, c in (("seg_s", seg_s, None if cells is None else cells[0]),
                         ("seg_m", seg_m, None if cells is None else cells[1])):
        shape = np.shape(seg)
        if c is None:
            c = _ARRAY_LINES.get(shape[1]) if np.ndim(seg) == 2 else None
            if c is None:
                raise ValueError(f"{name} must have shape (n, 2) or (n, 3) (start, end[, mid]), "
                                 f"got {shape}")
        c = cell_type(c)
        if np.ndim(seg) != 2 or shape[1] != c.n_nodes:
            raise ValueError(f"{name} must have shape (n, {c.n_nodes}) (cell {c.name}), "
                             f"got {shape}")
        out.append(c)
    return out[0], out[1]


def check_kernel_cells(cells: tuple[CellType, CellType], allowed: tuple[str, ...],
                       kernel: str) -> None:
    """Raise ValueError unless both ``cells`` are among the ``allowed`` names of ``kernel``."""
    for what, c in zip(("slave", "master"), cells):
        if c.name not in allowed:
            raise ValueError(f"{what} cells must be one of {list(allowed)} for {kernel}, "
                             f"got {c.name}")


def surface_cell(surface) -> CellType:
    """A contact surface's cell type: its ``cell``, else the line of its ``order``."""
    cell = getattr(surface, "cell", None)
    if cell is not None:
        return cell_type(cell)
    return cell_type("line3" if surface.order == 2 else "line2")
