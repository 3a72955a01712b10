"""Scene ``seed``: the paper's example, an inflated cable pressed into a soft cushion.

A nonlinear elastic cable (default St Venant-Kirchhoff law) pinned at
``(-a, 0)`` and ``(a, 0)``, with reference length ``L0 > 2 a`` so that it starts
as the stress-free arc bulging upwards, is inflated by a follower pressure
``p`` (pushing to ``+y``) until it meets and presses into a compressible
neo-Hookean cushion: the rectangle ``|x| <= w/2``, ``gap0 <= y - h_arc <= gap0 + H``
above the arc's apex, fixed on its top face. The cable's upper side is the
slave surface, the cushion's bottom face the master.

Mortar segments are rebuilt in every Newton iteration (``segmentation=iteration``)
or after every converged load step (``segmentation=step``, as in the paper).

With ``mu > 0`` the pair has Coulomb friction ``mu`` (``docs/friction.md``,
``mu = 0``, the default, builds none): the cable, pushed outwards by the
pressure while the cushion holds it, sticks where it touched first and slips
towards the ends of the contact zone, so its tension is no longer constant
along the contact (frictionless it is, to round-off: no tangential load acts
on it).  ``tension_variation`` measures by how much; ``n_stick``, ``n_slip``,
``stick_half_width`` and ``slip_half_width`` say where it sticks and slips.

No closed form exists. The checks are global: each body must be in
equilibrium on its own (pressure resultant + support reactions + contact
force on the cable; contact force + support reactions on the cushion), and
NTS and mortar must agree as the meshes are refined.
"""
from __future__ import annotations

import numpy as np
import skfem

from ..bodies.cable import LAWS, Cable
from ..contact.friction import SLIP, STICK, Coulomb
from ..contact.pair import ContactPair
from ..loads.pressure import FollowerPressure
from ..bodies.materials import NeoHooke
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..bodies.solid import Solid
from ..contact.surfaces import ContactSurface
from . import (METHODS, Param, Scene, Setup, cable_dofs, cable_quantities, grid_dofs,
               lame_quantities, positive, ratio)

__all__ = ["SCENE", "build"]


def cushion_mesh(width: float, height: float, y0: float, nx: int, ny: int,
                 refine: int) -> skfem.MeshTri:
    """Triangle mesh of the cushion, with boundaries ``bottom``, ``top``, ``left``, ``right``."""
    nx, ny = nx * 2**refine, ny * 2**refine
    mesh = skfem.MeshTri.init_tensor(np.linspace(-width / 2, width / 2, nx + 1),
                                     np.linspace(y0, y0 + height, ny + 1))
    tol = 1e-9 * max(width, height)
    return mesh.with_boundaries({
        "bottom": lambda x: np.abs(x[1] - y0) < tol,
        "top": lambda x: np.abs(x[1] - (y0 + height)) < tol,
        "left": lambda x: np.abs(x[0] + width / 2) < tol,
        "right": lambda x: np.abs(x[0] - width / 2) < tol,
    })


