"""The parts of scene ``patch3d``: the 3D contact patch test, two stacked non-matching
blocks (private until the 3D contact pair registers the scene).

The lower block ``[0, 1]^2 x [0, H]`` (``n_lower`` cells a side) stands on
frictionless rollers (``u_z = 0`` on ``Z = 0``); the upper block
``[m h, 1 - m h]^2 x [H, 2 H]`` (``h = 1 / n_lower``, ``m = margin``: its footprint
covers whole cells of the lower block, so its edges lie on the lower mesh's grid
lines) has ``n_upper`` cells a side.  The top of the upper block and the part of
the lower block's top that the footprint leaves uncovered carry the same
follower (Cauchy) pressure ``p``.  Each block's in-plane modes are held by
rollers on its two mid-planes (``u_x = 0`` on ``X = 1/2``, ``u_y = 0`` on
``Y = 1/2``, the same planes for both blocks since the footprint is centred); the
upper block's vertical position is held by contact alone.
``element = upper/lower`` picks ``tet1`` or ``hex1`` for each block (one name: both);
``distort`` tilts the free x-grid lines (not the ends, mid-planes or footprint
edges) by ``+-distort`` of a cell, so that the interface faces of ``hex1`` are
trapezoids (tet1 faces stay affine triangles).

Exact answer (:func:`exact_patch3d`): both blocks are one material, so both are
in the same uniaxial state ``F = diag(l, l, s)`` with Cauchy ``sigma_zz = -p`` and
``sigma_xx = sigma_yy = 0``: ``P_zz(s) + p l(s)^2 = 0`` with ``l(s)``, ``P_zz(s)`` the
lateral stretch and nominal stress of the law's uniaxial state
(:func:`~skfem_mortar.scenes.block3d.exact_uniaxial3d`).  The same equation holds at
small strain (linear elasticity, ``P`` the linear stress, the pressure on the
current faces).  The displacement is ``u = (F - I)(X - X_c)``, ``X_c = (1/2, 1/2,
0)``, in both blocks: affine, so every element reproduces it, and the interface
does not slide.  The contact pressure (force per current area) is ``p``, the
contact force ``p l^2 A`` on the footprint's reference area ``A``, the rollers'
reaction on the lower block's bottom ``p l^2``.

Readings (:func:`patch_metrics`): ``pressure_error`` (``max |p_A - p| / p`` over the
slave nodes), ``displacement_error`` (the largest nodal ``|u_h - u|`` of both blocks
over the largest ``|u|``), ``contact_force`` (the slave side's ``z`` resultant)
against ``p l^2 A``, ``force_balance`` (``|f_slave + f_master| / (p l^2 A)``: the two
sides' contact forces sum to zero) and ``support_reaction`` against ``p l^2``.
The scene's registration (the contact pair) waits for the 3D pair.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..bodies.solid import Solid, constitutive_law
from ..core.dirichlet import Dirichlet
from ..core.lazy import brentq
from ..loads.pressure3d import FollowerPressure3D
from . import Derived, Param, lame_quantities, positive, ratio
from ._contact3d import grid_mesh, nodes_on_plane, tilted_lines
from ._scene3d import LAWS, displacement, law_params, make_solid
from .block3d import exact_uniaxial3d

__all__ = ["PARAMS", "PatchParts", "build_bodies", "exact_patch3d", "patch_metrics",
           "derived", "estimate_dofs", "HEIGHT", "PAIRINGS"]

#: height of each block (the lower block is ``1 x 1 x HEIGHT``)
HEIGHT = 0.5

#: ``element`` values: one element for both blocks, or ``upper/lower``
PAIRINGS = ("tet1", "hex1", "tet1/hex1", "hex1/tet1")

#: the lowest axial stretch :func:`exact_patch3d` searches (a block crushed to 5 %)
S_MIN = 0.05


@dataclass
class PatchParts:
    """The bodies and items of ``patch3d`` without the contact pair.

    Attributes
    ----------
    upper, lower : Solid
    items : list
        Both bodies, the two pressures and the rollers.
    slave, master : tuple (Solid, str)
        The contact surfaces: a body and its boundary tag (``bottom`` of the upper
        block, ``covered`` of the lower one: the footprint on either side).
    footprint : tuple of float
        ``(lo, hi)``: the footprint is ``[lo, hi]^2`` at ``Z = HEIGHT``.
    support : ndarray
        The lower block's local dofs on its bottom rollers (``u_z``).
    """

    upper: Solid
    lower: Solid
    items: list
    slave: tuple
    master: tuple
    footprint: tuple[float, float]
    support: np.ndarray


def _elements(pairing: str) -> tuple[str, str]:
    """``(upper, lower)`` elements of ``pairing``."""
    if pairing not in PAIRINGS:
        raise ValueError(f"element must be one of {', '.join(PAIRINGS)}, got {pairing!r}")
    up, _, low = pairing.partition("/")
    return up, (low or up)


def _block(params: dict, element: str, n: int, lo: float, hi: float, z0: float,
           fixed: set[int], name: str, footprint: tuple | None = None,
           lines: np.ndarray | None = None) -> Solid:
    """A block ``[lo, hi]^2 x [z0, z0 + HEIGHT]`` of ``n`` cells a side, tagged ``bottom``,
    ``top`` and, with a ``footprint`` ``(a, b)``, its top faces inside ``[a, b]^2``
    ``covered``, the others ``uncovered``; ``lines``: its x-grid lines (default ``n``
    equal cells)."""
    h = (hi - lo) / n
    nz = max(1, int(round(HEIGHT / h)))
    xs = np.linspace(lo, hi, n + 1) if lines is None else np.asarray(lines, dtype=float)
    tilt = tilted_lines(n, h, float(params["distort"]), fixed | {0, n, n // 2})
    mesh = grid_mesh(element, xs, xs, np.linspace(z0, z0 + HEIGHT, nz + 1), tilt)
    tol = 1e-9
    tags = {"bottom": lambda x: np.abs(x[2] - z0) < tol,
            "top": lambda x: np.abs(x[2] - z0 - HEIGHT) < tol}
    mesh = mesh.with_boundaries(tags)
    if footprint is not None:
        top = mesh.boundaries["top"]
        c = mesh.p[:, mesh.facets[:, top]].mean(axis=1)
        inside = np.all((c[:2] > footprint[0]) & (c[:2] < footprint[1]), axis=0)
        mesh = mesh.with_boundaries({"covered": top[inside], "uncovered": top[~inside]})
    return make_solid(mesh, {**params, "element": element}, name)


def _rollers(body: Solid, name: str) -> list:
    """``u_x = 0`` on ``X = 1/2`` and ``u_y = 0`` on ``Y = 1/2`` (the mid-planes)."""
    return [Dirichlet(body, nodes=nodes_on_plane(body.mesh, k, 0.5, 1e-9), component=k,
                      name=f"{name}_roller_{'xy'[k]}") for k in (0, 1)]


def build_bodies(params: dict, upper_lines: np.ndarray | None = None) -> PatchParts:
    """The two blocks, their pressures and rollers (module docstring), the contact
    surfaces' names; ``params`` as the scene's (:data:`PARAMS`).  ``upper_lines``: the
    upper block's ``n_upper + 1`` x-grid lines, increasing from the footprint's edge to
    the other, through ``X = 1/2`` (default equal cells; ``distort`` is then not
    applied to them), to place a slave face across a line of the lower block's grid."""
    up_el, low_el = _elements(params["element"])
    n_low, n_up, m = int(params["n_lower"]), int(params["n_upper"]), int(params["margin"])
    lo, hi = m / n_low, 1.0 - m / n_low
    lower = _block(params, low_el, n_low, 0.0, 1.0, 0.0, {m, n_low - m}, "lower", (lo, hi))
    upper = _block(params, up_el, n_up, lo, hi, HEIGHT, set(), "upper",
                   lines=_upper_lines(upper_lines, n_up, lo, hi))
    q = float(params["pressure"])
    items = [upper, lower, FollowerPressure3D(upper, q, "top", name="pressure")]
    if m > 0:
        items.append(FollowerPressure3D(lower, q, "uncovered", name="uncovered_pressure"))
    support = lower.dofs_on("bottom", "z")
    items += [Dirichlet(lower, support, 0.0, name="lower_rollers_z"),
              *_rollers(lower, "lower"), *_rollers(upper, "upper")]
    surfaces = {"upper": (upper, "bottom"), "lower": (lower, "covered")}
    other = "lower" if params["slave"] == "upper" else "upper"
    return PatchParts(upper, lower, items, surfaces[params["slave"]], surfaces[other],
                      (lo, hi), support)


