"""Sparse direct solve of the (possibly indefinite, saddle-point) Newton system.

Two backends:

``superlu`` (scipy, always there)
    SuperLU with COLAMD column ordering and partial pivoting.  The block system
    ``[K  B^T; B  0]`` is indefinite (zero diagonal on the active multiplier
    rows), so a Cholesky solver is not an option; threshold pivoting handles
    it.  Measured on the hertz and seed tangents (47k and 75k unknowns): COLAMD
    with the default pivot threshold is the fastest of scipy's orderings; the
    symmetric orderings (``MMD_AT_PLUS_A`` with ``SymmetricMode``) give about
    25 % less fill but take twice as long (their ordering step is slow), and
    ``MMD_ATA`` is far slower.
``pardiso`` (Intel MKL PARDISO through ``pypardiso``, the optional extra ``fast``)
    Nested-dissection (METIS) ordering and a multithreaded supernodal LU with
    weighted matching for the zero diagonal; chosen automatically when
    ``pypardiso`` is installed.  PARDISO perturbs tiny pivots instead of
    failing, so its answer is checked (relative residual); a failed check falls
    back to SuperLU, which also gives the clean "singular" diagnosis.  The
    symbolic analysis is kept while the sparsity pattern repeats (the model's
    fixed pattern with the contact pairs' reservations: one analysis per
    solve on hertz), a poor answer of a kept analysis is refined before a new
    one.  A system that is symmetric but for its contact multiplier rows
    (``multipliers`` of :func:`solve_linear`) is symmetrized
    (:func:`symmetrize`) and factored by the symmetric indefinite solver
    (``mtype`` -2, upper triangle, Bunch-Kaufman with weighted matching): half
    the factor of the LU; its answer is checked against the original system,
    and the unsymmetric solver retries if it fails.  From :data:`SINGLE_ABOVE`
    unknowns on the symmetric factorization is single precision (iparm(28) = 1,
    float32 values: a factor of half the memory, about 35 % less time) and each
    answer is refined in double, ``x += S^-1 T(b - K x)`` with the original
    ``K``, until it passes the same residual check (one step from ~6e-8 to
    ~7e-12 at 1.7e5 unknowns); the double-precision factorization retries if
    it does not within :data:`REFINE_STEPS_SINGLE` steps.

SuperLU keeps nothing between calls: scipy's ``splu`` computes its COLAMD
column ordering in every call, and ``permc_spec`` takes only the name of an
ordering, not a permutation, so the ordering of a repeated pattern cannot be
handed back (pre-permuting the matrix with the last ``perm_c`` and
``NATURAL`` would, but changes SuperLU's pivoting; not done).

The environment variable ``SKFEM_MORTAR_SOLVER`` (``superlu`` or ``pardiso``)
overrides the automatic choice, and :func:`solve_linear` takes ``backend``.
"""
from __future__ import annotations

import logging
import os
import warnings
from typing import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..core.errors import InversionError
from .pardiso import (_good, _pardiso_available, _same_arrays, forget_analyses,  # noqa: F401
                      pardiso_solver)
from .symmetrization import Hint, SymmetricSystem, symmetrize  # noqa: F401

# pardiso_solver, forget_analyses (solver.pardiso) and symmetrize, SymmetricSystem
# (solver.symmetrization) are offered here too
__all__ = ["solve_linear", "factorize", "KeptFactors", "available_backends",
           "default_backend", "BACKENDS", "pardiso_solver", "forget_analyses", "symmetrize",
           "SymmetricSystem", "SYMMETRIC"]

log = logging.getLogger(__name__)

BACKENDS = ("superlu", "pardiso")
#: factor symmetrizable systems with PARDISO's symmetric indefinite solver
#: (``SKFEM_MORTAR_SYMMETRIC=0`` turns it off: the unsymmetric path)
SYMMETRIC = os.environ.get("SKFEM_MORTAR_SYMMETRIC", "1").strip() != "0"

def _single_above() -> int:
    """``SKFEM_MORTAR_SINGLE_ABOVE`` (default 50000), refused unless an integer >= 0."""
    text = os.environ.get("SKFEM_MORTAR_SINGLE_ABOVE", "50000").strip()
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise ValueError("SKFEM_MORTAR_SINGLE_ABOVE must be an integer >= 0 (unknowns; 0: "
                         f"always single precision), got {text!r}")
    return value


#: symmetrized systems of at least this many unknowns are factored in single
#: precision and refined in double (:class:`_Pardiso`, ``single``):
#: measured on hertz ``refine=3`` (1.7e5 unknowns, one core) the factorization
#: takes 0.25-0.31 s instead of 0.40-0.51 s and one refinement step (0.05 s)
#: brings the residual from 6e-8 to 7e-12; below ~5e4 unknowns the refinement
#: eats the gain (``SKFEM_MORTAR_SINGLE_ABOVE`` overrides; 0: always)
SINGLE_ABOVE = _single_above()


