"""Preflight, orientation: the surfaces of a contact pair face each other
(:func:`check_surface` for a solid's surface against its mesh, :func:`check_orientation`
for the pair on the initial state); a pair pointing the same way converges to a
penetration.  :func:`nodal_normals` is shared with the tie.

Tolerances (all scale-free)
---------------------------
``FACING = 0.5``
    ``|n_s . n_m|`` above which a near slave node counts as facing (< -0.5) or
    pointing the same way (> 0.5) as the master: within 60 degrees of
    (anti)parallel.  Facing surfaces have ``n_s . n_m`` near -1 where they meet,
    wrongly oriented ones near +1; the nodes between (a corner, a side wall
    within one element of the master) decide nothing.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.chain import polyline
from . import nts
from .cell_map import reversal
from .preflight_faces import facing_faces, inward_faces
from .surface_kinds import CURVE, FACE, entry
from .surfaces import RigidCircle, RigidPlane, segment_normals, tributary_lengths

__all__ = ["check_surface", "check_orientation", "nodal_normals", "FACING"]

FACING = 0.5


def _solid_mesh(surface: Any):
    """The skfem mesh of the solid owning ``surface`` (None for a cable or rigid surface)."""
    mesh = getattr(surface.body, "mesh", None)
    return mesh if mesh is not None and surface.nodes is not None else None


def check_surface(surface: Any) -> None:
    """A surface on a solid must have its normals pointing out of the solid.

    For each segment that is a boundary facet of the solid's mesh, with
    ``n`` its right-hand normal, ``m`` its midpoint and ``c`` the centroid of
    the element it bounds, ``n . (m - c) > 0`` outward.  More than half of the
    facet length pointing inward (a boundary traced clockwise) raises
    ValueError.  Cables and rigid surfaces have no inside: nothing to check.
    """
    mesh = _solid_mesh(surface)
    if mesh is None:
        return
    entry(_INWARD, surface.cell, "check_outward")(surface, mesh)   # the cells' kind


def _inward_faces_check(surface: Any, mesh: Any) -> None:
    """:func:`check_outward` on the faces of a 3D body (:func:`~.preflight_faces.inward_faces`)."""
    inward, l = inward_faces(surface, mesh)
    found = l > 0
    if l[inward].sum() > 0.5 * l.sum():
        raise ValueError(_inward_message(surface, int(inward.sum()), int(found.sum()), "faces"))


def _inward_curves_check(surface: Any, mesh: Any) -> None:
    """:func:`check_outward` on the boundary segments of a 2D body."""
    ends = surface.nodes[surface.segments[:, list(surface.cell.corners)]]  # body vertices
    nv = mesh.p.shape[1]
    fac = np.sort(mesh.facets[:2], axis=0)
    fkeys = fac[0].astype(np.int64) * nv + fac[1]
    order = np.argsort(fkeys)
    e = np.sort(ends, axis=1)
    keys = e[:, 0].astype(np.int64) * nv + e[:, 1]
    pos = np.clip(np.searchsorted(fkeys[order], keys), 0, len(order) - 1)
    found = fkeys[order][pos] == keys
    if not found.any():
        return
    elem = mesh.f2t[0, order[pos[found]]]
    t = mesh.t[:mesh.elem.refdom.nnodes]                       # the element's vertices
    centroid = mesh.p[:, t[:, elem]].mean(axis=1)
    nrm, l = segment_normals(mesh.p, ends[found])
    mid = 0.5 * (mesh.p[:, ends[found, 0]] + mesh.p[:, ends[found, 1]])
    inward = np.sum(nrm * (mid - centroid), axis=0) < 0
    if l[inward].sum() > 0.5 * l.sum():
        raise ValueError(_inward_message(surface, int(inward.sum()), int(found.sum()),
                                         "segments"))


#: the outward check of each surface kind (:mod:`.surface_kinds`)
_INWARD = {CURVE: _inward_curves_check, FACE: _inward_faces_check}


def _inward_message(surface: Any, n_in: int, n: int, what: str) -> str:
    rule = ("the outward normal is the right-hand normal of each segment, so a boundary "
            "must run counter-clockwise" if what == "segments" else "each face's corners "
            "must run counter-clockwise seen from outside the body")
    return (f"contact surface {surface.name!r} of body {surface.body.name!r}: its normals "
            f"point into the body ({n_in} of {n} {what}; {rule}): reverse its segments "
            f"({_reversed(surface)}) or build it with ContactSurface.from_solid(body, tag), "
            f"which orients the facets outward")


def _reversed(surface: Any) -> str:
    """The segments of ``surface`` run the other way, as an expression."""
    perm = reversal(surface.cell)
    cols = "::-1" if perm == tuple(range(len(perm)))[::-1] else str(list(perm))
    return f"surface.reversed(), i.e. segments[:, {cols}]"


def nodal_normals(x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Unit nodal normals ``(2, n)``: the normalized sum of the unit normals of the
    (one or two) segments at each node, ``n_k = sum_e n_e / |sum_e n_e|``."""
    ne, _ = segment_normals(x, seg)
    acc = np.zeros((2, x.shape[1]))
    for j in (0, 1):
        np.add.at(acc.T, seg[:, j], ne.T)
    s = np.hypot(*acc)
    return acc / np.where(s > 0, s, 1.0)


