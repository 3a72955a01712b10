"""The checkpoint of a contact pair: its entries, their checks, their restore.

:meth:`~skfem_mortar.contact.pair.ContactPair.state_dict` holds what shapes the
next load step: the pair's own entries (:data:`PAIR_STATE`: the converged
active set, ``c``, the row scale, the converged positions, the pressure
tolerance), the discretization's and those of the tangential rows
(``friction_status``, ``friction_p_ref`` and the method's slip history; none
without friction).  Missing entries are ``[]`` (not set yet).  A load checks
every entry before it restores any (ValueError naming the entry).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .discretization import check_entries
from .friction import OPEN, SLIP, STATUS_NAMES, STICK

__all__ = ["PAIR_STATE", "state_dict", "load_state_dict", "tangential_state",
           "check_tangential_state", "load_tangential_state"]

#: the pair's own checkpoint entries (the discretization's are beside them)
PAIR_STATE = ("started", "active", "c", "row_scale", "x0_slave", "x0_master", "tol_p")


def _arr(a: Any, dtype: type = float) -> np.ndarray:
    return np.zeros(0, dtype=dtype) if a is None else np.asarray(a, dtype=dtype).copy()


def state_dict(pair: Any) -> dict[str, np.ndarray]:
    """The checkpoint entries of ``pair`` (module doc)."""
    x0 = pair.converged_positions
    return {"started": np.array(pair._started),
            "active": pair.state.converged.copy(),
            "c": _arr(None if pair.c is None else [pair.c]),
            "row_scale": _arr(None if pair._row_scale is None else [pair._row_scale]),
            "x0_slave": _arr(None if x0 is None else x0[0]),
            "x0_master": _arr(None if x0 is None else x0[1]),
            "tol_p": np.array(pair._tol_p),
            **pair.discretization.state_dict(), **pair.rows.state_dict()}


def load_state_dict(pair: Any, state: dict[str, np.ndarray]) -> None:
    """Restore :func:`state_dict` (ValueError naming the entry that does not fit;
    nothing is restored then)."""
    need = set(state_dict(pair))
    if set(state) != need:
        raise ValueError(f"{pair.name}: checkpoint state has entries {sorted(state)}, "
                         f"expected {sorted(need)}")
    ns, nm = pair.slave.n_nodes, pair.master.n_nodes
    d = pair.slave.X.shape[0]               # coordinates per node: 2, or 3 in 3D
    check_entries(pair.name, state, {
        "active": [(ns,)], "c": [(0,), (1,)], "row_scale": [(0,), (1,)],
        "x0_slave": [(0,), (d, ns)], "x0_master": [(0,), (d, nm)], "started": [()],
        "tol_p": [()]})
    for k in ("c", "row_scale"):
        if state[k].size and not state[k][0] > 0:
            raise ValueError(f"{pair.name}: checkpoint entry {k!r} must be > 0, "
                             f"got {state[k][0]}")
    if not float(state["tol_p"]) >= 0:
        raise ValueError(f"{pair.name}: checkpoint entry 'tol_p' must be >= 0")
    own = set(PAIR_STATE) | set(pair.rows.state_keys())
    checked = pair.rows.check_state(state)
    # the discretization checks its entries before it takes any
    pair.discretization.load_state_dict({k: state[k] for k in need - own})
    pair.rows.load_state(state, checked)
    pair._started = bool(state["started"])
    pair._tol_p = float(state["tol_p"])
    pair.state.converged = np.asarray(state["active"], dtype=bool).copy()
    pair.c = float(state["c"][0]) if state["c"].size else None
    pair._row_scale = float(state["row_scale"][0]) if state["row_scale"].size else None
    pair.converged_positions = ((np.array(state["x0_slave"], dtype=float),
                                 np.array(state["x0_master"], dtype=float))
                                if state["x0_slave"].size else None)


def tangential_state(rows: Any) -> dict[str, np.ndarray]:
    """The tangential rows' entries: the converged statuses, ``p_ref`` and the
    slip history (``[]`` entries before it is set)."""
    h = rows.slip_history
    keys = rows.pair.discretization.slip_history_keys
    return {"friction_status": rows.statuses.converged.copy(),
            "friction_p_ref": (np.zeros(0) if rows.p_ref is None else np.array([rows.p_ref])),
            **{k: (np.zeros(0) if h is None else np.asarray(h[k]).copy()) for k in keys}}


def check_tangential_state(rows: Any, state: dict[str, np.ndarray]) -> dict | None:
    """The tangential entries of a checkpoint checked (ValueError naming the
    entry); the slip history they hold (None if not set yet)."""
    pair = rows.pair
    ns = pair.slave.n_nodes
    check_entries(pair.name, state, {"friction_status": [(ns,)],
                                     "friction_p_ref": [(0,), (1,)]})
    st = np.asarray(state["friction_status"])
    if not np.all(np.isin(st, (OPEN, STICK, SLIP))):
        raise ValueError(f"{pair.name}: checkpoint entry 'friction_status' must hold the "
                         f"codes {OPEN}, {STICK}, {SLIP} ({', '.join(STATUS_NAMES)})")
    if state["friction_p_ref"].size and not state["friction_p_ref"][0] > 0:
        raise ValueError(f"{pair.name}: checkpoint entry 'friction_p_ref' must be > 0")
    keys = pair.discretization.slip_history_keys
    if all(np.asarray(state[k]).size == 0 for k in keys):
        return None
    history = {k: np.asarray(state[k]).copy() for k in keys}
    pair.discretization.check_slip_history(history)
    return history


def load_tangential_state(rows: Any, state: dict[str, np.ndarray], history: dict | None
                          ) -> None:
    """Restore the tangential entries checked by :func:`check_tangential_state`."""
    rows.statuses.converged = np.asarray(state["friction_status"], dtype=np.int8).copy()
    rows.p_ref = float(state["friction_p_ref"][0]) if state["friction_p_ref"].size else None
    rows.slip_history = history
