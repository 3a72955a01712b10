"""Preflight, orientation on faces (the contact surfaces of 3D bodies): the 3D forms of
:func:`~.preflight_orientation.check_surface` (each face's normal points out of the
element it bounds) and of the facing test of
:func:`~.preflight_orientation.check_orientation` (slave nodal normals against the
normals of the master faces the nearest slave nodes project on).

A face's normal is ``n = (x_1 - x_0) x (x_2 - x_0)`` of its first three corners
(counter-clockwise seen from outside: :mod:`.boundary_cells`), its weight the area
``|n| / 2`` (tri3) or ``|n|`` (a parallelogram quad4; a warped one near it).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .nts_faces import face_sizes, face_weights, project_faces

__all__ = ["inward_faces", "facing_faces"]


def _corner_normals(x: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """``(x_1 - x_0) x (x_2 - x_0)`` of each face's first three corners, (3, n_f)."""
    P = x[:, conn[:, :3]]
    return np.cross(P[:, :, 1] - P[:, :, 0], P[:, :, 2] - P[:, :, 0], axis=0)


def inward_faces(surface: Any, mesh: Any) -> tuple[np.ndarray, np.ndarray]:
    """Which of the faces of ``surface`` (on the solid with skfem ``mesh``) point into
    the element they bound, and their areas.

    Inward: ``n . (c_face - c_element) < 0``; faces that are no boundary facet of the
    mesh count as neither (area 0)."""
    corners = list(surface.cell.corners)
    ends = surface.nodes[surface.segments[:, corners]]                 # body vertices
    nv = mesh.p.shape[1]
    k = len(corners)
    fac = np.sort(mesh.facets[:k], axis=0).astype(np.int64)
    e = np.sort(ends, axis=1).astype(np.int64)
    fkeys, keys = fac[0], e[:, 0]
    for j in range(1, k):
        fkeys, keys = fkeys * nv + fac[j], keys * nv + e[:, j]
    order = np.argsort(fkeys)
    pos = np.clip(np.searchsorted(fkeys[order], keys), 0, len(order) - 1)
    found = fkeys[order][pos] == keys
    elem = mesh.f2t[0, order[pos]]
    t = mesh.t[:mesh.elem.refdom.nnodes]
    centroid = mesh.p[:, t[:, elem]].mean(axis=1)
    n = _corner_normals(mesh.p, ends)
    mid = mesh.p[:, ends].mean(axis=2)
    area = np.where(found, np.sqrt(np.sum(n * n, axis=0)), 0.0)
    return found & (np.sum(n * (mid - centroid), axis=0) < 0), area


def _nodal_normals(x: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Unit nodal normals (3, n): the normalized sum of the area-weighted normals of
    the faces at each node."""
    n = _corner_normals(x, conn)
    acc = np.zeros((3, x.shape[1]))
    for j in range(conn.shape[1]):
        np.add.at(acc.T, conn[:, j], n.T)
    s = np.sqrt(np.sum(acc * acc, axis=0))
    return acc / np.where(s > 0, s, 1.0)


def facing_faces(pair: Any, z: np.ndarray, band: float = 1.0) -> tuple:
    """The facing test's data on faces: ``(near, projection, cos, weight)``.

    The slave nodes within ``band`` slave face sizes of the smallest distance to the
    master (:func:`~.nts_faces.project_faces`), ``n_s . n_m`` of each and its
    tributary area (the fields of :func:`~.preflight_orientation.check_orientation`'s
    facing data)."""
    xs, xm = pair.slave.x(z), pair.master.x(z)
    seg_s, seg_m = pair.slave.segments, pair.master.segments
    cm = pair.master.cell
    pr = project_faces(xs, xm, seg_m, cm, float(np.median(face_sizes(xm, seg_m))))
    h = np.zeros(xs.shape[1])
    np.maximum.at(h, seg_s, face_sizes(xs, seg_s)[:, None])
    d = pr["dist"]
    near = pr["mask"] & (d <= (d[pr["mask"]].min() if pr["mask"].any() else 0.0) + band * h)
    cos = np.sum(_nodal_normals(xs, seg_s) * pr["n"], axis=0)
    return near, pr, cos, face_weights(xs, seg_s, pair.slave.cell)
