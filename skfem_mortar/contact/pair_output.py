"""What a contact pair reports of a state: per slave node data and contact forces.

The readings go through the pair's multiplier space (pressure, gap as a
length) and its tangential rows (their columns, their force), so nothing here
asks which method or friction law the pair has.
"""
from __future__ import annotations

from typing import Any, Callable, NamedTuple

import numpy as np

from ..core.binding import rebind
from .active_set import chain_order
from .curves import polyline
from .nts_faces import face_distances, face_edges
from .search import distance_to_polyline
from .segmentation import surface_cell
from .surface_kinds import CURVE, FACE, entry

__all__ = ["contact_data", "along_surface", "forces", "weightless_read", "WEIGHTLESS",
           "READINGS"]


class Reading(NamedTuple):
    """What the outputs read differently on a surface kind (:mod:`.surface_kinds`).

    ``chords(segments, cell)`` the node pairs (n, 2) along which a weightless node
    finds its neighbours (:func:`weightless_read`); ``distance(p, xm, segments, cell)``
    the distance of points from the master surface (of nodes without a master
    partner); ``order(surface, cell)`` the rows' node order, or None for the surface's
    own order (:func:`along_surface`).
    """
    chords: Callable[[np.ndarray, Any], np.ndarray]
    distance: Callable[[np.ndarray, np.ndarray, np.ndarray, Any], np.ndarray]
    order: Callable[[Any, Any], "np.ndarray | None"]


#: the readings of each surface kind: curves in chain order, the faces of a 3D body
#: in the surface's order
READINGS = {
    CURVE: Reading(chords=polyline, distance=distance_to_polyline,
                   order=lambda s, c: chain_order(s.segments, s.closed, s.n_nodes, c)),
    FACE: Reading(chords=face_edges, distance=face_distances, order=lambda s, c: None)}


def contact_data(pair: Any, z: np.ndarray) -> dict[str, np.ndarray]:
    """:meth:`~skfem_mortar.contact.pair.ContactPair.contact_data`."""
    rebind(pair)  # this pair's model's layout, if another model was used since
    p, g, ev = pair.pressure_and_gap(z)
    # round-off tension of a converged state (within the KKT tolerance) is
    # written as 0: outputs never show a negative pressure that is not there
    p = np.where((p < 0) & (p >= -pair._tol_p), 0.0, p)
    p[p == 0] = 0.0  # no -0.0
    cell = surface_cell(pair.slave)
    p = weightless_read(p, ev.area, ev.mask,
                        entry(READINGS, cell, "contact_data").chords(pair.slave.segments, cell))
    x = pair.slave.x(z)
    g = np.where(ev.mask, g, np.nan)
    dist = np.where(ev.mask, g, 0.0)
    if not ev.mask.all():
        far = ~ev.mask
        master = surface_cell(pair.master)
        dist[far] = entry(READINGS, master, "contact_data").distance(
            x[:, far], pair.master.x(z), pair.master.segments, master)
    data = {**{c: x[i] for i, c in enumerate("xyz"[:x.shape[0]])}, "gap": g, "pressure": p,
            "has_master": ev.mask, "distance": dist}
    if pair.geometry == "axisymmetric":   # the coordinates by their names there
        data.update(r=x[0], z=x[1])
    data.update(pair.rows.columns(z))
    k = along_surface(pair.slave)
    return {**{name: v[k] for name, v in data.items()}, "node": k}


#: a node facing a master whose tributary weight is at most this fraction of its
#: heaviest neighbour's carries no force of its own (:func:`weightless_read`):
#: a line3 vertex on the axis weighs 0 on a straight cell and about -1e-5 of its mid
#: node on a sphere's pole cell (h = R / 100); the least ratio elsewhere is 1/4 (a
#: line3 vertex against its mid node in plane) or 1/6 (a line2 axis node against
#: its neighbour), so this acts on nothing else (but a line2 chain end next to a
#: segment 1000 times longer than its own)
WEIGHTLESS = 1e-3


def weightless_read(p: np.ndarray, area: np.ndarray, mask: np.ndarray,
                    chords: np.ndarray) -> np.ndarray:
    """``p`` with the pressure of every weightless node facing a master read from its
    heaviest neighbour along the surface (``chords``: the chords through every node,
    :func:`~.curves.polyline`).

    A ``line3`` vertex on the axis of an axisymmetric model weighs ``2 pi int N_A r
    dGamma`` = 0 on a straight cell, nearly 0 (of either sign) on a curved one: an NTS
    force there is about 0 and ``lam / a_A`` says nothing about the pressure; its
    neighbour, the mid node of its cell (weight ``2 pi int N_mid r dGamma > 0``),
    carries it.  Nodes with ``a_A <=`` :data:`WEIGHTLESS` times that neighbour's
    weight take its pressure; no other changes.
    """
    ends = np.asarray(chords, dtype=np.int64)
    node, mate = np.r_[ends[:, 0], ends[:, 1]], np.r_[ends[:, 1], ends[:, 0]]
    w = np.abs(area)
    order = np.lexsort((w[mate], node))          # each node's heaviest neighbour last
    last = np.r_[node[order][1:] != node[order][:-1], True]
    best = np.arange(area.size)
    best[node[order][last]] = mate[order][last]
    weightless = mask & (best != np.arange(area.size)) & (area <= WEIGHTLESS * w[best])
    if not weightless.any():
        return p
    out = p.copy()
    out[weightless] = p[best[weightless]]
    return out


def along_surface(s: Any) -> np.ndarray:
    """Surface node indices in the order of :func:`contact_data`'s rows: chain
    order, an open chain from its end with the smaller reference ``x`` (then
    ``y``), a closed one from the start of its first segment."""
    cell = surface_cell(s)
    order = entry(READINGS, cell, "along_surface").order(s, cell)
    if order is None:  # faces, or not one chain through every node: the surface's order
        return np.arange(s.n_nodes)
    a, b = s.X[:, order[0]], s.X[:, order[-1]]
    if not s.closed and (a[0], a[1]) > (b[0], b[1]):
        order = order[::-1]
    return np.ascontiguousarray(order, dtype=np.int64)


def forces(pair: Any, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`~skfem_mortar.contact.pair.ContactPair.forces`."""
    rebind(pair)  # this pair's model's layout, if another model was used since
    lam = np.asarray(z)[pair._normal]
    ev = pair.evaluate(z, tangent=True, with_lam=False)
    f = pair.thickness * (ev.G.T @ lam)
    # and the tangential part G_t^T lam_t of the step (0 without tangential rows)
    f = f + pair.thickness * pair.rows.force(z, ev)
    n_s = pair.slave.n_nodes
    d = pair.slave.X.shape[0]
    return f[:d * n_s].reshape(-1, d).T, f[d * n_s:].reshape(-1, d).T
