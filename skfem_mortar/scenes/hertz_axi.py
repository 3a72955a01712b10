"""Scene ``hertz_axi``: Hertz contact of a sphere on a flat body, axisymmetric.

The quarter disk of :mod:`~skfem_mortar.scenes.hertz` revolved about its axis
``r = 0``: a hemisphere of radius ``R`` (centre ``(0, R)``, touching ``z = 0``
at the origin) in an axisymmetric model (``x[0] = r``, ``x[1] = z``), pressed by
the total force ``F`` (``load``), a uniform dead traction ``F / (pi R^2)`` on its
flat top ``z = R`` (a total over the revolution), on a rigid plane or an
elastic cylinder of radius and height ``W = 30 a`` with its bottom clamped
(``base``).  The axis nodes are held at ``u_r = 0`` by the bodies themselves.
The slave surface is the hemisphere's meridian arc, the master the top of the
base or the rigid plate ``z = 0`` (:func:`~skfem_mortar.scenes._axi.rigid_plate`).
With ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`` (``1/E2 = 0`` for a rigid base)
Hertz's answer is::

    a = (3 F R / (4 E*))^(1/3),   p0 = 3 F / (2 pi a^2),
    p(r) = p0 sqrt(1 - r^2 / a^2),   delta = a^2 / R .

Meshes, elements and grading are those of ``hertz`` (:func:`graded_quarter_disk`,
:func:`graded_block`): element edges ``h0 = (a / 30) 2^-refine`` within ``1.2 a``
of the contact point.

Metrics: ``peak_pressure`` (the largest nodal pressure) and ``contact_radius``,
the least-squares fit of ``p^2 = p0^2 (1 - r^2 / a^2)`` over the nodes in
compression with ``r < 0.8 a`` (:func:`~skfem_mortar.scenes._axi.fit_ellipse`;
``peak_pressure_fit`` the fitted ``p0``), each with ``_exact`` and ``_error``;
``contact_radius_mid`` (midway between the outermost node in compression and
the next); ``peak_pressure_ref`` and ``contact_radius_ref`` (with ``_error``):
the same read per unit reference area at the reference radii, as linear theory
reads them (:func:`~skfem_mortar.scenes._axi.reference_pressure`);
``contact_force`` (the axial resultant of the multipliers' nodal forces, ``F``
at equilibrium) beside ``pressure_resultant_trapz`` (``2 pi int p r dr`` by the
trapezoidal rule over the nodes, a reading only); ``approach`` (the mean
``-u_z`` of the flat top less that of the base's bottom, 0) beside ``a^2 / R``
(a finite body has no distant point: reported, not checked).
"""
from __future__ import annotations

import math

import numpy as np

from ..bodies.materials import NeoHooke
from ..bodies.solid import KINEMATICS
from ..contact.pair import ContactPair
from ..contact.surfaces import ContactSurface
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..loads.traction import Traction
from . import METHODS, Param, Scene, Setup
from ._axi import (compression_span, fit_ellipse, profile, reference_pressure,
                   revolved_trapezoid, rigid_plate)
from .hertz import (ELEMENTS, FINE_ZONE, _body_class, contact_derived, graded_block,
                    graded_quarter_disk, one_step)

__all__ = ["SCENE", "build", "hertz_sphere"]

#: the fit window of ``contact_radius``, in units of the exact ``a``
FIT_WINDOW = 0.8


def hertz_sphere(radius: float, load: float, E: float, nu: float,
                 E_base: float | None, nu_base: float) -> dict:
    """Contact radius ``a``, peak pressure ``p0``, approach ``a^2 / R`` and ``E*`` of
    a sphere of radius ``radius`` pressed by the total force ``load`` on a half-space
    (``E_base=None``: rigid)."""
    inv = (1 - nu * nu) / E + (0.0 if E_base is None else (1 - nu_base ** 2) / E_base)
    Es = 1.0 / inv
    a = (3.0 * load * radius / (4.0 * Es)) ** (1.0 / 3.0)
    return {"E_star": Es, "contact_radius": a, "approach": a * a / radius,
            "peak_pressure": 3.0 * load / (2.0 * math.pi * a * a)}


def _bodies(params: dict, a: float, h0: float) -> tuple[list, object, ContactSurface, object]:
    """The hemisphere with its load, the base (or the rigid plate) and its support:
    ``(items, hemisphere, master, base or None)``."""
    R, F = float(params["radius"]), float(params["load"])
    element = params["element"]
    body = _body_class(element)
    kin = {"kinematics": params["kinematics"]}
    mesh_element = "tri1" if element == "mini" else element
    sphere = body(graded_quarter_disk(R, h0, FINE_ZONE * a, mesh_element),
                  NeoHooke(E=float(params["E"]), nu=float(params["nu"])), name="sphere", **kin)
    items = [sphere, Traction(sphere, "top", (0.0, -F / (math.pi * R * R)), name="load")]
    if params["base"] == "rigid":
        return items, sphere, rigid_plate(0.0, 0.0, 3.0 * a, math.sqrt(2.0) * h0), None
    W = 30.0 * a
    base = body(graded_block(W, h0, FINE_ZONE * a, mesh_element),
                NeoHooke(E=float(params["E_base"]), nu=float(params["nu_base"])), name="base",
                **kin)
    items += [base, Dirichlet(base, base.dofs_on("bottom"), 0.0, name="base_bottom")]
    return items, sphere, ContactSurface.from_solid(base, "top", name="base_top"), base