def _upper_lines(lines: np.ndarray | None, n: int, lo: float, hi: float
                 ) -> np.ndarray | None:
    """``lines`` checked against the footprint ``[lo, hi]`` (ValueError naming
    ``upper_lines``): ``n + 1`` increasing values from ``lo`` to ``hi`` through 1/2."""
    if lines is None:
        return None
    xs = np.asarray(lines, dtype=float)
    if (xs.shape != (n + 1,) or not np.all(np.diff(xs) > 0) or xs[0] != lo or xs[-1] != hi
            or not np.any(xs == 0.5)):
        raise ValueError(f"upper_lines must be n_upper + 1 = {n + 1} increasing x values "
                         f"from {lo} to {hi} through 0.5 (the rollers' plane), got {lines!r}")
    return xs


def exact_patch3d(params: dict) -> dict:
    """The exact state (module docstring): ``axial`` ``s``, ``lateral`` ``l``,
    ``F`` (3 x 3), ``pressure`` ``p``, ``area`` (the footprint's reference area),
    ``contact_force`` ``p l^2 A``, ``support_reaction`` ``p l^2`` and
    ``displacement(X)`` (``(3, ...)`` from reference points ``(3, ...)``).

    ``s`` is the first root below 1 (scanned in 200 steps down to :data:`S_MIN`,
    then brentq): the branch through the unloaded state.

    Raises
    ------
    ValueError
        If ``P_zz(s) + p l(s)^2`` has no root for ``s`` in ``[S_MIN, 1]`` before the
        law's uniaxial state ends (a pressure that crushes the blocks, or one past
        Saint Venant-Kirchhoff's limit point), naming ``pressure``.
    """
    material = LAWS[params["law"]](E=float(params["E"]), nu=float(params["nu"]))
    law, _ = constitutive_law(material, params["kinematics"], "strain")
    p = float(params["pressure"])

    def residual(s: float) -> float:
        lat, P = exact_uniaxial3d(law, s)
        return P + p * lat * lat

    grid = np.linspace(1.0, S_MIN, 200)           # from s = 1 down: the first root is
    lower = None                                   # the branch through the unloaded state
    for a, b in zip(grid[:-1], grid[1:]):
        try:
            if residual(b) < 0.0:
                lower = (b, a)
                break
        except ValueError:
            break
    if lower is None:
        raise ValueError(f"parameter 'pressure' crushes the blocks below {S_MIN} of their "
                         f"height or past the law's limit point (no uniaxial state), "
                         f"got {p!r}")
    s = brentq(residual, *lower, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    lat = exact_uniaxial3d(law, s)[0]
    F = np.diag([lat, lat, s])
    lo = int(params["margin"]) / int(params["n_lower"])
    area = (1.0 - 2.0 * lo) ** 2
    Xc = np.array([0.5, 0.5, 0.0])

    def u(X: np.ndarray) -> np.ndarray:
        X = np.asarray(X, dtype=float)
        Xr = X - Xc.reshape((3,) + (1,) * (X.ndim - 1))
        return np.einsum("ij,j...->i...", F - np.eye(3), Xr)

    return {"axial": s, "lateral": lat, "F": F, "pressure": p, "area": area,
            "contact_force": p * lat * lat * area, "support_reaction": p * lat * lat,
            "displacement": u}


def displacement_error(parts: PatchParts, exact: dict, z: np.ndarray) -> float:
    """The largest nodal ``|u_h - u|`` over both blocks, over the largest ``|u|``."""
    err, scale = 0.0, 0.0
    for body in (parts.upper, parts.lower):
        uh = displacement(body, z)[body.node_dofs]
        ue = exact["displacement"](body.X)
        err = max(err, float(np.abs(uh - ue).max()))
        scale = max(scale, float(np.abs(ue).max()))
    return err / scale


def patch_metrics(exact: dict, pressure: np.ndarray, f_slave: np.ndarray,
                  f_master: np.ndarray, reaction: float, u_error: float) -> dict:
    """The readings of the module docstring from the slave nodes' ``pressure``, the
    two sides' contact resultants ``f_slave``, ``f_master`` (3,), the rollers'
    ``reaction`` on the lower block's bottom and the displacement error."""
    p, F = exact["pressure"], exact["contact_force"]
    fz = abs(float(f_slave[2]))
    out = {"pressure_error": float(np.max(np.abs(np.asarray(pressure) - p)) / p),
           "pressure_min": float(np.min(pressure)), "pressure_max": float(np.max(pressure)),
           "pressure_exact": p, "displacement_error": float(u_error),
           "force_balance": float(np.linalg.norm(np.asarray(f_slave) + f_master)) / F,
           "axial_stretch_exact": exact["axial"], "lateral_stretch_exact": exact["lateral"]}
    for key, val in (("contact_force", fz), ("support_reaction", abs(float(reaction)))):
        out.update({key: val, f"{key}_exact": exact[key],
                    f"{key}_error": abs(val - exact[key]) / exact[key]})
    return out


def estimate_dofs(params: dict) -> int:
    """Displacement dofs of both blocks (no mesh built)."""
    total = 0
    for key, width in (("n_lower", 1.0), ("n_upper", 1.0 - 2.0 * int(params["margin"])
                                          / int(params["n_lower"]))):
        n = int(params[key])
        nz = max(1, int(round(HEIGHT * n / max(width, 1e-300))))
        total += 3 * (n + 1) ** 2 * (nz + 1)
    return total


def derived(params: dict) -> list:
    """The Lame parameters, the pressure, the strain scale ``pressure / E`` at most 0.2,
    even cell counts (a grid plane on each mid-plane) and a footprint of at least
    two lower cells a side (``n_lower - 2 margin >= 2``)."""
    E, q = float(params["E"]), float(params["pressure"])
    n_low, m = int(params["n_lower"]), int(params["margin"])
    return [*lame_quantities(E, float(params["nu"])), positive("pressure", q, "pressure"),
            ratio("the strain scale pressure / E", q / E, ("pressure", "E"), 0.0, 0.2),
            ratio("n_lower modulo 2 (a grid plane on the mid-plane)", n_low % 2,
                  ("n_lower",), 0, 0),
            ratio("n_upper modulo 2 (a grid plane on the mid-plane)",
                  int(params["n_upper"]) % 2, ("n_upper",), 0, 0),
            Derived("the footprint's lower cells a side n_lower - 2 margin", n_low - 2 * m,
                    ("n_lower", "margin"), 2, float(n_low))]


PARAMS = (
    Param("pressure", 0.05, "Cauchy pressure p on the upper block's top and the lower "
          "block's uncovered top", float, low=0.0, low_inclusive=False),
    *law_params("finite"),
    Param("element", "hex1", "elements of the upper/lower block (one name: both)", str,
          choices=PAIRINGS),
    Param("n_lower", 8, "cells a side of the lower block (even)", int, low=2, high=512),
    Param("n_upper", 4, "cells a side of the upper block (even)", int, low=2, high=512),
    Param("margin", 1, "lower cells between the footprint's edge and the lower block's "
          "edge", int, low=0, high=255),
    Param("slave", "upper", "which block's face is the slave surface", str,
          choices=("upper", "lower")),
    Param("distort", 0.0, "tilt of the free x-grid lines, a fraction of the cell: hex1 "
          "interface faces become trapezoids", float, low=0.0, high=0.45,
          high_inclusive=False),
)
