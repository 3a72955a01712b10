"""Scene ``block3d``: a homogeneous stretch, shear, or both, of a unit cube (3D).

The cube ``[0, 1]^3`` (``n`` cells a side, its interior nodes moved at random by up to
``distort`` times the cell size; quadratic nodes too, by a quarter of that) is
deformed homogeneously, ``x = F X``:

* ``mode=stretch``: uniaxial.  Frictionless supports ``u_x = 0`` on ``X = 0``, ``u_y = 0``
  on ``Y = 0``, ``u_z = 0`` on ``Z = 0``; the face ``X = 1`` is moved to ``x = stretch``;
  the other faces are free.  ``F = diag(stretch, l, l)`` with the lateral stretch ``l``
  from ``P_yy = P_zz = 0`` (:func:`exact_uniaxial3d`).
* ``mode=shear``: simple shear ``F = I + shear e_x (x) e_y``, prescribed on the whole
  boundary (all three components).
* ``mode=combined``: ``F = diag(stretch, l, l) + shear e_x (x) e_y``, prescribed on the
  whole boundary.

An affine displacement lies in every element's space (isoparametric, so also on
curved cells), its stress is constant, so it is in equilibrium without body force:
every law and element reproduces it to round-off on any mesh, and the mixed
(p2p1) and mean-dilatation (hex1-md) ones with their pressure or mean dilatation
constant too.

Metrics: ``max_displacement_error`` (the largest nodal ``|u_h - u|`` over all nodes,
quadratic ones included, over the largest ``|u|``), ``max_stress_error``
(``max |P - P(F)|_F / |P(F)|_F`` over all quadrature points; ``P(F)`` the law's
stress at the exact ``F``); ``mode=stretch`` also ``nominal_stress`` (the
reaction on ``X = 1`` per unit area) and ``lateral_stretch`` (the mean current
``y`` of the vertices on ``Y = 1``), each with ``_exact`` and ``_error``, against
the closed forms of :func:`exact_uniaxial3d`.
"""
from __future__ import annotations

import numpy as np

from ..bodies.solid import constitutive_law
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from . import Param, Scene, Setup, lame_quantities
from ._meshes3d import box_dofs, box_mesh
from ._scene3d import LAWS, displacement, element_param, law_params, make_solid, \
    memory_quantity
from .block import exact_uniaxial

__all__ = ["SCENE", "build", "exact_uniaxial3d", "deformation"]

MODES = ("stretch", "shear", "combined")


def exact_uniaxial3d(law, stretch: float) -> tuple[float, float]:
    """Lateral stretch ``l`` and nominal stress ``P_xx`` of the uniaxial state of
    ``law`` (a 3D law: NeoHooke, SaintVenantKirchhoff or LinearElastic).

    With ``l_y = l_z = l`` and ``P_yy = P_zz = 0`` the equations are those of the
    plane-stress block (``S_zz = 0`` there gives ``l_z = l_y`` by isotropy), so
    this is :func:`~skfem_mortar.scenes.block.exact_uniaxial` of the law in plane
    stress: neo-Hooke ``mu (l^2 - 1) + lambda ln(stretch l^2) = 0``, SVK
    ``E_yy = -nu E_xx``, linear ``eps_yy = -nu eps_xx``.

    Raises
    ------
    ValueError
        If no such state exists (naming ``stretch`` and its allowed range).
    """
    return exact_uniaxial(law.with_plane("stress"), stretch)


def deformation(mode: str, stretch: float, shear: float, lateral: float) -> np.ndarray:
    """The exact ``F`` (3 x 3) of ``mode`` (module docstring)."""
    F = np.eye(3)
    if mode in ("stretch", "combined"):
        F = np.diag([stretch, lateral, lateral])
    if mode in ("shear", "combined"):
        F[0, 1] = shear
    return F


def _supports(solid, mode: str, stretch: float, G: np.ndarray) -> list:
    """The Dirichlet items: frictionless supports and the moved face (stretch), or the
    whole boundary on ``u = G X`` (shear, combined)."""
    if mode == "stretch":
        return [Dirichlet(solid, boundary=tag, component=k, name=f"support_{tag}")
                for k, tag in enumerate(("left", "bottom", "front"))] + [
                Dirichlet(solid, boundary="right", component=0, value=stretch - 1.0,
                          name="pull")]
    dofs = np.unique(np.concatenate([solid.dofs_on(t) for t in solid.mesh.boundaries]))
    X = solid.basis.doflocs[:, dofs]
    value = np.einsum("ij,jn->in", G, X)[solid.dof_component[dofs], np.arange(dofs.size)]
    return [Dirichlet(solid, dofs, value, name="boundary")]


