"""The KKT conditions of a converged contact state, normal and tangential.

:meth:`~skfem_mortar.contact.pair.ContactPair.violation` asks a state whose
residual passed whether the contact conditions hold, to tolerances
``tol_g = K_GAP h`` (``h`` the median slave segment length) and
``tol_p = K_LAM * scale / L_c`` (``L_c`` the tributary length of the active
nodes, at least ``h``; in an axisymmetric model their tributary area
``2 pi int N_A r dGamma``, at least the smallest node's, :func:`_floor`).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .curves import tributary_weights
from .friction import OPEN, SLIP, STICK
from .segmentation import surface_cell

__all__ = ["K_GAP", "K_LAM", "violation", "friction_violation"]

#: KKT tolerances of a converged state: gaps to ``K_GAP`` times the median slave
#: segment length, pressures to ``K_LAM`` times the step's pressure scale (force
#: scale / contact length).  Newton meets the gap rows to ``rtol`` (1e-10) of the
#: force scale and the pressures to about ``rtol * S / h``, so 1e-6 leaves four
#: decades above what a converged state carries, and is far below any penetration
#: or tension that matters (the discretization error of a gap is O(h^2 / R), 1e-4 h
#: at h = R / 100).
K_GAP = 1e-6
K_LAM = 1e-6


def violation(pair: Any, z: np.ndarray, scale: float) -> str:
    """The KKT conditions of ``pair`` at ``z`` ("" if they hold): every node facing
    a master has ``g >= -tol_g``; every node has ``p >= -tol_p``; ``|g| <= tol_g``
    wherever ``p > tol_p``; a node facing no master carries no pressure; and the
    tangential rows' conditions (:func:`friction_violation`).  Sets the pair's
    pressure tolerance ``_tol_p``."""
    p, g, ev = pair.pressure_and_gap(z)
    m = ev.mask
    g = np.where(m, g, 0.0)
    act = pair.active
    length = max(float(np.sum(np.where(act, ev.area, 0.0))), _floor(pair))
    tol_g, tol_p = K_GAP * pair._h, K_LAM * scale / length
    pair._tol_p = tol_p
    bad = {"penetration": m & (g < -tol_g), "tension": p < -tol_p,
           "pressure on an open gap": m & (p > tol_p) & (np.abs(g) > tol_g),
           "pressure without a master": ~m & (np.abs(p) > tol_p)}
    worst = {"penetration": -g, "tension": np.abs(p)}
    more, size = pair.rows.violation(z, tol_g, tol_p)
    bad.update(more)
    worst.update(size)
    msgs = []
    for what, nodes in bad.items():
        if nodes.any():
            k = np.flatnonzero(nodes)
            w = worst.get(what, np.abs(g) if "gap" in what else np.abs(p))[k].max()
            msgs.append(f"{what} at {k.size} node(s) (worst {w:.3g}, e.g. node {k[0]})")
    if not msgs:
        return ""
    return (f"{pair.name}: KKT violated ({'; '.join(msgs)}; tolerances: gap "
            f"{tol_g:.3g}, pressure {tol_p:.3g})")


def _floor(pair: Any) -> float:
    """The least contact measure ``L_c`` of :func:`violation`: the median slave
    segment length ``h`` (plane, per unit thickness); with a weighted measure
    (``2 pi r`` in an axisymmetric model, where ``L_c`` is an area) the smallest
    positive reference tributary weight, so that ``L_c`` is the sum of the active
    nodes' weights whenever one is active (one node on the axis weighs
    ``2 pi h^2 / 6``, a node at ``r`` about ``2 pi r h``: no length in between fits both)."""
    measure = getattr(pair, "measure", None)
    if measure is None or measure.unit:
        return pair._h
    s = pair.slave
    w = tributary_weights(s.X, s.segments, surface_cell(s), measure)
    return float(w[w > 0].min(initial=pair._h))


def friction_violation(d: dict, tol_g: float, tol_p: float) -> tuple[dict, dict]:
    """The friction conditions of a converged state (``d`` the tangential data:
    ``t_t``, ``u_t``, ``Xi``, statuses): ``|t_t| <= Xi (1 + K_LAM) + tol_p``
    everywhere; ``|u_t| <= tol_g`` on stick nodes; on slip nodes that slip
    (``|u_t| > tol_g``) ``t_t u_t <= 0`` and ``||t_t| - Xi| <= K_LAM Xi + tol_p``;
    ``|t_t| <= tol_p`` on open nodes.  Returns (the nodes failing each, their sizes)."""
    t, u, b, stt = d["tangential_traction"], d["slip"], d["bound"], d["status"]
    moving = (stt == SLIP) & (np.abs(u) > tol_g)
    bad = {"tangential traction above the slip bound":
           np.abs(t) > b * (1 + K_LAM) + tol_p,
           "slip of a stick node": (stt == STICK) & (np.abs(u) > tol_g),
           "slip along the tangential traction": moving & (t * u > 0),
           "sliding below the slip bound": moving & (np.abs(np.abs(t) - b)
                                                    > K_LAM * b + tol_p),
           "tangential traction on an open node": (stt == OPEN) & (np.abs(t) > tol_p)}
    size = {"tangential traction above the slip bound": np.abs(t) - b,
            "slip of a stick node": np.abs(u), "slip along the tangential traction": t * u,
            "sliding below the slip bound": np.abs(np.abs(t) - b),
            "tangential traction on an open node": np.abs(t)}
    return bad, size
