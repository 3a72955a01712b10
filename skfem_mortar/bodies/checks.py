"""Input checks that belong to no single item: mesh validity (2D and 3D), the
element named for a mesh, the quadrature order.

scikit-fem integrates with ``|det J|``, so an element whose vertices are listed
in the wrong order (a folded mesh) or an element of zero area is not caught by
the assembly: the results are silently wrong or non-finite.
:func:`check_mesh` finds both before anything is assembled.
"""
from __future__ import annotations

import numpy as np

from ..core.validate import count

__all__ = ["check_mesh", "check_mesh_3d", "check_element", "signed_areas", "quadrature_order",
           "check_boundary_facets", "MAX_INTORDER", "SERENDIPITY"]

#: the highest quadrature order: scikit-fem's triangle rules stop at 19 (above,
#: it raises NotImplementedError deep in the basis)
MAX_INTORDER = 19

#: an element is degenerate below this fraction of the mean element area
AREA_TOL = 1e-12
#: a sliver: area below this fraction of its longest edge squared (aspect
#: ratio above ~1e7).  Its stiffness across the short side is ~1/ratio times
#: the others' and the contact segments on it are as short: measured on two
#: blocks in contact with one column of nodes moved next to another
#: (tests/test_extremes.py), ratio 1e-6 converges to round-off for every method,
#: 1e-8 fails for nts and mortar (dual at 1e-9), each after 25 iterations
#: and every step cut; such a mesh is refused before anything is assembled
SLIVER_TOL = 1e-7


def _corners(mesh) -> np.ndarray:
    nv = 3 if "Tri" in type(mesh).__name__ else 4
    return np.asarray(mesh.p, dtype=float)[:, mesh.t[:nv]]      # (2, nv, n_el)


def signed_areas(mesh) -> np.ndarray:
    """Signed area of every element from its corner vertices (shoelace formula),
    > 0 for counter-clockwise corners (skfem accepts either order)."""
    c = _corners(mesh)
    x, y = c[0], c[1]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0)


def check_mesh(mesh, name: str = "mesh") -> None:
    """Raise ValueError for a mesh with inverted (folded), zero-area, non-convex or
    non-finite elements.

    skfem accepts elements listed clockwise or counter-clockwise, so an
    inverted element is found by a fold: the two elements on an interior
    facet must lie on opposite sides of it.  Every element area must exceed
    ``AREA_TOL`` times the mean and ``SLIVER_TOL`` times its longest edge
    squared, and a quadrilateral must be convex (its four corner turns of one
    sign).

    Parameters
    ----------
    mesh : skfem.Mesh
        A 2D triangle or quadrilateral mesh.
    name : str
        Used in the message.
    """
    p = np.asarray(mesh.p, dtype=float)
    if not np.all(np.isfinite(p)):
        raise ValueError(f"{name}: node coordinates must be finite "
                         f"({int(np.sum(~np.isfinite(p).all(axis=0)))} non-finite nodes)")
    a = signed_areas(mesh)
    if a.size == 0:
        raise ValueError(f"{name}: the mesh has no elements")
    scale = float(np.mean(np.abs(a)))
    zero = np.flatnonzero(np.abs(a) <= AREA_TOL * scale)
    if zero.size:
        raise ValueError(f"{name}: {zero.size} element(s) of zero area (e.g. element "
                         f"{int(zero[0])}); every element area must exceed {AREA_TOL:g} "
                         f"times the mean")
    c = _corners(mesh)
    edges = np.roll(c, -1, axis=1) - c
    longest = np.max(edges[0] ** 2 + edges[1] ** 2, axis=0)
    sliver = np.flatnonzero(np.abs(a) < SLIVER_TOL * longest)
    if sliver.size:
        k = int(sliver[0])
        raise ValueError(f"{name}: {sliver.size} sliver element(s) (e.g. element {k}, area / "
                         f"longest edge^2 = {abs(a[k]) / longest[k]:.2g}); every element must "
                         f"have area / longest edge^2 >= {SLIVER_TOL:g} (nearly coincident "
                         f"nodes?)")
    if c.shape[1] == 4:
        d_next = np.roll(c, -1, axis=1) - c
        d_prev = np.roll(c, 1, axis=1) - c
        turn = d_next[0] * d_prev[1] - d_next[1] * d_prev[0]     # (4, n_el)
        bad = np.flatnonzero(np.any(turn * np.sign(a) <= 0, axis=0))
        if bad.size:
            raise ValueError(f"{name}: {bad.size} non-convex or bow-tie quadrilateral(s) "
                             f"(e.g. element {int(bad[0])}): every quadrilateral must be convex")
    f2t = mesh.f2t
    inner = np.flatnonzero(f2t[1] >= 0)
    f = mesh.facets[:, inner]
    x0, x1 = p[:, f[0]], p[:, f[1]]
    cen = c.mean(axis=1)                                          # (2, n_el)
    t = x1 - x0

    def side(e):
        d = cen[:, e] - x0
        return t[0] * d[1] - t[1] * d[0]
    folded = inner[side(f2t[0, inner]) * side(f2t[1, inner]) >= 0]
    if folded.size:
        e = f2t[:, folded[0]]
        raise ValueError(f"{name}: inverted element(s): elements {int(e[0])} and {int(e[1])} "
                         f"lie on the same side of their shared facet {int(folded[0])} "
                         f"({folded.size} such facets); the mesh folds over itself")


