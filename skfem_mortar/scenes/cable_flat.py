"""Scene ``cable_flat``: a pinned cable pressed by a follower pressure against a rigid plane
(reference problem 4).

A cable of reference length ``L0`` pinned at ``(-a, 0)`` and ``(a, 0)``, pressure
``p`` pushing to ``+y``, the rigid plane ``y = d`` in the way.  Frictionless
contact keeps the tension ``T`` constant; on the plane (``|x| < c``) the cable is
straight and the contact pressure equals ``p``; the free parts are arcs of
radius ``r = T / p`` tangent to the plane at ``(+-c, d)``.  With
``theta = atan2(a - c, r - d)``:

    (a - c)^2 + (r - d)^2 = r^2,   L = 2 c + 2 r theta,   p r = N(L / L0),

one equation in ``r`` after eliminating ``c = a - sqrt(2 r d - d^2)``; contact
force ``2 c p``.  Valid while ``0 < c < a`` and ``d / 2 < r <= r_touch``; otherwise
the exact values are reported as null and the metric ``exact_note`` says why
(:func:`flat_exact_note`): below the pressure ``N(L_t / L0) / r_touch`` at which the
free arc of radius ``r_touch = (a^2 + d^2) / (2 d)`` (length ``L_t``) just touches
the plane there is no contact at all.

The cable surface facing the plane (its left side, ``+y``) is the slave, the
plane (one long segment) the master.  ``segmentation`` (mortar only) rebuilds the
mortar segments every Newton iteration (default) or once per load step (``step``;
far master nodes are clipped at the slave element's ends, so the long plane
segment keeps its frozen segments: n = 200, 8 steps, force error 1.8e-5 for
mortar and 1.0e-5 for mortar-dual, the same as ``iteration``).  The start is the
stress-free arc of length ``L0`` bulging to
the plane (for ``L0 = 2 a`` the shallow regularized arc of
:meth:`~skfem_mortar.bodies.cable.Cable.between`); it must not touch the plane.
"""
from __future__ import annotations

import numpy as np
from ..core.lazy import brentq

from ..bodies.cable import LAWS, Cable, get_law
from ..contact.pair import ContactPair
from ..loads.pressure import FollowerPressure
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..contact.surfaces import ContactSurface, RigidPlane
from . import METHODS, Param, Scene, Setup, cable_dofs, cable_quantities, positive, ratio

__all__ = ["SCENE", "build", "flat_exact", "flat_exact_note"]


