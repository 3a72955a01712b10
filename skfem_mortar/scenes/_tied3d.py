"""The parts of scene ``tied3d``: a 3D cantilever meshed as two non-matching parts, to be
glued by a ``TiePair``, against the one-piece beam.

The beam ``[0, L] x [0, h] x [0, h]`` (``L = length``, ``h = 1``) of ``cantilever3d``
is clamped at ``X = 0`` and carries the dead tip load ``P`` in ``-z`` (a uniform
traction ``P / h^2`` on ``X = L``; ``load = P L^2 / (E I)``, ``I = h^4 / 12``).  It is
cut along

* ``interface=across``: the plane ``X = L / 2``; the part ``[0, L/2]`` has ``n_a``
  cells through the thickness, ``[L/2, L]`` ``n_b`` (both cubes, so the interface
  meshes do not match unless ``n_a = n_b``);
* ``interface=along``: the plane ``Z = h / 2`` from the clamp to the tip; the lower
  half has ``n_a`` cells per unit length, the upper ``n_b``; the interface meets the
  clamped face along ``X = 0, Z = h / 2``, where both parts' nodes are clamped.

``element`` is ``tet1`` or ``hex1`` (both parts); ``refine`` multiplies ``n_a`` and
``n_b`` by ``2^(refine - 1)``.  The slave is part ``b`` (the finer with the defaults),
the master part ``a``.  ``parts=one`` is the one-piece beam with part ``a``'s cell
size (the reference: :func:`one_piece`).

Readings (:func:`tied_metrics`): ``tip_deflection`` (the mean ``-u_z`` of the tip
face's vertices) against the one-piece beam's (``_exact``, ``_error``: the two
meshes' discretization difference, 0 to round-off on matching meshes) and
against Timoshenko's beam (``_beam``:
:func:`~skfem_mortar.scenes.cantilever3d.timoshenko_tip`, small strain);
``interface_force`` (the resultant of the tie's forces on the slave) against the
load it carries (``across``: ``P`` on part ``b``, upwards; exact at any mesh);
``traction_error`` (``across``), the multiplier's L2 error against the one-piece
beam's interface traction (:func:`cut_traction`, :func:`traction_error`); and
``oscillation``, the multiplier's largest departure from the mean of its neighbours
(:func:`oscillation`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import Basis

from ..bodies.solid import Solid, internal_force
from ..contact.boundary_cells import boundary_cells
from ..contact.cells import CellType
from ..contact.mortar_support import tributary_weights
from ..core.dirichlet import Dirichlet
from ..loads.traction import Traction
from . import Param, lame_quantities, ratio
from ._contact3d import grid_mesh
from ._scene3d import displacement, law_params, make_solid, memory_quantity
from .cantilever3d import timoshenko_tip

__all__ = ["PARAMS", "TiedParts", "build_bodies", "one_piece", "tip_deflection",
           "tied_metrics", "derived", "estimate_dofs", "cells_per_length", "CUTS",
           "cut_traction", "traction_error", "oscillation"]

#: the cut of each ``interface``: (axis, coordinate over ``L`` or ``h``) of its plane
CUTS = {"across": (0, "length"), "along": (2, None)}


def cells_per_length(params: dict) -> tuple[int, int]:
    """``n_a`` and ``n_b`` at the level ``refine`` (times ``2^(refine - 1)``)."""
    level = 2 ** (int(params["refine"]) - 1)
    return int(params["n_a"]) * level, int(params["n_b"]) * level


def cut_plane(params: dict) -> tuple[int, float]:
    """The axis and coordinate of the interface plane: ``X = L / 2`` or ``Z = h / 2``."""
    axis, scale = CUTS[params["interface"]]
    return axis, 0.5 * (float(params[scale]) if scale else 1.0)


@dataclass
class TiedParts:
    """The bodies and items of ``tied3d`` without the tie.

    Attributes
    ----------
    bodies : list of Solid
        Part ``a`` then part ``b`` (one body for ``parts=one``).
    items : list
        The bodies, the clamp of each and the tip load(s).
    slave, master : tuple (Solid, str) or None
        Part ``b`` and part ``a`` with their interface boundary tag (None for one piece).
    tip_force : float
        ``P``, the total tip load (downwards).
    """

    bodies: list
    items: list
    slave: tuple | None
    master: tuple | None
    tip_force: float


def _part(params: dict, box: tuple, n_per_length: float, name: str) -> Solid:
    """The box ``((x0, x1), (y0, y1), (z0, z1))`` in cells about ``1 / n_per_length``,
    tagged ``clamp`` (``X = 0``), ``tip`` (``X = L``) and ``interface`` (the cut)."""
    L = float(params["length"])
    lines = [np.linspace(lo, hi, max(1, int(round(n_per_length * (hi - lo)))) + 1)
             for lo, hi in box]
    mesh = grid_mesh(params["element"], *lines)
    tol = 1e-9 * L
    cut = cut_plane(params)
    mesh = mesh.with_boundaries({
        "clamp": lambda x: np.abs(x[0]) < tol, "tip": lambda x: np.abs(x[0] - L) < tol,
        "interface": lambda x: np.abs(x[cut[0]] - cut[1]) < tol})
    return make_solid(mesh, params, name)


def _loaded(params: dict, bodies: list) -> tuple[list, float]:
    """The bodies with their clamps and tip tractions ``(0, 0, -P / h^2)``, and ``P``."""
    L, E = float(params["length"]), float(params["E"])
    P = float(params["load"]) * E / (12.0 * L * L)
    items = list(bodies)
    for body in bodies:
        tags = body.mesh.boundaries
        if tags["clamp"].size:
            items.append(Dirichlet(body, boundary="clamp", name=f"clamp_{body.name}"))
        if tags["tip"].size:
            items.append(Traction(body, "tip", [0.0, 0.0, -P], name=f"tip_load_{body.name}"))
    return items, P


def one_piece(params: dict) -> TiedParts:
    """The one-piece beam in part ``a``'s cells (``n_a`` per unit length)."""
    L = float(params["length"])
    beam = _part(params, ((0.0, L), (0.0, 1.0), (0.0, 1.0)), cells_per_length(params)[0],
                 "beam")
    items, P = _loaded(params, [beam])
    return TiedParts([beam], items, None, None, P)


