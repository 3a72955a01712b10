"""Symmetry planes of 3D contact pairs, declared or read from the Dirichlet data.

Declared: ``ContactPair(..., symmetry=[(normal, offset), ...])``, each the plane
``normal . x = offset``.

Quarter and half models end at their symmetry planes, and so do their contact
surfaces: an edge of a master face on such a plane is no free border (the surface
continues in its mirror image), so a slave node on the plane, whose projection may
fall outside the face by round-off or by the deformation's drift along the plane, is
kept on that face's extension (:func:`~.nts_faces.project_faces`, ``mirrored``).

Read from the Dirichlet data (:func:`planes_from_fixed`): a coordinate plane
``x_k = c`` at the smallest or largest ``x_k`` of the slave surface's reference nodes
is a symmetry plane when at least two slave nodes lie on it (within :data:`PLANE_TOL`
times the surface's size), every one of them has its ``x_k`` dof held, and not every
slave node lies on it (a flat surface normal to ``e_k`` is no plane of symmetry).
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["PLANE_TOL", "check_planes", "planes_from_fixed", "on_planes"]

#: a node lies on a symmetry plane within this times the surface's size (round-off of
#: the coordinates a mesher computed, far below any element)
PLANE_TOL = 1e-9


def check_planes(symmetry: Any) -> list[tuple[np.ndarray, float]]:
    """The declared planes as ``(unit normal (3,), offset)`` (ValueError naming
    ``symmetry`` and the form it takes)."""
    if symmetry is None:
        return []
    out = []
    try:
        items = list(symmetry)
    except TypeError:
        items = None
    for item in items if items is not None else [None]:
        try:
            n, c = item
            n = np.asarray(n, dtype=float).ravel()
            c = float(c)
        except (TypeError, ValueError):
            n, c = None, np.nan
        if n is None or n.shape != (3,) or not np.all(np.isfinite(n)) or not np.isfinite(c) \
                or np.linalg.norm(n) == 0:
            raise ValueError(f"symmetry must be a list of planes (normal, offset): three "
                             f"finite numbers, not all zero, and a finite number (the plane "
                             f"normal . x = offset), got {symmetry!r}")
        s = np.linalg.norm(n)
        out.append((n / s, c / s))
    return out


def on_planes(X: np.ndarray, planes: list, size: float) -> np.ndarray | None:
    """Bool (n,): the points ``X (3, n)`` within ``PLANE_TOL * size`` of a plane (None
    without planes)."""
    if not planes:
        return None
    d = np.min(np.abs(np.stack([n @ X - c for n, c in planes])), axis=0)
    return d <= PLANE_TOL * size


def planes_from_fixed(X: np.ndarray, dofs: np.ndarray, fixed: np.ndarray
                      ) -> list[tuple[np.ndarray, float]]:
    """The symmetry planes the Dirichlet data show on the slave surface (module
    docstring): ``X (3, n)`` its reference nodes, ``dofs (3, n)`` their global dofs,
    ``fixed`` the prescribed global dofs."""
    size = float(np.ptp(X, axis=1).max()) if X.size else 0.0
    held = np.isin(dofs, np.asarray(fixed))
    planes = []
    for k in range(3):
        for c in (X[k].min(), X[k].max()):
            on = np.abs(X[k] - c) <= PLANE_TOL * size
            if 2 <= on.sum() < on.size and held[k, on].all():
                planes.append((np.eye(3)[k], float(c)))
    return planes
