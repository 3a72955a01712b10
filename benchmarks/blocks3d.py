"""Two stacked 3D blocks in contact, built from ``patch3d``'s parts (issue 38's
measurements: ``phases3d.py``, ``contact_cost3d.py``, the memory and resume tests).

    from blocks3d import blocks_model, blocks_params
    model, pair, parts = blocks_model(blocks_params(n_lower=32, n_upper=30), "nts")

The model is :mod:`skfem_mortar.scenes._patch3d`'s (the lower block on rollers,
the upper block's footprint on its grid lines, both pressed by the same follower
pressure, rollers on the mid-planes) with the contact pair of the upper block's
bottom (slave) on the lower block's covered top (master), as the scene registers
it: the patch3d scene with ``n_lower``/``n_upper`` cells a side.  Used as a
block-on-block contact model of any size: ``3 (n + 1)^2 (n / 2 + 1)`` dofs a
block of ``n`` cells a side (``dofs_of``).
"""
from __future__ import annotations

from typing import Any

__all__ = ["blocks_params", "blocks_model", "dofs_of", "sizes_for", "upper_of"]


def blocks_params(**over: Any) -> dict:
    """patch3d's default parameters (hex1, finite strain, p = 0.05), overridden."""
    from skfem_mortar.scenes._patch3d import PARAMS
    values = {p.name: p.default for p in PARAMS}
    values.update(over)
    return values


def blocks_model(params: dict, method: str, load: str = "follower", **options: Any
                 ) -> tuple[Any, Any, Any]:
    """``(model, pair, parts)``: patch3d's bodies and the pair (``options`` to
    :class:`~skfem_mortar.contact.pair.ContactPair`, e.g. ``n_gauss``).

    ``load``: ``"follower"`` patch3d's Cauchy pressures (an unsymmetric tangent: the
    solver factors the LU), or ``"dead"`` the same pressures as reference tractions
    ``(0, 0, -p)`` (a symmetric tangent but for the contact rows: the symmetrized
    system, in single precision from ``SINGLE_ABOVE`` unknowns; not patch3d's exact
    state, the same size and pattern)."""
    from skfem_mortar.contact.pair import ContactPair
    from skfem_mortar.contact.surfaces import ContactSurface
    from skfem_mortar.core.model import Model
    from skfem_mortar.loads.pressure3d import FollowerPressure3D
    from skfem_mortar.loads.traction import Traction
    from skfem_mortar.scenes._patch3d import build_bodies
    if load not in ("follower", "dead"):
        raise ValueError(f"load must be 'follower' or 'dead', got {load!r}")
    parts = build_bodies(params)
    if load == "dead":
        q = float(params["pressure"])
        tags = {"pressure": "top", "uncovered_pressure": "uncovered"}   # build_bodies'
        parts.items[:] = [Traction(it.body, tags[it.name], (0.0, 0.0, -q), name=it.name)
                          if isinstance(it, FollowerPressure3D) else it for it in parts.items]
    slave = ContactSurface.from_solid(*parts.slave, name="slave_face")
    master = ContactSurface.from_solid(*parts.master, name="master_face")
    pair = ContactPair(slave, master, method, name="contact", **options)
    return Model(parts.items + [pair], geometry="3d"), pair, parts


def dofs_of(n_lower: int, n_upper: int, margin: int = 1) -> int:
    """Both blocks' displacement dofs (patch3d's estimate, exact on hex1 grids)."""
    from skfem_mortar.scenes._patch3d import estimate_dofs
    return estimate_dofs({"n_lower": n_lower, "n_upper": n_upper, "margin": margin})


def upper_of(n_lower: int) -> int:
    """The even ``n_upper`` nearest ``0.8 n_lower``: the upper grid's cells are
    ``(n_lower - 2) / (0.8 n_lower)`` of the lower's, so no grid line matches but
    the footprint's edges and mid-planes."""
    return max(2, 2 * int(round(0.4 * n_lower)))


def sizes_for(dofs: float) -> tuple[int, int]:
    """Even ``(n_lower, upper_of(n_lower))`` whose dofs are closest to ``dofs``."""
    best = min(range(4, 200, 2), key=lambda n: abs(dofs_of(n, upper_of(n)) - dofs))
    return best, upper_of(best)
