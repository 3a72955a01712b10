"""What a solid is built from: the element names (2D, 3D and those of their own
classes) with their scikit-fem elements, the law and its kinematics, the facets of a
boundary, the components by name.  :class:`~skfem_mortar.bodies.solid.Solid` reads
them; the names are offered by :mod:`.solid` as well."""
from __future__ import annotations

import numpy as np
from skfem import (ElementHex1, ElementHex2, ElementQuad1, ElementQuad2, ElementTetP1,
                   ElementTetP2, ElementTriP1, ElementTriP2, Mesh)

from ..core.validate_arrays import index_array
from .checks import check_element
from .materials import PLANES, LinearElastic, Material

__all__ = ["ELEMENTS", "ELEMENTS_3D", "SPECIAL_ELEMENTS", "KINEMATICS", "element_domains",
           "displacement_element", "boundary_facets", "constitutive_law", "refuse_reduction"]

#: the strain measures a solid offers
KINEMATICS = ("finite", "small")

#: element name -> (skfem scalar element class, reference domain name, meshio cell type)
ELEMENTS: dict[str, tuple[type, str, str]] = {
    "tri1": (ElementTriP1, "RefTri", "triangle"),
    "tri2": (ElementTriP2, "RefTri", "triangle"),
    "quad1": (ElementQuad1, "RefQuad", "quad"),
    "quad2": (ElementQuad2, "RefQuad", "quad"),
}

#: the 3D elements: name -> (skfem scalar element class, reference domain name, meshio
#: cell type of the output cells, default quadrature order (``None``: the centroid))
ELEMENTS_3D: dict[str, tuple[type, str, str, int | None]] = {
    "tet1": (ElementTetP1, "RefTet", "tetra", None),
    "tet2": (ElementTetP2, "RefTet", "tetra10", 3),
    "hex1": (ElementHex1, "RefHex", "hexahedron", 3),
    "hex2": (ElementHex2, "RefHex", "hexahedron27", 5),
}

#: the elements of their own classes: name -> (reference domain, the element of their
#: displacements, module, class); ``Solid(..., element=name)`` builds that class (its
#: module imported on first use: this module imports none of them, they import it)
SPECIAL_ELEMENTS: dict[str, tuple[str, str, str, str]] = {
    "p2p1": ("RefTet", "tet2", "skfem_mortar.bodies.taylor_hood", "TaylorHoodSolid"),
    "hex1-md": ("RefHex", "hex1", "skfem_mortar.bodies.mean_dilatation",
                "MeanDilatationSolid"),
}


def element_domains() -> dict[str, str]:
    """Every element name of :class:`Solid` -> the reference domain of its mesh."""
    out = {k: v[1] for k, v in {**ELEMENTS, **ELEMENTS_3D}.items()}
    out.update({k: v[0] for k, v in SPECIAL_ELEMENTS.items()})
    return out


def displacement_element(mesh: Mesh, element: object, own: str, body: str) -> str:
    """For the classes of :data:`SPECIAL_ELEMENTS`: ``element`` checked against
    ``mesh`` (:func:`~skfem_mortar.bodies.checks.check_element`) and equal to the
    class's ``own`` name (ValueError naming ``element`` otherwise); the element of
    its displacements."""
    check_element(mesh, element, element_domains())
    if element != own:
        raise ValueError(f"element must be {own!r} for a {body} (got {element!r}; "
                         f"Solid(..., element={element!r}) builds its class)")
    return SPECIAL_ELEMENTS[own][1]


def boundary_facets(mesh: Mesh, boundary: str | np.ndarray,
                    unknown: str = "unknown boundary {tag!r}; known tags: {known}",
                    name: str = "boundary") -> np.ndarray:
    """Facet indices (int64) of ``boundary``: a tag of ``mesh.boundaries``, facet
    indices as given (flattened), integers in ``[0, mesh.nfacets)``, or a boolean mask
    of shape ``(mesh.nfacets,)`` (its True facets, as scikit-fem users pass them).

    An unknown tag raises ValueError with ``unknown`` formatted with the ``tag`` and
    the sorted ``known`` tags (each caller keeps the wording of its parameter); indices
    that are not integers (``1.5`` is refused, not truncated; a mask of another shape
    too: its 0/1 values were read as facets 0 and 1) or out of range raise
    ValueError naming ``name``.
    """
    # not Mesh.normalize_facets: it sorts index lists (np.unique) and words its own error
    if isinstance(boundary, str):
        known = sorted(mesh.boundaries or {})
        if boundary not in known:
            raise ValueError(unknown.format(tag=boundary, known=known))
        return np.asarray(mesh.boundaries[boundary], dtype=np.int64)
    mask = np.asarray(boundary)
    if mask.dtype.kind == "b" and mask.shape == (mesh.nfacets,):
        return np.flatnonzero(mask).astype(np.int64)
    return index_array(name, boundary, int(mesh.nfacets)).ravel()


