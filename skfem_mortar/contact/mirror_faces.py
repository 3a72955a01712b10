"""Mirror images of master faces across the symmetry planes of a 3D mortar pair.

A quarter (or half) model's slave face with an edge on a symmetry plane is projected
onto its auxiliary plane along its own normal ``n_0``, which leans across the plane
(:mod:`.segmentation3d`).  A master edge on the plane then projects off it by the
master's distance from the auxiliary plane times that lean, and the strip of the slave
face between its own edge and the projected master edge meets no master face: on
``hertz3d`` (refine -3, rigid plane, converged) up to 3e-4 of such a face's covered
area, so the quarter's pressures differed from the half's by 4.4e-5 of the peak.  In
the whole model the mirror image of the master face covers that strip.  Snapping
points within ``1e-9 h`` of the plane cannot close it: the strip is about
``1e-5 h`` wide there.

So the faces of the master within ``band`` of a plane get mirror images
(:func:`mirrored_master`): ghost nodes ``x_g = R x_j + 2 c e`` with the reflection
``R = I - 2 e e^T`` of the plane ``e . x = c``, and the kernel runs on the master
extended by them.  Every integral of a ghost node is one of its real node:
``dx_g / dx_j = R``, so (:func:`fold`)::

    G = G_ext P,   H = P^T H_ext P,   M = M_ext Q

with ``P`` the identity on the slave's and the real master's dofs and ``R`` from each
ghost's dofs to its node's, and ``Q`` the node map (ghost column to its node).  A
node on two planes (the quarter's corner) gets the images across each plane and
across both.  The slave's nodal normals on the planes are the kernel's (``mirror=``).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .contact_eval import ContactEval

__all__ = ["mirrored_master", "fold", "evaluate_mirrored"]


def _reflections(planes: list) -> list[tuple[np.ndarray, np.ndarray, list[int]]]:
    """``(R, t, which)`` of every product of distinct planes' reflections (``x -> R x +
    t``), ``which`` the planes reflected across."""
    out = []
    for mask in range(1, 2 ** len(planes)):
        R, t = np.eye(3), np.zeros(3)
        which = [k for k in range(len(planes)) if mask >> k & 1]
        for k in which:
            e, c = np.asarray(planes[k][0], float), float(planes[k][1])
            Rk = np.eye(3) - 2.0 * np.outer(e, e)
            R, t = Rk @ R, Rk @ t + 2.0 * c * e
        out.append((R, t, which))
    return out


def mirrored_master(xm: np.ndarray, seg_m: np.ndarray, planes: list,
                    band: "float | np.ndarray") -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """The master extended by the mirror images of its faces within ``band`` (a length,
    or one per face) of the planes (of each plane reflected across; module docstring).

    Returns
    -------
    xm_ext : ndarray (3, n_m + n_g)
    seg_ext : int ndarray (n_f + n_f_g, k)
        The faces, then the ghost faces (their orientation reversed: a reflection
        turns a counter-clockwise face clockwise).
    node : int ndarray (n_m + n_g,)
        The real node of each node of ``xm_ext``.
    R : list of ndarray (3, 3)
        The reflection of each ghost node block, in order.
    """
    n_m = xm.shape[1]
    dist = [np.abs(np.asarray(e, float) @ xm[:, seg_m].reshape(3, -1) - c).reshape(seg_m.shape)
            .min(axis=1) for e, c in planes]
    X, faces, node, Rs = [xm], [seg_m], [np.arange(n_m)], []
    base = n_m
    for R, t, which in _reflections(planes):
        near = np.all([dist[k] <= band for k in which], axis=0)
        if not near.any():
            continue
        used = np.unique(seg_m[near])
        local = np.full(n_m, -1)
        local[used] = base + np.arange(used.size)
        X.append(R @ xm[:, used] + t[:, None])
        faces.append(local[seg_m[near]][:, ::-1])
        node.append(used)
        Rs += [R] * used.size
        base += used.size
    return np.hstack(X), np.vstack(faces), np.concatenate(node), Rs


def fold(ev: ContactEval, n_s: int, n_m: int, node: np.ndarray, Rs: list) -> ContactEval:
    """The kernel's answer on the extended master folded onto the real one (module
    docstring)."""
    d, n_ext = 3, node.size
    rows = [np.arange(d * (n_s + n_m))]
    cols = [np.arange(d * (n_s + n_m))]
    vals = [np.ones(d * (n_s + n_m))]
    if Rs:
        R = np.stack(Rs)                                          # (n_g, 3, 3)
        g = np.arange(n_m, n_ext)
        r = d * (n_s + g)[:, None, None] + np.arange(d)[None, :, None]
        c = d * (n_s + node[g])[:, None, None] + np.arange(d)[None, None, :]
        rows.append(np.broadcast_to(r, R.shape).ravel())
        cols.append(np.broadcast_to(c, R.shape).ravel())
        vals.append(R.ravel())
    P = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(d * (n_s + n_ext), d * (n_s + n_m)))
    Q = sp.csr_matrix((np.ones(n_ext), (np.arange(n_ext), node)), shape=(n_ext, n_m))
    info = ev.info.copy()
    if "M" in info:
        info["M"] = (info["M"] @ Q).tocsr()
    return ContactEval(g=ev.g, G=None if ev.G is None else (ev.G @ P).tocsr(),
                       H=None if ev.H is None else (P.T @ ev.H @ P).tocsr(),
                       area=ev.area, mask=ev.mask, info=info)


def evaluate_mirrored(kernel, xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray,
                      seg_m: np.ndarray, planes: list, band: "float | np.ndarray",
                      **options) -> ContactEval:
    """``kernel(xs, seg_s, xm_ext, seg_ext, **options)`` on the master extended by its
    mirror images (:func:`mirrored_master`), folded back (:func:`fold`)."""
    xm_ext, seg_ext, node, Rs = mirrored_master(xm, seg_m, planes, band)
    ev = kernel(xs, seg_s, xm_ext, seg_ext, **options)
    return fold(ev, xs.shape[1], xm.shape[1], node, Rs)
