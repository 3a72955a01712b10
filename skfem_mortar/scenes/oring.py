"""Scene ``oring``: an O-ring squeezed between rigid plates normal to its axis.

An O-ring of cross-section diameter ``d`` and mean radius ``R_m`` (``ratio =
R_m / d``, default 5) of nearly incompressible neo-Hookean rubber (``nu``
default 0.4995; ``element``: MINI u-p triangles, :class:`~skfem_mortar.bodies.mixed.MixedSolid`,
or the mean-dilatation quadrilaterals, :class:`~skfem_mortar.bodies.sri.SRISolid`)
is squeezed axially between two rigid plates.  By symmetry the half ``z >= 0``
of the cross-section (a half disk centred at ``(R_m, 0)``, radius ``c = d / 2``)
is modelled, ``u_z = 0`` on the mid-plane.  The relative motion is prescribed:
the plate ``z = c`` (the slave surface is the half disk's arc, the master the
plate, :func:`~skfem_mortar.scenes._axi.rigid_plate`, reaching ``10 c + 0.1 R_m``
to either side of ``R_m``) stays, and the mid-plane
is moved up by ``squeeze d / 2``, rising linearly with the load factor (the
same as moving the plate down by it; the squeeze is the cross-section's height
reduction over ``d``, default 25 %).  ``mu > 0`` adds Coulomb friction.

``geometry``: ``axisymmetric`` (the ring of revolution, ``x[0] = r``) or
``plane`` (the same cross-section in plane strain, a straight cord, its
horizontal rigid motion removed by ``u_x = 0`` at the centre ``(R_m, 0)``,
where symmetry puts it).  ``hold_centre`` holds the centre at ``u_r = 0`` in
axisymmetry too: the ring then keeps its hoop strain near 0 as plane strain
does, and its force per circumference tends to the plane-strain one as
``R_m / d`` grows (measured at ``R_m / d = 100``, 10 % squeeze: 1e-5 relative;
the hold's reaction ``centre_reaction`` 0.25 % of the axial force).  A free ring
(default) relieves the compressive hoop stress of plane strain (``nu (sigma_rr +
sigma_zz)``) by expanding: ``u_r / R_m`` 2.7 % there, and its force per
circumference is 17 % below the plane-strain one however slender the ring.
The force per unit mean circumference is ``F / (2 pi R_m)``, ``F`` the total
axial contact force over the revolution (plane: the force per unit length).

Mesh: the half disk as two mirrored quarter disks of
:func:`~skfem_mortar.scenes.hertz.graded_quarter_disk`, graded towards the
first contact point ``(R_m, c)``: element edges ``h0 = (b_g / 30) 2^-refine``
within ``1.2 b_g`` of it, ``b_g = sqrt(d delta)`` the half-width of the
geometric overlap (``delta = squeeze d / 2``), growing by 0.3 times the
distance beyond; ``sri`` splits each triangle of the mesh graded to ``2 h0``
into three quadrilaterals.

Metrics: ``contact_width`` (between the ends of the nodes in compression,
:func:`~skfem_mortar.scenes._axi.compression_span`), ``peak_pressure``,
``contact_force`` (the total axial force on the plate) and
``force_per_circumference``; against Hertz line contact of a cylinder of radius
``c`` on a plane under the computed force per length ``P`` (``E* = E / (1 - nu^2)``,
``b = sqrt(4 P c / (pi E*))``, ``p0 = 2 P / (pi b)``, valid at small squeeze):
``half_width_hertz``, ``peak_pressure_hertz`` with ``_error``; Lindley's
empirical ``F / (2 pi R_m) = E d (1.25 s^1.5 + 50 s^6)`` (``s`` the squeeze,
a sanity band only: an empirical fit for rubber rings, not a reference);
``force_squeeze`` (the force per circumference at every converged step).
"""
from __future__ import annotations

import math

import numpy as np
from skfem import MeshQuad, MeshTri

from ..bodies.materials import NeoHooke
from ..bodies.mixed import MixedSolid
from ..bodies.solid import KINEMATICS
from ..bodies.sri import SRISolid
from ..contact.friction import Coulomb
from ..contact.pair import ContactPair
from ..contact.surfaces import ContactSurface
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from . import METHODS, Param, Scene, Setup, grid_dofs, lame_quantities, positive
from ._axi import compression_span, profile, rigid_plate
from .hertz import FINE_ZONE, graded_quarter_disk, hertz_exact, triangles_to_quads

__all__ = ["SCENE", "build", "half_disk", "lindley_force", "ELEMENTS"]