def build_bodies(params: dict) -> TiedParts:
    """The two parts (or the one-piece beam, ``parts=one``) of ``params`` (:data:`PARAMS`)."""
    if params["parts"] == "one":
        return one_piece(params)
    L = float(params["length"])
    na, nb = cells_per_length(params)
    if params["interface"] == "across":
        boxes = (((0.0, 0.5 * L), (0.0, 1.0), (0.0, 1.0)), ((0.5 * L, L), (0.0, 1.0), (0.0, 1.0)))
    else:
        boxes = (((0.0, L), (0.0, 1.0), (0.0, 0.5)), ((0.0, L), (0.0, 1.0), (0.5, 1.0)))
    a = _part(params, boxes[0], na, "part_a")
    b = _part(params, boxes[1], nb, "part_b")
    items, P = _loaded(params, [a, b])
    return TiedParts([a, b], items, (b, "interface"), (a, "interface"), P)


def tip_deflection(bodies: list, z: np.ndarray) -> float:
    """The mean ``-u_z`` over the tip face's vertices of ``bodies``, each position once
    (a vertex that two parts share, on the tip's edge along the cut, counts once with
    the mean of its two values, as the one-piece beam's vertex there)."""
    u, X = [], []
    for body in bodies:
        facets = body.mesh.boundaries["tip"]
        if facets.size:
            nodes = np.unique(body.mesh.facets[:, facets])
            u.append(displacement(body, z)[body.node_dofs[2, nodes]])
            X.append(body.X[:, nodes])
    u, X = np.concatenate(u), np.concatenate(X, axis=1)
    _, where = np.unique(np.round(X / np.ptp(X, axis=1).max(), 9), axis=1,
                         return_inverse=True)
    where = where.ravel()
    return -float(np.mean(np.bincount(where, u) / np.bincount(where)))


