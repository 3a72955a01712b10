"""Scene ``thick_sphere``: a thick-walled sphere under internal pressure, axisymmetric,
against Lame's solution.

The sphere ``a <= rho <= b`` (``rho`` the distance from the centre) is modelled
by its meridian quarter ``r >= 0, z >= 0`` in an axisymmetric model
(``Model(items, geometry="axisymmetric")``, :mod:`skfem_mortar.bodies.axisymmetric`):
``u_z = 0`` on the equator plane ``z = 0`` (symmetry), ``u_r = 0`` on the axis
by the body itself.  A dead pressure ``p`` acts on the reference inner face
(consistent nodal forces ``f_l = int p n . N_l 2 pi R ds`` over the discrete
inner face, ``n`` its normal into the wall: totals over the revolution).  In
linear elasticity the displacement is radial,

    u_rho(rho) = p a^3 / (E (b^3 - a^3)) ((1 - 2 nu) rho + (1 + nu) b^3 / (2 rho^2)) .

Mesh: a tensor grid in ``(rho, theta)`` (``theta`` the polar angle from the
axis, ``n`` elements through the wall, ``2 n`` along the quarter), mapped to
``(r, z) = rho (sin theta, cos theta)``: linear elements have straight chords,
quadratic ones are isoparametric (MeshTri2 / MeshQuad2) with every node, the
mid nodes included, mapped, so the mid nodes of the arcs lie on them.

Elements (``element``): ``tri1``, ``tri2``, ``quad1``, ``quad2``, ``mini``
(:class:`~skfem_mortar.bodies.mixed.MixedSolid`, MINI u-p) and ``sri`` (the one-point
volumetric quads, :class:`~skfem_mortar.bodies.sri.SRISolid`: in an axisymmetric model
the mean dilatation with the ``2 pi R`` weight), all at small strain
(:class:`~skfem_mortar.bodies.material.LinearElastic`): the scene's answer is exactly
linear in ``p`` (one Newton iteration), and :func:`derived` keeps ``p / E <= 1e-3``
so that the displacements stay small against the wall, as the theory assumes.

Metrics: ``l2_error`` (``||u_h - u|| / ||u||`` in ``L2`` over the discrete
wall with the ``2 pi R`` weight, the element's own quadrature), ``nodal_error``
(the largest nodal ``|u_h - u|`` over the largest ``|u|``), ``u_inner``
(mean radial displacement of the inner face's vertices) against ``u_inner_exact``
(``u_rho(a)``), and ``sigma_tt_inner`` (the hoop stress averaged over the
elements at the inner face) against Lame's hoop stress at their mean radius.
Measured (``nu = 0.3``, ``n = 4, 8, 16``): ``l2_error`` 6.5e-2, 1.9e-2, 4.9e-3
(tri1, orders 1.78, 1.93), 2.2e-2, 5.7e-3, 1.4e-3 (quad1, 1.95, 1.99), 9.1e-4,
1.1e-4, 1.4e-5 (tri2, 3.04, 3.03), 7.4e-4, 9.6e-5, 1.2e-5 (quad2, 2.95, 2.99).
At ``nu = 0.4999`` (``n = 2, 4, 8, 16``): mini 2.2e-1, 6.9e-2, 1.8e-2, 4.4e-3
(orders 1.71, 1.95, 2.01), sri 5.7e-2, 1.6e-2, 4.1e-3, 1.0e-3 (1.84, 1.95,
1.99), while plain tri1 locks: 0.96, 0.87, 0.68, 0.47 (and quad1 0.99 ... 0.76).
MINI's hoop stress
at the inner face converges slowly (``sigma_tt_inner_error`` 0.33, 0.19, 0.094 at
``n = 4, 8, 16``), as plain tri1's does at ``nu = 0.3`` (0.23, 0.14, 0.076): the
element averages of triangles next to the face; sri's is 7e-4, 6e-4, 2e-4.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from skfem import (ElementQuad1, ElementQuad2, ElementTriMini, ElementTriP1, ElementTriP2,
                   ElementVector, FacetBasis, LinearForm, MeshQuad, MeshQuad2, MeshTri,
                   MeshTri2)
from skfem.helpers import dot

from ..bodies.material import LinearElastic
from ..bodies.mixed import MixedSolid
from ..bodies.solid import Solid
from ..bodies.sri import SRISolid
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..loads.traction import PointLoad
from . import Param, Scene, Setup, grid_dofs, lame_quantities, positive, ratio

__all__ = ["SCENE", "build", "lame_displacement", "sphere_mesh", "ELEMENTS"]

#: the scene's elements (``sri``: the one-point volumetric quads)
ELEMENTS = ("tri1", "tri2", "quad1", "quad2", "mini", "sri")

_SCALAR = {"tri1": ElementTriP1, "tri2": ElementTriP2, "quad1": ElementQuad1,
           "quad2": ElementQuad2, "mini": ElementTriMini, "sri": ElementQuad1}


def lame_displacement(rho: np.ndarray, a: float, b: float, E: float, nu: float,
                      p: float) -> np.ndarray:
    """Lame's radial displacement ``u_rho(rho)`` of the sphere ``a <= rho <= b`` under
    the internal pressure ``p`` (module docstring)."""
    rho = np.asarray(rho, dtype=float)
    return p * a ** 3 / (E * (b ** 3 - a ** 3)) * ((1 - 2 * nu) * rho
                                                  + (1 + nu) * b ** 3 / (2 * rho ** 2))


def lame_hoop_stress(rho: np.ndarray, a: float, b: float, p: float) -> np.ndarray:
    """Lame's hoop stress ``sigma_tt = p a^3 / (b^3 - a^3) (1 + b^3 / (2 rho^3))``."""
    rho = np.asarray(rho, dtype=float)
    return p * a ** 3 / (b ** 3 - a ** 3) * (1 + b ** 3 / (2 * rho ** 3))


