"""The symmetrization of a saddle-point Newton system: its multiplier rows scaled
to their columns (active rows) or solved for (inactive rows), as the upper
triangle that PARDISO's symmetric indefinite solver factors (:func:`symmetrize`).
"""
from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np
import scipy.sparse as sp

__all__ = ["symmetrize", "SymmetricSystem", "SYMMETRY_RTOL", "Hint"]

#: what multiplier rows would couple to once active: ``hint() -> (rows, cols, vals)``
Hint = Callable[[], "tuple[np.ndarray, np.ndarray, np.ndarray] | None"]


class _Symmetrized(NamedTuple):
    """Where the entries of the multiplier rows and their transposes lie in a
    pattern, and its upper triangle (:func:`symmetrize`)."""

    indptr: np.ndarray
    indices: np.ndarray
    ent: np.ndarray      # positions of the multiplier rows' entries
    row: np.ndarray      # their row
    tpos: np.ndarray     # position of the transposed entry (col, row)
    diag: np.ndarray     # whether the entry is on the diagonal
    upper: np.ndarray    # positions of the upper triangle (col >= row), in CSR order
    u_indptr: np.ndarray
    u_indices: np.ndarray


_SYM_CACHE: dict = {}


def _symmetrized_pattern(A: sp.csr_matrix, mult: np.ndarray) -> _Symmetrized | None:
    """The positions :func:`symmetrize` needs, cached per pattern and multiplier
    rows; None if the multiplier rows are not structurally symmetric."""
    key = _SYM_CACHE.get("key")
    if (key is not None and (key[0] is A.indptr or np.array_equal(key[0], A.indptr))
            and (key[1] is A.indices or np.array_equal(key[1], A.indices))
            and np.array_equal(key[2], mult)):
        return _SYM_CACHE["value"]
    n = A.shape[0]
    counts = np.diff(A.indptr)
    rows = np.repeat(np.arange(n, dtype=np.int64), counts)
    cols = A.indices.astype(np.int64)
    ent = np.flatnonzero(mult[rows])
    r, c = rows[ent], cols[ent]
    keys = rows * n + cols  # sorted (canonical csr)
    t = r + c * n
    tpos = np.minimum(np.searchsorted(keys, t), keys.size - 1)
    value = None
    if np.array_equal(keys[tpos], t):
        upper = np.flatnonzero(cols >= rows)
        u_indptr = np.zeros(n + 1, dtype=A.indptr.dtype)
        np.cumsum(np.bincount(rows[upper], minlength=n), out=u_indptr[1:])
        value = _Symmetrized(A.indptr, A.indices, ent, r, tpos, r == c, upper,
                             u_indptr, A.indices[upper])
    _SYM_CACHE.update(key=(A.indptr, A.indices, mult.copy()), value=value)
    return value


#: relative mismatch of a multiplier row against its column above which the
#: system is not taken as symmetrizable (the row is c s G, the column -G^T:
#: equal up to round-off of the product)
SYMMETRY_RTOL = 1e-12


class SymmetricSystem(NamedTuple):
    """What :func:`symmetrize` returns.

    ``U`` the upper triangle of the symmetrized matrix (csr), ``b`` its
    right-hand side, ``transform(r)`` the same change of another right-hand
    side (for iterative refinement), ``analysis()`` the matrix of ``U``'s
    pattern to *analyse* (PARDISO's weighted matching and scaling are computed
    from the values of the matrix analysed and kept with the analysis): ``U``
    with every inactive multiplier row that has a coupling column shown as an
    active one (diagonal 0, its column's values), so that the matching pairs
    every multiplier that can become active with a displacement and a later
    active-set change finds its 2 x 2 pivot there; an inactive row with no
    coupling values yet (one the contact search has not reached) is shown
    active with the ``hint`` coupling of :func:`solve_linear` where given
    (``ContactPair.analysis_coupling``: the node's normal times its tributary
    length on its own dofs), so one analysis serves a solve whose contact zone
    grows beyond the first search (hertz ``refine=3``, rigid base, one step:
    1 analysis instead of 2, 0 perturbed pivots).  Measured on hertz
    (``refine=2``, one step): the analysis of the plain ``U`` answered 5 of 7
    reused solves with 1 to 3 perturbed pivots and a residual of 2e-5 to
    4e-8 (refinement, at ``refine=3`` two new analyses); shown active: none.
    """

    U: sp.csr_matrix
    b: np.ndarray
    transform: Callable[[np.ndarray], np.ndarray]
    analysis: Callable[[], sp.csr_matrix]


