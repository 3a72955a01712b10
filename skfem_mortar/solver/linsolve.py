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

import ctypes
import logging
import os
import sys
import warnings
from typing import Callable, NamedTuple

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..core.errors import InversionError

__all__ = ["solve_linear", "factorize", "KeptFactors", "available_backends",
           "default_backend", "BACKENDS", "pardiso_solver", "forget_analyses", "symmetrize",
           "SymmetricSystem", "SYMMETRIC"]

log = logging.getLogger(__name__)

BACKENDS = ("superlu", "pardiso")
#: relative residual above which a PARDISO answer is not trusted (SuperLU retries)
PARDISO_RTOL = 1e-8
#: below this many unknowns PARDISO runs on one thread: MKL's thread start-up and
#: spin-waiting cost more than they save there (measured on 2 busy cores: 400
#: unknowns 26 ms on 2 threads, 6 ms on one; 2000 unknowns 250 ms against 12 ms)
PARDISO_SERIAL_BELOW = 20000
#: iterative refinement steps on a poor answer of a reused analysis before a new
#: analysis (its matching, computed for earlier values, may pivot poorly after
#: an active-set change; each step is one solve with the factors, ~5 % of a
#: factorization)
REFINE_STEPS = 3
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
#: refinement steps of a single-precision factorization at most (each one solve
#: with the factors and a product with the matrix, ~10 % of a factorization),
#: while each step at least halves the residual: measured at hertz ``refine=4``
#: (6.5e5 unknowns) the first solve of a step needs 5 (1.9e-3 down by ~15 a
#: step); a stall means perturbed pivots of a reused matching, and a new
#: analysis follows
REFINE_STEPS_SINGLE = 10

#: what multiplier rows would couple to once active: ``hint() -> (rows, cols, vals)``
Hint = Callable[[], "tuple[np.ndarray, np.ndarray, np.ndarray] | None"]

_pardiso_solvers: dict = {}  # the process's, by matrix type (and "single" for -2)


def _point_to_mkl() -> None:
    """Tell pypardiso where MKL's runtime library is, when it lies in ``sys.prefix/lib``
    (pip's place): otherwise its import and every solver it builds search the whole
    prefix tree for it (about 1 s each)."""
    if os.environ.get("PYPARDISO_MKL_RT"):
        return
    import glob

    for prefix in (sys.prefix, sys.base_prefix):
        found = sorted(glob.glob(os.path.join(prefix, "lib", "libmkl_rt.so*")), key=len)
        if found:
            os.environ["PYPARDISO_MKL_RT"] = found[0]
            return


def _pardiso_available() -> bool:
    if "pypardiso" not in sys.modules:
        _point_to_mkl()
    try:
        import pypardiso  # noqa: F401
    except Exception:  # ImportError, or MKL missing at import time
        return False
    return True


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


def _same_arrays(pattern: tuple[np.ndarray, np.ndarray], A: sp.spmatrix) -> bool:
    """Whether ``A``'s ``indptr`` and ``indices`` are those of ``pattern`` (the same
    memory, or equal)."""
    ip, ix = pattern
    return ((A.indptr is ip or np.array_equal(ip, A.indptr))
            and (A.indices is ix or np.array_equal(ix, A.indices)))