@dataclass
class _Facing:
    near: np.ndarray       # slave nodes nearest the master (bool)
    proj: dict             # nts.nearest_nodes' projection
    cos: np.ndarray        # n_s . n_m per slave node
    weight: np.ndarray     # tributary length per slave node


def _facing(pair: Any, z: np.ndarray) -> _Facing:
    return entry(_FACING, pair.slave.cell, "check_orientation")(pair, z)   # the cells' kind


def _facing_curves(pair: Any, z: np.ndarray) -> _Facing:
    """:func:`_facing` on curves: the chords' normals at the nearest slave nodes."""
    xs, xm = pair.slave.x(z), pair.master.x(z)
    seg_s = polyline(pair.slave.segments, pair.slave.cell)
    seg_m = polyline(pair.master.segments, pair.master.cell)
    near, pr = nts.nearest_nodes(xs, seg_s, xm, seg_m, band=1.0)
    cos = np.sum(nodal_normals(xs, seg_s) * pr["n"], axis=0)
    return _Facing(near, pr, cos, tributary_lengths(xs, seg_s))


#: the facing reading of each surface kind (:mod:`.surface_kinds`)
_FACING = {CURVE: _facing_curves, FACE: lambda pair, z: _Facing(*facing_faces(pair, z))}


def check_orientation(pair: Any, z: np.ndarray) -> None:
    """The slave and the master of ``pair`` must face each other where they meet.

    Over the slave nodes nearest the master (:func:`skfem_mortar.contact.nts.nearest_nodes`,
    one slave element length deep), with ``n_s`` the slave nodal normal and
    ``n_m`` the normal of the master segment the node projects on, facing
    surfaces have ``n_s . n_m < 0``.  When the tributary length of the nodes
    with ``n_s . n_m > FACING`` exceeds that of the nodes with
    ``n_s . n_m < -FACING``, the surfaces point the same way: ValueError
    naming the pair, the surface to turn and how.

    Skipped for NTS with a slave on a body that is neither a solid nor a cable
    (a user's item, e.g. springs): such a surface has no outside, and NTS uses
    only the master's normal (mortar uses the slave's, so it is checked).
    """
    if (pair.method == "nts" and _solid_mesh(pair.slave) is None
            and _cable_side(pair.slave) is None):
        return
    f = _facing(pair, z)
    if not f.near.any():
        return
    w = f.weight[f.near]
    c = f.cos[f.near]
    same, facing = w[c > FACING].sum(), w[c < -FACING].sum()
    if not same > facing:
        return
    wrong, why = _blame(pair, f)
    n_same = int(np.sum(c > FACING))
    raise ValueError(
        f"contact pair {pair.name!r}: the slave {pair.slave.name!r} and the master "
        f"{pair.master.name!r} point the same way where they meet (n_s . n_m > {FACING:g} at "
        f"{n_same} of the {int(f.near.sum())} slave nodes nearest the master; surfaces in "
        f"contact face each other, else the solve converges to a penetration): {why}"
        + "".join(f"; {_turn(pair, s)}" for s in wrong))


