"""Geometry of node chains (polylines of directed segments ``seg = (start, end)``):
segment lengths and normals, tributary lengths, the neighbours along a chain.

Shared by the bodies (cable elements) and the contact layer (contact surfaces),
so it lives in the core.
"""
from __future__ import annotations

import numpy as np

__all__ = ["segment_lengths", "segments_at_nodes", "segment_normals", "tributary_lengths"]


def segment_lengths(x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Lengths ``l = |x[:, seg[:, 1]] - x[:, seg[:, 0]]|`` (n_seg,) of segments of nodes ``x`` (2, n)."""
    return np.hypot(*(x[:, seg[:, 1]] - x[:, seg[:, 0]]))


def segments_at_nodes(seg: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """The neighbours along a chain: for every node the segment that ends there and
    the one that starts there, (n_nodes,) each, -1 where there is none.

    ``ending[seg[:, 0]]`` is then the previous segment of each segment and
    ``starting[seg[:, 1]]`` its next one.
    """
    seg = np.asarray(seg, dtype=np.int64).reshape(-1, 2)
    ending = np.full(n_nodes, -1, dtype=np.int64)
    starting = np.full(n_nodes, -1, dtype=np.int64)
    ar = np.arange(seg.shape[0])
    ending[seg[:, 1]] = ar
    starting[seg[:, 0]] = ar
    return ending, starting


def segment_normals(x: np.ndarray, seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outward unit normals and lengths of segments.

    ``t = x[:, seg[:, 1]] - x[:, seg[:, 0]]``, ``l = |t|``, ``n = (t_y, -t_x) / l``.

    Returns
    -------
    n : ndarray (2, n_seg)
    l : ndarray (n_seg,)
    """
    t = x[:, seg[:, 1]] - x[:, seg[:, 0]]
    l = np.hypot(t[0], t[1])
    return np.vstack([t[1], -t[0]]) / np.where(l > 0, l, 1.0), l


def tributary_lengths(x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Tributary length of each node: half the lengths of the segments it belongs to,
    ``a_k = sum_{e ∋ k} l_e / 2``."""
    l = segment_lengths(x, seg)
    return np.bincount(seg.ravel(), weights=np.repeat(0.5 * l, 2), minlength=x.shape[1])
