"""Scene ``ring``: a closed cable ring under internal follower pressure (reference problem 2).

Reference nodes on the circle of radius ``R0 = radius0``; internal pressure
``p`` normal to the deformed cable.  The continuum ring has tension
``T = p R`` and stretch ``R / R0``, so its radius solves

    p R = N(R / R0) .

The discrete ring (n elements, consistent nodal loads ``p l / 2`` along each
element normal) balances ``2 T sin(pi/n) = p l cos(pi/n)`` at every node with
``l = 2 R sin(pi/n)``, so it solves ``p R cos(pi/n) = N(R / R0)`` exactly: the
computed radius matches that to round-off and the continuum radius at second
order in ``1/n``.

Rigid motions are removed by pinning node 0 (at angle 0) and the ``y``
displacement of node ``n/2`` (at angle pi; ``n`` must be even).  The ring then
expands about node 0, so the radius is measured from the centroid of the
current nodes (the discrete solution is a regular polygon).  The stress-free
start has no geometric stiffness; the tangent uses the floor
``tension_floor * p R0`` (times the load factor), below the tension of the
solution (see :class:`~skfem_mortar.bodies.cable.Cable`).  Newton's relative
tolerance is :func:`~skfem_mortar.bodies.cable.newton_rtol` (1e-10 unless the ring is
so stiff that round-off forbids it).
"""
from __future__ import annotations

import math

import numpy as np
from ..core.lazy import brentq

from ..bodies.cable import LAWS, Cable, get_law, newton_rtol
from ..loads.pressure import FollowerPressure
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..solver.newton import NewtonOptions
from . import Param, Scene, Setup, cable_dofs, cable_quantities, positive

__all__ = ["SCENE", "build", "ring_radius"]


def ring_radius(pressure: float, radius0: float, EA: float, law: str,
                n_elements: int | None = None) -> float:
    """Radius ``R`` of the inflated ring: the smallest ``R > R0`` with
    ``p R c = N(R / R0)``, ``c = cos(pi / n)`` (discrete ring) or 1 (continuum,
    ``n_elements=None``).

    Raises
    ------
    ValueError
        If no equilibrium exists (the pressure is too high for the law:
        ``linear`` needs ``p c R0 < EA``, ``hencky`` ``p c R0 <= EA / e``).
    """
    if not pressure > 0:
        raise ValueError(f"pressure must be > 0, got {pressure}")
    N = get_law(law).force
    c = 1.0 if n_elements is None else math.cos(math.pi / n_elements)
    k = pressure * c * radius0            # N(lam) = k lam, lam = R / R0

    def g(lam):
        return float(N(np.asarray(lam, dtype=float), EA)) - k * lam

    grid = 1.0 + np.logspace(-14, 4, 2000)
    vals = N(grid, EA) - k * grid
    sign = np.nonzero(vals > 0.0)[0]
    if sign.size == 0 or g(1.0) >= 0.0:
        # largest pressure with an equilibrium: max of N(lam) / (lam c R0)
        limit = float(np.max(N(grid, EA) / (grid * c * radius0)))
        raise ValueError(f"pressure = {pressure} admits no inflated equilibrium for the "
                         f"{get_law(law).name} law: pressure must be below about "
                         f"{limit:.6g} (linear: EA / (c R0), hencky: EA / (e c R0))")
    i = sign[0]
    lo = 1.0 if i == 0 else grid[i - 1]
    lam = brentq(g, lo, grid[i], xtol=1e-16, rtol=4 * np.finfo(float).eps, maxiter=200)
    return lam * radius0


def build(params: dict, method: str | None = None) -> Setup:
    """Ring, pressure and supports; metrics against both exact relations."""
    n = int(params["n_elements"])
    if n < 4 or n % 2:
        raise ValueError(f"n_elements must be an even integer >= 4, got {n}")
    R0, EA, p, law = (float(params["radius0"]), float(params["EA"]),
                      float(params["pressure"]), params["law"])
    R_exact = ring_radius(p, R0, EA, law)          # raises for an impossible pressure
    R_discrete = ring_radius(p, R0, EA, law, n)
    ring = Cable.ring(R0, n, EA=EA, law=law, tension_only=bool(params["tension_only"]),
                      tension_floor=float(params["tension_floor"]) * p * R0, name="ring")
    nd = ring.node_dofs
    model = Model([
        ring,
        FollowerPressure(ring, p, side="right", name="pressure"),  # outside of a CCW ring
        Dirichlet(ring, [nd[0, 0], nd[1, 0], nd[1, n // 2]], 0.0, name="supports"),
    ])

    def metrics(result) -> dict:
        x = ring.x(result.z)
        radius = float(np.mean(np.hypot(*(x - x.mean(axis=1, keepdims=True)))))
        tension = float(np.mean(ring.tension(result.z)))
        t_exact = p * R_exact
        return {
            "radius": radius,
            "radius_exact": R_exact,
            "radius_error": abs(radius - R_exact) / R_exact,
            "radius_discrete": R_discrete,
            "radius_discrete_error": abs(radius - R_discrete) / R_discrete,
            "tension": tension,
            "tension_exact": t_exact,
            "tension_error": abs(tension - t_exact) / t_exact,
        }

    return Setup(model=model, metrics=metrics,
                 solve_options={"newton": NewtonOptions(rtol=newton_rtol(EA, p * R0))})


def derived(params: dict) -> list:
    """The ring's radius, axial stiffness, tension scale ``p R0`` and their ratio."""
    R0 = float(params["radius0"])
    return [positive("radius0", R0, "radius0"),
            *cable_quantities(float(params["EA"]), float(params["pressure"]), R0, "radius0")]


SCENE = Scene(
    name="ring",
    summary="Closed cable ring inflated by a follower pressure: discrete radius exact "
            "to round-off, second order to the continuum (reference problem 2).",
    params=(
        Param("radius0", 1.0, "reference radius R0 of the node circle", float,
              low=0.0, low_inclusive=False),
        Param("EA", 10.0, "axial stiffness", float, low=0.0, low_inclusive=False),
        Param("pressure", 1.0, "internal pressure p (force per current length)", float,
              low=0.0, low_inclusive=False),
        Param("law", "svk", "axial law N(lambda)", str, choices=tuple(LAWS)),
        Param("n_elements", 64, "number of elements (even)", int, low=4,
              high=1_000_000),
        Param("tension_only", False, "slack elements carry nothing", bool),
        Param("tension_floor", 0.1, "tangent-only floor of the geometric stiffness, in units "
              "of p radius0 (below the tension p R > p radius0 of the solution; 0: exact "
              "tangent)", float, low=0.0, high=1.0),
    ),
    build=build,
    methods=(None,),
    default_steps=4,
    estimate_dofs=lambda params: cable_dofs(params["n_elements"]),
    sizes=("n_elements",),
    derived=derived,
)