def build(params: dict, method: str | None = None) -> Setup:
    """Cable, pressure, cushion and the contact pair, for ``method``."""
    a, L0 = float(params["half_span"]), float(params["length0"])
    method = method or "mortar"
    if L0 <= 2 * a:
        raise ValueError(f"length0 must exceed 2 half_span = {2 * a:g} (the cable starts as a "
                         f"stress-free arc), got {L0:g}")
    # tension_floor (tangent only, see Cable): the stress-free start has no N/l
    # stiffness; a floor well below the final tension p a keeps the first Newton
    # iterations from overshooting into the cushion. It does not change the answer.
    cable = Cable.between((-a, 0.0), (a, 0.0), L0, int(params["n_cable"]), bulge="left",
                          EA=float(params["EA"]), law=params["law"], name="cable",
                          tension_floor=0.1 * float(params["pressure"]) * a)
    apex = float(cable.X[1].max())
    y0 = apex + float(params["gap"])
    mesh = cushion_mesh(float(params["cushion_width"]), float(params["cushion_height"]), y0,
                        12, 3, int(params["refine_cushion"]))
    cushion = Solid(mesh, NeoHooke(E=float(params["E_cushion"]), nu=float(params["nu_cushion"])),
                    element="tri1", name="cushion")
    slave = ContactSurface.from_cable(cable, side="left", name="cable_top")
    master = ContactSurface.from_solid(cushion, "bottom", name="cushion_bottom")
    options = {}
    if method != "nts":
        options = {"n_gauss": int(params["n_gauss"]),
                   "segmentation": params["segmentation"]}
    mu = float(params["mu"])
    pair = ContactPair(slave, master, method, name="contact",
                       friction=Coulomb(mu) if mu > 0.0 else None, **options)
    pressure = FollowerPressure(cable, float(params["pressure"]), side="left", name="pressure")
    supports = Dirichlet(cable, cable.support_dofs(), 0.0, name="supports")
    clamp = Dirichlet(cushion, cushion.dofs_on("top"), 0.0, name="clamp")
    model = Model([cable, cushion, pressure, supports, clamp, pair])

    def metrics(result) -> dict:
        z = result.z
        R = result.residual()
        f_slave, f_master = pair.forces(z)
        on_cable, on_cushion = f_slave.sum(axis=1), f_master.sum(axis=1)
        p_res = pressure.resultant(z, 1.0)
        # reactions: R at a prescribed dof is the force the support exerts there
        r_cable = np.array([R[d].sum() for d in _split_xy(cable, supports.local_dofs)])
        r_cushion = np.array([R[d].sum() for d in _split_xy(cushion, clamp.local_dofs)])
        data = pair.contact_data(z)
        act = pair.active
        ev = pair.evaluate(z, tangent=False, with_lam=False)
        u_cushion = cushion.x(z) - cushion.X
        bottom = np.unique(mesh.facets[:, mesh.boundaries["bottom"]])
        p_norm = float(np.linalg.norm(p_res))
        c_norm = float(np.linalg.norm(on_cable))
        extra = _tension_metrics(cable, slave, pair, z)
        return {**extra,
            "contact_force": c_norm,
            "max_indentation": float(max(0.0, u_cushion[1, bottom].max())),
            "contact_length": float(ev.area[act].sum()),
            "pressure_resultant": p_norm,
            "n_active": int(act.sum()),
            "max_pressure": float(np.max(data["pressure"])) if data["pressure"].size else 0.0,
            "action_reaction_error": float(np.linalg.norm(on_cable + on_cushion)
                                           / max(c_norm, 1e-300)),
            # the internal forces of a body sum to zero, so the residual summed over
            # its supports is the reaction: P + F_c + R_supports = 0 on each body
            "cable_equilibrium_error": float(np.linalg.norm(p_res + on_cable + r_cable)
                                             / max(p_norm, 1e-300)),
            "cushion_equilibrium_error": float(np.linalg.norm(on_cushion + r_cushion)
                                               / max(c_norm, 1e-300)),
        }

    # the linear predictor along the last increment saves an iteration where the
    # contact zone grows (mortar default: at most 7 -> 6 iterations per step)
    return Setup(model=model, metrics=metrics, solve_options={"extrapolate": True},
                 # the cushion first: pictures draw the cable over it
                 outputs=[cushion, cable, *pair.outputs()])


def _tension_metrics(cable, slave, pair, z: np.ndarray) -> dict:
    """The cable tension over the contact zone and where the cable sticks and slips.

    The contact zone is the cable elements whose two nodes are both in the normal
    active set at the end; ``tension_variation = (max N - min N) / mean N`` over
    them (0 without such elements).  With friction: ``n_stick``, ``n_slip`` and
    ``stick_half_width``, ``slip_half_width`` (the largest ``|x|`` of a sticking,
    sliding node; 0 for none), beside ``contact_half_width`` (of an active node).
    """
    active = np.zeros(cable.X.shape[1], dtype=bool)
    active[slave.nodes[pair.active]] = True
    zone = np.all(active[np.asarray(cable.elements).reshape(-1, 2)], axis=1)
    N = cable.tension(z)[zone]
    x = np.abs(cable.x(z)[0, slave.nodes])
    out = {"tension_variation": float(np.ptp(N) / np.mean(N)) if N.size else 0.0,
           "tension_min": float(N.min()) if N.size else 0.0,
           "tension_max": float(N.max()) if N.size else 0.0,
           "contact_half_width": float(x[pair.active].max(initial=0.0))}
    if pair.friction is not None:  # the last step's statuses (checkpointed)
        status = pair.statuses.converged
        out.update(n_stick=int(np.sum(status == STICK)), n_slip=int(np.sum(status == SLIP)),
                   stick_half_width=float(x[status == STICK].max(initial=0.0)),
                   slip_half_width=float(x[status == SLIP].max(initial=0.0)))
    return out