def constitutive_law(material: Material, kinematics: str | None = None,
                     plane: str = "strain") -> tuple[Material, str]:
    """The law a solid evaluates and its kinematics: ``material`` in ``plane``
    (:meth:`~skfem_mortar.bodies.materials.Material.with_plane`), linearized for
    ``kinematics="small"``.

    ``kinematics=None`` is ``"small"`` for a
    :class:`~skfem_mortar.bodies.materials.LinearElastic` material, else
    ``"finite"``.

    Raises
    ------
    ValueError
        ``material`` not a Material; ``kinematics`` not one of
        :data:`KINEMATICS` (or ``"finite"`` with a LinearElastic material: it
        has no finite-strain law); ``plane`` not one of ``"strain"``, ``"stress"``.
    """
    if not isinstance(material, Material):
        raise ValueError("material must be a skfem_mortar.bodies.materials.Material")
    small_law = isinstance(material, LinearElastic)
    if kinematics is None:
        kinematics = "small" if small_law else "finite"
    if not isinstance(kinematics, str) or kinematics not in KINEMATICS:
        raise ValueError(f"kinematics must be one of {', '.join(map(repr, KINEMATICS))} "
                         f"(got {kinematics!r})")
    if small_law and kinematics != "small":
        raise ValueError("kinematics must be 'small' for a LinearElastic material (it is "
                         "the small-strain law; for finite strain use SaintVenantKirchhoff "
                         f"or NeoHooke), got {kinematics!r}")
    if not isinstance(plane, str) or plane not in PLANES:
        raise ValueError(f"plane must be one of {', '.join(map(repr, PLANES))} "
                         f"(got {plane!r})")
    law = material.with_plane(plane)
    return (law.linearized() if kinematics == "small" else law), kinematics


def refuse_reduction(body: str, plane: str | None) -> None:
    """For the bodies that treat the volume apart in 2D (MixedSolid, SRISolid): ValueError
    naming ``plane`` unless it is ``"strain"`` (or None, the default): plane stress does
    not lock, so they have no plane-stress form."""
    if plane is not None and plane != "strain":
        raise ValueError(f"plane must be 'strain' for a {body} (plane stress does not lock: "
                         f"use Solid(..., plane='stress')), got {plane!r}")


def _as_slice(idx: np.ndarray) -> slice | np.ndarray:
    """``idx`` (sorted, distinct) as the slice it is when evenly spaced, else itself."""
    if idx.size == 0:
        return idx
    step = int(idx[1] - idx[0]) if idx.size > 1 else 1
    if np.array_equal(idx, idx[0] + step * np.arange(idx.size)):
        return slice(int(idx[0]), int(idx[-1]) + 1, step)
    return idx


def _component_index(component: int | str | None, dim: int = 2) -> int | None:
    """The component ``0 .. dim - 1`` named by ``component`` (None: all); ValueError
    naming the allowed ones (a bool or a float is refused: ``True == 1``)."""
    if component is None:
        return None
    names = {0: 0, 1: 1, "x": 0, "y": 1} if dim == 2 else \
        {0: 0, 1: 1, 2: 2, "x": 0, "y": 1, "z": 2}
    if not isinstance(component, (str, int, np.integer)) or isinstance(component, (bool, np.bool_)) \
            or component not in names:
        allowed = "0, 1, 'x' or 'y'" if dim == 2 else "0, 1, 2, 'x', 'y' or 'z'"
        raise ValueError(f"component must be None, {allowed} (got {component!r})")
    return names[component]
