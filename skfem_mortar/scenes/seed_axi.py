"""Scene ``seed_axi``: the paper's scene in axisymmetry, a balloon inflated inside a tube.

A closed-end balloon of revolution (a neo-Hookean :class:`~skfem_mortar.bodies.membrane.Membrane`
of thickness ``H`` and shear modulus ``mu``: a cylinder of radius ``R_b`` and
length ``2 L_c`` closed by hemispherical caps) is inflated inside a neo-Hookean
tube (a :class:`~skfem_mortar.bodies.solid.Solid` of revolution, inner radius
``R_i = tube_ratio R_b``, wall ``wall``, half-length ``L_c + R_b``).  By
symmetry the half ``z >= 0`` is modelled: the balloon's meridian runs from the
mid-plane ``(R_b, 0)`` up the cylinder to the pole ``(0, L_c + R_b)``, ``u_z =
0`` at its mid-plane node and on the tube's mid-plane face; ``u_r = 0`` at the
pole by the membrane itself.  The balloon's outside (the right of its meridian)
is the slave surface, the tube's inner face the master.

``control=volume`` (default): a :class:`~skfem_mortar.loads.volume.VolumeControl`
prescribes ``V = V_0 (1 + (volume_ratio - 1) lf)``, the pressure its unknown.
``control=pressure``: a follower pressure rising to ``pressure`` (in units of
``mu H / R_b``).  Free, the balloon has a limit point: a closed-end neo-Hookean
cylinder's pressure peaks at ``p = 0.7499 mu H / R_b``, hoop stretch 1.577
(axial 1.178, :func:`cylinder_limit`); a hemispherical cap's at
``1.2395 mu H / R_b``, hoop stretch ``7^(1/6) = 1.383``.  Under pressure control
the tube must catch the cylinder before its limit, so ``tube_ratio`` at most
:data:`MAX_TUBE_RATIO` = 1.3 is required there (refused otherwise), and the
pressure below the caps' limit; volume control passes either.  ``tube=False``
builds the free balloon (no tube, no contact): the limit check.

Checks (metrics, each relative to the pressure's force): ``axial_balance_error``,
``|F_p,z + F_c,z + R_mid|`` over ``p pi r_mid^2`` (``F_p,z`` the pressure's nodal
forces summed: ``p pi r_mid^2`` exactly for the follower pressure, whose nodal
loads ``2 pi p int N_A r n ds`` telescope, ``r_mid`` the current mid-plane
radius; 0 under volume control, whose volume ``pi int r^2 dz`` closes the
meridian by the mid-plane disk through the mid-plane node, so the disk's pressure
acts on that node; ``F_c`` the contact force on the balloon, ``R_mid`` the
mid-plane reaction); ``radial_balance_error``, the virtual radial translation
``delta u_r = 1``: ``|F_p,r + F_c,r + R_axis - 2 pi int N_theta ds|`` over ``F_p,r``
(``F_p,r = 2 pi p int r dz`` along the meridian, ``N_theta`` the hoop tension per
current length, by the membrane's two-point Gauss rule, ``R_axis`` the pole's
radial reaction); ``tube_radial_error``, ``|F_c,r(tube) - 2 pi int P_tt dA_0|`` over
``F_p,r`` (``P_tt`` the hoop component of the first Piola stress at the tube's
quadrature points: ``2 pi int sigma_tt da`` in the current configuration).
Also ``cut_force`` (``2 pi H sum_q w_q R_q W_1 t_z`` on the first element, the
meridional pull across the mid-plane, ``2 pi r_mid N_s``) and ``cut_balance_error``,
``|p pi r_mid^2 + F_c,z - cut_force|`` over ``p pi r_mid^2`` (the discrete pressure
on the first element is ``p pi (r_0^2 + r_0 r_1 + r_1^2) / 3``: O(h^2), reported).
"""
from __future__ import annotations

import math