def cut_traction(body: Solid, z: np.ndarray, axis: int, value: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, CellType]:
    """The one-piece beam's interface traction on the plane ``X[axis] = value``: the
    internal nodal forces ``int Grad v : P dV`` of the elements beyond the plane at its
    nodes (the force the part before it exerts on the part beyond, as the tie's
    multipliers on part ``b``), over the nodes' tributary areas ``int N_C dA`` on the
    plane (a lumped traction).

    Returns
    -------
    X : ndarray (3, n)
        The plane's nodes.
    t : ndarray (3, n)
        The traction there.
    conn, cell
        The plane's faces (into the ``n`` nodes) and their cell type.
    """
    mesh = body.mesh
    p = np.asarray(mesh.p, dtype=float)
    beyond = np.flatnonzero(p[axis, mesh.t].mean(axis=0) > value)
    basis = Basis(mesh, body.basis.elem, elements=beyond,
                  quadrature=(body.basis.X, body.basis.W))
    P = body.material.stress(body.deformation_gradient(z)[:, :, beyond])
    r = internal_force.assemble(basis, P=P)
    tol = 1e-9 * np.ptp(p, axis=1).max()
    on = np.flatnonzero(np.all(np.abs(p[axis, mesh.facets] - value) < tol, axis=0))
    conn, cell = boundary_cells(mesh, on)
    w = tributary_weights(p, conn, cell, 2)
    nodes, local = np.unique(conn, return_inverse=True)
    return (p[:, nodes], r[body.node_dofs[:, nodes]] / w[nodes],
            local.reshape(conn.shape), cell)


def traction_error(X: np.ndarray, lam: np.ndarray, weight: np.ndarray, X_ref: np.ndarray,
                   t_ref: np.ndarray, axis: int) -> float:
    """The multiplier's L2 error against a reference traction, in the lumped norm of the
    slave nodes: ``sqrt(sum_A w_A |lam_A - t(X_A)|^2 / sum_A w_A |t(X_A)|^2)``, ``w_A =
    int N_A dA`` (``weight``; 0 leaves a node out), ``t`` the reference's nodal values
    ``t_ref`` at ``X_ref`` (a grid on the plane normal to ``axis``) interpolated
    bilinearly to the slave nodes ``X``."""
    from scipy.interpolate import RegularGridInterpolator

    plane = [i for i in range(3) if i != axis]
    lines = [np.unique(np.round(X_ref[i], 12)) for i in plane]
    idx = [np.searchsorted(line, np.round(X_ref[i], 12)) for line, i in zip(lines, plane)]
    grid = np.zeros((lines[0].size, lines[1].size, 3))
    grid[idx[0], idx[1]] = t_ref.T
    t = RegularGridInterpolator(lines, grid)(X[plane].T).T
    num = np.sum(weight * np.sum((lam - t) ** 2, axis=0))
    return float(np.sqrt(num / np.sum(weight * np.sum(t ** 2, axis=0))))