def quadrature_order(value: object, low: int) -> int:
    """``intorder`` checked: an integer (``2.0`` refused) in ``[low, MAX_INTORDER]``,
    ValueError naming it, the bound and why otherwise."""
    order = count("intorder", value, low)
    if order > MAX_INTORDER:
        raise ValueError(f"intorder must be at most {MAX_INTORDER} (scikit-fem has no "
                         f"higher triangle rule), got {order}")
    return order


def check_boundary_facets(mesh, facets: np.ndarray, boundary: object, name: str = "boundary"
                          ) -> None:
    """ValueError unless ``facets`` (of the tag or indices ``boundary``) is not empty, lists
    each facet once and holds boundary facets only, each belonging to exactly one element
    (a facet between two elements is inside the body: a surface or a load on it would act
    on the body from within; a facet listed twice would count twice).  The message names
    ``name`` and the tag."""
    which = f"{name} {boundary!r}" if isinstance(boundary, str) else name
    if facets.size == 0:
        raise ValueError(f"{which} must contain at least one facet")
    twice = np.flatnonzero(np.bincount(facets) > 1)
    if twice.size:
        raise ValueError(f"{which} must list each facet once: facet {int(twice[0])} is "
                         f"listed more than once ({twice.size} such)")
    inner = facets[mesh.f2t[1, facets] >= 0]
    if inner.size:
        raise ValueError(f"{which} must hold boundary facets, each belonging to exactly one "
                         f"element: {inner.size} of its {facets.size} facets are interior "
                         f"(e.g. facet {int(inner[0])}, shared by elements "
                         f"{int(mesh.f2t[0, inner[0]])} and {int(mesh.f2t[1, inner[0]])})")


#: names a user may try for the 20-node (serendipity) hexahedron, refused naming hex2
SERENDIPITY = ("hex20", "hexs2", "hex2s", "hexahedron20", "serendipity")

#: a reference domain's cells, in words, and its skfem meshes
_KINDS = {"RefTri": ("triangles", "MeshTri"), "RefQuad": ("quadrilaterals", "MeshQuad"),
          "RefTet": ("tetrahedra", "MeshTet1 or MeshTet2"),
          "RefHex": ("hexahedra", "MeshHex1 or MeshHex2")}


def _serendipity(what: str) -> ValueError:
    return ValueError(f"{what}: 20-node (serendipity) hexahedra are not supported; use "
                      f"element 'hex2' (27-node hexahedra: MeshHex2, meshio 'hexahedron27')")


def check_element(mesh, element: object, refdoms: dict[str, str]) -> None:
    """ValueError unless ``element`` is a name of ``refdoms`` (element name -> the
    reference domain of its mesh, e.g. ``"RefTet"``) and ``mesh`` a scikit-fem mesh
    of that domain.  The messages list the allowed names (all, or those that fit
    the mesh); serendipity hexahedra (a name of :data:`SERENDIPITY`, a meshio mesh
    with ``hexahedron20`` cells, a mesh of ``ElementHexS2``) are refused naming hex2."""
    from skfem import ElementHexS2, Mesh

    if isinstance(element, str) and element.lower() in SERENDIPITY:
        raise _serendipity(f"element {element!r}")
    if not isinstance(element, str) or element not in refdoms:
        raise ValueError(f"element must be one of {sorted(refdoms)} (got {element!r})")
    if "hexahedron20" in (getattr(mesh, "cells_dict", None) or {}):
        raise _serendipity("mesh holds hexahedron20 cells")
    if not isinstance(mesh, Mesh):
        raise ValueError(f"mesh must be a skfem Mesh (MeshTri, MeshQuad, MeshTet1, MeshTet2, "
                         f"MeshHex1 or MeshHex2), got {type(mesh).__name__}")
    if mesh.elem is ElementHexS2:
        raise _serendipity(f"mesh ({type(mesh).__name__})")
    have, need = mesh.elem.refdom.__name__, refdoms[element]
    if have != need:
        fits = sorted(k for k, v in refdoms.items() if v == have)
        kind, meshes = _KINDS[need]
        dim = "3D" if need in ("RefTet", "RefHex") else "2D"
        raise ValueError(f"element {element!r} needs a {dim} mesh of {kind} ({meshes}), got "
                         f"{type(mesh).__name__}; element must be one of {fits} for it")


