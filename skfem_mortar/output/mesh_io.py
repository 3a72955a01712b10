"""Meshes from files: meshio's formats (gmsh ``.msh`` among them) read into a
scikit-fem mesh with its tagged boundaries.

The volume cells make the mesh (``tetra``, ``tetra10``, ``hexahedron``,
``hexahedron27``; in 2D ``triangle``, ``triangle6``, ``quad``, ``quad9``) through
scikit-fem's own reader (:func:`skfem.io.meshio.from_meshio`, which reorders
meshio's hexahedra to scikit-fem's node order).  Each tagged boundary cell (a
linear or quadratic triangle or quadrilateral in 3D, a line in 2D) is found
among the mesh's facets by its corner nodes (the set of them: a facet's node
order carries no orientation, and a quadratic facet's other nodes follow from
its corners), so that ``mesh.boundaries[name]`` holds facet indices that
``Solid.dofs_on``, ``Dirichlet(..., boundary=name)`` and the loads take.
The tags' names come from the file (gmsh's physical names, or meshio's cell
sets); an unnamed gmsh tag is named by its number.  Points no volume cell uses
(gmsh writes its geometry's points too) are dropped, and the nodes renumbered.
"""
from __future__ import annotations

import os
from typing import Any

import numpy as np

__all__ = ["read_mesh", "VOLUME_CELLS", "FACET_CELLS"]

#: the volume cell types, by dimension, in the order they are looked for
VOLUME_CELLS = {3: ("tetra", "tetra10", "hexahedron", "hexahedron27"),
                2: ("triangle", "triangle6", "quad", "quad9")}

#: facet cell type -> its number of corner nodes (meshio lists the corners first)
FACET_CELLS = {"triangle": 3, "triangle6": 3, "triangle7": 3, "quad": 4, "quad8": 4,
               "quad9": 4, "line": 2, "line3": 2}


def _volume_type(m: Any) -> tuple[str, int]:
    """The volume cell type of a meshio mesh (one only) and its dimension."""
    for dim in (3, 2):
        found = [c for c in VOLUME_CELLS[dim] if c in m.cells_dict]
        if len(found) > 1:
            raise ValueError(f"path: the mesh mixes {found} cells; one type per mesh")
        if found:
            return found[0], dim
    have = sorted(m.cells_dict)
    if "hexahedron20" in have:
        raise ValueError("path: serendipity hexahedra (hexahedron20, 20 nodes) are not "
                         "supported; mesh with 27-node hexahedra (hex2: gmsh "
                         "Mesh.SecondOrderIncomplete = 0)")
    raise ValueError(f"path: no volume cells of {VOLUME_CELLS[3] + VOLUME_CELLS[2]} in the "
                     f"mesh (it has {have})")


def _tag_names(m: Any) -> dict[int, str]:
    """gmsh physical tag -> name (``field_data``), unnamed tags by their number."""
    return {int(v[0]): str(k) for k, v in (m.field_data or {}).items()}


def _tagged_facets(m: Any, dim: int) -> dict[str, list[np.ndarray]]:
    """Name -> list of (n, corners) node arrays of the tagged boundary cells."""
    out: dict[str, list[np.ndarray]] = {}
    facet_types = [c for c, k in FACET_CELLS.items() if (k >= 3) == (dim == 3)]
    names = _tag_names(m)
    phys = m.cell_data.get("gmsh:physical")
    for i, block in enumerate(m.cells):
        if block.type not in facet_types:
            continue
        corners = np.asarray(block.data)[:, :FACET_CELLS[block.type]]
        if phys is not None:
            tags = np.asarray(phys[i]).astype(np.int64)
            for tag in np.unique(tags):
                out.setdefault(names.get(int(tag), str(int(tag))), []).append(
                    corners[tags == tag])
    for name, sets in (m.cell_sets or {}).items():   # meshio's named sets
        if name.startswith("gmsh:") or name in out:
            continue
        for i, idx in enumerate(sets):
            block = m.cells[i]
            if idx is not None and len(idx) and block.type in facet_types:
                out.setdefault(name, []).append(
                    np.asarray(block.data)[np.asarray(idx), :FACET_CELLS[block.type]])
    return out