import numpy as np
from skfem import MeshQuad

from ..bodies.materials import NeoHooke
from ..bodies.membrane import Membrane
from ..bodies.solid import Solid
from ..contact.pair import ContactPair
from ..contact.surfaces import ContactSurface
from ..core.dirichlet import Dirichlet
from ..core.lazy import brentq
from ..core.model import Model
from ..loads.pressure import FollowerPressure
from ..loads.volume import VolumeControl
from . import METHODS, Param, Scene, Setup, cable_dofs, grid_dofs, lame_quantities, positive, ratio
from ._axi import reaction
from .balloon import LIMIT_STRETCH, P_MAX_FACTOR

__all__ = ["SCENE", "build", "cylinder_limit", "balloon_meridian", "MAX_TUBE_RATIO"]

#: the largest tube radius over the balloon's under pressure control (module docstring)
MAX_TUBE_RATIO = 1.3
_GAUSS = np.array([0.5 - 0.5 / math.sqrt(3.0), 0.5 + 0.5 / math.sqrt(3.0)])


def cylinder_limit() -> tuple[float, float, float]:
    """The closed-end neo-Hookean cylinder membrane's limit point: ``(hoop stretch,
    axial stretch, p R / (mu H))`` at the pressure maximum.  With tensions per
    current length ``T_1 = mu H (l1 / l2 - 1 / (l1 l2)^3)`` (axial ``l1``, hoop
    ``l2``: ``T_2`` with the roles swapped), the closed end asks ``T_2 = 2 T_1`` and
    ``p = T_2 / (l2 R)``; the maximum over ``l2`` by golden-section search."""
    def axial(l2: float) -> float:
        return brentq(lambda l1: (l2 / l1 - (l1 * l2) ** -3)
                      - 2.0 * (l1 / l2 - (l1 * l2) ** -3), 0.2, 10.0, xtol=1e-14)

    def p(l2: float) -> float:
        l1 = axial(l2)
        return (l2 / l1 - (l1 * l2) ** -3) / l2
    lo, hi = 1.05, 3.0
    g = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(80):
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        lo, hi = (a, hi) if p(a) < p(b) else (lo, b)
    l2 = 0.5 * (lo + hi)
    return l2, axial(l2), p(l2)


def balloon_meridian(R_b: float, L_c: float, n: int) -> np.ndarray:
    """The half balloon's meridian (2, m): from ``(R_b, 0)`` up the cylinder to
    ``(R_b, L_c)`` and around the cap to the pole ``(0, L_c + R_b)``, ``n`` elements
    of about equal length over the whole."""
    n_cap = max(2, int(round(n * 0.5 * math.pi * R_b / (L_c + 0.5 * math.pi * R_b))))
    n_cyl = max(1, n - n_cap)
    z = np.linspace(0.0, L_c, n_cyl + 1)
    th = np.linspace(0.0, 0.5 * math.pi, n_cap + 1)[1:]
    return np.hstack([np.vstack([np.full(n_cyl + 1, R_b), z]),
                      np.vstack([R_b * np.cos(th), L_c + R_b * np.sin(th)])])


def tube_mesh(R_i: float, R_o: float, L: float, n_r: int, n_z: int):
    """The tube's meridian section ``[R_i, R_o] x [0, L]`` (quadrilaterals), boundaries
    ``inner``, ``outer``, ``midplane`` (``z = 0``), ``end``."""
    mesh = MeshQuad.init_tensor(np.linspace(R_i, R_o, n_r + 1), np.linspace(0.0, L, n_z + 1))
    tol = 1e-9 * L
    return mesh.with_boundaries({
        "inner": lambda x: np.abs(x[0] - R_i) < tol, "outer": lambda x: np.abs(x[0] - R_o) < tol,
        "midplane": lambda x: np.abs(x[1]) < tol, "end": lambda x: np.abs(x[1] - L) < tol})