class _Pardiso:
    """One PARDISO instance per process and matrix type (its construction looks up MKL).

    The symbolic analysis (ordering and symbolic factorization, phase 11;
    about 40 % of a solve) is kept while the sparsity pattern repeats
    (the model's fixed pattern and a contact pair's reservation: equal
    ``indptr`` and ``indices``): a repeated pattern
    costs phases 22 + 33 only (a new one: 11, then 22 + 33).  Should the reused analysis give a poor answer
    (its weighted matching was computed for the earlier values), a fresh full
    solve follows.  ``analyses``, ``factorizations`` and ``solves`` count the
    phases run.

    ``mtype`` 11 (real unsymmetric, the default) or -2 (real symmetric
    indefinite: the caller passes the upper triangle; Bunch-Kaufman pivoting
    with weighted matching and scaling, iparm(11) = iparm(13) = 1, so the
    zero diagonal of the active multiplier rows is paired off before the
    ordering; pivots that are still too small are perturbed (iparm(14) counts
    them) and answered with iterative refinement).  Measured on hertz
    (elastic base, ``refine=2``, 1.75e5 unknowns, one core of a loaded
    machine): without the matching the factorization is 25 % faster but
    perturbs 25 pivots and answers to a relative residual of 4e-6 (refinement
    needed); with it no perturbation and 4e-12.  PARDISO refines its answer
    (2 steps) only when it perturbed pivots (``iparm(8) = 0``): a maximum of
    2 steps (``iparm(8) = 2``) made it refine every answer, measured at
    ``refine=3`` (1.7e5 unknowns) 0.085 s of the 0.145 s of a solve with the
    factors, for a residual of 9e-17 instead of 1.2e-16 (the answer is checked
    and refined by :meth:`solve` anyway).
    """

    def __init__(self, mtype: int = 11, single: bool = False):
        _point_to_mkl()
        import pypardiso

        self.mtype, self.single = mtype, single
        self.solver = pypardiso.PyPardisoSolver(mtype=mtype)
        if mtype == -2:
            iparm = {1: 1,    # our own settings below (zeros elsewhere: MKL's defaults)
                     2: 2,    # nested dissection (METIS)
                     8: 0,    # iterative refinement (2 steps) only after perturbed pivots
                     10: 8,   # perturb pivots below 1e-8 of the norm
                     11: 1,   # symmetric scaling ...
                     13: 1,   # ... with weighted matching (2 x 2 pivots for the zero diagonal)
                     18: -1,  # report the factor's nonzeros in iparm(18)
                     21: 1}   # Bunch-Kaufman pivoting
            for i, v in iparm.items():
                self.solver.set_iparm(i, v)
        if single:
            self.solver.set_iparm(28, 1)  # single precision: float32 values, rhs, answers
        self.pattern: tuple[np.ndarray, np.ndarray] | None = None
        self.analyses = self.factorizations = self.solves = 0
        #: changes with every analysis, factorization and release: the factors
        #: held are those of the same stamp (:class:`KeptFactors`)
        self.stamp = 0
        #: perturbed pivots of the last factorization (iparm(14))
        self.perturbed = 0

    def release(self) -> None:
        self.solver.free_memory(everything=True)
        self.pattern = None
        self.stamp += 1

    def _threads(self, n: int) -> int | None:
        """Limit MKL to one thread (for this thread of Python) on small systems;
        returns the previous local setting to restore, None if untouched."""
        if n >= PARDISO_SERIAL_BELOW:
            return None
        try:
            f = self.solver.libmkl.MKL_Set_Num_Threads_Local
        except AttributeError:
            return None
        f.restype, f.argtypes = ctypes.c_int, [ctypes.c_int]
        return int(f(1))

    def _run(self, A: sp.csr_matrix, b: np.ndarray, phase: int) -> np.ndarray:
        s = self.solver
        s._check_A(A)
        s.set_phase(phase)
        previous = self._threads(A.shape[0])
        try:
            b = s._check_b(A, b)
            x = np.asarray(self._call_single(A, b) if self.single else s._call_pardiso(A, b),
                           dtype=float).ravel()
        finally:
            if previous is not None:
                self.solver.libmkl.MKL_Set_Num_Threads_Local(previous)
        self.stamp += phase != 33
        self.analyses += phase == 11
        self.factorizations += phase == 23
        self.solves += phase != 11
        self.perturbed = int(s.get_iparm(14))
        return x

    def _call_single(self, A: sp.csr_matrix, b: np.ndarray) -> np.ndarray:
        """pypardiso's ``_call_pardiso`` with float32 values, right-hand side and
        answer (iparm(28) = 1; pypardiso hands PARDISO float64 arrays only)."""
        s = self.solver
        a32 = np.ascontiguousarray(A.data, dtype=np.float32)
        b32 = np.asfortranarray(b, dtype=np.float32)
        x32 = np.zeros_like(b32)
        err = ctypes.c_int32(0)
        ip, dp = ctypes.POINTER(ctypes.c_int32), ctypes.POINTER(ctypes.c_double)
        ia = A.indptr.astype(np.int32) + 1   # 1-based, as pypardiso passes them
        ja = A.indices.astype(np.int32) + 1
        one = ctypes.c_int32(1)
        s._mkl_pardiso(s.pt.ctypes.data_as(ctypes.POINTER(s._pt_type[0])), ctypes.byref(one),
                       ctypes.byref(one), ctypes.byref(ctypes.c_int32(s.mtype)),
                       ctypes.byref(ctypes.c_int32(s.phase)),
                       ctypes.byref(ctypes.c_int32(A.shape[0])), ctypes.cast(a32.ctypes.data, dp),
                       ia.ctypes.data_as(ip), ja.ctypes.data_as(ip), s.perm.ctypes.data_as(ip),
                       ctypes.byref(ctypes.c_int32(1 if b.ndim == 1 else b.shape[1])),
                       s.iparm.ctypes.data_as(ip), ctypes.byref(ctypes.c_int32(s.msglvl)),
                       ctypes.cast(b32.ctypes.data, dp), ctypes.cast(x32.ctypes.data, dp),
                       ctypes.byref(err))
        if err.value != 0:
            from pypardiso.pardiso_wrapper import PyPardisoError
            raise PyPardisoError(err.value)
        return np.ascontiguousarray(x32, dtype=float)

    def same_pattern(self, A: sp.csr_matrix) -> bool:
        """Whether ``A`` has the pattern of the kept analysis."""
        return self.pattern is not None and _same_arrays(self.pattern, A)

    def solve(self, A: sp.csr_matrix, b: np.ndarray, check=None, correction=None,
              analysis=None) -> np.ndarray | None:
        """The answer of ``A x = b``, or None; ``check(x)`` (default: the relative
        residual of ``A``) decides whether it is good.  A poor answer of a
        reused analysis is first refined (at most :data:`REFINE_STEPS` times
        ``x += A^-1 correction(x)``, phase 33, ``correction(x)`` by default
        ``b - A x``), then a fresh analysis follows.  ``analysis()``, if
        given, is the matrix (of ``A``'s pattern) a new analysis is run on
        (:attr:`SymmetricSystem.analysis`), else ``A``; a poor answer of a
        fresh analysis of it is refined too, then ``A`` itself is analysed."""
        good = check or (lambda x: _good(A, x, b))
        correction = correction or (lambda x: b - A @ x)
        tries = [analysis] if analysis is not None else []
        for reuse, proxy in ([(True, None)] if self.same_pattern(A) else []) + [
                (False, p) for p in tries + [None]]:
            try:
                if not reuse:
                    if self.pattern is not None:
                        self.release()
                    self._run(A if proxy is None else proxy(), b, 11)  # (timed apart)
                    # read-only index arrays (the model's cached pattern) are kept as they are
                    self.pattern = tuple(a if not a.flags.writeable else a.copy()
                                         for a in (A.indptr, A.indices))
                x = self._run(A, b, 23)
            except Exception as exc:  # empty rows (ValueError), PyPardisoError
                log.debug("pardiso failed (%s)", exc)
                self.release()
                continue
            if good(x):
                return x
            steps = REFINE_STEPS if reuse or proxy is not None else 0
            last = np.inf
            for _ in range(REFINE_STEPS_SINGLE if self.single else steps):
                r = correction(x)
                if self.single:
                    size = float(np.linalg.norm(r))
                    if not size < 0.5 * last:
                        break  # stalls: a fresh analysis follows
                    last = size
                try:
                    x = x + self._run(A, r, 33)
                except Exception:  # noqa: BLE001 (PyPardisoError): a fresh analysis follows
                    break
                if good(x):
                    return x
            log.debug("pardiso (%s analysis): residual too large", "kept" if reuse else "new")
        self.release()
        return None


