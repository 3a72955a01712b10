"""Scene ``hertz3d``: Hertz contact of a sphere in 3D, a quarter or a half (issue 38).

The quarter (or half) of ``hertz_axi``'s hemisphere pressed by a total force on a
rigid plane or an elastic quarter cylinder, graded meshes, the symmetry planes as
rollers that the contact surfaces read (:mod:`~skfem_mortar.scenes._hertz3d`: the
bodies, meshes, Hertz's answer and the readings).  Metrics as ``hertz_axi``'s:
``peak_pressure``, ``contact_radius`` (the fit over the whole sphere's nodes),
``peak_pressure_fit``, ``contact_force`` (times the symmetry factor) against ``F``.
"""
from __future__ import annotations

from ..contact.pair import ContactPair
from ..contact.surfaces import ContactSurface
from ..core.model import Model
from . import METHODS, Scene, Setup
from ._hertz3d import PARAMS, build_bodies, derived, estimate_dofs, exact_hertz3d, hertz_metrics
from .hertz import one_step

__all__ = ["SCENE", "build", "contact_surfaces"]


def contact_surfaces(parts) -> tuple[ContactSurface, ContactSurface]:
    """The sphere's faces (slave) and the master: the rigid plane as quad4 faces, or the
    elastic base's top."""
    slave = ContactSurface.from_solid(*parts.slave, name="sphere_face")
    if parts.base is None:
        return slave, ContactSurface(None, None, parts.master["faces"], X=parts.master["X"],
                                     name="plane", cell="quad4")
    return slave, ContactSurface.from_solid(*parts.master, name="base_top")


def build(params: dict, method: str | None = None) -> Setup:
    """The sphere (and base), load, rollers and the contact pair; Hertz readings."""
    parts, exact = build_bodies(params), exact_hertz3d(params)
    method = method or "nts"
    slave, master = contact_surfaces(parts)
    options = {} if method == "nts" else {"segmentation": params["segmentation"]}
    pair = ContactPair(slave, master, method, name="contact", **options)
    model = Model(parts.items + [pair], geometry="3d")

    def metrics(result) -> dict:
        z = result.z
        pressure = pair.pressure_and_gap(z)[0]         # per slave node, surface order
        out = hertz_metrics(exact, pair.slave.x(z), pressure,
                            float(pair.total_force(z)[2]), parts.symmetry,
                            float(params["load"]))
        out.update({"element_size": parts.h0, "n_active": int(pair.active.sum())})
        return out

    return Setup(model=model, metrics=metrics)


SCENE = Scene(
    name="hertz3d",
    summary="Hertz contact of a sphere in 3D: a quarter (or half) hemisphere pressed by a "
            "total force on an elastic cylinder or a rigid plane, symmetry planes as rollers.",
    params=PARAMS,
    build=build,
    methods=METHODS,
    default_steps=4,
    estimate_dofs=estimate_dofs,
    sizes=("refine",),
    derived=derived,
    one_step=one_step,
    one_step_text="with mortar or mortar-dual and segmentation=iteration",
)
