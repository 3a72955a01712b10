"""The model's geometry: ``"plane"`` (plane strain or stress, per unit thickness),
``"axisymmetric"`` (coordinates ``(r, z) = (x, y)``, the axis at ``r = 0``,
integrals over the full revolution) or ``"3d"``.

:class:`~skfem_mortar.core.model.Model` hands its geometry to its items at
every use, as it hands them its thickness (:attr:`Item.geometry
<skfem_mortar.core.item.Item.geometry>`); an item declares the geometries it
works in (:attr:`Item.geometries <skfem_mortar.core.item.Item.geometries>`,
``None``: any), and a model refuses an item built for another geometry,
naming it.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

if TYPE_CHECKING:
    from .item import Item

__all__ = ["GEOMETRIES", "model_geometry"]

#: the geometries a model may have
GEOMETRIES = ("plane", "axisymmetric", "3d")


def model_geometry(geometry: str | None, items: Sequence["Item"], thickness: float) -> str:
    """The geometry of a model of ``items``: ``geometry`` checked, or (``None``)
    ``"3d"`` when an item works only in 3D (a body on a 3D mesh), else ``"plane"``.

    Raises
    ------
    ValueError
        ``geometry`` not one of :data:`GEOMETRIES`; an item whose
        :attr:`~skfem_mortar.core.item.Item.geometries` does not hold it (naming
        the item and what it was built for); a ``thickness`` other than 1 in an
        axisymmetric or 3D model (it has no thickness).
    """
    if geometry is None:
        only3d = any(getattr(it, "geometries", None) == ("3d",) for it in items)
        geometry = "3d" if only3d else "plane"
    if not isinstance(geometry, str) or geometry not in GEOMETRIES:
        raise ValueError(f"geometry must be one of {', '.join(map(repr, GEOMETRIES))}, "
                         f"got {geometry!r}")
    if geometry != "plane" and thickness != 1.0:
        article = "an" if geometry == "axisymmetric" else "a"
        raise ValueError(f"thickness applies to a plane model only; {article} {geometry!r} "
                         f"model has none (got thickness={thickness:g}): leave it out")
    _refuse_mixed_dimensions(items)
    for it in items:
        allowed = getattr(it, "geometries", None)
        if allowed is not None and geometry not in allowed:
            tail = (f"build it for that geometry or give the model geometry={allowed[0]!r}"
                    if "3d" not in (geometry, *allowed) else
                    "it has no form in that geometry (a 3D model holds 3D bodies: Solid on "
                    "a 3D mesh, and their loads and supports)" if geometry == "3d" else
                    "a body on a 3D mesh works in a '3d' model only")
            raise ValueError(
                f"item {getattr(it, 'name', '')!r} ({type(it).__name__}) works in a "
                f"{' or '.join(map(repr, allowed))} geometry, and this model's geometry "
                f"is {geometry!r}: {tail}")
    return geometry


def _refuse_mixed_dimensions(items: Sequence["Item"]) -> None:
    """ValueError naming ``items`` and the bodies when 3D bodies (``geometries ==
    ("3d",)``) and bodies built for 2D geometries are in one model."""
    bodies = [it for it in items if getattr(it, "dof_kind", None) == "u"
              and getattr(it, "geometries", None) is not None]
    three = [it for it in bodies if "3d" in it.geometries]
    two = [it for it in bodies if "3d" not in it.geometries]
    if three and two:
        def names(its):
            return ", ".join(f"{getattr(it, 'name', '')!r} ({type(it).__name__})"
                             for it in its)
        raise ValueError(f"items mix 2D and 3D bodies: {names(three)} 3D, {names(two)} 2D "
                         f"(plane or axisymmetric); a model's bodies are all 2D or all 3D")