def build(params: dict, method: str | None = None) -> Setup:
    """Hemisphere (+ base), load, contact pair in an axisymmetric model; Hertz metrics."""
    R, F = float(params["radius"]), float(params["load"])
    rigid = params["base"] == "rigid"
    method = method or "nts"
    ex = hertz_sphere(R, F, float(params["E"]), float(params["nu"]),
                      None if rigid else float(params["E_base"]), float(params["nu_base"]))
    a = ex["contact_radius"]
    h0 = a / 30.0 * 2.0 ** (-int(params["refine"]))
    items, sphere, master, base = _bodies(params, a, h0)
    slave = ContactSurface.from_solid(sphere, "arc", name="sphere_arc")
    options = {} if method == "nts" else {"segmentation": params["segmentation"]}
    pair = ContactPair(slave, master, method, name="contact", **options)
    model = Model(items + [pair], geometry="axisymmetric")
    top = sphere.dofs_on("top", "y")

    def metrics(result) -> dict:
        z = result.z
        r, p = profile(pair, z)
        fit_p0, fit_a = fit_ellipse(r, p, FIT_WINDOW * a)
        order = np.argsort(pair.slave.X[0])
        ref_p0, ref_a = fit_ellipse(pair.slave.X[0, order],
                                    reference_pressure(pair, z)[order], FIT_WINDOW * a)
        out = {"contact_force": float(pair.total_force(z)[1]), "load": F,
               "pressure_resultant_trapz": revolved_trapezoid(r, p),
               "contact_radius_mid": compression_span(r, p)[1], "peak_pressure_fit": fit_p0,
               "approach": float(-np.mean(sphere.u(z)[top])), "approach_hertz": ex["approach"],
               "n_active": int(pair.active.sum()), "element_size": h0,
               "E_star": ex["E_star"], "a_over_R": a / R}
        out["contact_force_error"] = abs(out["contact_force"] - F) / F
        ref_peak = float(np.nanmax(reference_pressure(pair, z)))
        for q, val in (("peak_pressure", float(p.max())), ("contact_radius", fit_a),
                       ("peak_pressure_ref", ref_peak), ("contact_radius_ref", ref_a)):
            exact = ex[q.replace("_ref", "")]
            out[q] = val
            out[f"{q}_exact"] = exact
            out[f"{q}_error"] = abs(val - exact) / exact
        return out

    return Setup(model=model, metrics=metrics)


def derived(params: dict) -> list:
    """Radius, load, both bodies' Lame parameters, ``E*`` and ``a / R``."""
    return contact_derived(params, hertz_sphere, "the sphere", "contact_radius",
                           "the contact radius over the radius a / R")


SCENE = Scene(
    name="hertz_axi",
    summary="Hertz contact of a sphere: an axisymmetric hemisphere pressed by a total "
            "force on an elastic cylinder or a rigid plane.",
    params=(
        Param("radius", 8.0, "sphere radius R", float, low=0.0, low_inclusive=False),
        Param("load", 0.3, "total force F over the revolution (a / R = 0.025 by default)",
              float, low=0.0, low_inclusive=False),
        Param("E", 200.0, "Young's modulus of the sphere", float, low=0.0, low_inclusive=False),
        Param("nu", 0.3, "Poisson's ratio of the sphere", float, low=0.0, high=0.5,
              high_inclusive=False),
        Param("E_base", 200.0, "Young's modulus of the elastic base", float, low=0.0,
              low_inclusive=False),
        Param("nu_base", 0.3, "Poisson's ratio of the elastic base", float, low=0.0,
              high=0.5, high_inclusive=False),
        Param("base", "rigid", "what the sphere is pressed on", str,
              choices=("rigid", "elastic")),
        Param("refine", 0, "mesh level: element size (a/30) 2^-refine in the contact zone",
              int, low=-3, high=3),
        Param("element", "tri1", "bodies' element: tri1, tri2, quad1, quad2 or mini (as hertz)",
              str, choices=ELEMENTS),
        Param("segmentation", "iteration", "mortar only: rebuild the mortar segments every "
              "Newton iteration, or once per load step", str, choices=("iteration", "step")),
        Param("kinematics", "finite", "bodies' strain: finite (neo-Hooke) or small (linear "
              "elasticity; contact on the current configuration)", str, choices=KINEMATICS),
    ),
    build=build,
    methods=METHODS,
    default_steps=4,
    derived=derived,
    one_step=one_step,
    one_step_text="with mortar or mortar-dual and segmentation=iteration",
)