def _split_xy(body, local_dofs) -> tuple[np.ndarray, np.ndarray]:
    """Global indices of the prescribed x-dofs and y-dofs of a body."""
    local = np.asarray(local_dofs)
    is_x = np.isin(local, body.node_dofs[0])
    if hasattr(body, "dofs_on"):  # solids: x-dofs of every kind (vertex, facet, ...)
        is_x = np.isin(local, body.dofs_on(np.arange(body.mesh.facets.shape[1]), "x"))
    return body.offset + local[is_x], body.offset + local[~is_x]


def estimate_dofs(params: dict) -> int:
    """Dofs of the cable and of the refined ``12 x 3`` cushion mesh."""
    k = 2 ** int(params["refine_cushion"])
    return cable_dofs(params["n_cable"]) + grid_dofs(12 * k, 3 * k)


def derived(params: dict) -> list:
    """The cable's scales, ``length0 / (2 half_span)`` in ``(1, 10]``, the cushion's
    Lame parameters and its sizes relative to the span in ``[1e-3, 1e3]`` (gap at
    most 100 spans: farther, the cable cannot reach it; the mesh check refuses
    thinner cushions as slivers)."""
    a, L0 = float(params["half_span"]), float(params["length0"])
    out = [positive("half_span", a, "half_span"), positive("length0", L0, "length0"),
           ratio("length0 / (2 half_span)", L0 / (2.0 * a), ("length0", "half_span"), 1.0,
                 10.0),
           *cable_quantities(float(params["EA"]), float(params["pressure"]), a, "half_span"),
           *lame_quantities(float(params["E_cushion"]), float(params["nu_cushion"]),
                            "E_cushion", "nu_cushion", "the cushion")]
    for name in ("cushion_width", "cushion_height"):
        out.append(ratio(f"{name} / half_span", float(params[name]) / a, (name, "half_span"),
                         1e-3, 1e3))
    out.append(ratio("gap / half_span", float(params["gap"]) / a, ("gap", "half_span"),
                     1e-12, 100.0))
    return out


SCENE = Scene(
    name="seed",
    summary="The paper's example: a nonlinear elastic cable inflated by a follower pressure "
            "into a soft neo-Hookean cushion.",
    params=(
        Param("half_span", 1.0, "half the distance a between the cable's supports", float,
              low=0.0, low_inclusive=False),
        Param("length0", 2.4, "reference length L0 of the cable (> 2a: stress-free arc start)",
              float, low=0.0, low_inclusive=False),
        Param("EA", 50.0, "axial stiffness of the cable", float, low=0.0, low_inclusive=False),
        Param("law", "svk", "axial law N(lambda) of the cable", str, choices=tuple(LAWS)),
        Param("pressure", 20.0, "inflation pressure p (force per current length)", float,
              low=0.0, low_inclusive=False),
        Param("gap", 0.1, "initial gap between the arc's apex and the cushion", float,
              low=0.0, low_inclusive=False),
        Param("cushion_width", 3.0, "width of the cushion", float, low=0.0, low_inclusive=False),
        Param("cushion_height", 0.75, "height of the cushion", float, low=0.0,
              low_inclusive=False),
        Param("E_cushion", 20.0, "Young's modulus of the cushion", float, low=0.0,
              low_inclusive=False),
        Param("nu_cushion", 0.3, "Poisson's ratio of the cushion", float, low=-1.0, high=0.5,
              low_inclusive=False, high_inclusive=False),
        Param("mu", 0.0, "Coulomb friction coefficient (0: frictionless, no friction built)",
              float, low=0.0, high=2.0),
        Param("n_cable", 48, "number of cable elements", int, low=4, high=1_000_000),
        Param("refine_cushion", 2, "uniform refinements of the 12 x 3 cushion mesh", int,
              low=0, high=6),
        Param("segmentation", "iteration", "when mortar segments are rebuilt", str,
              choices=("iteration", "step")),
        Param("n_gauss", 2, "Gauss points per mortar segment", int, low=1, high=10),
    ),
    build=build,
    methods=("mortar", "mortar-dual", "nts"),
    default_steps=10,
    estimate_dofs=estimate_dofs,
    sizes=("n_cable", "refine_cushion"),
    derived=derived,
)
