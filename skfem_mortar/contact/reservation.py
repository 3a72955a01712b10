"""The tangent triplets of a contact pair over a reserved pattern (explicit zeros).

With the reserved pattern ``P`` of a contact discretization
(:meth:`~skfem_mortar.contact.discretization.PatternedDiscretization.pattern`:
row ``A`` holds the local dofs ``S_A`` multiplier ``A`` can couple to), the
pair's tangent blocks have the fixed sparsity

    K_ulam = -G^T        on  {(d, A) : d in S_A}
    K_lamu = c G         on  {(A, d) : d in S_A}   (zero on inactive rows)
    K_lamlam = I         on  the diagonal          (zero on active rows)
    K_uu = -H            on  union_A S_A x S_A     (the structure of P^T P)

mapped to global unknowns (dofs of a rigid master dropped).  The triplet index
arrays are built once per reservation and returned as the same objects, so the
model's sparsity pattern repeats while the reservation does; the values of
``G`` and ``H`` are scattered into it each evaluation (entries the reservation
lacks are reported, and :meth:`Reservation.widened` takes them in).
"""
from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..core.item import Contribution

__all__ = ["Reservation", "FrictionReservation", "with_triplets"]

def _keys(M: sp.spmatrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows, columns and sorted keys ``row * n_cols + col`` of a canonical csr matrix."""
    M = sp.csr_matrix(M)
    M.sum_duplicates()  # also sorts the indices
    rows = np.repeat(np.arange(M.shape[0], dtype=np.int64), np.diff(M.indptr))
    cols = M.indices.astype(np.int64)
    return rows, cols, rows * M.shape[1] + cols


def _scatter(M: sp.spmatrix | None, keys: np.ndarray, n_cols: int) -> np.ndarray | None:
    """The entries of ``M`` summed at their positions among ``keys`` (zeros
    elsewhere); None if an entry of ``M`` lies outside ``keys``."""
    if M is None:
        return np.zeros(keys.size)
    C = M.tocoo()
    nz = C.data != 0  # a stored zero needs no place
    k = C.row[nz].astype(np.int64) * n_cols + C.col[nz]
    if k.size == 0:
        return np.zeros(keys.size)
    if keys.size == 0:
        return None
    pos = np.minimum(np.searchsorted(keys, k), keys.size - 1)
    if not np.array_equal(keys[pos], k):
        return None
    return np.bincount(pos, weights=C.data[nz], minlength=keys.size)


def _ones(M: sp.spmatrix) -> sp.csr_matrix:
    """Ones at the nonzero entries of ``M``."""
    C = sp.csr_matrix(M, dtype=float, copy=True)
    C.eliminate_zeros()
    C.data[:] = 1.0
    return C


def with_triplets(out: Contribution, kr: list, kc: list, kv: list, gd: np.ndarray,
                   hessians: tuple) -> Contribution:
    """``out`` with the triplets ``kr, kc, kv`` and ``-H`` of each local ``H`` in
    ``hessians`` (None skipped; dofs of a rigid master, ``gd < 0``, dropped)."""
    for H in hessians:
        if H is not None:
            H = H.tocoo()
            ok = (gd[H.row] >= 0) & (gd[H.col] >= 0)
            kr.append(gd[H.row[ok]])
            kc.append(gd[H.col[ok]])
            kv.append(-H.data[ok])
    out.k_rows = np.concatenate(kr).astype(np.int64)
    out.k_cols = np.concatenate(kc).astype(np.int64)
    out.k_vals = np.concatenate(kv)
    return out


class Reservation:
    """The tangent triplets of a contact pair over a reserved pattern.

    Parameters
    ----------
    P : sparse matrix (n_s, n_local)
        The reserved pattern (nonzero structure only).
    gd : int ndarray (n_local,)
        Global index of each local dof, ``-1`` for a rigid master's.
    offset : int
        Global index of the pair's first multiplier.
    extra_h : sparse matrix (n_local, n_local), optional
        Further ``K_uu`` entries to reserve (beyond ``P^T P``).

    Attributes
    ----------
    rows, cols : int ndarray
        The global triplet indices, blocks ``K_ulam, K_lamu, K_lamlam, K_uu`` in this order.
    """

    def __init__(self, P: sp.spmatrix, gd: np.ndarray, offset: int,
                 extra_h: sp.spmatrix | None = None):
        P = _ones(P)
        self.P, self.gd, self.offset = P, np.asarray(gd, dtype=np.int64), int(offset)
        n_s, n_loc = P.shape
        self.n_loc = n_loc
        prow, pcol, self.keys_g = _keys(P)
        S = (P.T @ P).tocsr()
        if extra_h is not None:
            S = S + _ones(extra_h)
        S.data[:] = 1.0
        self.S = S
        hrow, hcol, self.keys_h = _keys(S)
        self.keep_g = self.gd[pcol] >= 0
        self.keep_h = (self.gd[hrow] >= 0) & (self.gd[hcol] >= 0)
        self.row_g = prow[self.keep_g]  # the multiplier row of each kept G entry
        u = self.gd[pcol[self.keep_g]]
        lam = self.offset + self.row_g
        diag = self.offset + np.arange(n_s, dtype=np.int64)
        self.rows = np.concatenate([u, lam, diag, self.gd[hrow[self.keep_h]]])
        self.cols = np.concatenate([lam, u, diag, self.gd[hcol[self.keep_h]]])

    def fits(self, gd: np.ndarray, offset: int) -> bool:
        """Whether it was built for these global dofs and multiplier offset."""
        return offset == self.offset and np.array_equal(gd, self.gd)

    def values(self, G: sp.spmatrix, H: sp.spmatrix | None, active: np.ndarray, c: float,
               row_scale: float) -> np.ndarray | None:
        """The tangent values at :attr:`rows`, :attr:`cols`: ``-G^T``, ``c s G`` on
        active rows, ``s`` on the diagonal of inactive ones, ``-H`` (``s`` the row
        scale; explicit zeros elsewhere).  None if ``G`` or ``H`` has an entry
        outside the reservation."""
        Gd = _scatter(G, self.keys_g, self.n_loc)
        Hd = _scatter(H, self.keys_h, self.n_loc)
        if Gd is None or Hd is None:
            return None
        g = Gd[self.keep_g]
        return np.concatenate([-g, np.where(active[self.row_g], c * row_scale * g, 0.0),
                               np.where(active, 0.0, row_scale), -Hd[self.keep_h]])

    def widened(self, G: sp.spmatrix, H: sp.spmatrix | None) -> "Reservation":
        """The reservation that also holds every entry of ``G`` and ``H``."""
        P = self.P + _ones(G)
        extra = self.S if H is None else self.S + _ones(H)
        return Reservation(P, self.gd, self.offset, extra)

    def blocks(self, G_col: sp.spmatrix, G_row: sp.spmatrix, diag: np.ndarray,
               H: sp.spmatrix | None) -> np.ndarray | None:
        """The tangent values at :attr:`rows`, :attr:`cols` of general blocks:
        ``-G_col^T`` (columns), ``G_row`` (rows), ``diag`` on the multiplier
        diagonal, ``-H``; None if an entry lies outside the reservation."""
        Gc = _scatter(G_col, self.keys_g, self.n_loc)
        Gr = _scatter(G_row, self.keys_g, self.n_loc)
        Hd = _scatter(H, self.keys_h, self.n_loc)
        if Gc is None or Gr is None or Hd is None:
            return None
        return np.concatenate([-Gc[self.keep_g], Gr[self.keep_g], diag, -Hd[self.keep_h]])


class FrictionReservation:
    """The tangent triplets of a contact pair with friction over reserved patterns.

    The normal blocks are a :class:`Reservation` over the method's pattern
    ``P_n``; the tangential ones a :class:`Reservation` over
    ``P_t = P_n + E`` (``E`` the slip's further columns,
    :meth:`~skfem_mortar.contact.discretization.FrictionDiscretization.slip_pattern`)
    at the tangential multipliers, which holds ``K_u,lam_t = -G_t^T``,
    ``K_lam_t,u = s_t (diag(dC/du) G_t + diag(dC/dg) G_n)`` (``G_n``'s rows
    lie in ``P_n``), the diagonal ``s_t dC/dlam_t`` and ``K_uu = -H_t`` on
    ``P_t^T P_t``; and the diagonal ``K_lam_t,lam_n = s_t dC/dlam_n``.

    Parameters
    ----------
    normal : Reservation
        The normal rows' (offset: the pair's).
    P_t : sparse matrix (n_s, n_local)
        The tangential rows' pattern.
    extra_h : sparse matrix, optional
        Further ``K_uu`` entries of the tangential part.
    """

    def __init__(self, normal: Reservation, P_t: sp.spmatrix,
                 extra_h: sp.spmatrix | None = None):
        self.normal = normal
        n_s = normal.P.shape[0]
        self.tangential = Reservation(_ones(P_t) + normal.P, normal.gd, normal.offset + n_s,
                                      extra_h)
        idx = np.arange(n_s, dtype=np.int64) + normal.offset
        self.rows = np.concatenate([normal.rows, self.tangential.rows, idx + n_s])
        self.cols = np.concatenate([normal.cols, self.tangential.cols, idx])

    def values(self, G_n: sp.spmatrix, H_n: sp.spmatrix | None, G_t: sp.spmatrix,
               B: sp.spmatrix, H_t: sp.spmatrix | None, active: np.ndarray, c: float,
               row_scale: float, s_t: float, fr: Any) -> np.ndarray | None:
        """The values at :attr:`rows`, :attr:`cols` (None if an entry of a matrix
        lies outside its reservation)."""
        vn = self.normal.values(G_n, H_n, active, c, row_scale)
        vt = self.tangential.blocks(G_t, s_t * B, s_t * fr.d_lam_t, H_t)
        if vn is None or vt is None:
            return None
        return np.concatenate([vn, vt, s_t * fr.d_lam_n])

    def widened(self, G_n: sp.spmatrix, H_n: sp.spmatrix | None, G_t: sp.spmatrix,
                H_t: sp.spmatrix | None) -> "FrictionReservation":
        """The reservation that also holds every entry of the given matrices."""
        t = self.tangential
        extra = t.S if H_t is None else t.S + _ones(H_t)
        return FrictionReservation(self.normal.widened(G_n, H_n), t.P + _ones(G_t), extra)