#: MINI u-p triangles or mean-dilatation quadrilaterals (both for nu -> 0.5)
ELEMENTS = ("mini", "sri")


def lindley_force(squeeze: float, E: float, d: float) -> float:
    """Lindley's empirical force per unit mean circumference of an O-ring,
    ``E d (1.25 s^1.5 + 50 s^6)`` at the squeeze ``s`` (a sanity band only)."""
    return E * d * (1.25 * squeeze ** 1.5 + 50.0 * squeeze ** 6)


def _mirror_join(q: MeshTri, tol: float) -> MeshTri:
    """The quarter disk ``q`` (``x >= 0``) and its mirror image ``x -> -x`` as one mesh,
    the nodes on ``x = 0`` shared (the mirror's triangles turned counter-clockwise)."""
    p, t = q.p, q.t
    on = np.flatnonzero(np.abs(p[0]) < tol)
    off = np.setdiff1d(np.arange(p.shape[1]), on)
    index = np.empty(p.shape[1], dtype=np.int64)
    index[on] = on
    index[off] = p.shape[1] + np.arange(off.size)
    P = np.hstack([p, np.vstack([-p[0, off], p[1, off]])])
    T = np.hstack([t, index[t][[0, 2, 1]]])
    return MeshTri(P, np.ascontiguousarray(T))


def half_disk(R_m: float, c: float, h0: float, fine: float, element: str):
    """The half cross-section ``z >= 0`` of the disk of radius ``c`` about ``(R_m, 0)``,
    graded towards its top point ``(R_m, c)``; boundaries ``arc`` and ``midplane``.
    ``element="sri"``: quadrilaterals (each triangle of the mesh graded to ``2 h0``
    split in three, the arc's new nodes moved onto the circle)."""
    quads = element == "sri"
    q = graded_quarter_disk(c, 2.0 * h0 if quads else h0, fine, "tri1")
    tol = 1e-9 * c
    m = _mirror_join(q, tol)
    P = np.vstack([R_m - m.p[0], c - m.p[1]])      # turned by pi: contact point on top
    mesh = MeshTri(P, m.t)
    if quads:
        Q = triangles_to_quads(mesh)
        P = Q.p.copy()
        b = Q.boundary_nodes()
        b = b[P[1, b] > tol]
        v = P[:, b] - np.array([[R_m], [0.0]])
        P[:, b] = np.array([[R_m], [0.0]]) + c * v / np.hypot(v[0], v[1])
        mesh = MeshQuad(P, Q.t)
    return mesh.with_boundaries({"midplane": lambda x: np.abs(x[1]) < tol,
                                 "arc": lambda x: x[1] > tol})


def _ring(params: dict, h0: float, fine: float):
    """The O-ring's body on the half cross-section."""
    d, E, nu = float(params["d"]), float(params["E"]), float(params["nu"])
    R_m = float(params["ratio"]) * d
    mesh = half_disk(R_m, 0.5 * d, h0, fine, params["element"])
    cls = SRISolid if params["element"] == "sri" else MixedSolid
    return cls(mesh, NeoHooke(E=E, nu=nu), name="oring", kinematics=params["kinematics"])