def forget_analyses() -> None:
    """Drop the symbolic analyses the PARDISO instances keep: the next solve
    analyses afresh.  :func:`~skfem_mortar.solver.stepping.solve` calls it at the
    start of every attempt of a load step, so that a step's solves depend on that
    step alone (the analysis, and the weighted matching computed with it, come
    from the step's first matrix): a resumed run then repeats them to the last
    bit, and a run does not depend on what the process solved before it.  Costs
    one analysis per step (none more for a one-step run)."""
    for s in _pardiso_solvers.values():
        s.pattern = None


def pardiso_solver(mtype: int = 11, single: bool = False) -> _Pardiso:
    """The process's PARDISO instance of matrix type ``mtype`` (11 or -2; with
    ``single`` the single-precision one, key ``(mtype, "single")``), with its
    counters ``analyses``, ``factorizations``, ``solves`` (ImportError without pypardiso)."""
    key = (mtype, "single") if single else mtype
    if key not in _pardiso_solvers:
        _pardiso_solvers[key] = _Pardiso(mtype, single)
    return _pardiso_solvers[key]


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


def _good(A: sp.spmatrix, x: np.ndarray, b: np.ndarray) -> bool:
    if not np.all(np.isfinite(x)):
        return False
    bn = float(np.linalg.norm(b))
    return float(np.linalg.norm(A @ x - b)) <= PARDISO_RTOL * max(bn, np.finfo(float).tiny)


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
