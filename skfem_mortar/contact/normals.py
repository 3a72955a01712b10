"""Averaged nodal normals of a surface of any dimension, with their exact first and
second derivatives with respect to the node coordinates of each node's neighbourhood.

The nodal normal of node ``A`` is the normalized sum of the unit normals, at ``A``, of
the cells holding it::

    s_A = sum_{e ∋ A} w_e u_e(xi_A),   n_A = s_A / |s_A|,   u_e = v_e / |v_e|,

``v_e`` the cell's area vector at ``A``'s reference position ``xi_A``
(:func:`~skfem_mortar.contact.cell_map.area_vectors`: a curve's right-hand normal in
2D, ``T_1 x T_2`` on a surface in 3D) and ``w_e`` 1, or 0 for a degenerate cell (its
length or area at most :data:`DEGENERATE` times the mean: it has no normal).  On a 2D
chain this is ``normalize(nu_prev + nu_next)`` of straight segments and, on 3-node
segments, the normalized sum of the two elements' normals at a vertex and the element's
own normal at a mid node: the normals of the 2D mortar kernels.  Any number of cells may
meet at a node.

Derivatives: ``u_e`` is a function of the cell's ``k d`` node coordinates; ``v`` is
linear (2D) or bilinear (3D: ``d2v_i / dx_{b c} dx_{b' c'} = eps_{i c c'} (G_{b 1} G_{b'
2} - G_{b 2} G_{b' 1})``, ``G = dN/dxi`` at ``xi_A``) in them, and the normalization
``f(v) = v / |v|`` has ``df = (I - f f^T) / |v|`` and ::

    d2f_i / dv_j dv_k = (3 f_i f_j f_k - delta_ij f_k - delta_ik f_j - delta_jk f_i) / |v|^2 .

Mirror normals: a symmetry line (2D) or plane (3D) ``e . x = c`` (``e`` a unit
normal) stands for the mirror image of the surface beyond it; a node on it (within
:data:`MIRROR_TOL` of the surface's size) averages its cells' normals with their
mirror images, ``s_A + R s_A = 2 P s_A`` with ``R = I - 2 e e^T``, ``P = I - e e^T``:
its normal is ``P s_A / |P s_A|``, the e-component removed (in an axisymmetric model
the axis, ``e = e_r``, ``c = 0``: a node on the axis gets an axial normal).  ``P`` is
constant, so ``dP s = P ds`` and ``d2P s = P d2s`` before the normalization.

Each node's neighbourhood (the nodes of its cells, ``K`` at most, padded with -1) gives
the local variables of its normal, so that a kernel that takes nodal normals as local
variables chains them in at assembly (``H = J^T H_loc J + sum_k df/dn_k d2n_k/dx2``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .cell_map import area_vectors, cell_measures, check_connectivity, norms
from .cells import CellType, cell_type

__all__ = ["NodalNormals", "nodal_normals", "normalize_jet", "DEGENERATE", "MIRROR_TOL",
           "mirror_nodes", "mirror_of_axis"]

#: a cell at most this fraction of the mean length or area takes no part in the average
#: (as the 2D kernels' ``LEN_TOL``)
DEGENERATE = 1e-10
#: a node within this fraction of the surface's size of a symmetry line or plane is on it
MIRROR_TOL = 1e-10


def mirror_nodes(x: np.ndarray, mirror) -> list[tuple[np.ndarray, np.ndarray]]:
    """The symmetry lines or planes ``mirror`` with the nodes on each.

    ``mirror`` holds pairs ``(e, c)``, the line or plane ``e·x = c``; returns
    ``[(e / |e|, on)]``, ``on`` (n,) bool where ``|e·x - c| <= MIRROR_TOL * size``,
    ``size`` the largest side of the nodes' bounding box (1 for one node).

    Raises
    ------
    ValueError
        When an ``e`` is not a nonzero vector of ``d = x.shape[0]`` finite components
        or a ``c`` is not a finite number.
    """
    x = np.asarray(x, dtype=float)
    d = x.shape[0]
    size = float(np.ptp(x, axis=1).max()) if x.shape[1] > 1 else 0.0
    size = size if size > 0 else 1.0
    out = []
    for item in mirror:
        try:
            e, c = item
            e, c = np.asarray(e, dtype=float), float(c)
        except (TypeError, ValueError):
            raise ValueError(f"mirror must hold pairs (e, c) of a normal vector and an "
                             f"offset, got {item!r}") from None
        r = float(np.linalg.norm(e)) if e.shape == (d,) else 0.0
        if not (r > 0 and np.isfinite(r) and np.isfinite(c)):
            raise ValueError(f"mirror normal e must be a nonzero finite vector of {d} "
                             f"components and c finite, got e={e!r}, c={c!r}")
        e = e / r
        out.append((e, np.abs(e @ x - c) <= MIRROR_TOL * size))
    return out


def mirror_of_axis(axis: int | None, d: int = 2) -> tuple:
    """The symmetry line of an axisymmetric model's axis ``x[axis] = 0`` as a
    ``mirror`` entry (``()`` for ``axis`` None: no mirror), e.g. from a measure's
    :attr:`~skfem_mortar.contact.measures.Measure.axis`."""
    if axis is None:
        return ()
    return ((np.eye(d)[axis], 0.0),)


def _project(e: np.ndarray, on: np.ndarray, s: np.ndarray, ds, d2s) -> None:
    """``P = I - e e^T`` applied in place to the columns ``on`` of ``s`` (d, n) and its
    derivative arrays (d, n, ...)."""
    for a in (s, ds, d2s):
        if a is not None:
            a[:, on] -= e.reshape((-1,) + (1,) * (a.ndim - 1)) * np.einsum(
                "i,i...->...", e, a[:, on])[None]


@dataclass
class NodalNormals:
    """Nodal normals and their derivatives over each node's neighbourhood.

    Attributes
    ----------
    n : ndarray (d, n_nodes)
        Unit nodal normals (zero at a node on no cell, or only on degenerate ones).
    nodes : int ndarray (n_nodes, K)
        The neighbourhood of each node (the nodes of the cells holding it, the node
        itself first, then ascending), padded with -1.
    dn : ndarray (d, n_nodes, K, d) or None
        ``dn[i, A, j, c] = d n_i(A) / d x_c(nodes[A, j])`` (zero on padding).
    d2n : ndarray (d, n_nodes, K, d, K, d) or None
        The second derivatives, symmetric in the two variable pairs.
    """

    n: np.ndarray
    nodes: np.ndarray
    dn: np.ndarray | None = None
    d2n: np.ndarray | None = None


def normalize_jet(s: np.ndarray, ds: np.ndarray | None = None, d2s: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """``f = s / |s|`` with its derivatives (module docstring), vectorized.

    Parameters
    ----------
    s : ndarray (d, m)
    ds : ndarray (d, m, P), optional
        Derivatives of ``s`` w.r.t. ``P`` variables.
    d2s : ndarray (d, m, P, P), optional

    Returns
    -------
    f, df, d2f : (d, m), (d, m, P), (d, m, P, P) (None where not asked). A zero ``s``
        gives zero ``f`` and derivatives.
    """
    r = norms(s)
    inv = np.where(r > 0, 1.0 / np.where(r > 0, r, 1.0), 0.0)
    f = s * inv
    if ds is None:
        return f, None, None
    a = np.einsum("im,imp->mp", f, ds)                            # f . ds
    df = (ds - f[:, :, None] * a) * inv[:, None]
    if d2s is None:
        return f, df, None
    # d2f_i = (d2s_i - f_i (f.d2s))/r + (3 f_i a a^T - ds_i a^T - a ds_i^T - f_i ds.ds)/r^2
    #       = d2s_i / r + f_i W - (U_i + U_i^T),  W = (3 a a^T - ds.ds)/r^2 - (f.d2s)/r,
    # U_i = ds_i a^T / r^2: one (m, P, P) temporary per component, not d of them
    inv2 = (inv * inv)[:, None, None]
    W = (3.0 * a[:, :, None] * a[:, None, :] - np.einsum("imp,imq->mpq", ds, ds)) * inv2
    W -= np.einsum("im,impq->mpq", f, d2s) * inv[:, None, None]
    d2f = np.empty_like(d2s)
    for i in range(s.shape[0]):
        U = ds[i][:, :, None] * (a[:, None, :] * inv2)
        d2f[i] = d2s[i] * inv[:, None, None]
        d2f[i] += f[i][:, None, None] * W
        d2f[i] -= U
        d2f[i] -= U.transpose(0, 2, 1)
    return f, df, d2f


def _area_jet(T: np.ndarray, G: np.ndarray, order: int):
    """Area vectors ``v (d, m)`` of tangents ``T (d, dim, m)`` with their derivatives
    w.r.t. the cell's node coordinates, variables ``(b, c)`` flattened to ``b d + c``:
    ``dv (d, m, k d)``, ``d2v (d, m, k d, k d)``; ``G (k, dim, m)`` the shape
    derivatives at the point."""
    d, _, m = T.shape
    k = G.shape[0]
    v = area_vectors(T)
    if order < 1:
        return v, None, None
    if d == 2:   # v = (t_y, -t_x): dv_i/dx_{b c} = G_b R_ic
        R = np.array([[0.0, 1.0], [-1.0, 0.0]])
        dv = np.einsum("bm,ic->imbc", G[:, 0], R).reshape(d, m, k * d)
        d2v = np.zeros((d, m, k * d, k * d)) if order > 1 else None
        return v, dv, d2v
    eps = np.zeros((3, 3, 3))
    eps[0, 1, 2] = eps[1, 2, 0] = eps[2, 0, 1] = 1.0
    eps[0, 2, 1] = eps[2, 1, 0] = eps[1, 0, 2] = -1.0
    # dv_i/dx_{b c} = eps_{i c l} (G_{b 0} T2_l - G_{b 1} T1_l)
    w = G[:, 0, None, :] * T[None, :, 1] - G[:, 1, None, :] * T[None, :, 0]   # (k, l, m)
    dv = np.einsum("icl,blm->imbc", eps, w).reshape(d, m, k * d)
    if order < 2:
        return v, dv, None
    cross = G[:, 0, None, :] * G[None, :, 1] - G[:, 1, None, :] * G[None, :, 0]  # (b, b', m)
    d2v = np.einsum("icq,bpm->imbcpq", eps, cross).reshape(d, m, k * d, k * d)
    return v, dv, d2v


def _neighbourhoods(conn: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """``nodes (n_nodes, K)`` (the node first, then its cells' other nodes ascending,
    -1 padded) and ``slot (n_cell, k, k)``: the slot of cell node ``b`` in the
    neighbourhood of cell node ``a``."""
    n_cell, k = conn.shape
    A = np.repeat(conn, k, axis=1).ravel()                      # (n_cell k k): node a
    B = np.tile(conn, (1, k)).ravel()                           # node b
    own = A == B
    key = np.unique(A * (n_nodes + 1) + np.where(own, 0, B + 1))  # the node itself first
    owner, other = key // (n_nodes + 1), key % (n_nodes + 1) - 1
    first = np.searchsorted(owner, np.arange(n_nodes))
    rank = np.arange(key.size) - first[owner]
    K = int(rank.max()) + 1 if key.size else 1
    nodes = np.full((n_nodes, K), -1, dtype=np.int64)
    nodes[owner, rank] = np.where(other < 0, owner, other)
    pos = np.searchsorted(key, A * (n_nodes + 1) + np.where(own, 0, B + 1))
    return nodes, rank[pos].reshape(n_cell, k, k)


def nodal_normals(x: np.ndarray, conn: np.ndarray, cell: "str | CellType",
                  order: int = 2, mirror=()) -> NodalNormals:
    """Averaged unit nodal normals (module docstring) with derivatives up to ``order``.

    Parameters
    ----------
    x : ndarray (d, n)
        Node coordinates (d = cell.dim + 1).
    conn : int ndarray (n_cell, cell.n_nodes)
    cell : str or CellType
    order : {0, 1, 2}
        0: values only; 1: and first derivatives; 2: and second.
    mirror : sequence of (e, c)
        Symmetry lines or planes ``e . x = c``: a node on one gets the mirror normal
        ``P s / |P s|`` (module docstring, :func:`mirror_nodes`).

    Returns
    -------
    NodalNormals
    """
    cell = cell_type(cell)
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[0] != cell.dim + 1:
        raise ValueError(f"x must have shape (d, n) with d = {cell.dim + 1} for "
                         f"{cell.name} cells, got {x.shape}")
    if order not in (0, 1, 2):
        raise ValueError(f"order must be 0, 1 or 2, got {order!r}")
    n_nodes, d = x.shape[1], x.shape[0]
    conn = check_connectivity(conn, cell, n_nodes)
    n_cell, k = conn.shape
    size = cell_measures(x, conn, cell)
    weight = (size > DEGENERATE * (size.mean() if size.size else 0.0)).astype(float)
    G = cell.dshape(cell.ref_nodes)                               # (k, dim, a)
    Gm = np.repeat(G[:, :, None, :], n_cell, axis=2).reshape(k, cell.dim, n_cell * k)
    T = np.einsum("dsb,bja->djsa", x[:, conn], G).reshape(d, cell.dim, n_cell * k)
    v, dv, d2v = _area_jet(T, Gm, order)
    u, du, d2u = normalize_jet(v, dv, d2v)                        # incidence (e, a)
    w = np.repeat(weight, k)
    A = conn.ravel()
    s = np.stack([np.bincount(A, weights=u[i] * w, minlength=n_nodes) for i in range(d)])
    nodes, slot = _neighbourhoods(conn, n_nodes)
    mirrors = mirror_nodes(x, mirror)
    if order == 0:
        for e, on in mirrors:
            _project(e, on, s, None, None)
        return NodalNormals(normalize_jet(s)[0], nodes)
    K = nodes.shape[1]
    P = K * d
    # variable (b, c) of incidence (e, a) -> variable slot[e, a, b] d + c of node A
    var = (slot[:, :, :, None] * d + np.arange(d)).reshape(n_cell * k, k * d)
    row = A[:, None] * P + var                                    # (m, k d)
    ds = np.stack([np.bincount(row.ravel(), weights=(du[i] * w[:, None]).ravel(),
                               minlength=n_nodes * P) for i in range(d)]).reshape(d, n_nodes, P)
    d2s = None
    if order == 2:
        idx = (A[:, None, None] * P + var[:, :, None]) * P + var[:, None, :]
        d2s = np.stack([np.bincount(idx.ravel(), weights=(d2u[i] * w[:, None, None]).ravel(),
                                    minlength=n_nodes * P * P)
                        for i in range(d)]).reshape(d, n_nodes, P, P)
    for e, on in mirrors:
        _project(e, on, s, ds, d2s)
    n, dn, d2n = normalize_jet(s, ds, d2s)
    return NodalNormals(n, nodes, dn.reshape(d, n_nodes, K, d),
                        None if d2n is None else d2n.reshape(d, n_nodes, K, d, K, d))
