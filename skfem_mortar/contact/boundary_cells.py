"""A mesh's boundary facets as outward-oriented contact cells, in 2D and 3D.

scikit-fem lists a facet's vertices sorted (``mesh.facets``), so their order carries no
orientation, and its oriented boundaries pick an element side, not a vertex order.  The
vertices of facet ``f`` are read here from its element ``e = f2t[0, f]`` in the
reference element's local facet order (``t[refdom.facets[j], e]`` with ``t2f[j, e] =
f``: cyclic around a quadrilateral facet) and turned over (:func:`~.cell_map.reversal`)
where the facet's area vector at its centre points into the element:

    v . (c_f - c_e) < 0,

``c_f``, ``c_e`` the facet's and the element's vertex centroids (:mod:`.cell_map`: a
line's right-hand normal, a surface cell's ``T_1 x T_2``).  Triangles and tetrahedra
give ``line2`` / ``tri3`` cells, quadrilaterals and hexahedra ``line2`` / ``quad4``.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .cell_map import area_vectors, cell_tangents, reversal
from .cells import CellType, cell_type

__all__ = ["boundary_cells", "facet_cell", "closed_surface"]

#: the linear facet cell of each mesh dimension and facet vertex count
_FACET_CELLS = {(2, 2): "line2", (3, 3): "tri3", (3, 4): "quad4"}


def facet_cell(mesh: Any) -> CellType:
    """The linear cell type of the facets of ``mesh`` (line2 in 2D, tri3 on
    tetrahedra, quad4 on hexahedra)."""
    dim = int(mesh.p.shape[0])
    k = len(mesh.elem.refdom.facets[0])
    name = _FACET_CELLS.get((dim, k))
    if name is None:
        raise ValueError(f"mesh must be a 2D or 3D mesh of triangles, quadrilaterals, "
                         f"tetrahedra or hexahedra, got {type(mesh).__name__}")
    return cell_type(name)


def boundary_cells(mesh: Any, facets: np.ndarray) -> tuple[np.ndarray, CellType]:
    """The facets ``facets`` of ``mesh`` as cells whose area vector points out of their
    element.

    Parameters
    ----------
    mesh : skfem.Mesh
        A 2D or 3D mesh (its vertices ``p``, elements ``t``, ``f2t``, ``t2f``).
    facets : int ndarray (n_f,)
        Boundary facet indices.

    Returns
    -------
    conn : int ndarray (n_f, k)
        Mesh vertex indices of each facet, outward (a line's right-hand normal points
        out; a surface cell runs counter-clockwise seen from outside).
    cell : CellType
        ``line2``, ``tri3`` or ``quad4``.
    """
    cell = facet_cell(mesh)
    facets = np.asarray(facets, dtype=np.int64)
    local_facets = np.asarray(mesh.elem.refdom.facets)          # (n_local, k)
    elem = mesh.f2t[0, facets]
    j = np.argmax(mesh.t2f[:, elem] == facets, axis=0)          # local facet of f in e
    conn = mesh.t[local_facets[j].T, elem].T.astype(np.int64)   # (n_f, k), cyclic
    p = np.asarray(mesh.p, dtype=float)
    nv = mesh.elem.refdom.nnodes
    c_e = p[:, mesh.t[:nv, elem]].mean(axis=1)
    c_f = p[:, conn].mean(axis=2)
    centre = np.asarray(cell.ref_nodes)[:, list(cell.corners)].mean(axis=1, keepdims=True)
    v = area_vectors(cell_tangents(p, conn, cell, centre))[..., 0]
    flip = np.sum(v * (c_f - c_e), axis=0) < 0
    conn[flip] = conn[flip][:, list(reversal(cell))]
    return conn, cell


def closed_surface(conn: np.ndarray, cell: "str | CellType", n_nodes: int) -> bool:
    """Whether surface cells (``dim`` 2) close up: every edge is shared by exactly two
    cells, run once each way.

    Raises
    ------
    ValueError
        When an edge is run twice the same way (cells not consistently oriented) or is
        shared by more than two cells (a branching surface).
    """
    cell = cell_type(cell)
    ends = np.array([[e[0], e[-1]] for e in cell.edges])          # (n_edges, 2)
    directed = conn[:, ends].reshape(-1, 2)                        # every cell's edges
    key = directed[:, 0] * n_nodes + directed[:, 1]
    if np.unique(key).size != key.size:
        raise ValueError("surface cells are not consistently oriented: an edge is run "
                         "twice the same way (a cell turned over, or a branching surface)")
    undirected = np.sort(directed, axis=1)
    _, count = np.unique(undirected[:, 0] * n_nodes + undirected[:, 1], return_counts=True)
    return bool(np.all(count == 2))
