"""A scikit-fem element field as VTK cells: the node order VTK (and meshio) expect.

scikit-fem numbers the local nodes of an element in its own order; VTK has
another for hexahedra (linear and quadratic).  A quadratic element is written
as the quadratic VTK cell (``tetra10``, ``hexahedron27``, ``triangle6``,
``quad9``) on all its nodes, so that ParaView draws it curved: the points are
the nodes of the scalar Lagrange basis (vertices first, then edge, face and
interior nodes, as :meth:`skfem.Basis.split_indices` numbers each component of
a vector basis), and each cell lists them in VTK's order:

    conn_vtk[:, i] = element_dofs[VTK_ORDER[cell][i]]

``VTK_ORDER[cell][i]`` is the scikit-fem local node at VTK's local node ``i``
(VTK's parametric coordinates: ``vtkTriQuadraticHexahedron`` and the others'
``GetParametricCoords``; ``tests/test_vtk_cells.py`` checks every cell of a
mesh against them: each cell is the affine image of VTK's reference cell with
a positive Jacobian).  Tetrahedra, triangles and quadrilaterals keep
scikit-fem's order; hexahedra take the order of scikit-fem's own meshio export.
A cell whose corners scikit-fem numbers left-handed is listed mirrored
(:data:`MIRROR`), so that every cell has a positive volume in VTK.
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["VTK_ORDER", "MIRROR", "CELL_TYPES", "REORDERED", "vtk_order", "vtk_cells",
           "basis_cells", "nodal_vectors"]

#: scikit-fem's hexahedron node at each VTK node (``skfem.io.meshio.HEX_MAPPING``):
#: 8 corners, 12 edges, 6 faces, the centre
_HEX = (0, 3, 6, 2, 1, 5, 7, 4, 10, 16, 14, 9, 12, 18, 17, 11, 8, 15, 19, 13,
        20, 25, 22, 23, 21, 24, 26)

#: meshio (VTK) cell type -> scikit-fem local node at each VTK local node
VTK_ORDER: dict[str, tuple[int, ...]] = {
    "triangle": tuple(range(3)), "triangle6": tuple(range(6)),
    "quad": tuple(range(4)), "quad9": tuple(range(9)),
    "tetra": tuple(range(4)), "tetra10": tuple(range(10)),
    "hexahedron": _HEX[:8], "hexahedron27": _HEX,
}

#: VTK's local nodes under the mirror ``xi <-> eta`` of its reference cell: a
#: cell whose corners are numbered left-handed (scikit-fem's ``init_tensor``
#: tetrahedra are, one in two) is listed so, right-handed (a positive volume in VTK)
MIRROR: dict[str, tuple[int, ...]] = {
    "tetra": (0, 2, 1, 3), "tetra10": (0, 2, 1, 3, 6, 5, 4, 7, 9, 8),
    "hexahedron": (0, 3, 2, 1, 4, 7, 6, 5),
    "hexahedron27": (0, 3, 2, 1, 4, 7, 6, 5, 11, 10, 9, 8, 15, 14, 13, 12, 16, 19, 18, 17,
                     22, 23, 20, 21, 24, 25, 26),
    "triangle": (0, 2, 1), "triangle6": (0, 2, 1, 5, 4, 3),
    "quad": (0, 3, 2, 1), "quad9": (0, 3, 2, 1, 7, 6, 5, 4, 8),
}

#: the VTK corners spanning a cell's Jacobian at corner 0 (its sign: the handedness)
_SPAN = {"tetra": (1, 2, 3), "tetra10": (1, 2, 3), "hexahedron": (1, 3, 4),
         "hexahedron27": (1, 3, 4), "triangle": (1, 2), "triangle6": (1, 2),
         "quad": (1, 3), "quad9": (1, 3)}

#: scikit-fem scalar element class name -> meshio (VTK) cell type
CELL_TYPES: dict[str, str] = {
    "ElementTriP1": "triangle", "ElementTriP2": "triangle6",
    "ElementQuad1": "quad", "ElementQuad2": "quad9",
    "ElementTetP1": "tetra", "ElementTetP2": "tetra10",
    "ElementHex1": "hexahedron", "ElementHex2": "hexahedron27",
}


def _scalar_element(elem: Any) -> Any:
    """The scalar element of ``elem`` (the element itself, or an ``ElementVector``'s)."""
    return getattr(elem, "elem", elem)


#: the cell types :func:`vtk_cells` reorders (a 3D body's cells come in
#: scikit-fem's local order; 2D cells are written as they are given)
REORDERED = ("tetra", "tetra10", "hexahedron", "hexahedron27")


def vtk_order(points: np.ndarray, cell: str, conn: np.ndarray) -> np.ndarray:
    """One cell block from scikit-fem's local node order to VTK's.

    ``conn_vtk[:, i] = conn[:, VTK_ORDER[cell][i]]``, then the rows of left-handed
    cells (a negative Jacobian at VTK's corner 0) listed mirrored (:data:`MIRROR`).

    Parameters
    ----------
    points : (N, d) array
        Node coordinates (``d`` = 2 or 3; a zero z column is allowed).
    cell : str
        A meshio cell type of :data:`VTK_ORDER`.
    conn : (n_el, n_loc) int array
        Node numbers of each element in scikit-fem's local order.
    """
    conn = np.asarray(conn, dtype=np.int64)[:, list(VTK_ORDER[cell])]
    d = len(_SPAN[cell])
    x = np.asarray(points, dtype=float)[conn[:, [0, *_SPAN[cell]]]][:, :, :d]
    left = np.linalg.det(x[:, 1:] - x[:, :1]) < 0
    if left.any():
        conn[left] = conn[left][:, list(MIRROR[cell])]
    return np.ascontiguousarray(conn)


def vtk_cells(points: np.ndarray, cells: list) -> list:
    """The cell blocks an output gives (scikit-fem's local order, the
    :class:`~skfem_mortar.core.item.Output` protocol) in VTK's order: the 3D
    types of :data:`REORDERED` by :func:`vtk_order`, the others as they are."""
    return [(c, vtk_order(points, c, conn) if c in REORDERED else conn) for c, conn in cells]


def basis_cells(basis: Any) -> tuple[np.ndarray, list[tuple[str, np.ndarray]]]:
    """The nodes of a (scalar or vector) Lagrange basis and its elements as VTK cells.

    Parameters
    ----------
    basis : skfem.CellBasis
        A basis of one of the elements of :data:`CELL_TYPES` (or an
        ``ElementVector`` of one).

    Returns
    -------
    points : (N, 3) array
        The node locations of the scalar basis (``N`` its dofs; a 2D mesh gets
        ``z = 0``).
    cells : list of one (cell type, (n_el, n_loc) int array)
        The meshio cell block in VTK's node order (:func:`vtk_order`).

    Raises
    ------
    ValueError
        For an element not in :data:`CELL_TYPES`, naming the allowed ones.
    """
    elem = _scalar_element(basis.elem)
    name = type(elem).__name__
    if name not in CELL_TYPES:
        raise ValueError(f"basis element must be one of {sorted(CELL_TYPES)} (or an "
                         f"ElementVector of one), got {name}")
    cell = CELL_TYPES[name]
    if elem is basis.elem:
        edofs, locs = np.asarray(basis.element_dofs), np.asarray(basis.doflocs)
    else:  # the first component's dofs, renumbered as the scalar basis numbers them
        first = np.asarray(basis.split_indices()[0], dtype=np.int64)
        number = np.full(basis.N, -1, dtype=np.int64)
        number[first] = np.arange(first.size)
        n_comp = len(basis.split_indices())
        edofs = number[np.asarray(basis.element_dofs)[::n_comp]]
        locs = np.asarray(basis.doflocs)[:, first]
    points = np.zeros((locs.shape[1], 3))
    points[:, :locs.shape[0]] = locs.T
    return points, [(cell, vtk_order(points, cell, edofs.T))]


def nodal_vectors(basis: Any, u: np.ndarray) -> np.ndarray:
    """A vector basis's dof vector ``u`` as a point field ``(N, d)`` on the nodes
    :func:`basis_cells` gives (``u[split_indices()[c]]`` in column ``c``)."""
    return np.column_stack([np.asarray(u)[np.asarray(i)] for i in basis.split_indices()])