def available_backends() -> list[str]:
    """The backends that work here (``superlu`` always)."""
    return ["superlu"] + (["pardiso"] if _pardiso_available() else [])


def default_backend() -> str:
    """``SKFEM_MORTAR_SOLVER`` if set, else ``pardiso`` when installed, else ``superlu``."""
    env = os.environ.get("SKFEM_MORTAR_SOLVER", "").strip().lower()
    if env:
        if env not in BACKENDS:
            raise ValueError(f"SKFEM_MORTAR_SOLVER must be one of {BACKENDS}, got {env!r}")
        return env
    return "pardiso" if _pardiso_available() else "superlu"


def solve_linear(K: sp.spmatrix, b: np.ndarray, backend: str | None = None,
                 multipliers: np.ndarray | None = None, hint: Hint | None = None) -> np.ndarray:
    """Solve ``K x = b`` with a sparse direct solver.

    Parameters
    ----------
    K : sparse matrix (n, n)
    b : ndarray (n,)
    backend : {"superlu", "pardiso"}, optional
        Default :func:`default_backend`.  ``pardiso`` without ``pypardiso``
        installed raises ImportError.
    multipliers : bool ndarray (n,), optional
        The multiplier rows of a system that is symmetric but for them (every
        item symmetric but the contact pairs' rows, ``Model.symmetrizable``):
        PARDISO then factors the symmetrized system (:func:`symmetrize`) with
        its symmetric indefinite solver (half the factor).  SuperLU solves the
        system as it is (scipy offers no symmetric indefinite factorization;
        its ``SymmetricMode`` measured slower, see the module docstring).
    hint : callable, optional
        ``hint()`` returns ``(rows, cols, vals)``: what multiplier rows would
        couple to once active (``Model.analysis_coupling``), read only when
        PARDISO analyses a symmetrized system (:class:`SymmetricSystem`).

    Raises
    ------
    InversionError
        When the matrix is singular or the solution is not finite (the Newton
        solver treats this like a failed iteration and cuts the load step).
    """
    return _direct(K, b, backend, multipliers, keep=False, hint=hint)[0]


def factorize(K: sp.spmatrix, b: np.ndarray, backend: str | None = None,
              multipliers: np.ndarray | None = None, hint: Hint | None = None
              ) -> tuple[np.ndarray, "KeptFactors | None"]:
    """:func:`solve_linear`, and the factors it used, kept to be applied again.

    The answer is the direct one (the same paths and checks as
    :func:`solve_linear`; SuperLU through ``splu``, whose object is kept,
    instead of ``spsolve``).  The second value applies the inverse of the
    factored matrix ``K0`` to later right-hand sides (:class:`KeptFactors`):
    the preconditioner of :mod:`~skfem_mortar.solver.krylov`.  It is None for
    an empty system.
    """
    return _direct(K, b, backend, multipliers, keep=True, hint=hint)


def _direct(K: sp.spmatrix, b: np.ndarray, backend: str | None,
            multipliers: np.ndarray | None, keep: bool, hint: Hint | None = None
            ) -> tuple[np.ndarray, "KeptFactors | None"]:
    """The direct answer of ``K x = b`` and, with ``keep``, its kept factors."""
    if K.shape[0] == 0:
        return np.zeros(0), None
    backend = backend or default_backend()
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    b = np.asarray(b, dtype=float)
    if backend == "pardiso":
        mult = None if multipliers is None else np.asarray(multipliers, dtype=bool)
        x, kept = _pardiso(K, b, mult, hint)
        if x is not None:
            return x, _handed(kept, K) if keep else None
    x, kept = _superlu(K, b, keep)
    return x, _handed(kept, K)


def _handed(kept: "KeptFactors | None", K: sp.spmatrix) -> "KeptFactors | None":
    """``kept`` with the matrix as the caller handed it over (its pattern is compared)."""
    if kept is not None:
        kept.matrix = K
    return kept


def _superlu(K: sp.spmatrix, b: np.ndarray, keep: bool = False
             ) -> tuple[np.ndarray, "KeptFactors | None"]:
    """SuperLU's answer (``spsolve``; with ``keep`` ``splu``, whose object is kept)."""
    A = sp.csc_matrix(K)
    kept = None
    with warnings.catch_warnings():
        warnings.simplefilter("error", spla.MatrixRankWarning)
        try:
            if keep:
                lu = spla.splu(A)
                x = lu.solve(b)
                kept = KeptFactors(lu.solve, A, "superlu")
            else:
                x = spla.spsolve(A, b)
        except (spla.MatrixRankWarning, RuntimeError) as exc:
            raise InversionError(f"singular tangent: {exc}") from None
    if not np.all(np.isfinite(x)):
        raise InversionError("the linear solve returned non-finite values")
    return np.atleast_1d(x), kept


