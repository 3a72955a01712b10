"""The PARDISO instance: one per process and matrix type, its kept analysis and factors.

Intel MKL PARDISO through ``pypardiso`` (the optional extra ``fast``): the
symbolic analysis is kept while the sparsity pattern repeats, a poor answer of
a kept analysis is refined before a new one, and a symmetric instance may factor
in single precision (iparm(28) = 1) and refine in double (:class:`_Pardiso`).
Which systems go to which instance, and what happens when it fails, is
:mod:`skfem_mortar.solver.linsolve`'s (module docstring).
"""
from __future__ import annotations

import ctypes
import logging
import os
import sys

import numpy as np
import scipy.sparse as sp

__all__ = ["pardiso_solver", "forget_analyses", "PARDISO_RTOL"]

log = logging.getLogger(__name__)

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
#: refinement steps of a single-precision factorization at most (each one solve
#: with the factors and a product with the matrix, ~10 % of a factorization),
#: while each step at least halves the residual: measured at hertz ``refine=4``
#: (6.5e5 unknowns) the first solve of a step needs 5 (1.9e-3 down by ~15 a
#: step); a stall means perturbed pivots of a reused matching, and a new
#: analysis follows
REFINE_STEPS_SINGLE = 10

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


def _good(A: sp.spmatrix, x: np.ndarray, b: np.ndarray) -> bool:
    if not np.all(np.isfinite(x)):
        return False
    bn = float(np.linalg.norm(b))
    return float(np.linalg.norm(A @ x - b)) <= PARDISO_RTOL * max(bn, np.finfo(float).tiny)

