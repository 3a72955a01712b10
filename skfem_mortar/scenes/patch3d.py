"""Scene ``patch3d``: the 3D contact patch test (issue 38).

Two stacked non-matching blocks under a uniform follower pressure, the upper
block's footprint on grid lines of the lower block's top, the uncovered top
loaded by the same pressure, rollers on each block's mid-planes
(:mod:`~skfem_mortar.scenes._patch3d`: the blocks, the exact uniaxial state at
small and finite strain, the readings).  ``--method`` picks the contact method
(mortar by default; NTS fails the non-matching patch test and reports by how
much); ``n_gauss`` is the mortar cells' Gauss rule.  Metrics: ``pressure_error``,
``displacement_error``, ``contact_force``, ``force_balance``, ``support_reaction``
(each with ``_exact``/``_error`` where it has one).
"""
from __future__ import annotations

from ..contact.pair import ContactPair
from ..contact.surfaces import ContactSurface
from ..core.model import Model
from . import METHODS, Param, Scene, Setup
from ._patch3d import (PARAMS, build_bodies, derived, displacement_error, estimate_dofs,
                       exact_patch3d, patch_metrics)

__all__ = ["SCENE", "build"]


def build(params: dict, method: str | None = None) -> Setup:
    """Both blocks, their pressures and rollers, and the contact pair of the footprint;
    the readings of :func:`~skfem_mortar.scenes._patch3d.patch_metrics`."""
    parts, exact = build_bodies(params), exact_patch3d(params)
    method = method or "mortar"
    slave = ContactSurface.from_solid(*parts.slave, name="slave_face")
    master = ContactSurface.from_solid(*parts.master, name="master_face")
    options = {} if method == "nts" else {"n_gauss": int(params["n_gauss"])}
    pair = ContactPair(slave, master, method, name="contact", **options)
    model = Model(parts.items + [pair], geometry="3d")

    def metrics(result) -> dict:
        z = result.z
        f_slave, f_master = pair.forces(z)
        reaction = parts.lower.reaction(result.residual(), parts.support)
        return patch_metrics(exact, pair.pressure_and_gap(z)[0], f_slave.sum(axis=1),
                             f_master.sum(axis=1), reaction,
                             displacement_error(parts, exact, z))

    return Setup(model=model, metrics=metrics)


SCENE = Scene(
    name="patch3d",
    summary="3D contact patch test: two stacked non-matching blocks under a uniform "
            "pressure, exact contact pressure p on tet1/hex1 faces (3D).",
    params=PARAMS + (Param("n_gauss", 5, "mortar only: degree of the Gauss rule on each "
                           "integration cell", int, low=1, high=20),),
    build=build,
    methods=METHODS,
    default_steps=1,
    estimate_dofs=estimate_dofs,
    sizes=("n_lower", "n_upper"),
    derived=derived,
)
