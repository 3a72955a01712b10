"""Geometry of node chains (polylines of directed segments ``seg = (start, end)``,
or curved 3-node segments ``(start, end, mid)``): segment lengths and normals,
tributary lengths, the neighbours along a chain.

A 3-node segment is the curve ``x(xi) = N_1 x_start + N_2 x_end + N_3 x_mid``,
``xi in [-1, 1]``, with ``N_1 = xi (xi - 1)/2``, ``N_2 = xi (xi + 1)/2``,
``N_3 = 1 - xi^2``.  Shared by the bodies (cable elements) and the contact layer
(contact surfaces), so it lives in the core.

Every function takes the segments' ``cell``: a line cell of the cell table
(:class:`~skfem_mortar.contact.cells.CellType`, read by its attributes ``name``,
``n_nodes``, ``corners``, ``edges``, ``dshape``, ``shape``, ``quadrature``; this module
imports nothing from the contact layer) or its name ``"line2"``/``"line3"``.  Without
it (``cell=None``, the callers not yet switched) a connectivity of 3 columns is read
as line3 and one of 2 as line2, which in 3D (tri3) and for piecewise cells
(``line2x2``) is wrong: pass the cell.
"""
from __future__ import annotations

import numpy as np

__all__ = ["segment_lengths", "segments_at_nodes", "segment_normals", "tributary_lengths",
           "curve_points", "polyline", "N_GAUSS_CURVE"]

#: Gauss points per 3-node segment for its length and tributary weights: exact on a
#: straight segment (``|dx/dxi|`` linear, ``N_A |dx/dxi|`` cubic); on a curved one the
#: integrand is smooth and 5 points give ~1e-10 of L for a sag of 10 % of L
N_GAUSS_CURVE = 5


def _kind(seg: np.ndarray, cell) -> "str | object":
    """``"line2"``, ``"line3"`` or another line cell (the object) of the segments
    ``seg``; ``cell`` None: by the column count (module docstring).  ValueError when
    the cell's node count is not the column count, or the cell is not a line."""
    cols = np.shape(seg)[1] if np.ndim(seg) == 2 else 2
    if cell is None:
        return "line3" if cols == 3 else "line2"
    name = cell if isinstance(cell, str) else getattr(cell, "name", None)
    if isinstance(cell, str) and name not in ("line2", "line3"):
        raise ValueError(f"cell must be 'line2', 'line3' or a line CellType, got {cell!r}")
    n = {"line2": 2, "line3": 3}.get(name, getattr(cell, "n_nodes", None))
    if not isinstance(cell, str) and getattr(cell, "dim", None) != 1:
        raise ValueError(f"cell must be a line cell (dim 1), got {cell!r}")
    if n != cols:
        raise ValueError(f"seg must have {n} columns for {name} cells, got {cols}")
    return name if name in ("line2", "line3") else cell


def _generic_jacobians(x: np.ndarray, seg: np.ndarray, cell):
    """``N (k, q)``, ``w (q,)`` and ``|dx/dxi| (n_seg, q)`` by the cell's own rule."""
    pts, w = cell.quadrature(2 * N_GAUSS_CURVE - 1)
    N, dN = np.asarray(cell.shape(pts)), np.asarray(cell.dshape(pts))[:, 0]
    t = np.einsum("dsk,kq->dsq", x[:, seg], dN)
    return N, w, np.sqrt(np.einsum("dsq,dsq->sq", t, t))