def sphere_mesh(a: float, b: float, n: int, element: str):
    """The meridian quarter of the wall (module docstring), boundaries ``inner``,
    ``outer``, ``equator`` (``z = 0``) and ``axis`` (``r = 0``)."""
    cls = MeshTri if element.startswith(("tri", "mini")) else MeshQuad
    lin = cls.init_tensor(np.linspace(a, b, n + 1), np.linspace(0.0, np.pi / 2, 2 * n + 1))
    quadratic = element.endswith("2")
    mesh = ({MeshTri: MeshTri2, MeshQuad: MeshQuad2}[cls].from_mesh(lin) if quadratic
            else lin)
    rho, th = mesh.doflocs
    xy = np.vstack([rho * np.sin(th), rho * np.cos(th)])
    equator = np.isclose(th, np.pi / 2, rtol=0, atol=1e-12)
    xy[:, equator] = np.vstack([rho[equator], np.zeros(equator.sum())])
    xy[0, th == 0.0] = 0.0
    mesh = dataclasses.replace(mesh, doflocs=xy)
    tol = 1e-9 * b

    def arc(x: np.ndarray) -> np.ndarray:   # boundary facets off the axis and equator
        return (np.abs(x[0]) > tol) & (np.abs(x[1]) > tol)

    return mesh.with_boundaries({        # chords' midpoints lie inside the circles
        "inner": lambda x: arc(x) & (np.hypot(x[0], x[1]) < 0.5 * (a + b)),
        "outer": lambda x: arc(x) & (np.hypot(x[0], x[1]) > 0.5 * (a + b)),
        "equator": lambda x: np.abs(x[1]) < tol,
        "axis": lambda x: np.abs(x[0]) < tol})


def _body(mesh, element: str, E: float, nu: float):
    """The wall, small strain (LinearElastic) on every element."""
    if element == "mini":
        return MixedSolid(mesh, LinearElastic(E=E, nu=nu), name="sphere")
    if element == "sri":
        return SRISolid(mesh, LinearElastic(E=E, nu=nu), name="sphere")
    return Solid(mesh, LinearElastic(E=E, nu=nu), element=element, name="sphere")


def pressure_load(body, element: str, p: float) -> PointLoad:
    """The dead pressure ``p`` on the reference inner face, nodal forces
    ``f_l = -int p N_l n 2 pi R ds`` (``n`` the body's outward normal, towards the centre)."""
    mesh = body.mesh
    order = 2 if element.endswith("2") else 1
    fb = FacetBasis(mesh, ElementVector(_SCALAR[element]()),
                    facets=mesh.boundaries["inner"], intorder=2 * order + 2)
    f = LinearForm(lambda v, w: -p * dot(w.n, v) * 2.0 * np.pi * w.x[0]).assemble(fb)
    dofs = np.flatnonzero(f)
    return PointLoad(body, dofs, f[dofs], name="pressure")


