"""Geometry of node chains (polylines of directed segments ``seg = (start, end)``,
or curved 3-node segments ``(start, end, mid)``): segment lengths and normals,
tributary lengths, the neighbours along a chain.

A 3-node segment is the curve ``x(xi) = N_1 x_start + N_2 x_end + N_3 x_mid``,
``xi in [-1, 1]``, with ``N_1 = xi (xi - 1)/2``, ``N_2 = xi (xi + 1)/2``,
``N_3 = 1 - xi^2``.  Shared by the bodies (cable elements) and the contact layer
(contact surfaces), so it lives in the core.
"""
from __future__ import annotations

import numpy as np

__all__ = ["segment_lengths", "segments_at_nodes", "segment_normals", "tributary_lengths",
           "curve_points", "polyline", "N_GAUSS_CURVE"]

#: Gauss points per 3-node segment for its length and tributary weights: exact on a
#: straight segment (``|dx/dxi|`` linear, ``N_A |dx/dxi|`` cubic); on a curved one the
#: integrand is smooth and 5 points give ~1e-10 of L for a sag of 10 % of L
N_GAUSS_CURVE = 5


def _shape(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``N (3, n)`` and ``dN/dxi (3, n)`` of the 3-node segment at ``xi (n,)``."""
    N = np.stack([0.5 * xi * (xi - 1.0), 0.5 * xi * (xi + 1.0), 1.0 - xi * xi])
    dN = np.stack([xi - 0.5, xi + 0.5, -2.0 * xi])
    return N, dN


def curve_points(x: np.ndarray, seg: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """Points ``(2, n_seg, n_xi)`` of the segments at the local coordinates ``xi``
    (2-node segments: the straight line, ``N = (1 - xi)/2, (1 + xi)/2``)."""
    xi = np.asarray(xi, dtype=float)
    if seg.shape[1] == 3:
        N, _ = _shape(xi)
    else:
        N = np.stack([0.5 * (1.0 - xi), 0.5 * (1.0 + xi)])
    return np.einsum("dsk,kq->dsq", x[:, seg], N)


def _jacobians(x: np.ndarray, seg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss rule on 3-node segments: ``N (3, q)``, weights ``w (q,)`` and
    ``|dx/dxi| (n_seg, q)``."""
    eta, w = np.polynomial.legendre.leggauss(N_GAUSS_CURVE)
    N, dN = _shape(eta)
    t = np.einsum("dsk,kq->dsq", x[:, seg], dN)      # (2, n_seg, q)
    return N, w, np.hypot(t[0], t[1])


def segment_lengths(x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Lengths (n_seg,) of segments of nodes ``x`` (2, n): ``l = |x[:, seg[:, 1]] -
    x[:, seg[:, 0]]|`` for 2-node segments, ``l = int |dx/dxi| dxi`` (Gauss rule of
    :data:`N_GAUSS_CURVE` points) for 3-node ones."""
    if seg.shape[1] == 3:
        _, w, J = _jacobians(x, seg)
        return J @ w
    return np.hypot(*(x[:, seg[:, 1]] - x[:, seg[:, 0]]))


def segments_at_nodes(seg: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """The neighbours along a chain: for every node the segment that ends there and
    the one that starts there, (n_nodes,) each, -1 where there is none (mid nodes
    of 3-node segments: -1, they neither start nor end one).

    ``ending[seg[:, 0]]`` is then the previous segment of each segment and
    ``starting[seg[:, 1]]`` its next one.
    """
    seg = np.asarray(seg, dtype=np.int64)
    seg = seg[:, :2] if seg.ndim == 2 and seg.shape[1] == 3 else seg.reshape(-1, 2)
    ending = np.full(n_nodes, -1, dtype=np.int64)
    starting = np.full(n_nodes, -1, dtype=np.int64)
    ar = np.arange(seg.shape[0])
    ending[seg[:, 1]] = ar
    starting[seg[:, 0]] = ar
    return ending, starting


def segment_normals(x: np.ndarray, seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outward unit normals and lengths of segments.

    ``t = x[:, seg[:, 1]] - x[:, seg[:, 0]]``, ``n = (t_y, -t_x) / |t|``: for a
    3-node segment the normal at its middle ``xi = 0`` (where ``dx/dxi = t / 2``),
    with ``l`` its curve length (:func:`segment_lengths`).

    Returns
    -------
    n : ndarray (2, n_seg)
    l : ndarray (n_seg,)
    """
    t = x[:, seg[:, 1]] - x[:, seg[:, 0]]
    c = np.hypot(t[0], t[1])
    n = np.vstack([t[1], -t[0]]) / np.where(c > 0, c, 1.0)
    return n, (segment_lengths(x, seg) if seg.shape[1] == 3 else c)


def tributary_lengths(x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Tributary length of each node: ``a_k = int N_k dGamma`` over its segments;
    half the lengths of its 2-node segments, ``a_k = sum_{e ∋ k} l_e / 2``, and
    ``L/6, L/6, 2L/3`` (start, end, mid) on a straight 3-node segment of length
    ``L`` with a centred mid node (Gauss rule of :data:`N_GAUSS_CURVE` points)."""
    if seg.shape[1] == 3:
        N, w, J = _jacobians(x, seg)
        return np.bincount(seg.ravel(), weights=((J * w) @ N.T).ravel(), minlength=x.shape[1])
    l = segment_lengths(x, seg)
    return np.bincount(seg.ravel(), weights=np.repeat(0.5 * l, 2), minlength=x.shape[1])


def polyline(seg: np.ndarray) -> np.ndarray:
    """The chords through the nodes of the segments, (n, 2): 2-node segments as they
    are, each 3-node segment as its two halves ``(start, mid), (mid, end)`` (in chain
    order).  For what needs a polyline only up to the curve's sag (touch tests, the
    distance of an unpaired node)."""
    seg = np.asarray(seg, dtype=np.int64)
    if seg.shape[1] == 2:
        return seg
    return np.stack([seg[:, [0, 2]], seg[:, [2, 1]]], axis=1).reshape(-1, 2)
