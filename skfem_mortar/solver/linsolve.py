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
    back to SuperLU, which also gives the clean "singular" diagnosis.

The environment variable ``SKFEM_MORTAR_SOLVER`` (``superlu`` or ``pardiso``)
overrides the automatic choice, and :func:`solve_linear` takes ``backend``.
"""
from __future__ import annotations

import ctypes
import logging
import os
import sys
import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..core.errors import InversionError

__all__ = ["solve_linear", "available_backends", "default_backend", "BACKENDS"]

log = logging.getLogger(__name__)

BACKENDS = ("superlu", "pardiso")
#: relative residual above which a PARDISO answer is not trusted (SuperLU retries)
PARDISO_RTOL = 1e-8
#: below this many unknowns PARDISO runs on one thread: MKL's thread start-up and
#: spin-waiting cost more than they save there (measured on 2 busy cores: 400
#: unknowns 26 ms on 2 threads, 6 ms on one; 2000 unknowns 250 ms against 12 ms)
PARDISO_SERIAL_BELOW = 20000

_pardiso_solver = None  # the process's _Pardiso


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


def solve_linear(K: sp.spmatrix, b: np.ndarray, backend: str | None = None) -> np.ndarray:
    """Solve ``K x = b`` with a sparse direct solver.

    Parameters
    ----------
    K : sparse matrix (n, n)
    b : ndarray (n,)
    backend : {"superlu", "pardiso"}, optional
        Default :func:`default_backend`.  ``pardiso`` without ``pypardiso``
        installed raises ImportError.

    Raises
    ------
    InversionError
        When the matrix is singular or the solution is not finite (the Newton
        solver treats this like a failed iteration and cuts the load step).
    """
    if K.shape[0] == 0:
        return np.zeros(0)
    backend = backend or default_backend()
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    b = np.asarray(b, dtype=float)
    if backend == "pardiso":
        x = _pardiso(K, b)
        if x is not None:
            return x
    return _superlu(K, b)


def _superlu(K: sp.spmatrix, b: np.ndarray) -> np.ndarray:
    with warnings.catch_warnings():
        warnings.simplefilter("error", spla.MatrixRankWarning)
        try:
            x = spla.spsolve(sp.csc_matrix(K), b)
        except (spla.MatrixRankWarning, RuntimeError) as exc:
            raise InversionError(f"singular tangent: {exc}") from None
    if not np.all(np.isfinite(x)):
        raise InversionError("the linear solve returned non-finite values")
    return np.atleast_1d(x)


class _Pardiso:
    """One PARDISO instance per process (its construction looks up MKL, ~1 s).

    Newton iterations often repeat the sparsity pattern (same active set and
    mortar segments): then the symbolic analysis (ordering, ~40 % of a solve)
    of the previous call is reused (phases 22 + 33 instead of 13).  Should the
    reused analysis give a poor answer (its weighted matching was computed for
    the earlier values), a fresh full solve follows.
    """

    def __init__(self):
        _point_to_mkl()
        import pypardiso

        self.solver = pypardiso.PyPardisoSolver()
        self.pattern: tuple[np.ndarray, np.ndarray] | None = None

    def release(self) -> None:
        self.solver.free_memory(everything=True)
        self.pattern = None

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
            return np.asarray(s._call_pardiso(A, s._check_b(A, b)), dtype=float).ravel()
        finally:
            if previous is not None:
                self.solver.libmkl.MKL_Set_Num_Threads_Local(previous)

    def solve(self, A: sp.csr_matrix, b: np.ndarray) -> np.ndarray | None:
        same = (self.pattern is not None and np.array_equal(self.pattern[0], A.indptr)
                and np.array_equal(self.pattern[1], A.indices))
        phases = ([23] if same else []) + [13]
        for phase in phases:
            if phase == 13 and self.pattern is not None:
                self.release()
            try:
                x = self._run(A, b, phase)
            except Exception as exc:  # empty rows (ValueError), PyPardisoError
                log.debug("pardiso phase %d failed (%s)", phase, exc)
                self.release()
                continue
            if phase == 13:
                self.pattern = (A.indptr.copy(), A.indices.copy())
            if _good(A, x, b):
                return x
            log.debug("pardiso phase %d: residual too large", phase)
        self.release()
        return None


def _good(A: sp.spmatrix, x: np.ndarray, b: np.ndarray) -> bool:
    if not np.all(np.isfinite(x)):
        return False
    bn = float(np.linalg.norm(b))
    return float(np.linalg.norm(A @ x - b)) <= PARDISO_RTOL * max(bn, np.finfo(float).tiny)


def _pardiso(K: sp.spmatrix, b: np.ndarray) -> np.ndarray | None:
    """PARDISO's answer, or None when it fails or its residual is too large."""
    global _pardiso_solver
    if _pardiso_solver is None:
        _pardiso_solver = _Pardiso()
    A = sp.csr_matrix(K, dtype=float)
    if not A.has_sorted_indices:
        A = A.sorted_indices()  # (pypardiso would sort the caller's arrays in place)
    x = _pardiso_solver.solve(A, b)
    if x is None:
        log.debug("pardiso gave no acceptable answer; SuperLU retries")
    return x