def flat_exact(half_span: float, length0: float, EA: float, pressure: float,
               plane_gap: float, law: str) -> dict | None:
    """Exact radius, tension, contact half-width and force, or None outside ``0 < c < a``.

    Solves ``f(r) = p r - N(L(r) / L0) = 0`` for the root nearest below the radius
    ``r_touch = (a^2 + d^2) / (2 d)`` at which the free arc just touches the plane.
    """
    N = get_law(law).force
    a, L0, p, d = half_span, length0, pressure, plane_gap

    def c_of(r):
        return a - np.sqrt(np.maximum(2 * r * d - d * d, 0.0))

    def f(r):
        c = c_of(r)
        theta = np.arctan2(a - c, r - d)
        L = 2 * c + 2 * r * theta
        with np.errstate(all="ignore"):
            return p * r - N(L / L0, EA)

    r_touch = (a * a + d * d) / (2 * d)
    grid = np.linspace(r_touch, 0.5 * d, 20001)[:-1]
    vals = f(grid)
    if not (np.isfinite(vals[0]) and vals[0] > 0):
        return None  # the free arc does not reach the plane
    neg = np.flatnonzero(~(vals > 0))
    if neg.size == 0:
        return None
    i = neg[0]
    r = brentq(lambda t: float(f(np.array(t))), grid[i], grid[i - 1],
               xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
    c = float(c_of(r))
    if not (0.0 < c < a):
        return None
    return {"radius": r, "tension": p * r, "contact_half_width": c,
            "contact_force": 2 * c * p}


def touch_pressure(half_span: float, length0: float, EA: float, plane_gap: float,
                   law: str) -> float:
    """The pressure at which the free arc just touches the plane: ``N(L_t / L0) / r_t``
    for the arc of radius ``r_t = (a^2 + d^2) / (2 d)`` through both supports tangent
    to the plane, of length ``L_t = 2 r_t atan2(a, r_t - d)``; below it, no contact."""
    a, d = half_span, plane_gap
    r_touch = (a * a + d * d) / (2 * d)
    length = 2 * r_touch * np.arctan2(a, r_touch - d)
    return float(get_law(law).force(np.array(length / length0), EA)) / r_touch


def flat_exact_note(half_span: float, length0: float, EA: float, pressure: float,
                    plane_gap: float, law: str) -> str:
    """Why :func:`flat_exact` has no values at these parameters (one sentence)."""
    p_touch = touch_pressure(half_span, length0, EA, plane_gap, law)
    if pressure <= p_touch:
        return (f"no exact values: at pressure {pressure:.6g} the free cable does not "
                f"reach the plane (contact starts above pressure {p_touch:.6g}, where "
                f"the free arc just touches it), so this run has no contact")
    return (f"no exact values: the exact solution covers free arcs of radius between "
            f"plane_gap / 2 = {0.5 * plane_gap:.6g} and (half_span^2 + plane_gap^2) / "
            f"(2 plane_gap) = {(half_span ** 2 + plane_gap ** 2) / (2 * plane_gap):.6g} "
            f"with the contact inside the span; these parameters (a cable of length0 = "
            f"{length0:.6g}) leave that range")


def build(params: dict, method: str | None = None) -> Setup:
    """Cable, follower pressure, pinned supports, rigid plane and the contact pair."""
    a, L0, EA, p, d = (float(params[k]) for k in
                       ("half_span", "length0", "EA", "pressure", "plane_gap"))
    law, n = params["law"], int(params["n_elements"])
    method = method or "nts"
    if L0 < 2 * a:
        raise ValueError(f"length0 must be >= 2 half_span = {2 * a:g} (stress-free arc start), "
                         f"got {L0:g}")
    exact = flat_exact(a, L0, EA, p, d, law)
    cable = Cable.between((-a, 0.0), (a, 0.0), L0, n, bulge="left", EA=EA, law=law,
                          name="cable")
    if cable.X[1].max() >= d:
        raise ValueError(f"plane_gap must exceed the height {cable.X[1].max():.6g} of the "
                         f"start arc of length0 = {L0:g}, got {d:g}")
    slave = ContactSurface.from_cable(cable, side="left", name="cable_top")
    plane = RigidPlane((0.0, d), (0.0, -1.0), length=max(100.0 * a, 10 * L0), name="plane")
    options = {} if method == "nts" else {"segmentation": params["segmentation"]}
    pair = ContactPair(slave, plane, method, name="contact", **options)
    model = Model([cable, FollowerPressure(cable, p, side="left", name="pressure"),
                   Dirichlet(cable, cable.support_dofs(), 0.0, name="supports"), pair])

    def metrics(result) -> dict:
        z = result.z
        force = float(np.linalg.norm(pair.total_force(z)))
        tension = float(np.mean(cable.tension(z)))
        act = pair.active
        # half the extent of the slave nodes in compression (resolves c to O(h))
        lam = z[pair.dofs]
        comp = act & (lam > 1e-8 * max(lam.max(), 0.0))
        xs = slave.x(z)[0][comp]
        half = float(0.5 * (xs.max() - xs.min())) if comp.any() else 0.0
        out = {"n_active": int(act.sum())}
        if exact is None:   # a null exact value is explained, not left silent
            out["exact_note"] = flat_exact_note(a, L0, EA, p, d, law)
        for q, val in (("contact_force", force), ("contact_half_width", half),
                       ("tension", tension)):
            out[q] = val
            ref = None if exact is None else exact[q]
            out[f"{q}_exact"] = ref
            out[f"{q}_error"] = None if ref is None else abs(val - ref) / abs(ref)
        return out

    return Setup(model=model, metrics=metrics)


def derived(params: dict) -> list:
    """Span, length, gap, stiffness and tension scales; ``length0 / (2 half_span)`` in
    ``[1, 10]`` (a stress-free arc start) and ``plane_gap / half_span`` at most 100
    (a cable of at most 10 spans cannot reach farther)."""
    a, L0, d = (float(params[k]) for k in ("half_span", "length0", "plane_gap"))
    return [positive("half_span", a, "half_span"), positive("length0", L0, "length0"),
            positive("plane_gap", d, "plane_gap"),
            ratio("length0 / (2 half_span)", L0 / (2.0 * a), ("length0", "half_span"), 1.0, 10.0),
            ratio("plane_gap / half_span", d / a, ("plane_gap", "half_span"), 0.0, 100.0),
            *cable_quantities(float(params["EA"]), float(params["pressure"]), a, "half_span")]


SCENE = Scene(
    name="cable_flat",
    summary="Cable pinned at (-a, 0), (a, 0) pressed by a follower pressure against the "
            "rigid plane y = d (reference problem 4).",
    params=(
        Param("half_span", 1.0, "half the distance a between the supports", float,
              low=0.0, low_inclusive=False),
        Param("length0", 2.0, "reference length L0 >= 2a (stress-free arc start)", float,
              low=0.0, low_inclusive=False),
        Param("EA", 100.0, "axial stiffness", float, low=0.0, low_inclusive=False),
        Param("pressure", 20.0, "pressure p pushing to +y (force per current length)",
              float, low=0.0, low_inclusive=False),
        Param("plane_gap", 0.5, "height d of the rigid plane y = d", float,
              low=0.0, low_inclusive=False),
        Param("law", "linear", "axial law N(lambda)", str, choices=tuple(LAWS)),
        Param("n_elements", 100, "number of cable elements", int, low=2, high=1_000_000),
        Param("segmentation", "iteration", "mortar only: rebuild the mortar segments every "
              "Newton iteration, or once per load step (frozen during the step)", str,
              choices=("iteration", "step")),
    ),
    build=build,
    methods=METHODS,
    default_steps=8,
    estimate_dofs=lambda params: cable_dofs(params["n_elements"]),
    sizes=("n_elements",),
    derived=derived,
)