def _shape(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``N (3, n)`` and ``dN/dxi (3, n)`` of the 3-node segment at ``xi (n,)``."""
    N = np.stack([0.5 * xi * (xi - 1.0), 0.5 * xi * (xi + 1.0), 1.0 - xi * xi])
    dN = np.stack([xi - 0.5, xi + 0.5, -2.0 * xi])
    return N, dN


def curve_points(x: np.ndarray, seg: np.ndarray, xi: np.ndarray, cell=None) -> np.ndarray:
    """Points ``(2, n_seg, n_xi)`` of the segments at the local coordinates ``xi``
    (2-node segments: the straight line, ``N = (1 - xi)/2, (1 + xi)/2``)."""
    xi = np.asarray(xi, dtype=float)
    kind = _kind(seg, cell)
    if not isinstance(kind, str):
        N = np.asarray(kind.shape(xi[None]))
    elif kind == "line3":
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


def segment_lengths(x: np.ndarray, seg: np.ndarray, cell=None) -> np.ndarray:
    """Lengths (n_seg,) of segments of nodes ``x`` (2, n): ``l = |x[:, seg[:, 1]] -
    x[:, seg[:, 0]]|`` for 2-node segments, ``l = int |dx/dxi| dxi`` (Gauss rule of
    :data:`N_GAUSS_CURVE` points) for 3-node ones (another cell: by its own rule)."""
    kind = _kind(seg, cell)
    if not isinstance(kind, str):
        _, w, J = _generic_jacobians(x, seg, kind)
        return J @ w
    if kind == "line3":
        _, w, J = _jacobians(x, seg)
        return J @ w
    return np.hypot(*(x[:, seg[:, 1]] - x[:, seg[:, 0]]))


def segments_at_nodes(seg: np.ndarray, n_nodes: int, cell=None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """The neighbours along a chain: for every node the segment that ends there and
    the one that starts there, (n_nodes,) each, -1 where there is none (mid nodes
    of 3-node segments: -1, they neither start nor end one).

    ``ending[seg[:, 0]]`` is then the previous segment of each segment and
    ``starting[seg[:, 1]]`` its next one.
    """
    seg = np.asarray(seg, dtype=np.int64)
    kind = _kind(seg, cell)
    if not isinstance(kind, str):
        seg = seg[:, list(kind.corners)]
    else:
        seg = seg[:, :2] if kind == "line3" else seg.reshape(-1, 2)
    ending = np.full(n_nodes, -1, dtype=np.int64)
    starting = np.full(n_nodes, -1, dtype=np.int64)
    ar = np.arange(seg.shape[0])
    ending[seg[:, 1]] = ar
    starting[seg[:, 0]] = ar
    return ending, starting


def segment_normals(x: np.ndarray, seg: np.ndarray, cell=None) -> tuple[np.ndarray, np.ndarray]:
    """Outward unit normals and lengths of segments.

    ``t = x[:, seg[:, 1]] - x[:, seg[:, 0]]``, ``n = (t_y, -t_x) / |t|``: for a
    3-node segment the normal at its middle ``xi = 0`` (where ``dx/dxi = t / 2``),
    with ``l`` its curve length (:func:`segment_lengths`).

    Returns
    -------
    n : ndarray (2, n_seg)
    l : ndarray (n_seg,)
    """
    kind = _kind(seg, cell)
    a, b = (0, 1) if isinstance(kind, str) else kind.corners
    t = x[:, seg[:, b]] - x[:, seg[:, a]]
    c = np.hypot(t[0], t[1])
    n = np.vstack([t[1], -t[0]]) / np.where(c > 0, c, 1.0)
    return n, (c if kind == "line2" else segment_lengths(x, seg, cell))


def tributary_lengths(x: np.ndarray, seg: np.ndarray, cell=None) -> np.ndarray:
    """Tributary length of each node: ``a_k = int N_k dGamma`` over its segments;
    half the lengths of its 2-node segments, ``a_k = sum_{e ∋ k} l_e / 2``, and
    ``L/6, L/6, 2L/3`` (start, end, mid) on a straight 3-node segment of length
    ``L`` with a centred mid node (Gauss rule of :data:`N_GAUSS_CURVE` points; another
    cell: by its own rule)."""
    kind = _kind(seg, cell)
    if kind != "line2":
        N, w, J = _jacobians(x, seg) if kind == "line3" else _generic_jacobians(x, seg, kind)
        return np.bincount(seg.ravel(), weights=((J * w) @ N.T).ravel(), minlength=x.shape[1])
    l = segment_lengths(x, seg)
    return np.bincount(seg.ravel(), weights=np.repeat(0.5 * l, 2), minlength=x.shape[1])


def polyline(seg: np.ndarray, cell=None) -> np.ndarray:
    """The chords through the nodes of the segments, (n, 2): 2-node segments as they
    are, each 3-node segment as its two halves ``(start, mid), (mid, end)`` (in chain
    order); another line cell as the chords between the nodes of its edge
    (``cell.edges[0]``, in order along it).  For what needs a polyline only up to the
    curve's sag (touch tests, the distance of an unpaired node)."""
    seg = np.asarray(seg, dtype=np.int64)
    kind = _kind(seg, cell)
    if kind == "line2":
        return seg
    edge = [0, 2, 1] if kind == "line3" else list(kind.edges[0])
    return np.stack([seg[:, [p, q]] for p, q in zip(edge[:-1], edge[1:])],
                    axis=1).reshape(-1, 2)
