"""Scene ``balloon``: a hemispherical neo-Hookean membrane inflated under volume
control past its pressure maximum.

A hemisphere of radius ``R`` and thickness ``H`` (the meridian from the equator
``(R, 0)`` to the pole ``(0, R)``, ``n_elements`` equal arcs; ``u_z = 0`` at the
equator node, ``u_r = 0`` at the pole by the membrane itself) of incompressible
neo-Hookean material (shear modulus ``mu``), the plane ``z = 0`` closing it by
symmetry.  Inflated uniformly to the stretch ``lambda``, a sphere holds the
pressure (membrane equilibrium ``p = 2 T / r`` with ``T = mu H (1 - lambda^-6)``)

    p(lambda) = 2 mu H / R (1 / lambda - 1 / lambda^7) ,

which peaks at ``lambda = 7^(1/6)``, ``p_max = 1.2395 mu H / R``.

``control=volume`` (default): a :class:`~skfem_mortar.loads.volume.VolumeControl`
prescribes ``V = V_h(0) lambda^3`` with ``lambda`` rising linearly with the load
factor from 1 to ``stretch`` (``V_h(0)`` the discrete reference volume); the
pressure is its unknown and passes the maximum.  The metrics compare ``p`` with
the closed form at every converged step with ``lambda >= 1.05``, relative to
``p_max`` (``pressure_error``: the largest), where ``lambda := (V / V_h(0))^(1/3)``.

``control=pressure``: a follower pressure rising to ``pressure_ratio * p_max``;
the run stops at the limit point with the message of
:mod:`~skfem_mortar.solver.limit_point` (exit 1).
"""
from __future__ import annotations

import numpy as np

from ..bodies.membrane import Membrane
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..loads.pressure import FollowerPressure
from ..loads.volume import VolumeControl
from . import Param, Scene, Setup, cable_dofs, positive, ratio

__all__ = ["SCENE", "build", "balloon_pressure", "P_MAX_FACTOR", "LIMIT_STRETCH"]

#: the stretch of the pressure maximum, ``7^(1/6)``
LIMIT_STRETCH = 7.0 ** (1.0 / 6.0)
#: ``p_max / (mu H / R) = 2 (7^(-1/6) - 7^(-7/6))`` = 1.2395
P_MAX_FACTOR = 2.0 * (LIMIT_STRETCH ** -1 - LIMIT_STRETCH ** -7)


def balloon_pressure(stretch: np.ndarray | float, mu: float, H: float, R: float):
    """``p = 2 mu H / R (1 / lambda - 1 / lambda^7)``, the inflated sphere's pressure."""
    lam = np.asarray(stretch, dtype=float)
    return 2.0 * mu * H / R * (1.0 / lam - lam ** -7)


def build(params: dict, method: str | None = None) -> Setup:
    """The hemisphere, its equator support and the volume control or the pressure."""
    R, H, mu = (float(params[k]) for k in ("radius", "thickness", "mu"))
    n, stretch = int(params["n_elements"]), float(params["stretch"])
    theta = np.linspace(0.0, 0.5 * np.pi, n + 1)
    membrane = Membrane(np.vstack([R * np.cos(theta), R * np.sin(theta)]), H=H, mu=mu,
                        name="balloon")
    equator = Dirichlet(membrane, membrane.node_dofs[1, [0]], 0.0, name="equator")
    p_max = P_MAX_FACTOR * mu * H / R
    if params["control"] == "volume":
        def target(lf: float) -> float:
            return control.reference_volume * (1.0 + (stretch - 1.0) * lf) ** 3
        control = VolumeControl(membrane, target, name="volume")
    else:   # the meridian runs from the equator up: its outside is on the right
        control = FollowerPressure(membrane, float(params["pressure_ratio"]) * p_max,
                                   side="right", name="pressure")
    model = Model([membrane, control, equator], geometry="axisymmetric")

    def metrics(result) -> dict:
        out: dict = {"pressure_max_exact": p_max, "limit_stretch_exact": LIMIT_STRETCH}
        if not isinstance(control, VolumeControl):
            out["pressure"] = control.current_pressure(float(result.load_factors[-1]))
            return out
        lam = np.array([(control.enclosed(z) / control.reference_volume) ** (1 / 3)
                        for z in result.states[1:]])
        p = np.array([control.pressure(z) for z in result.states[1:]])
        err = np.abs(p - balloon_pressure(lam, mu, H, R)) / p_max
        use = lam >= 1.05 - 1e-12
        k = int(np.argmax(p))
        out.update(stretch=float(lam[-1]), pressure=float(p[-1]),
                   pressure_max=float(p[k]), stretch_at_pressure_max=float(lam[k]),
                   pressure_error=float(err[use].max()) if use.any() else None,
                   compared_volumes=int(use.sum()))
        return out

    return Setup(model=model, metrics=metrics)


def derived(params: dict) -> list:
    """The scales ``mu``, ``H``, ``R`` and the membrane's slenderness ``H / R`` in
    ``(0, 0.1]`` (a membrane: thin)."""
    R, H, mu = (float(params[k]) for k in ("radius", "thickness", "mu"))
    return [positive("radius", R, "radius"), positive("thickness", H, "thickness"),
            positive("mu", mu, "mu"), positive("mu thickness", mu * H, "mu", "thickness"),
            ratio("thickness / radius", H / R, ("thickness", "radius"), 0.0, 0.1)]


SCENE = Scene(
    name="balloon",
    summary="A hemispherical neo-Hookean membrane inflated under volume control past its "
            "pressure maximum, against p = 2 mu H / R (1/lambda - 1/lambda^7).",
    params=(
        Param("radius", 1.0, "reference radius R", float, low=0.0, low_inclusive=False),
        Param("thickness", 0.01, "reference thickness H", float, low=0.0,
              low_inclusive=False),
        Param("mu", 1.0, "shear modulus", float, low=0.0, low_inclusive=False),
        Param("n_elements", 64, "meridian elements", int, low=2, high=1_000_000),
        Param("control", "volume", "prescribe the enclosed volume, or the pressure "
              "(stops at the limit point)", str, choices=("volume", "pressure")),
        Param("stretch", 3.0, "volume control: the final stretch lambda", float,
              low=1.0, high=10.0, low_inclusive=False),
        Param("pressure_ratio", 1.2, "pressure control: the final pressure over p_max",
              float, low=0.0, high=10.0, low_inclusive=False),
    ),
    build=build,
    default_steps=40,
    estimate_dofs=lambda params: cable_dofs(params["n_elements"]),
    sizes=("n_elements",),
    derived=derived,
)