def build(params: dict, method: str | None = None) -> Setup:
    """The wall, its support, the pressure; metrics against Lame."""
    a, b, E, nu, p = (float(params[k]) for k in ("a", "b", "E", "nu", "pressure"))
    element, n = params["element"], int(params["n"])
    body = _body(sphere_mesh(a, b, n, element), element, E, nu)
    model = Model([body, Dirichlet(body, body.dofs_on("equator", "y"), 0.0, name="equator"),
                   pressure_load(body, element, p)], geometry="axisymmetric")

    def exact(X: np.ndarray) -> np.ndarray:
        rho = np.hypot(X[0], X[1])
        return lame_displacement(rho, a, b, E, nu, p) * X / rho

    def metrics(result) -> dict:
        z = result.z
        n_u = getattr(body, "n_u", body.n_dofs)
        bas = body.basis
        uh = np.asarray(bas.interpolate(body.u(z)[:n_u]))       # (2, n_el, n_qp)
        ue = exact(np.asarray(bas.mapping.F(bas.quadrature[0])))
        dx = body._dx
        l2 = float(np.sqrt(np.sum((uh - ue) ** 2 * dx) / np.sum(ue ** 2 * dx)))
        un = body.u(z)[body.node_dofs]
        une = exact(body.X)
        inner = np.unique(body.mesh.facets[:, body.mesh.boundaries["inner"]])
        rho = np.hypot(*body.X[:, inner])
        ur = np.sum(un[:, inner] * body.X[:, inner], axis=0) / rho
        cells = body.output_data(z)[1]
        at_inner = np.unique(body.mesh.f2t[0, body.mesh.boundaries["inner"]])
        rho_c = np.hypot(*body.mesh.p[:, body.mesh.t[:, at_inner]].mean(axis=1))
        stt = float(np.mean(cells["sigma_tt"][0][at_inner]))
        stt_e = float(np.mean(lame_hoop_stress(rho_c, a, b, p)))
        u_a = lame_displacement(a, a, b, E, nu, p)
        return {"l2_error": l2,
                "nodal_error": float(np.abs(un - une).max() / np.abs(une).max()),
                "u_inner": float(ur.mean()), "u_inner_exact": float(u_a),
                "u_inner_error": float(abs(ur.mean() - u_a) / u_a),
                "sigma_tt_inner": stt, "sigma_tt_inner_exact": stt_e,
                "sigma_tt_inner_error": abs(stt - stt_e) / abs(stt_e),
                "n": n, "h": (b - a) / n}

    return Setup(model=model, metrics=metrics)


def estimate_dofs(params: dict) -> int:
    """Dofs of the ``n x 2 n`` grid (MINI: plus a bubble per triangle and the pressures)."""
    n, element = int(params["n"]), params["element"]
    order = 2 if element.endswith("2") else 1
    extra = 5 * 4 * n * n if element == "mini" else 0
    return grid_dofs(n, 2 * n, order) + extra


def derived(params: dict) -> list:
    """Lame parameters, the pressure, ``b / a > 1`` and ``p / E <= 1e-3`` (module doc)."""
    E, nu, p = float(params["E"]), float(params["nu"]), float(params["pressure"])
    a, b = float(params["a"]), float(params["b"])
    return [*lame_quantities(E, nu), positive("pressure", p, "pressure"),
            ratio("b / a", b / a, ("a", "b"), 1.0 + 1e-3, 1e3),
            ratio("pressure / E", p / E, ("pressure", "E"), 0.0, 1e-3)]


SCENE = Scene(
    name="thick_sphere",
    summary="Axisymmetric thick-walled sphere under internal pressure against Lame: "
            "L2 displacement error of order 2 (linear, mini, sri) and 3 (quadratic).",
    params=(
        Param("a", 1.0, "inner radius", float, low=0.0, low_inclusive=False),
        Param("b", 2.0, "outer radius (> a)", float, low=0.0, low_inclusive=False),
        Param("E", 1.0, "Young's modulus", float, low=0.0, low_inclusive=False),
        Param("nu", 0.3, "Poisson's ratio", float, low=-1.0, high=0.5,
              low_inclusive=False, high_inclusive=False),
        Param("pressure", 1e-6, "dead pressure p on the reference inner face (p / E <= 1e-3)",
              float, low=0.0, low_inclusive=False),
        Param("element", "quad2", "element (all small strain): tri1, tri2, quad1, quad2, mini "
              "(MINI u-p), sri (one-point volumetric quads, mean dilatation)", str,
              choices=ELEMENTS),
        Param("n", 4, "elements through the wall (2 n along the quarter meridian)", int,
              low=1, high=2000),
    ),
    build=build,
    methods=(None,),
    default_steps=1,
    estimate_dofs=estimate_dofs,
    sizes=("n",),
    derived=derived,
)
