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

import logging
import os
import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import InversionError

__all__ = ["solve_linear", "available_backends", "default_backend", "BACKENDS"]

log = logging.getLogger(__name__)

BACKENDS = ("superlu", "pardiso")
#: relative residual above which a PARDISO answer is not trusted (SuperLU retries)
PARDISO_RTOL = 1e-8

_pardiso_solver = None  # one instance per process: its construction looks up MKL (~1 s)


def _pardiso_available() -> bool:
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


def _pardiso(K: sp.spmatrix, b: np.ndarray) -> np.ndarray | None:
    """PARDISO's answer, or None when it fails or its residual is too large."""
    global _pardiso_solver
    import pypardiso

    if _pardiso_solver is None:
        _pardiso_solver = pypardiso.PyPardisoSolver()
    A = sp.csr_matrix(K, dtype=float)
    if not A.has_sorted_indices:
        A = A.sorted_indices()  # (pypardiso would sort the caller's arrays in place)
    s = _pardiso_solver
    try:
        x = np.asarray(s.solve(A, b), dtype=float).ravel()
    except Exception as exc:  # empty rows (ValueError), PyPardisoError
        log.debug("pardiso failed (%s); SuperLU retries", exc)
        return None
    finally:
        s.free_memory(everything=True)
    if not np.all(np.isfinite(x)):
        return None
    bn = float(np.linalg.norm(b))
    res = float(np.linalg.norm(A @ x - b))
    if res > PARDISO_RTOL * max(bn, np.finfo(float).tiny):
        log.debug("pardiso residual %.2e relative; SuperLU retries", res / max(bn, 1e-300))
        return None
    return x
