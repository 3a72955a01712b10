"""Shared pieces of the axisymmetric contact scenes (``hertz_axi``, ``oring``, ``seed_axi``).

The readings of a contact pair's nodal pressures that these scenes report
(:func:`profile`, :func:`fit_ellipse`, :func:`compression_span`,
:func:`revolved_trapezoid`), the rigid plate normal to the axis
(:func:`rigid_plate`) and the support reactions summed per component
(:func:`reaction`).
"""
from __future__ import annotations

import math

import numpy as np

from ..contact.surfaces import ContactSurface

__all__ = ["profile", "fit_ellipse", "compression_span", "revolved_trapezoid", "rigid_plate",
           "reaction", "reference_pressure"]


def profile(pair, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The slave nodes' current first coordinate (``r`` in an axisymmetric model, ``x``
    in a plane one) and nodal pressure, sorted by that coordinate."""
    d = pair.contact_data(z)
    r = np.asarray(d["r"] if "r" in d else d["x"], dtype=float)
    p = np.asarray(d["pressure"], dtype=float)
    order = np.argsort(r)
    return r[order], p[order]


def fit_ellipse(r: np.ndarray, p: np.ndarray, window: float) -> tuple[float, float]:
    """The least-squares fit of ``p^2 = p0^2 (1 - r^2 / a^2)`` over the nodes in
    compression with ``r < window``: ``p^2 = c0 + c1 r^2`` fitted linearly,
    ``p0 = sqrt(c0)``, ``a = sqrt(-c0 / c1)``.  ``(nan, nan)`` with fewer than two
    such nodes or a fit that does not fall with ``r``."""
    use = (r < window) & (p > 0.0)          # (False at NaN)
    if use.sum() < 2:
        return math.nan, math.nan
    A = np.column_stack([np.ones(use.sum()), r[use] ** 2])
    (c0, c1), *_ = np.linalg.lstsq(A, p[use] ** 2, rcond=None)
    if not (c0 > 0.0 and c1 < 0.0):
        return math.nan, math.nan
    return float(math.sqrt(c0)), float(math.sqrt(-c0 / c1))


def compression_span(r: np.ndarray, p: np.ndarray) -> tuple[float, float]:
    """The contact zone's ends read from the nodes (sorted by ``r``): midway between the
    first (last) node in compression and the node before (after) it, or that node
    itself at the end of the surface; ``(0, 0)`` when no node is in compression
    (``p`` above ``1e-8`` of its largest value: an inactive multiplier is zero up to
    round-off)."""
    top = float(p.max(initial=0.0))
    comp = np.flatnonzero(p > 1e-8 * top) if top > 0.0 else np.zeros(0, dtype=int)
    if comp.size == 0:
        return 0.0, 0.0
    i, k = int(comp.min()), int(comp.max())
    return float(0.5 * (r[i] + r[max(i - 1, 0)])), float(0.5 * (r[k] + r[min(k + 1, len(r) - 1)]))


def revolved_trapezoid(r: np.ndarray, p: np.ndarray) -> float:
    """``2 pi int p r dr`` by the trapezoidal rule over the nodes (a reading only: the
    contact resultant is the sum of the multipliers' nodal forces)."""
    return float(2.0 * math.pi * np.trapezoid(p * r, r))


def reference_pressure(pair, z: np.ndarray) -> np.ndarray:
    """The nodal pressure per unit *reference* area, ``p_A a_A(x) / a_A(X)`` in the
    surface's node order: the pair's own tributary area at the current state over the
    same at the reference state (``z = 0``), as linear theory reads a pressure; NaN
    at a node without a reference area (no master segment facing it there)."""
    p, _, ev = pair.pressure_and_gap(z)
    ev0 = pair.evaluate(np.zeros_like(np.asarray(z, dtype=float)), tangent=False,
                        with_lam=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ev0.area > 0.0, p * ev.area / ev0.area, np.nan)


def rigid_plate(level: float, r_min: float, r_max: float, h: float, up: bool = True,
                name: str = "plate") -> ContactSurface:
    """The rigid plate ``z = level`` normal to the axis on ``r_min <= r <= r_max``, a chain
    of segments about ``h`` long (the slave's element size: mortar projects each
    master node onto nearby slave elements), its outward normal ``+z`` (``up``, a body
    resting on it) or ``-z`` (a body below it)."""
    n = max(2, int(math.ceil((r_max - r_min) / h)))
    r = np.linspace(r_max, r_min, n + 1)
    if not up:
        r = r[::-1]
    X = np.vstack([r, np.full(n + 1, float(level))])
    seg = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    return ContactSurface(None, None, seg, X=X, name=name)


def reaction(body, residual: np.ndarray, local_dofs: np.ndarray) -> np.ndarray:
    """The support reaction ``(R_r, R_z)`` of the prescribed ``local_dofs`` of
    ``body``: the residual summed over them, split by component (the internal forces of
    a body balance, so the residual at a support is the force it exerts)."""
    local = np.asarray(local_dofs, dtype=np.int64)
    is_r = np.isin(local, np.asarray(body.node_dofs)[0])
    if hasattr(body, "dofs_on"):
        is_r = np.isin(local, body.dofs_on(np.arange(body.mesh.facets.shape[1]), "x"))
    g = body.offset + local
    return np.array([residual[g[is_r]].sum(), residual[g[~is_r]].sum()])
