"""The tributary lengths of a slave chain and their exact derivative.

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
  :func:`~skfem_mortar.contact.curves.tributary_weights`, so exact for the rule).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .cells import CellType, cell_type
from .curves import N_TRIBUTARY, ends, is_affine, shape_values

__all__ = ["tributary_jacobian", "tributary_pattern"]


def tributary_jacobian(x: np.ndarray, seg: np.ndarray, n_cols: int | None,
                       cell: "str | CellType") -> sp.csr_matrix:
    """``da_k/dx`` of the tributary lengths of nodes ``x`` (2, n) on segments ``seg``.

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

    Returns
    -------
    csr_matrix (n, n_cols)
    """
    x = np.asarray(x, dtype=float)
    seg = np.asarray(seg, dtype=np.int64)
    n = x.shape[1]
    n_cols = 2 * n if n_cols is None else int(n_cols)
    cell = cell_type(cell)
    if not is_affine(cell):
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