def _sizes(params: dict) -> tuple[int, int, int]:
    """Membrane elements, tube elements through the wall and along it."""
    k = 2.0 ** int(params["refine"])
    return int(24 * k), max(1, int(2 * k)), int(16 * k)


def hoop_integral(membrane: Membrane, z: np.ndarray) -> float:
    """``2 pi int N_theta ds`` over the current meridian, by the two-point Gauss rule
    on each element: ``2 pi sum_e L_e sum_q w_q H W_2(l1, l2_q)`` (``N_theta = H W_2 / l1``
    per current length, ``ds = l1 L_e dxi``)."""
    x, X = membrane.x(z), membrane.X
    i, j = membrane.elements[:, 0], membrane.elements[:, 1]
    L = np.hypot(*(X[:, j] - X[:, i]))
    l1 = np.hypot(*(x[:, j] - x[:, i])) / L
    N = np.column_stack([1.0 - _GAUSS, _GAUSS])                     # (q, a)
    r, R = x[0][membrane.elements] @ N.T, X[0][membrane.elements] @ N.T
    _, _, W2, *_ = membrane.law.derivatives(l1[:, None], r / R)
    return float(2.0 * math.pi * np.sum(L[:, None] * 0.5 * membrane.H * W2))


def cut_force(membrane: Membrane, z: np.ndarray) -> float:
    """The axial force the first element transmits across the mid-plane,
    ``2 pi H L sum_q w_q R_q W_1(l1, l2_q) t_z / L`` (``t`` its current unit tangent):
    ``2 pi r_mid N_s`` in the continuum."""
    x, X = membrane.x(z), membrane.X
    i, j = membrane.elements[0]
    d = x[:, j] - x[:, i]
    l1 = np.hypot(*d) / np.hypot(*(X[:, j] - X[:, i]))
    N = np.column_stack([1.0 - _GAUSS, _GAUSS])
    r, R = N @ x[0, [i, j]], N @ X[0, [i, j]]
    _, W1, *_ = membrane.law.derivatives(np.full(2, l1), r / R)
    return float(2.0 * math.pi * membrane.H * np.sum(0.5 * R * W1) * d[1] / np.hypot(*d))


def load_force(item, z: np.ndarray, lf: float, n: int) -> np.ndarray:
    """The nodal forces (length ``n``) an item applies at ``z``: minus its residual."""
    c = item.assemble(z, lf, tangent=False)
    return -np.bincount(c.r_index, weights=c.r_value, minlength=n)[:n]


def _balloon(params: dict, n: int):
    """The membrane, its mid-plane support and the volume control or the pressure."""
    R_b, mu, H = (float(params[k]) for k in ("radius", "mu", "thickness"))
    membrane = Membrane(balloon_meridian(R_b, float(params["half_length"]), n), H=H, mu=mu,
                        name="balloon")
    mid = Dirichlet(membrane, membrane.node_dofs[1, [0]], 0.0, name="balloon_midplane")
    if params["control"] == "volume":
        vr = float(params["volume_ratio"])
        control = VolumeControl(membrane, lambda lf: control.reference_volume
                                * (1.0 + (vr - 1.0) * lf), name="volume")
    else:
        control = FollowerPressure(membrane, float(params["pressure"]) * mu * H / R_b,
                                   side="right", name="pressure")
    return membrane, mid, control


def _tube(params: dict, n_r: int, n_z: int):
    """The tube and its mid-plane support."""
    R_b, L_c = float(params["radius"]), float(params["half_length"])
    R_i = float(params["tube_ratio"]) * R_b
    tube = Solid(tube_mesh(R_i, R_i + float(params["wall"]), L_c + R_b, n_r, n_z),
                 NeoHooke(E=float(params["E_tube"]), nu=float(params["nu_tube"])),
                 element="quad1", name="tube")
    return tube, Dirichlet(tube, tube.dofs_on("midplane", "y"), 0.0, name="tube_midplane")


