"""Scene ``cable_arc``: a pinned cable inflated freely by a follower pressure (reference problem 3).

A cable of reference length ``L0`` pinned at ``(-a, 0)`` and ``(a, 0)``, pressure
``p`` pushing to ``+y``.  The continuum solution is a circular arc of radius
``r = T / p`` through both supports, with half-angle ``theta``:

    a = r sin(theta),   L = 2 r theta,   T = N(L / L0)
    =>  N(2 a theta / (L0 sin theta)) = p a / sin(theta) ,

apex height ``r (1 - cos theta)``.  The discrete solution is exact as well: n
equal chords inscribed in a circle of radius ``r_n`` with chord half-angle
``alpha``, the node balance ``2 T sin(alpha) = p l cos(alpha)`` of the ring,

    a = r_n sin(n alpha),   T = p r_n cos(alpha) = N(2 n r_n sin(alpha) / L0) ,

so the computed apex and tension match it to round-off and the continuum at
second order in ``1/n``.  The apex is the highest node (the midpoint of the
middle chord is higher by O(1/n^2) when ``n`` is odd).

Start (see :meth:`skfem_mortar.bodies.cable.Cable.between`): for ``L0 > 2 a`` the
stress-free arc; for ``L0 = 2 a`` a shallow arc of height ``start_sag * 2a``
with unchanged rest lengths (regularization of the singular straight start;
it moves only Newton's starting point, not the answer); for ``L0 < 2 a``
straight and pre-stretched.  The stress-free start has no geometric
stiffness: the tangent uses the floor ``tension_floor * p a`` (times the load
factor) on it, below the tension ``p r >= p a`` of every solution (see
:class:`~skfem_mortar.bodies.cable.Cable`).  Newton's relative tolerance is
:func:`~skfem_mortar.bodies.cable.newton_rtol` (1e-10 unless the cable is so stiff
that round-off forbids it).
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
from . import Param, Scene, Setup, cable_dofs, cable_quantities, positive, ratio

__all__ = ["SCENE", "build", "arc_exact", "arc_discrete"]


def _first_root(g, grid: np.ndarray, what: str, p_limit: float) -> float:
    vals = g(grid)
    pos = np.nonzero(np.isfinite(vals) & (vals > 0.0))[0]
    if pos.size == 0 or pos[0] == 0:
        raise ValueError(f"pressure admits no inflated equilibrium ({what}): pressure "
                         f"must be below about {p_limit:.6g} (or raise EA)")
    i = pos[0]
    return brentq(lambda t: float(g(np.array([t]))[0]), grid[i - 1], grid[i],
                  xtol=1e-16, rtol=4 * np.finfo(float).eps, maxiter=200)


def arc_exact(half_span: float, length0: float, EA: float, pressure: float,
              law: str) -> dict:
    """Continuum arc: ``theta``, radius, tension, current length and apex height.

    ``theta`` is the smallest root in (0, pi) of
    ``N(2 a theta / (L0 sin theta)) - p a / sin theta``.
    """
    N, a, L0, p = get_law(law).force, half_span, length0, pressure

    def g(t):
        s = np.sin(t)
        return N(2 * a * t / (L0 * s), EA) - p * a / s

    grid = np.linspace(0.0, math.pi, 20001)[1:-1]
    # largest pressure with an equilibrium: max of N(lambda(theta)) sin(theta) / a
    limit = float(np.max(N(2 * a * grid / (L0 * np.sin(grid)), EA) * np.sin(grid) / a))
    theta = _first_root(g, grid, f"{get_law(law).name} law, continuum arc", limit)
    r = a / math.sin(theta)
    return {"theta": theta, "radius": r, "tension": p * r, "length": 2 * r * theta,
            "apex_height": r * (1.0 - math.cos(theta))}


def arc_discrete(half_span: float, length0: float, EA: float, pressure: float,
                 law: str, n_elements: int) -> dict:
    """Discrete solution: equal chords, half-angle ``alpha`` in (0, pi/n), the
    smallest root of ``N(2 n a sin(alpha) / (L0 sin(n alpha))) - p a cos(alpha) / sin(n alpha)``.
    """
    N, a, L0, p, n = get_law(law).force, half_span, length0, pressure, int(n_elements)

    def g(al):
        sn = np.sin(n * al)
        return N(2 * n * a * np.sin(al) / (L0 * sn), EA) - p * a * np.cos(al) / sn

    grid = np.linspace(0.0, math.pi / n, 20001)[1:-1]
    lam = 2 * n * a * np.sin(grid) / (L0 * np.sin(n * grid))
    limit = float(np.max(N(lam, EA) * np.sin(n * grid) / (a * np.cos(grid))))
    alpha = _first_root(g, grid, f"{get_law(law).name} law, {n} elements", limit)
    r = a / math.sin(n * alpha)
    top = 1.0 if n % 2 == 0 else math.cos(alpha)
    return {"alpha": alpha, "radius": r, "tension": p * r * math.cos(alpha),
            "apex_height": r * (top - math.cos(n * alpha))}


def build(params: dict, method: str | None = None) -> Setup:
    """Cable, pressure and pinned supports; metrics against the exact arcs."""
    a, L0, EA, p = (float(params[k]) for k in ("half_span", "length0", "EA", "pressure"))
    law, n = params["law"], int(params["n_elements"])
    if n < 2:
        raise ValueError(f"n_elements must be >= 2, got {n}")
    exact = arc_exact(a, L0, EA, p, law)           # raises when no equilibrium exists
    discrete = arc_discrete(a, L0, EA, p, law, n)
    cable = Cable.between((-a, 0.0), (a, 0.0), L0, n, bulge="left",
                          start_sag=float(params["start_sag"]), EA=EA, law=law,
                          tension_only=bool(params["tension_only"]),
                          tension_floor=float(params["tension_floor"]) * p * a, name="cable")
    model = Model([
        cable,
        FollowerPressure(cable, p, side="left", name="pressure"),
        Dirichlet(cable, cable.support_dofs(), 0.0, name="supports"),
    ])

    def metrics(result) -> dict:
        z = result.z
        apex = float(np.max(cable.x(z)[1]))
        tension = float(np.mean(cable.tension(z)))
        out = {}
        for q, val in (("apex_height", apex), ("tension", tension)):
            out[q] = val
            out[f"{q}_exact"] = exact[q]
            out[f"{q}_error"] = abs(val - exact[q]) / abs(exact[q])
            out[f"{q}_discrete"] = discrete[q]
            out[f"{q}_discrete_error"] = abs(val - discrete[q]) / abs(discrete[q])
        return out

    return Setup(model=model, metrics=metrics,
                 solve_options={"newton": NewtonOptions(rtol=newton_rtol(EA, p * a))})


def derived(params: dict) -> list:
    """Span, length, stiffness and tension scales; ``length0 / (2 half_span)`` in
    ``[0.5, 10]`` (from halved and pre-stretched to a nearly closed arc)."""
    a, L0 = float(params["half_span"]), float(params["length0"])
    return [positive("half_span", a, "half_span"), positive("length0", L0, "length0"),
            ratio("length0 / (2 half_span)", L0 / (2.0 * a), ("length0", "half_span"), 0.5, 10.0),
            *cable_quantities(float(params["EA"]), float(params["pressure"]), a, "half_span")]


SCENE = Scene(
    name="cable_arc",
    summary="Cable pinned at (-a, 0), (a, 0) inflated by a follower pressure into a "
            "circular arc (reference problem 3).",
    params=(
        Param("half_span", 1.0, "half the distance a between the supports", float,
              low=0.0, low_inclusive=False),
        Param("length0", 2.5, "reference (stress-free) length L0 of the cable", float,
              low=0.0, low_inclusive=False),
        Param("EA", 100.0, "axial stiffness", float, low=0.0, low_inclusive=False),
        Param("pressure", 1.0, "pressure p pushing to +y (force per current length)",
              float, low=0.0, low_inclusive=False),
        Param("law", "linear", "axial law N(lambda)", str, choices=tuple(LAWS)),
        Param("n_elements", 32, "number of elements", int, low=2, high=1_000_000),
        Param("tension_only", False, "slack elements carry nothing", bool),
        Param("start_sag", 0.05, "height/span of the start arc when length0 equals the "
              "span (regularization of the straight start; does not change the answer)",
              float, low=0.0, high=0.5, low_inclusive=False),
        Param("tension_floor", 0.1, "tangent-only floor of the geometric stiffness, in units "
              "of p a (below the tension p r >= p a of the solution, so the answer and the "
              "quadratic convergence are kept; 0: exact tangent)", float, low=0.0, high=1.0),
    ),
    build=build,
    methods=(None,),
    default_steps=4,
    estimate_dofs=lambda params: cable_dofs(params["n_elements"]),
    sizes=("n_elements",),
    derived=derived,
)
