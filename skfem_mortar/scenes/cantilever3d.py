"""Scene ``cantilever3d``: a square beam clamped at one end under a tip load (3D).

The beam ``[0, L] x [0, h] x [0, h]`` (``L = length``, ``h = 1``; ``n`` cells through
the thickness, ``round(n L / h)`` along) is clamped at ``X = 0`` (all three
components) and carries the dead tip load ``P`` in ``-z``, a uniform traction
``P / h^2`` on its end face ``X = L``.  The load is given as
``load = P L^2 / (E I)``, ``I = h^4 / 12``.

Small strain (default): the slender limit is Timoshenko's beam,

    w = P L^3 / (3 E I) + P L / (kappa G A) ,   kappa = 10 (1 + nu) / (12 + 11 nu)

(Cowper's shear coefficient of a square; the second term is 0.8 % of the first at
``L / h = 10``, ``nu = 0.3``).  The 3D body departs from it near the clamp (its
cross-section cannot warp or contract there) by ``O(h / L)`` of the shear term.

Finite strain: the slender limit is the inextensible elastica under a dead
vertical tip force, ``E I theta'' = -P cos(theta)``, ``theta(0) = 0``,
``theta'(L) = 0``, tip ``(x, w) = int_0^L (cos theta, sin theta) ds``
(:func:`elastica_tip`); at ``load = 1`` the tip drops by 0.30 L.

Metrics: ``tip_deflection`` (the mean ``-u_z`` of the end face's vertices) and, at
finite strain, ``tip_shortening`` (their mean ``-u_x``); with ``_beam`` (the slender
limit above, of the kinematics) and ``_beam_error`` (relative to it).  Against its
own refinement: the deflection of ``n`` against that of ``2 n`` (tests/test_scenes3d.py,
where ``nu = 0.4999`` also shows the nearly incompressible elements against
locking ones).
"""
from __future__ import annotations

import math

import numpy as np

from ..core.dirichlet import Dirichlet
from ..core.lazy import brentq
from ..core.model import Model
from ..loads.traction import Traction
from . import Param, Scene, Setup, lame_quantities, ratio
from ._meshes3d import box_dofs, box_mesh
from ._scene3d import displacement, element_param, law_params, make_solid, memory_quantity

__all__ = ["SCENE", "build", "timoshenko_tip", "elastica_tip"]


def timoshenko_tip(load: float, length: float, nu: float) -> float:
    """Tip deflection over ``h`` of the Timoshenko beam (module docstring) at
    ``load = P L^2 / (E I)``, ``length = L / h``: ``load L / 3 + load (1 + nu) /
    (6 kappa L)`` (with ``E I = 1 / 12`` in units of ``E h^4``, ``G A = 1 / (2 (1 + nu))``)."""
    kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu)
    P = load / (12.0 * length ** 2)                 # P / (E h^2)
    return load * length / 3.0 + P * length * 2.0 * (1.0 + nu) / kappa


def elastica_tip(load: float, steps: int = 400) -> tuple[float, float]:
    """Tip deflection and shortening over ``L`` of the inextensible elastica under a
    dead tip force ``P`` at ``load = P L^2 / (E I)`` (module docstring): shooting on
    ``theta'(0)`` (brentq) with a 4th-order Runge-Kutta march of ``steps`` steps.

    ``theta'(1)`` is negative at ``theta'(0) = 0`` and not negative at
    ``theta'(0) = load`` (``theta' = load int_s^1 cos theta``), so the root is bracketed."""
    h = 1.0 / steps

    def march(k: float, full: bool = False):
        th, dth, x, w = 0.0, k, 0.0, 0.0

        def f(y):
            return np.array([y[1], -load * math.cos(y[0]), math.cos(y[0]), math.sin(y[0])])
        y = np.array([th, dth, x, w])
        for _ in range(steps):
            k1 = f(y)
            k2 = f(y + 0.5 * h * k1)
            k3 = f(y + 0.5 * h * k2)
            k4 = f(y + h * k3)
            y = y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        return y if full else y[1]

    k = brentq(march, 0.0, float(load), xtol=1e-14)
    y = march(k, full=True)
    return float(y[3]), float(1.0 - y[2])


def build(params: dict, method: str | None = None) -> Setup:
    """Model, metrics and outputs of the beam (``method`` is unused: no contact)."""
    L, n, load = float(params["length"]), int(params["n"]), float(params["load"])
    E, nu = float(params["E"]), float(params["nu"])
    nx = max(1, round(n * L))
    mesh = box_mesh(params["element"], (nx, n, n), (L, 1.0, 1.0))
    solid = make_solid(mesh, params, "beam")
    P = load * E / (12.0 * L * L)                            # P = load E I / L^2, h = 1
    model = Model([solid, Dirichlet(solid, boundary="left", name="clamp"),
                   Traction(solid, "right", [0.0, 0.0, -P], name="tip_load")])
    tip = np.unique(mesh.facets[:, mesh.boundaries["right"]])
    finite = params["kinematics"] == "finite"
    if finite:
        w_beam, s_beam = (L * v for v in elastica_tip(load))
    else:
        w_beam, s_beam = timoshenko_tip(load, L, nu), None

    def metrics(result) -> dict:
        u = displacement(solid, result.z)[solid.node_dofs][:, tip]
        w = -float(np.mean(u[2]))
        out = {"tip_deflection": w, "tip_deflection_beam": w_beam,
               "tip_deflection_beam_error": abs(w - w_beam) / w_beam}
        if finite:
            s = -float(np.mean(u[0]))
            out.update({"tip_shortening": s, "tip_shortening_beam": s_beam,
                        "tip_shortening_beam_error": abs(s - s_beam) / s_beam})
        return out

    return Setup(model=model, metrics=metrics)


def estimate_dofs(params: dict) -> int:
    """Displacement dofs of the beam (no mesh built)."""
    n = int(params["n"])
    return box_dofs(params["element"], (max(1, round(n * float(params["length"]))), n, n))


def derived(params: dict) -> list:
    """The Lame parameters, the slenderness and the run's estimated memory."""
    return [*lame_quantities(float(params["E"]), float(params["nu"])),
            ratio("the slenderness L / h", float(params["length"]), ("length",), 1.0, 1e4),
            memory_quantity(estimate_dofs(params), "n", "length")]


SCENE = Scene(
    name="cantilever3d",
    summary="Square cantilever beam under a dead tip load, small strain against Timoshenko's "
            "beam, finite strain against the elastica (3D).",
    params=(
        Param("length", 10.0, "beam length L over its thickness h", float, low=1.0,
              high=1e4),
        Param("load", 1.0, "tip force P in units of E I / L^2 (finite strain, 1: the tip "
              "drops by 0.30 L)", float, low=0.0, high=20.0, low_inclusive=False),
        *law_params("small"),
        element_param("hex2"),
        Param("n", 2, "cells through the thickness (round(n L / h) along)", int, low=1,
              high=256),
    ),
    build=build,
    methods=(None,),
    default_steps=4,
    estimate_dofs=estimate_dofs,
    sizes=("n", "length"),
    derived=derived,
    one_step=lambda values, method: values["kinematics"] == "small",
    one_step_text="at small strain",
)