def _pressure(control, z: np.ndarray, lf: float) -> float:
    """The balloon's pressure: the volume control's unknown or the applied one."""
    return control.pressure(z) if isinstance(control, VolumeControl) else \
        control.current_pressure(lf)


def build(params: dict, method: str | None = None) -> Setup:
    """Balloon, control, tube, supports and the contact pair; balances as metrics."""
    if (params["control"] == "pressure" and params["tube"]
            and float(params["tube_ratio"]) > MAX_TUBE_RATIO):
        raise ValueError(f"tube_ratio must be at most {MAX_TUBE_RATIO} under pressure control "
                         f"(the tube must catch the balloon's cylinder below its limit point, "
                         f"hoop stretch {cylinder_limit()[0]:.3f}), got {params['tube_ratio']!r}; "
                         f"use control=volume for a wider tube")
    method = method or "mortar"
    n, n_r, n_z = _sizes(params)
    membrane, mid, control = _balloon(params, n)
    items, pair, tube, tube_mid = [membrane, control, mid], None, None, None
    if params["tube"]:
        tube, tube_mid = _tube(params, n_r, n_z)
        pair = ContactPair(ContactSurface.from_cable(membrane, side="right", name="balloon_out"),
                           ContactSurface.from_solid(tube, "inner", name="tube_inner"), method,
                           name="contact")
        items += [tube, tube_mid, pair]
    model = Model(items, geometry="axisymmetric")
    pole = np.flatnonzero(membrane.pole)
    scale = float(params["mu"]) * float(params["thickness"]) / float(params["radius"])

    def metrics(result) -> dict:
        z, lf = result.z, float(result.load_factors[-1])
        Rz = result.residual()
        p = _pressure(control, z, lf)
        x = membrane.x(z)
        e = membrane.elements
        Fp_scale = p * math.pi * x[0, 0] ** 2
        Fp_z = float(load_force(control, z, lf, model.n)[membrane.offset
                                                        + membrane.node_dofs[1]].sum())
        Fp_r = 2.0 * math.pi * p * float(np.sum(0.5 * (x[0, e[:, 0]] + x[0, e[:, 1]])
                                                 * (x[1, e[:, 1]] - x[1, e[:, 0]])))
        Fc, Fm = pair.forces(z) if pair is not None else (np.zeros((2, 1)), np.zeros((2, 1)))
        R_mid = float(Rz[membrane.offset + membrane.node_dofs[1, 0]])
        R_axis = float(Rz[membrane.offset + membrane.node_dofs[0, pole]].sum())
        l1, l2 = membrane.stretches(z)
        out = {"pressure": p, "pressure_over_scale": p / scale,
               "hoop_stretch_mid": float(x[0, 0] / membrane.X[0, 0]),
               "hoop_stretch_max": float(l2.max()),
               "axial_balance_error": abs(Fp_z + Fc[1].sum() + R_mid) / abs(Fp_scale),
               "cut_force": cut_force(membrane, z),
               "radial_balance_error": abs(Fp_r + Fc[0].sum() + R_axis
                                           - hoop_integral(membrane, z)) / abs(Fp_r),
               "contact_force_axial": float(Fc[1].sum()),
               "contact_force_radial": float(Fc[0].sum())}
        out["cut_balance_error"] = abs(Fp_scale + Fc[1].sum() - out["cut_force"]) / Fp_scale
        if isinstance(control, VolumeControl):   # the pressure's largest value on the path
            ps = [control.pressure(zk) for zk in result.states[1:]]
            k = int(np.argmax(ps))
            out.update(pressure_max_over_scale=ps[k] / scale, hoop_stretch_mid_at_pressure_max=
                       float(membrane.x(result.states[1 + k])[0, 0] / membrane.X[0, 0]))
        if pair is not None:
            F, P = tube.first_piola(z)
            hoop = 2.0 * math.pi * float(np.sum(P[2, 2] * tube.basis.dx))
            out.update(tube_radial_error=abs(Fm[0].sum() - hoop) / abs(Fp_r),
                       n_active=int(pair.active.sum()),
                       contact_length=float(np.ptp(x[1, pair.slave.nodes[pair.active]]))
                       if pair.active.any() else 0.0,
                       tube_midplane_reaction=reaction(tube, Rz, tube_mid.local_dofs)[1])
        return out

    outputs = [membrane] + ([tube, *pair.outputs()] if pair is not None else [])
    return Setup(model=model, metrics=metrics, outputs=outputs,
                 solve_options={"extrapolate": True})