def check_mesh_3d(mesh, name: str = "mesh") -> None:
    """Raise ValueError, naming the elements or nodes, for a 3D mesh with non-finite
    nodes, unreferenced nodes, flat or inverted elements.

    scikit-fem integrates with ``|det J|`` and its own generators list elements in
    either orientation, so orientation is no test.  An element is flat when
    ``|det J|`` at its centre is below ``AREA_TOL`` times the mean; inverted when
    ``det J`` at its corners changes sign (a hexahedron turned inside out) or when
    it and its neighbour across an interior facet lie on the same side of the facet
    (the mesh folds over itself).

    Parameters
    ----------
    mesh : skfem.Mesh
        A tetrahedral or hexahedral mesh (linear or quadratic).
    name : str
        Used in the message.
    """
    p = np.asarray(mesh.p, dtype=float)
    bad = np.flatnonzero(~np.isfinite(p).all(axis=0))
    if bad.size:
        raise ValueError(f"{name}: node coordinates must be finite (nodes {bad[:10].tolist()}"
                         f"{' ...' if bad.size > 10 else ''})")
    if mesh.nelements == 0:
        raise ValueError(f"{name}: the mesh has no elements")
    used = np.zeros(p.shape[1], dtype=bool)
    used[np.asarray(mesh.dofs.element_dofs).ravel()] = True
    free = np.flatnonzero(~used)
    if free.size:
        raise ValueError(f"{name}: {free.size} node(s) belong to no element (nodes "
                         f"{free[:10].tolist()}{' ...' if free.size > 10 else ''}): "
                         f"remove them (unreferenced nodes have no stiffness)")
    ref = np.asarray(mesh.elem.doflocs, dtype=float).T                # (3, n_nodes_loc)
    nv = mesh.t.shape[0]
    corners = np.concatenate([ref[:, :nv], ref[:, :nv].mean(axis=1, keepdims=True)], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):         # skfem inverts J of flat ones
        det = np.asarray(mesh.mapping().detDF(corners))             # (n_el, nv + 1)
    flat = np.flatnonzero(np.abs(det[:, -1]) <= AREA_TOL * np.mean(np.abs(det[:, -1])))
    if flat.size:
        raise ValueError(f"{name}: {flat.size} element(s) of zero volume (elements "
                         f"{flat[:10].tolist()}); every element volume must exceed "
                         f"{AREA_TOL:g} times the mean")
    turned = np.flatnonzero(np.any(det[:, :nv] * det[:, -1:] <= 0.0, axis=1))
    if turned.size:
        raise ValueError(f"{name}: {turned.size} inverted element(s) (elements "
                         f"{turned[:10].tolist()}): det J changes sign inside them (corners "
                         f"listed in the wrong order, or an element turned inside out)")
    _check_folds(mesh, p, name)


def _check_folds(mesh, p: np.ndarray, name: str) -> None:
    """ValueError naming the elements when the two elements of an interior facet lie on
    the same side of it (the facet's plane through its centre, normal from three of
    its corners)."""
    f2t = mesh.f2t
    inner = np.flatnonzero(f2t[1] >= 0)
    if inner.size == 0:
        return
    f = mesh.facets[:, inner]
    x = p[:, f]                                                       # (3, nf, n)
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], axis=0)
    centre = x.mean(axis=1)
    cen = p[:, mesh.t].mean(axis=1)                                   # (3, n_el)
    side = [np.sum(normal * (cen[:, f2t[k, inner]] - centre), axis=0) for k in (0, 1)]
    folded = inner[side[0] * side[1] >= 0]
    if folded.size:
        e = f2t[:, folded[0]]
        raise ValueError(f"{name}: inverted element(s): elements {int(e[0])} and {int(e[1])} "
                         f"lie on the same side of their shared facet {int(folded[0])} "
                         f"({folded.size} such facets); the mesh folds over itself")