class KeptFactors:
    """The factors of a matrix ``K0``, kept to apply ``K0^-1`` to later right-hand sides.

    ``solve(r)`` is ``K0^-1 r`` by the kept factors: SuperLU's ``splu`` object;
    PARDISO's phase 33 on the factors in its instance (``mtype`` 11), or for the
    symmetrized system (``mtype`` -2, :func:`symmetrize`) ``S0^-1 T0(r)``: the
    symmetrization is a linear change ``T0`` of the right-hand side (``transform``)
    with ``S0 = T0 K0``, so ``S0^-1 T0 = K0^-1``.  PARDISO refines an answer
    against ``K0`` (``S0``) after perturbed pivots, so ``solve`` need not be exactly
    linear (a flexible Krylov method takes that).  ``alive()`` is False once the
    PARDISO instance has factored another matrix or released its memory.
    ``matrix`` is ``K0`` as the caller handed it over (its pattern: :meth:`same_pattern`);
    ``kind`` one of ``superlu``, ``pardiso``, ``pardiso-symmetric``,
    ``pardiso-symmetric-single``: single-precision factors (:data:`SINGLE_ABOVE`),
    whose ``solve`` is ``K0^-1`` to about single precision only (unrefined: a
    preconditioner; the direct answer itself is refined in double).
    """

    def __init__(self, solve: Callable[[np.ndarray], np.ndarray], matrix: sp.spmatrix,
                 kind: str, handle: "_Pardiso | None" = None):
        self._solve, self.matrix, self.kind, self.handle = solve, matrix, kind, handle
        self.stamp = None if handle is None else handle.stamp

    def alive(self) -> bool:
        """Whether the factors are still there (PARDISO: not replaced since)."""
        return self.handle is None or self.handle.stamp == self.stamp

    def solve(self, r: np.ndarray) -> np.ndarray:
        """``K0^-1 r`` by the kept factors (RuntimeError once they are gone)."""
        if not self.alive():
            raise RuntimeError("the kept PARDISO factors were replaced")
        return self._solve(np.asarray(r, dtype=float))

    def same_pattern(self, K: sp.spmatrix) -> bool:
        """Whether ``K`` has ``K0``'s shape and sparsity pattern (csr or csc alike)."""
        A = self.matrix
        return (K.shape == A.shape and K.format == A.format in ("csr", "csc")
                and _same_arrays((A.indptr, A.indices), K))



def _pardiso(K: sp.spmatrix, b: np.ndarray, mult: np.ndarray | None = None,
             hint: Hint | None = None) -> tuple[np.ndarray | None, KeptFactors | None]:
    """PARDISO's answer, or None when it fails or its residual is too large,
    and the factors that gave it (:class:`KeptFactors`).
    With ``mult`` (the multiplier rows of a symmetrizable system) and
    :data:`SYMMETRIC` on, the symmetric indefinite factorization of the
    symmetrized system first (:func:`symmetrize`), else (or if that fails) the
    unsymmetric one."""
    A = K if sp.isspmatrix_csr(K) and K.dtype == float else sp.csr_matrix(K, dtype=float)
    if not A.has_sorted_indices:
        A = A.sorted_indices()  # (pypardiso would sort the caller's arrays in place)
    if mult is not None and SYMMETRIC:
        sym = symmetrize(A, b, mult, hint)
        if sym is not None:
            for single in [True, False] if sym.U.shape[0] >= SINGLE_ABOVE else [False]:
                h = pardiso_solver(-2, single)
                x = h.solve(sym.U, sym.b, check=lambda x: _good(A, x, b),
                            correction=lambda x: sym.transform(b - A @ x),
                            analysis=sym.analysis)
                if x is not None:
                    U, transform = sym.U, sym.transform
                    return x, KeptFactors(lambda r: h._run(U, transform(r), 33), A,
                                          "pardiso-symmetric" + "-single" * single, h)
                log.debug("symmetric pardiso (%s precision) gave no acceptable answer",
                          "single" if single else "double")
            log.debug("unsymmetric pardiso retries")
    h = pardiso_solver(11)
    x = h.solve(A, b)
    if x is None:
        log.debug("pardiso gave no acceptable answer; SuperLU retries")
        return None, None
    return x, KeptFactors(lambda r: h._run(A, r, 33), A, "pardiso", h)