def build(params: dict, method: str | None = None) -> Setup:
    """The ring's half cross-section, the mid-plane's motion, the plate, the pair."""
    d, E, nu = float(params["d"]), float(params["E"]), float(params["nu"])
    s, c = float(params["squeeze"]), 0.5 * float(params["d"])
    R_m = float(params["ratio"]) * d
    method = method or "mortar-dual"
    delta = s * c                                    # the half model's share of s d
    b_g = math.sqrt(d * delta)
    h0 = b_g / 30.0 * 2.0 ** (-int(params["refine"]))
    ring = _ring(params, h0, min(FINE_ZONE * b_g, 2.0 * c))
    mid = Dirichlet(ring, ring.dofs_on("midplane", "y"), delta, name="midplane")
    items = [ring, mid]
    plane = params["geometry"] == "plane"
    centre = int(np.argmin(np.hypot(ring.X[0] - R_m, ring.X[1])))
    held = Dirichlet(ring, ring.node_dofs[0, [centre]], 0.0, name="centre")
    if plane or params["hold_centre"]:
        items.append(held)
    reach = 10.0 * c + 0.1 * R_m         # the free ring's radial expansion stays on the plate
    plate = rigid_plate(c, max(R_m - reach, 0.0), R_m + reach, math.sqrt(2.0) * h0, up=False)
    mu = float(params["mu"])
    options = {} if method == "nts" else {"segmentation": "iteration"}
    pair = ContactPair(ContactSurface.from_solid(ring, "arc", name="oring_arc"), plate, method,
                       name="contact", friction=Coulomb(mu) if mu > 0.0 else None, **options)
    model = Model(items + [pair], geometry=params["geometry"])
    per = 1.0 if plane else 2.0 * math.pi * R_m      # force per unit mean circumference

    def metrics(result) -> dict:
        z = result.z
        r, p = profile(pair, z)
        left, right = compression_span(r, p)
        F = -float(pair.total_force(z)[1])           # the plate pushes the ring down
        P = F / per
        ex = hertz_exact(c, P, E, nu, None, 0.3) if P > 0 else {"half_width": 0.0,
                                                               "peak_pressure": 0.0}
        out = {"contact_width": right - left, "peak_pressure": float(p.max(initial=0.0)),
               "contact_force": F, "force_per_circumference": P, "squeeze": s,
               "half_width_hertz": ex["half_width"], "peak_pressure_hertz": ex["peak_pressure"],
               "lindley_force_per_circumference": lindley_force(s, E, d),
               "n_active": int(pair.active.sum()), "element_size": h0,
               "centre_reaction": float(result.residual()[ring.offset + held.local_dofs[0]])
               if held in items else 0.0,
               "force_squeeze": [[float(lf) * s, -float(pair.total_force(zk)[1]) / per]
                                 for lf, zk in zip(result.load_factors[1:], result.states[1:])]}
        if P > 0:
            out["half_width_hertz_error"] = abs(0.5 * (right - left) / ex["half_width"] - 1)
            out["peak_pressure_hertz_error"] = abs(out["peak_pressure"] / ex["peak_pressure"]
                                                   - 1)
        return out

    return Setup(model=model, metrics=metrics, outputs=[ring, *pair.outputs()])


def estimate_dofs(params: dict) -> int:
    """An upper estimate: a uniform grid of the half disk's extent at ``h0`` near the
    contact zone (the graded mesh has fewer), plus MINI's bubbles and pressures."""
    s = float(params["squeeze"])
    n = int(math.ceil(60.0 / math.sqrt(2.0 * s) * 2.0 ** int(params["refine"])))
    return grid_dofs(min(n, 4000), min(n, 4000) // 2) * 2


def derived(params: dict) -> list:
    """The diameter, the Lame parameters and ``E d``."""
    d, E, nu = float(params["d"]), float(params["E"]), float(params["nu"])
    return [positive("d", d, "d"), *lame_quantities(E, nu),
            positive("E d", E * d, "E", "d")]


def one_step(params: dict, method: str | None) -> bool:
    """Never: the squeeze is a displacement path through large strain (and with
    friction a history); the default steps are the force-squeeze curve's points."""
    return False


SCENE = Scene(
    name="oring",
    summary="An O-ring of nearly incompressible neo-Hooke squeezed axially between rigid "
            "plates, axisymmetric or its plane-strain cross-section.",
    params=(
        Param("d", 1.0, "cross-section diameter d", float, low=0.0, low_inclusive=False),
        Param("ratio", 5.0, "mean radius over the cross-section diameter R_m / d", float,
              low=0.5, high=200.0, low_inclusive=False),
        Param("E", 1.0, "Young's modulus", float, low=0.0, low_inclusive=False),
        Param("nu", 0.4995, "Poisson's ratio (> 0: the mixed elements' pressure equation "
              "divides by lambda)", float, low=0.0, high=0.5, low_inclusive=False,
              high_inclusive=False),
        Param("squeeze", 0.25, "final height reduction over d", float, low=0.0, high=0.4,
              low_inclusive=False),
        Param("mu", 0.0, "Coulomb friction coefficient with the plate (0: frictionless)",
              float, low=0.0, high=2.0),
        Param("geometry", "axisymmetric", "the ring of revolution, or its cross-section in "
              "plane strain", str, choices=("axisymmetric", "plane")),
        Param("hold_centre", False, "axisymmetric: hold the centre (R_m, 0) at u_r = 0 too "
              "(no radial expansion: the plane-strain limit as R_m / d grows); its reaction "
              "is reported", bool),
        Param("element", "mini", "MINI u-p triangles or mean-dilatation quadrilaterals (sri)",
              str, choices=ELEMENTS),
        Param("refine", 0, "mesh level: element size (b_g / 30) 2^-refine near the contact",
              int, low=-3, high=3),
        Param("kinematics", "finite", "the ring's strain: finite (neo-Hooke) or small",
              str, choices=KINEMATICS),
    ),
    build=build,
    methods=METHODS,
    default_steps=10,
    estimate_dofs=estimate_dofs,
    sizes=("refine",),
    derived=derived,
    one_step=one_step,
)