def estimate_dofs(params: dict) -> int:
    """The membrane's and the tube grid's dofs."""
    n, n_r, n_z = _sizes(params)
    return cable_dofs(n) + (grid_dofs(n_r, n_z) if params["tube"] else 0)


def derived(params: dict) -> list:
    """Scales, the slenderness ``H / R_b`` (a membrane), the tube's Lame parameters."""
    R, H, mu = (float(params[k]) for k in ("radius", "thickness", "mu"))
    return [positive("radius", R, "radius"), positive("mu thickness", mu * H, "mu", "thickness"),
            ratio("thickness / radius", H / R, ("thickness", "radius"), 0.0, 0.1),
            ratio("wall / radius", float(params["wall"]) / R, ("wall", "radius"), 1e-3, 1e3),
            ratio("half_length / radius", float(params["half_length"]) / R,
                  ("half_length", "radius"), 1e-3, 1e3),
            *lame_quantities(float(params["E_tube"]), float(params["nu_tube"]), "E_tube",
                             "nu_tube", "the tube")]


SCENE = Scene(
    name="seed_axi",
    summary="The paper's scene in axisymmetry: a closed-end neo-Hookean balloon inflated "
            "under volume control inside a neo-Hookean tube.",
    params=(
        Param("radius", 1.0, "balloon radius R_b", float, low=0.0, low_inclusive=False),
        Param("half_length", 1.5, "half-length L_c of the balloon's cylinder", float, low=0.0,
              low_inclusive=False),
        Param("thickness", 0.01, "balloon thickness H", float, low=0.0, low_inclusive=False),
        Param("mu", 1.0, "balloon shear modulus", float, low=0.0, low_inclusive=False),
        Param("control", "volume", "prescribe the volume, or the pressure", str,
              choices=("volume", "pressure")),
        Param("volume_ratio", 1.8, "volume control: the final volume over the reference one",
              float, low=1.0, high=50.0, low_inclusive=False),
        Param("pressure", 0.9, "pressure control: the final pressure over mu H / R_b (below "
              f"the caps' limit {P_MAX_FACTOR:.4f}, stretch {LIMIT_STRETCH:.3f})", float,
              low=0.0, high=P_MAX_FACTOR, low_inclusive=False, high_inclusive=False),
        Param("tube", True, "with the tube (False: the free balloon and its limit point)",
              bool),
        Param("tube_ratio", 1.2, "tube inner radius over R_b (at most 1.3 under pressure "
              "control)", float, low=1.0, high=10.0, low_inclusive=False),
        Param("wall", 0.25, "tube wall thickness", float, low=0.0, low_inclusive=False),
        Param("E_tube", 1.0, "tube Young's modulus", float, low=0.0, low_inclusive=False),
        Param("nu_tube", 0.3, "tube Poisson's ratio", float, low=0.0, high=0.5,
              high_inclusive=False),
        Param("refine", 0, "mesh level: 24 2^refine membrane elements, a 2 x 16 grid "
              "refined 2^refine for the tube", int, low=-2, high=6),
    ),
    build=build,
    methods=METHODS,
    default_steps=20,
    estimate_dofs=estimate_dofs,
    sizes=("refine",),
    derived=derived,
)
