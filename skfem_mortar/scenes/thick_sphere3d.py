"""Scene ``thick_sphere3d``: a thick-walled sphere under internal pressure (Lame's problem).

The shell ``a <= |X| <= b`` carries the dead pressure ``p`` on its inner sphere (the
reference traction ``p X / a``, pushing outwards); an eighth of it is modelled,
``X, Y, Z >= 0``, with the symmetry conditions ``u_x = 0`` on ``X = 0``, ``u_y = 0``
on ``Y = 0``, ``u_z = 0`` on ``Z = 0``.  The mesh is three mapped hexahedral
patches of a cube-sphere map (each hexahedron split into six tetrahedra for the
tetrahedral elements), ``n x n`` cells a patch and ``n`` through the wall, whose
quadratic nodes lie on the spheres (:func:`~skfem_mortar.scenes._meshes3d.shell_octant`).

Small strain (default), Lame's solution:

    u_r(r) = p a^3 / (E (b^3 - a^3)) ((1 - 2 nu) r + (1 + nu) b^3 / (2 r^2)) .

Finite strain (``kinematics=finite``) departs from it by ``O(p / E)``.

Metrics: ``displacement_l2_error``, ``||u_h - u||_L2 / ||u||_L2`` over the body (by a
quadrature of twice the element's degree plus 2, :func:`~._scene3d.l2_error`);
``inner_radial_displacement`` and ``outer_radial_displacement``, the mean ``u . X / |X|``
over the vertices on each sphere, with ``_exact`` and ``_error`` (relative).  The
L2 error falls at order 2 for tet1 and hex1, 3 for tet2, hex2 and p2p1; hex1-md
at order 2 also as ``nu -> 0.5`` where tet1 locks (tests/test_scenes3d.py).
"""
from __future__ import annotations

import numpy as np

from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..loads.traction import Traction
from . import Param, Scene, Setup, lame_quantities, positive, ratio
from ._meshes3d import shell_dofs, shell_octant
from ._scene3d import displacement, element_param, l2_error, law_params, make_solid, \
    memory_quantity

__all__ = ["SCENE", "build", "lame_radial"]


def lame_radial(r: np.ndarray, a: float, b: float, E: float, nu: float, p: float
                ) -> np.ndarray:
    """Lame's radial displacement ``u_r(r)`` of the thick sphere (module docstring)."""
    r = np.asarray(r, dtype=float)
    return p * a ** 3 / (E * (b ** 3 - a ** 3)) * ((1.0 - 2.0 * nu) * r
                                                   + (1.0 + nu) * b ** 3 / (2.0 * r * r))


def build(params: dict, method: str | None = None) -> Setup:
    """Model, metrics and outputs of the shell (``method`` is unused: no contact)."""
    a, b, p = float(params["a"]), float(params["b"]), float(params["pressure"])
    E, nu = float(params["E"]), float(params["nu"])
    mesh = shell_octant(params["element"], a, b, int(params["n"]))
    solid = make_solid(mesh, params, "shell")
    items = [solid, Traction(solid, "inner", lambda x: p * x / np.linalg.norm(x, axis=0),
                             name="pressure")]
    items += [Dirichlet(solid, boundary=tag, component=k, name=f"symmetry_{tag}")
              for k, tag in enumerate(("x0", "y0", "z0"))]
    model = Model(items)

    def exact(x: np.ndarray) -> np.ndarray:
        r = np.linalg.norm(x, axis=0)
        return lame_radial(r, a, b, E, nu, p) * x / r

    error = l2_error(solid, exact)
    nodes = {tag: np.unique(mesh.facets[:, mesh.boundaries[tag]]) for tag in ("inner", "outer")}

    def metrics(result) -> dict:
        z = result.z
        u = displacement(solid, z)[solid.node_dofs]
        out = {"displacement_l2_error": error(z), "n_dofs": int(solid.basis.N)}
        for tag, r in (("inner", a), ("outer", b)):
            X = solid.X[:, nodes[tag]]
            ur = float(np.mean(np.sum(u[:, nodes[tag]] * X, axis=0) / np.linalg.norm(X, axis=0)))
            ur_exact = float(lame_radial(r, a, b, E, nu, p))
            out.update({f"{tag}_radial_displacement": ur,
                        f"{tag}_radial_displacement_exact": ur_exact,
                        f"{tag}_radial_displacement_error": abs(ur - ur_exact) / ur_exact})
        return out

    return Setup(model=model, metrics=metrics)


def estimate_dofs(params: dict) -> int:
    """Displacement dofs of the shell (no mesh built)."""
    return shell_dofs(params["element"], int(params["n"]))


def derived(params: dict) -> list:
    """The Lame parameters, the pressure, ``b / a`` and the run's estimated memory."""
    a, b = float(params["a"]), float(params["b"])
    return [positive("the inner radius a", a, "a"),
            ratio("the radius ratio b / a", b / a, ("b", "a"), 1.0 + 1e-6, 1e6),
            positive("the pressure", float(params["pressure"]), "pressure"),
            *lame_quantities(float(params["E"]), float(params["nu"])),
            memory_quantity(estimate_dofs(params), "n")]


SCENE = Scene(
    name="thick_sphere3d",
    summary="Thick-walled sphere under a dead internal pressure, an eighth with symmetry "
            "conditions, small strain, against Lame's solution (3D).",
    params=(
        Param("a", 1.0, "inner radius", float, low=0.0, low_inclusive=False),
        Param("b", 2.0, "outer radius (> a)", float, low=0.0, low_inclusive=False),
        Param("pressure", 0.01, "internal pressure p (dead: on the reference sphere)", float,
              low=0.0, low_inclusive=False),
        *law_params("small"),
        element_param("hex1"),
        Param("n", 4, "cells along each edge of the three patches and through the wall "
              "(hex1: 3 (n + 1) (3 n^2 + 3 n + 1) dofs; quadratic: as hex1 at 2 n)", int,
              low=1, high=512),
    ),
    build=build,
    methods=(None,),
    default_steps=1,
    estimate_dofs=estimate_dofs,
    sizes=("n",),
    derived=derived,
)
