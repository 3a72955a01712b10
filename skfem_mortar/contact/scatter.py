"""Local jets into global triplets: the one scatter of every contact kernel.

A kernel evaluates, per cell (a mortar integration cell, an NTS slave node, a
slip term), a row quantity ``f`` as a jet in ``nv`` local variables whose
global dofs are ``dofs`` (n, nv).  Its first derivatives go to ``G``::

    G[row_i, dofs[i, j]] += dfi/dv_j,

and the second derivatives of a weighted sum (``sum_A lam_A f_A``) to ``H``::

    H[dofs[i, j], dofs[i, k]] += d2 q_i / dv_j dv_k.

:class:`Triplets` collects these COO triplets in the order they are added and
turns them into csr once; the duplicates are summed by scipy in that order, so
a kernel that adds its parts in a fixed order gets the same matrix to the last
bit whatever else changes.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..core.coo import element_coo

__all__ = ["Triplets"]


class Triplets:
    """COO triplets of a sparse matrix built from per-cell local jets.

    Parameters
    ----------
    itype : numpy integer dtype
        Index dtype of the rows and columns (``np.int32`` halves the memory of a
        large Hessian's indices).
    """

    def __init__(self, itype: type = np.int64):
        self.itype = itype
        self.r: list[np.ndarray] = []
        self.c: list[np.ndarray] = []
        self.v: list[np.ndarray] = []

    def rows(self, rows: np.ndarray, dofs: np.ndarray, grad: np.ndarray,
             used: np.ndarray | None = None) -> None:
        """First derivatives: ``G[rows[i], dofs[i, j]] += grad[i, j]``.

        Parameters
        ----------
        rows : int ndarray (n,)
            The row (slave node) of each cell's quantity.
        dofs : int ndarray (n, nv)
            The global dofs of the cell's local variables.
        grad : ndarray (n, nv)
            ``df_i/dv_j`` (a jet's ``g.T``; or weighted).
        used : bool ndarray (n, nv), optional
            Only these entries (cells of fewer local variables than ``nv``).
        """
        if used is None:
            self.r.append(np.repeat(np.asarray(rows).astype(self.itype, copy=False),
                                    dofs.shape[1]))
            self.c.append(dofs.ravel())
            self.v.append(grad.ravel())
        else:
            rows = np.asarray(rows).astype(self.itype, copy=False)
            self.r.append(np.broadcast_to(rows[:, None], used.shape)[used])
            self.c.append(dofs[used])
            self.v.append(grad[used])

    def outer(self, rows: np.ndarray, cols: np.ndarray, vals: np.ndarray) -> None:
        """A dense block per cell: ``A[rows[i, a], cols[i, b]] += vals[i, a, b]``.

        ``rows`` (n, p), ``cols`` (n, q), ``vals`` (n, p, q) (e.g. ``D_e``, ``M_e``
        of a mortar cell: slave nodes by slave or master nodes).
        """
        self.r.append(np.repeat(rows, cols.shape[1], axis=1).ravel())
        self.c.append(np.tile(cols, (1, rows.shape[1])).ravel())
        self.v.append(vals.ravel())

    def block(self, dofs: np.ndarray, hess: np.ndarray) -> None:
        """Second derivatives: ``H[dofs[i, j], dofs[i, k]] += hess[j, k, i]``.

        ``hess`` (nv, nv, n) is a jet's :meth:`~skfem_mortar.contact.jets.Jet.hessian`.
        """
        r, c = element_coo(dofs)
        self.r.append(r)
        self.c.append(c)
        self.v.append(hess.transpose(2, 0, 1).ravel())

    def csr(self, shape: tuple[int, int]) -> sp.csr_matrix:
        """The summed matrix (duplicates added in the order of the triplets)."""
        def cat(parts, dtype):
            return np.concatenate(parts) if parts else np.zeros(0, dtype=dtype)
        return sp.coo_matrix((cat(self.v, float), (cat(self.r, self.itype),
                                                   cat(self.c, self.itype))),
                             shape=shape).tocsr()