def _facet_index(mesh: Any, corners: np.ndarray, name: str) -> np.ndarray:
    """Indices of the mesh facets with the given corner nodes (in any order)."""
    facets = np.sort(np.asarray(mesh.facets), axis=0)             # (k, nf) corners sorted
    want = np.sort(corners, axis=1)
    if want.shape[1] != facets.shape[0]:
        raise ValueError(f"path: boundary {name!r} has {want.shape[1]}-corner cells, the "
                         f"mesh's facets have {facets.shape[0]} corners")
    # one integer per corner set (sorted corners: the key is the set's), numbered by
    # np.unique over the rows: no positional base that overflows int64 on quad facets
    _, ids = np.unique(np.vstack([facets.T, want]), axis=0, return_inverse=True)
    ids = ids.ravel()
    key, wkey = ids[:facets.shape[1]], ids[facets.shape[1]:]
    order = np.argsort(key)
    pos = np.searchsorted(key[order], wkey)
    pos = np.minimum(pos, len(order) - 1)
    found = key[order][pos] == wkey
    if not found.all():
        k = int(np.flatnonzero(~found)[0])
        raise ValueError(f"path: boundary {name!r}: {int((~found).sum())} of its cells are "
                         f"no facet of the mesh (e.g. the one with corners "
                         f"{want[k].tolist()})")
    return order[pos].astype(np.int64)


def read_mesh(path: str | os.PathLike | Any) -> Any:
    """A scikit-fem mesh and its tagged boundaries from a file meshio reads.

    Parameters
    ----------
    path : path or meshio.Mesh
        The file (gmsh ``.msh`` 2.2 or 4.1, VTU, ...) or a mesh meshio read.

    Returns
    -------
    skfem.Mesh
        ``MeshTet1``, ``MeshTet2``, ``MeshHex1``, ``MeshHex2`` (or a 2D mesh) whose
        ``boundaries`` map each tag's name to its facet indices (module docstring)
        and whose ``subdomains`` map each tagged volume's name to its elements.

    Raises
    ------
    ValueError
        Naming ``path``: no volume cells or several types, serendipity
        hexahedra, a tagged boundary cell that is no facet of the mesh.
    """
    import meshio
    from skfem.io.meshio import INV_HEX_MAPPING, from_meshio

    m = path if isinstance(path, meshio.Mesh) else meshio.read(path)
    cell, dim = _volume_type(m)
    used = np.unique(np.concatenate([np.asarray(b.data).ravel() for b in m.cells
                                     if b.type == cell]))
    number = np.full(len(m.points), -1, dtype=np.int64)
    number[used] = np.arange(used.size)
    vol = [(i, b) for i, b in enumerate(m.cells) if b.type == cell]
    phys = m.cell_data.get("gmsh:physical")
    sub_tags = np.concatenate([np.asarray(phys[i]) for i, _ in vol]) if phys else None
    vmesh = meshio.Mesh(np.asarray(m.points)[used, :dim],
                        [(cell, number[np.concatenate([np.asarray(b.data) for _, b in vol])])])
    mesh = from_meshio(vmesh)
    # scikit-fem numbers a quadratic mesh's vertices first: the file's node of each
    # vertex, by the cells' corners (scikit-fem's rows are meshio's columns ``rows``)
    rows = list(INV_HEX_MAPPING[:8]) if cell.startswith("hexahedron") else \
        list(range(mesh.t.shape[0]))
    vertex = np.full(used.size, -1, dtype=np.int64)
    vertex[vmesh.cells[0].data[:, rows].T] = mesh.t
    boundaries = {}
    for name, blocks in _tagged_facets(m, dim).items():
        corners = number[np.concatenate(blocks)]
        corners = np.where(corners >= 0, vertex[corners], -1)
        boundaries[name] = np.unique(_facet_index(mesh, corners, name))
    names = _tag_names(m)
    subdomains = ({names.get(int(t), str(int(t))): np.flatnonzero(sub_tags == t)
                   for t in np.unique(sub_tags)} if sub_tags is not None else None)
    return type(mesh)(mesh.doflocs, mesh.t, boundaries or None, subdomains or None)