def _blame(pair: Any, f: _Facing) -> tuple[list[str], str]:
    """Which surface(s) of ``pair`` to turn, and why.

    A solid's surface has been checked outward (:func:`check_surface`), so the
    other one is wrong; two solid surfaces that both point outward the same way
    are the wrong faces.  Otherwise the side the slave lies on decides: with
    ``g`` the mean normal gap ``(x_s - x_m) . n_m`` of the nearest nodes and
    ``h`` their mean slave segment length, ``g > h / 2``: the master's normal
    points at the slave, the slave's away from the master (turn the slave);
    ``g < -h / 2``: the other way round; in between (touching, penetrating) both
    are possible.
    """
    s_solid, m_solid = _solid_mesh(pair.slave) is not None, _solid_mesh(pair.master) is not None
    w = f.weight[f.near]
    g = float(np.sum(f.proj["g"][f.near] * w) / w.sum())
    h = float(np.mean(w))
    if s_solid and m_solid:
        away = "slave" if g > 0 else "master"
        surf = pair.slave if away == "slave" else pair.master
        return [], (f"both are outward boundaries of their solids, so the {away} "
                    f"{surf.name!r} is the face turned away from the other body: choose "
                    f"the boundary (tag) that faces it")
    if s_solid:
        return ["master"], f"the slave {pair.slave.name!r} is a solid's outward boundary"
    if m_solid:
        return ["slave"], f"the master {pair.master.name!r} is a solid's outward boundary"
    if g > 0.5 * h:
        return ["slave"], (f"the slave lies on the side the master's normal points to "
                           f"(mean gap {g:.3g}), so the slave's normal points away")
    if g < -0.5 * h:
        return ["master"], (f"the slave lies behind the master's normal (mean gap "
                            f"{g:.3g}), so the master's normal points away from it")
    return ["master", "slave"], (f"the surfaces touch (mean gap {g:.3g}), so either may "
                                 f"be the wrong one")


def _turn(pair: Any, which: str) -> str:
    """How to turn the ``which`` ("slave" or "master") surface of ``pair``."""
    s = pair.slave if which == "slave" else pair.master
    head = f"to turn the {which} {s.name!r}: "
    if isinstance(s, RigidPlane):
        n = -np.asarray(s.normal) + 0.0  # + 0.0: no '-0'
        return head + (f"flip the plane's normal, RigidPlane(point, normal=({n[0]:.3g}, "
                       f"{n[1]:.3g}))")
    if isinstance(s, RigidCircle):
        if getattr(s, "inside", False):
            return head + "drop inside=True (the body is outside the circle)"
        return head + "RigidCircle(..., inside=True) (the body is inside the circle)"
    side = _cable_side(s)
    if side is not None:
        other = "right" if side == "left" else "left"
        return head + (f"take the cable's other side, ContactSurface.from_cable(cable, "
                       f"side={other!r}) instead of side={side!r}")
    return head + f"reverse its segments ({_reversed(s)})"


def _cable_side(surface: Any) -> str | None:
    """``"left"`` or ``"right"`` for a surface built on a cable's elements, else None."""
    el = getattr(surface.body, "elements", None)
    if el is None or surface.nodes is None or _solid_mesh(surface) is not None:
        return None
    el = np.asarray(el, dtype=np.int64).reshape(-1, 2)
    first = surface.nodes[surface.segments[0]]
    if np.any(np.all(el == first, axis=1)):
        return "right"
    if np.any(np.all(el == first[::-1], axis=1)):
        return "left"
    return None