def symmetrize(A: sp.csr_matrix, b: np.ndarray, mult: np.ndarray, hint: Hint | None = None
               ) -> SymmetricSystem | None:
    """The symmetric form of a saddle-point system, as its upper triangle.

    The multiplier rows ``r`` (``mult``) of the Newton system are of two kinds:
    an *active* row is ``f_r`` times the transpose of its column (``c s G_r``
    against ``-G_r^T``), and is scaled by ``f_r = (row . col) / (row . row)``
    (refused unless ``|f_r row - col| <= SYMMETRY_RTOL |col|``); an *inactive* row
    is ``s lam_r`` alone (no off-diagonal value), so its unknown
    ``x_r = b_r / A_rr`` is known: its column times ``x_r`` moves to the right-hand
    side, the column's values become explicit zeros and the row ``x_r = b_r``
    (diagonal 1).  The pattern is kept, so the symmetric analysis survives
    active-set changes.  Returns a :class:`SymmetricSystem`, or None when the
    multiplier rows are not structurally or numerically symmetric to their
    columns.
    """
    sym = _symmetrized_pattern(A, mult)
    if sym is None:
        return None
    n = A.shape[0]
    data = A.data.copy()
    b = np.array(b, dtype=float)
    v_row, v_col = data[sym.ent], data[sym.tpos]
    off = ~sym.diag
    offsum = np.bincount(sym.row[off], weights=np.abs(v_row[off]), minlength=n)
    inactive = mult & (offsum == 0)
    ina_e = inactive[sym.row]
    # inactive rows: the known unknown, its column to the right-hand side
    d = np.zeros(n)
    d[sym.row[sym.diag]] = v_row[sym.diag]
    if np.any(d[inactive] == 0):
        return None
    x_known = np.zeros(n)
    x_known[inactive] = b[inactive] / d[inactive]
    move = ina_e & off
    cols_e = A.indices[sym.ent].astype(np.int64)
    np.subtract.at(b, cols_e[move], v_col[move] * x_known[sym.row[move]])
    data[sym.tpos[move]] = 0.0
    data[sym.ent[ina_e & sym.diag]] = 1.0
    b[inactive] = x_known[inactive]
    # active rows: scale to the column
    act_e = ~ina_e & off
    rr = np.bincount(sym.row[act_e], weights=v_row[act_e] ** 2, minlength=n)
    rc = np.bincount(sym.row[act_e], weights=v_row[act_e] * v_col[act_e], minlength=n)
    active = mult & ~inactive
    f = np.ones(n)
    f[active] = rc[active] / np.where(rr[active] > 0, rr[active], 1.0)
    mis = np.abs(f[sym.row[act_e]] * v_row[act_e] - v_col[act_e])
    scale = np.zeros(n)
    np.maximum.at(scale, sym.row[act_e], np.abs(v_col[act_e]))
    if np.any(mis > SYMMETRY_RTOL * scale[sym.row[act_e]] + 0.0) or np.any(rr[active] == 0):
        return None
    data[sym.ent[~ina_e]] *= f[sym.row[~ina_e]]
    b[active] *= f[active]
    U = _upper(sym, data, n)
    cm, rm, vm = cols_e[move], sym.row[move], v_col[move]

    def transform(r: np.ndarray) -> np.ndarray:
        """The same change of a right-hand side ``r`` (linear in ``r``)."""
        r = np.array(r, dtype=float)
        known = np.zeros(n)
        known[inactive] = r[inactive] / d[inactive]
        np.subtract.at(r, cm, vm * known[rm])
        r[inactive] = known[inactive]
        r[active] *= f[active]
        return r

    def analysis() -> sp.csr_matrix:
        """``U`` with every inactive row that has a coupling column shown as
        active, and every other inactive row with the ``hint`` coupling in its
        pattern (:class:`SymmetricSystem`)."""
        coupled = np.bincount(sym.row[move], weights=np.abs(v_col[move]), minlength=n) > 0
        shown = move & coupled[sym.row]
        pdata = data.copy()
        pdata[sym.tpos[shown]] = v_col[shown]
        hinted = _hinted(A, hint, inactive & ~coupled) if hint is not None else None
        if hinted is not None:
            pos, vals, rows = hinted
            pdata[pos] = vals
            coupled[rows] = True
        pdata[sym.ent[sym.diag & coupled[sym.row]]] = 0.0
        return _upper(sym, pdata, n)
    return SymmetricSystem(U, b, transform, analysis)


def _hinted(A: sp.csr_matrix, hint: Hint, rows_wanted: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The places, in the pattern of ``A``, of the transposed ``hint`` entries
    ``(col, row)`` of the rows ``rows_wanted`` (bool) that lie in the pattern, their
    values and rows; None if there are none."""
    got = hint()
    if got is None:
        return None
    r, c, v = (np.asarray(a) for a in got)
    keep = rows_wanted[r] & (v != 0.0)
    r, c, v = r[keep], c[keep], v[keep]
    if r.size == 0:
        return None
    n = A.shape[0]
    rows_of = np.repeat(np.arange(n, dtype=np.int64), np.diff(A.indptr))
    keys = rows_of * n + A.indices  # sorted (canonical csr)
    t = c.astype(np.int64) * n + r  # the transposed entry (col, row)
    pos = np.minimum(np.searchsorted(keys, t), keys.size - 1)
    found = keys[pos] == t
    if not found.any():
        return None
    return pos[found], v[found], np.unique(r[found])


def _upper(sym: _Symmetrized, data: np.ndarray, n: int) -> sp.csr_matrix:
    """The upper triangle of the pattern ``sym`` with the values ``data`` (csr)."""
    U = sp.csr_matrix((data[sym.upper], sym.u_indices, sym.u_indptr), shape=(n, n))
    U.has_sorted_indices = True
    return U
