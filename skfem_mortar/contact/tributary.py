"""The tributary weights of a slave chain and their exact derivative.

A node's tributary length ``a_k = int N_k dGamma`` over its segments on the
*current* positions (:func:`skfem_mortar.core.chain.tributary_lengths`) turns
a traction into an NTS nodal force.  The Tresca bound is a traction per unit
current length (:class:`~skfem_mortar.contact.friction.Tresca`), so NTS's nodal
bound ``bound * a_k(x)`` moves with the slave and its rows need ``da_k/dx``:

* 2-node segments: ``a_k = sum_{e ∋ k} l_e / 2``, ``dl_e/dx_end = -dl_e/dx_start
  = (x_end - x_start) / l_e``;
* any other line cell of the table (``line3``, a registered one):
  ``a_k = sum_e sum_q w_q N_k(eta_q) J_eq``, ``J_eq = |x'(eta_q)|``,
  ``dJ_eq/dx_a = dN_a(eta_q) x'(eta_q) / J_eq`` (the cell's rule of
  :data:`~skfem_mortar.contact.curves.N_TRIBUTARY` points, the weights of
  :func:`~skfem_mortar.contact.curves.tributary_weights`, so exact for the rule);
* with the weight ``w`` of a measure (:mod:`~skfem_mortar.contact.measures`:
  ``2 pi r`` in an axisymmetric model) ``a_k = int N_k w dGamma`` by the same
  rule on every cell, and its derivative has the weight's term too
  (:func:`tributary_jacobian`).
"""
from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from .cells import CellType, cell_type
from .curves import N_TRIBUTARY, ends, is_affine, shape_values
from .jets import Jet

__all__ = ["tributary_jacobian", "tributary_pattern"]


def tributary_jacobian(x: np.ndarray, seg: np.ndarray, n_cols: int | None,
                       cell: "str | CellType", measure: Any = None) -> sp.csr_matrix:
    """``da_k/dx`` of the tributary weights of nodes ``x`` (2, n) on segments ``seg``.

    Parameters
    ----------
    x : ndarray (2, n)
        Current node coordinates.
    seg : int ndarray (n_seg, n_nodes of ``cell``)
        The cells.
    n_cols : int or None
        Columns of the result (None: ``2 n``); node ``j``'s dofs are columns
        ``2 j, 2 j + 1`` (the contact kernels' local order, slave first).
    cell : str or CellType
        The line cell type of ``seg``.
    measure : Measure, optional
        The weight ``w`` of ``dGamma`` (:mod:`~skfem_mortar.contact.measures`;
        None or unit: the tributary lengths above).  Otherwise, with ``x_q =
        sum_a N_a(eta_q) x_a`` the rule's points (:func:`_weighted`)::

            d a_b / d x_a = sum_q w_q N_b(eta_q) [dN_a(eta_q) u_q w(x_q)
                                                  + J_q N_a(eta_q) dw/dx (x_q)].

    Returns
    -------
    csr_matrix (n, n_cols)
    """
    x = np.asarray(x, dtype=float)
    seg = np.asarray(seg, dtype=np.int64)
    n = x.shape[1]
    n_cols = 2 * n if n_cols is None else int(n_cols)
    cell = cell_type(cell)
    if measure is not None and not measure.unit:
        D = _weighted(x, seg, cell, measure)
    elif not is_affine(cell):
        eta, w = cell.quadrature(2 * N_TRIBUTARY - 1)
        N, dN, _ = shape_values(cell, eta[0])                  # (n_nodes, q)
        t = np.einsum("dsk,kq->dsq", x[:, seg], dN)            # x'(eta_q), (2, n_seg, q)
        J = np.hypot(t[0], t[1])
        u = t / np.where(J > 0, J, 1.0)                        # unit tangents
        # d a_{seg[e, b]} / d x_{seg[e, a]}, component d: sum_q w_q N_b dN_a u_d
        D = np.einsum("q,bq,aq,dsq->sbad", w, N, dN, u)        # (n_seg, n, n, 2)
    else:
        seg = ends(seg, cell)
        t = x[:, seg[:, 1]] - x[:, seg[:, 0]]
        l = np.hypot(t[0], t[1])
        u = (t / np.where(l > 0, l, 1.0)).T                    # (n_seg, 2)
        sign = np.array([-0.5, 0.5])                           # dl/dx_start, dl/dx_end, halved
        D = np.broadcast_to(sign[None, None, :, None] * u[:, None, None, :],
                            (len(seg), 2, 2, 2))
    rows, cols = _entries(seg)
    return sp.csr_matrix((D.ravel(), (rows, cols)), shape=(n, n_cols))


def _weighted(x: np.ndarray, seg: np.ndarray, cell: CellType, measure: Any) -> np.ndarray:
    """``d a_b / d x_a`` (n_seg, n_nodes, n_nodes, 2) of ``a_b = int N_b w dGamma`` by
    the rule of :func:`~skfem_mortar.contact.curves.tributary_weights`; ``dw/dx``
    from a first-order jet of the measure's weight at the rule's points."""
    eta, w = cell.quadrature(2 * N_TRIBUTARY - 1)
    N, dN, _ = shape_values(cell, eta[0])                      # (n_nodes, q)
    t = np.einsum("dsk,kq->dsq", x[:, seg], dN)
    xq = np.einsum("dsk,kq->dsq", x[:, seg], N)
    J = np.hypot(t[0], t[1])
    u = t / np.where(J > 0, J, 1.0)
    W = measure.weight(xq)
    Wj = measure.weight(tuple(Jet.variable(xq[c], c, 2, False) for c in (0, 1)))
    dW = (np.broadcast_to(Wj.g, t.shape) if isinstance(Wj, Jet)
          else np.zeros(t.shape))                              # (2, n_seg, q)
    return (np.einsum("q,bq,aq,dsq->sbad", w, N, dN, u * W)
            + np.einsum("q,bq,aq,dsq->sbad", w, N, N, J * dW))


def tributary_pattern(seg: np.ndarray, n: int, n_cols: int | None = None) -> sp.csr_matrix:
    """Ones where :func:`tributary_jacobian` may be nonzero (node ``k``'s row: the
    dofs of the nodes of its segments), whatever the positions."""
    seg = np.asarray(seg, dtype=np.int64)
    rows, cols = _entries(seg)
    M = sp.csr_matrix((np.ones(rows.size), (rows, cols)),
                      shape=(n, 2 * n if n_cols is None else int(n_cols)))
    M.data[:] = 1.0
    return M


def _entries(seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the entries ``(segment, node b, node a, component)``."""
    k = seg.shape[1]
    shape = (len(seg), k, k, 2)
    rows = np.broadcast_to(seg[:, :, None, None], shape)
    cols = 2 * np.broadcast_to(seg[:, None, :, None], shape) + np.arange(2)
    return rows.ravel(), cols.ravel()
