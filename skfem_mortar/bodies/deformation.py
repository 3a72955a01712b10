"""The checked deformation gradient: ``F`` of shape ``(2, 2, ...)``, finite, and
``det F > 0`` (:class:`~skfem_mortar.core.errors.InversionError` otherwise)."""
from __future__ import annotations

import numpy as np
from skfem.helpers import det

from ..core.errors import InversionError

__all__ = ["checked_det"]


def _finite(F: np.ndarray) -> np.ndarray:
    """``F`` as floats of shape ``(d, d, ...)``, ``d`` 2 or 3; InversionError if not finite."""
    F = np.asarray(F, dtype=float)
    if F.shape[:2] not in ((2, 2), (3, 3)):
        raise ValueError(f"F must have shape (2, 2, ...) or (3, 3, ...), got {F.shape}")
    if not np.all(np.isfinite(F)):
        raise InversionError("non-finite deformation gradient")
    return F


def _eye(F: np.ndarray) -> np.ndarray:
    """The ``d x d`` identity (``d = F.shape[0]``) broadcast against the trailing axes of ``F``."""
    return np.eye(F.shape[0])[(...,) + (np.newaxis,) * (F.ndim - 2)]


def checked_det(F: np.ndarray) -> np.ndarray:
    """``J = det F``; raise :class:`InversionError` if any ``J <= 0`` or non-finite."""
    F = np.asarray(F, dtype=float)
    if F.shape[:2] not in ((2, 2), (3, 3)):
        raise ValueError(f"F must have shape (2, 2, ...) or (3, 3, ...), got {F.shape}")
    J = det(F)   # skfem.helpers: the same products as our own 2 x 2 formula, bit for bit
    if not np.all(np.isfinite(J)):
        raise InversionError("non-finite deformation gradient")
    if np.any(J <= 0.0):
        n = int(np.count_nonzero(J <= 0.0))
        raise InversionError(f"inverted material point(s): det F <= 0 at {n} point(s), "
                             f"min det F = {J.min():.3e}")
    return J
