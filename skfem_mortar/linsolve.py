"""Sparse direct solve of the (possibly indefinite, saddle-point) Newton system."""
from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import InversionError

__all__ = ["solve_linear"]


def solve_linear(K: sp.spmatrix, b: np.ndarray) -> np.ndarray:
    """Solve ``K x = b`` with scipy's SuperLU.

    The block system ``[K  B^T; B  0]`` is indefinite, so a Cholesky solver is
    not an option; SuperLU with COLAMD ordering and partial pivoting handles it.

    Raises
    ------
    InversionError
        When the matrix is singular or the solution is not finite (the Newton
        solver treats this like a failed iteration and cuts the load step).
    """
    if K.shape[0] == 0:
        return np.zeros(0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", spla.MatrixRankWarning)
        try:
            x = spla.spsolve(sp.csc_matrix(K), b)
        except (spla.MatrixRankWarning, RuntimeError) as exc:
            raise InversionError(f"singular tangent: {exc}") from None
    if not np.all(np.isfinite(x)):
        raise InversionError("the linear solve returned non-finite values")
    return np.atleast_1d(x)