def build(params: dict, method: str | None = None) -> Setup:
    """Model, metrics and outputs of the block (``method`` is unused: no contact)."""
    mode, stretch, shear = params["mode"], float(params["stretch"]), float(params["shear"])
    n = int(params["n"])
    mesh = box_mesh(params["element"], (n, n, n), distort=float(params["distort"]))
    solid = make_solid(mesh, params, "block")
    material = LAWS[params["law"]](E=float(params["E"]), nu=float(params["nu"]))
    law, _ = constitutive_law(material, params["kinematics"], "strain")
    lateral, pxx = exact_uniaxial3d(law, stretch) if mode != "shear" else (1.0, 0.0)
    F = deformation(mode, stretch, shear, lateral)
    G = F - np.eye(3)
    model = Model([solid, *_supports(solid, mode, stretch, G)])
    u_exact = G @ solid.basis.doflocs
    scale = float(np.abs(u_exact).max())
    P_exact = law.stress(F.reshape(3, 3, 1, 1))
    right = solid.dofs_on("right", 0)
    top = np.unique(mesh.facets[:, mesh.boundaries["top"]])

    def metrics(result) -> dict:
        z = result.z
        u = displacement(solid, z)
        err = np.abs(u - u_exact[solid.dof_component[:u.size], np.arange(u.size)]).max()
        _, P = solid.first_piola(z)
        dev = np.sqrt(np.sum((P - P_exact) ** 2, axis=(0, 1)))
        out = {"max_displacement_error": float(err) / scale,
               "max_stress_error": float(dev.max() / np.sqrt(np.sum(P_exact ** 2)))}
        if mode == "stretch":
            s = solid.reaction(result.residual(), right)       # per unit reference area
            ly = float(np.mean(solid.x(z)[1, top]))
            out.update({"nominal_stress": s, "nominal_stress_exact": pxx,
                        "nominal_stress_error": abs(s - pxx) / abs(pxx),
                        "lateral_stretch": ly, "lateral_stretch_exact": lateral,
                        "lateral_stretch_error": abs(ly - lateral) / lateral})
        return out

    return Setup(model=model, metrics=metrics)


def estimate_dofs(params: dict) -> int:
    """Displacement dofs of the cube (no mesh built)."""
    n = int(params["n"])
    return box_dofs(params["element"], (n, n, n))


def derived(params: dict) -> list:
    """The Lame parameters of ``E`` and ``nu`` and the run's estimated memory."""
    return [*lame_quantities(float(params["E"]), float(params["nu"])),
            memory_quantity(estimate_dofs(params), "n")]


SCENE = Scene(
    name="block3d",
    summary="Unit cube in a homogeneous stretch, shear or both, every 3D law and element "
            "on a distorted mesh: exact to round-off (3D).",
    params=(
        Param("mode", "stretch", "uniaxial stretch on frictionless supports, simple shear, "
              "or both (the last two prescribed on the whole boundary)", str, choices=MODES),
        Param("stretch", 1.5, "stretch of the block along x (< 1 compresses)", float,
              low=0.1, high=10.0),
        Param("shear", 0.5, "simple shear gamma: x += gamma Y", float, low=-10.0, high=10.0),
        *law_params("finite"),
        element_param("hex1"),
        Param("n", 3, "cells along each side (hex1: 3 (n + 1)^3 dofs; quadratic: as hex1 "
              "at 2 n)", int, low=1, high=512),
        Param("distort", 0.1, "random interior node shift, as a fraction of the cell size",
              float, low=0.0, high=0.15, high_inclusive=False),
    ),
    build=build,
    methods=(None,),
    default_steps=4,
    estimate_dofs=estimate_dofs,
    sizes=("n",),
    derived=derived,
    one_step=lambda values, method: values["kinematics"] == "small",
    one_step_text="at small strain (a linear problem)",
)
