"""The normal rows of a contact pair: ``-G^T lam`` in the body rows and the
semi-smooth complementarity rows of the normal multipliers.

The pair adds to the potential energy ``-lam . g(x)`` (``g`` the gaps of the
slave nodes in the pair's multiplier space, ``lam >= 0`` compression), so

    R_u   += -G^T lam               (G = dg/dx)
    K_uu  += -H                     (H = sum_A lam_A d^2 g_A/dx^2)
    K_ulam = -G^T

and the multiplier rows are ``s C(lam, g)``, ``C = c g`` (active) / ``lam``
(inactive), ``s`` the space's row scale:

    K_lamu = c s G   (active rows),   K_lamlam = s I   (inactive rows).

Over the method's reserved pattern
(:class:`~skfem_mortar.contact.reservation.Reservation`) the triplets carry
explicit zeros; without one they follow ``G`` and ``H`` as they come.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..core.item import Contribution
from .reservation import with_triplets

__all__ = ["assemble_normal"]


def assemble_normal(pair: Any, z: np.ndarray, load_factor: float,
                    tangent: bool = True) -> Contribution:
    """The normal rows of ``pair`` at ``z`` (module doc); with ``tangent`` a
    Newton iteration (the active set and the method's state are updated)."""
    lam = np.asarray(z)[pair._normal]
    ev = pair.evaluate(z, tangent=True, with_lam=tangent)
    c = pair._c(z, load_factor, ev)
    active = pair._active_set(lam, ev, c, track=tangent)
    if tangent:  # e.g. NTS: segment hysteresis between iterations, vertex trap
        pair.discretization.after_iteration(ev)
    gd = pair.global_dofs()
    # body rows: -G^T lam
    G = ev.G.tocoo()
    keep = gd[G.col] >= 0
    rows_u, cols_l, vals = gd[G.col[keep]], pair.offset + G.row[keep], G.data[keep]
    # multiplier rows: C(lam, g)
    rs = pair._row_scale
    Cval = np.where(active, c * ev.g, lam) * rs
    out = Contribution(np.concatenate([rows_u, pair.offset + np.arange(pair.n_dofs)]),
                       np.concatenate([-vals * lam[G.row[keep]], Cval]))
    if not tangent:
        return out
    res = pair._reservation(z, gd)
    if res is not None:  # the triplets over the reserved pattern (explicit zeros)
        kv = res.values(ev.G, ev.H, active, c, rs)
        if kv is None:
            res = pair._widen(ev)
            kv = res.values(ev.G, ev.H, active, c, rs)
        out.k_rows, out.k_cols, out.k_vals = res.rows, res.cols, kv
        out.reserved = True
        return out
    kr, kc, kv = [rows_u], [cols_l], [-vals]  # K_ulam = -G^T
    act_g = active[G.row[keep]]  # K_lamu = c G on active rows
    kr.append(cols_l[act_g])
    kc.append(rows_u[act_g])
    kv.append(c * rs * vals[act_g])
    inact = np.flatnonzero(~active)  # K_lamlam = I on inactive rows
    kr.append(pair.offset + inact)
    kc.append(pair.offset + inact)
    kv.append(np.full(inact.size, rs))
    return with_triplets(out, kr, kc, kv, gd, (ev.H,))  # K_uu = -H