def oscillation(lam: np.ndarray, conn: np.ndarray, cell: CellType, tied: np.ndarray
                ) -> float:
    """``max_A |lam_A - mean_(B ~ A) lam_B| / max_A |lam_A|`` over the interior tied
    nodes ``A`` whose neighbours ``B`` (sharing a cell edge) are all tied: ``O(h^2)`` for
    a smooth traction on a uniform mesh (the neighbours come in opposite pairs), ``O(1)``
    for a checkerboard (the oscillation of multipliers that lock on tetrahedral faces)."""
    ends = np.array([[e[0], e[-1]] for e in cell.edges])
    edges = np.sort(conn[:, ends].reshape(-1, 2), axis=1)
    edges, count = np.unique(edges, axis=0, return_counts=True)
    n = lam.shape[1]
    border = np.zeros(n, dtype=bool)
    border[edges[count == 1].ravel()] = True
    adj = sp.coo_matrix((np.ones(2 * len(edges)), (edges.ravel(), edges[:, ::-1].ravel())),
                        shape=(n, n)).tocsr()
    deg = np.asarray(adj.sum(axis=1)).ravel()
    all_tied = np.asarray(adj @ (~tied).astype(float)).ravel() == 0
    inner = tied & ~border & all_tied & (deg > 0)
    mean = (adj @ lam.T).T / np.where(deg > 0, deg, 1.0)
    scale = np.linalg.norm(lam[:, tied], axis=0).max()
    return float(np.linalg.norm((lam - mean)[:, inner], axis=0).max() / scale
                 ) if inner.any() else 0.0


def tied_metrics(params: dict, deflection: float, reference: float,
                 interface_force: np.ndarray | None, P: float) -> dict:
    """The readings of the module docstring from the tip ``deflection`` of the tied
    parts, the one-piece beam's ``reference``, the tie's resultant on the slave
    ``interface_force`` (3,) and the tip load ``P``."""
    out = {"tip_deflection": deflection, "tip_deflection_exact": reference,
           "tip_deflection_error": abs(deflection - reference) / abs(reference)}
    if params["kinematics"] == "small":
        beam = timoshenko_tip(float(params["load"]), float(params["length"]),
                              float(params["nu"]))
        out.update({"tip_deflection_beam": beam,
                    "tip_deflection_beam_error": abs(deflection - beam) / beam})
    if interface_force is not None and params["interface"] == "across":
        f = float(interface_force[2])
        out.update({"interface_force": f, "interface_force_exact": P,
                    "interface_force_error": abs(f - P) / P})
    return out


def estimate_dofs(params: dict) -> int:
    """Displacement dofs of the two parts and the one-piece reference (no mesh built)."""
    L = float(params["length"])
    total = 0
    for n, volume in zip(cells_per_length(params), (1.5 * L, 0.5 * L)):
        total += int(3 * (n * L + 1) * (n + 1) ** 2 * volume / L)
    return total


def derived(params: dict) -> list:
    """The Lame parameters, the slenderness, the strain scale ``load / (6 L)`` (the
    linear beam's largest bending strain ``P L h / (2 E I)``) at most 0.05 and the
    run's estimated memory."""
    L = float(params["length"])
    return [*lame_quantities(float(params["E"]), float(params["nu"])),
            ratio("the slenderness L / h", L, ("length",), 1.0, 100.0),
            ratio("the strain scale load / (6 L)", float(params["load"]) / (6.0 * L),
                  ("load", "length"), 0.0, 0.05),
            memory_quantity(estimate_dofs(params), "n_a", "n_b", "length")]


PARAMS = (
    Param("length", 4.0, "beam length L over its thickness h", float, low=1.0, high=100.0),
    Param("load", 0.5, "tip force P in units of E I / L^2", float, low=0.0,
          low_inclusive=False),
    *law_params("small"),
    Param("element", "hex1", "element of both parts", str, choices=("tet1", "hex1")),
    Param("n_a", 2, "cells per unit length of part a at refine = 1 (the master; the "
          "one-piece beam's)", int, low=1, high=256),
    Param("n_b", 3, "cells per unit length of part b (the slave) at refine = 1", int,
          low=1, high=256),
    Param("refine", 1, "refinement level: n_a and n_b times 2^(refine - 1)", int, low=1,
          high=8),
    Param("multipliers", "standard", "the tie's multiplier space: standard (Phi_A = N_A) "
          "or dual (biorthogonal)", str, choices=("standard", "dual")),
    Param("interface", "across", "the cut: across the beam at X = L/2, or along it at "
          "Z = h/2, meeting the clamped face", str, choices=("across", "along")),
    Param("parts", "two", "two parts glued by the tie, or the one-piece beam", str,
          choices=("two", "one")),
)
