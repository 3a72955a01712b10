"""The tangential rows of a contact pair: a friction law's stick/slip rows, or none.

A :class:`~skfem_mortar.contact.pair.ContactPair` holds one object of this
module as ``pair.rows`` and calls it without asking which it is:
:class:`NoTangentialRows` for a law without tangential multipliers
(:data:`~skfem_mortar.contact.friction.FRICTIONLESS`, ``friction=None``: the
normal rows of :mod:`.normal_rows` alone) and :class:`TangentialRows` for a
friction law.  With a law every slave node carries ``d - 1`` tangential
multipliers (one in 2D) after the normal ones, with the semi-smooth stick/slip
rows of :func:`~skfem_mortar.contact.friction.complementarity` on the slip of
:mod:`skfem_mortar.contact.slip`, the statuses of
:class:`~skfem_mortar.contact.active_set.StatusSet` and the rows' scale
``s_t = s / p_ref`` (docs/friction.md).  The law is asked only for its bound
(:meth:`~skfem_mortar.contact.friction.FrictionLaw.slip_bound`), the bound's
weight derivative and when it acts; the multiplier space for the bound's
weight, the pressure and slip readings.  The checkpoint entries are
:mod:`.pair_state`'s, the KKT conditions of friction :mod:`.kkt`'s.
"""
from __future__ import annotations

import logging
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..core.item import Contribution
from .active_set import StatusSet
from .contact_eval import ContactEval
from .discretization import FrictionDiscretization
from .friction import (OPEN, SLIP, STATUS_NAMES, STICK, FrictionLaw, FrictionRows,
                       complementarity)
from .kkt import friction_violation
from .normal_rows import assemble_normal
from .pair_state import check_tangential_state, load_tangential_state, tangential_state
from .reservation import FrictionReservation, with_triplets
from .segmentation import surface_cell
from .surfaces import AXIS_TOL
from .curves import tributary_weights
from .tributary import tributary_jacobian, tributary_pattern

__all__ = ["TangentialRows", "NoTangentialRows", "tangential_rows", "P_REF_FIT", "NEAR_BOUND"]

log = logging.getLogger(__name__)

#: a failed step is put down to a tangential load above the friction bound
#: (:meth:`TangentialRows.hint`) when every active node slides in the failed
#: attempt or the last converged tangential force is this close to its bound
NEAR_BOUND = 0.98

#: a step that starts with no slip bound has only a guess of ``p_ref`` (``c h^k``);
#: a tracked iteration re-fixes it to the iterate's largest bound when the two differ
#: by more than this factor.  The rows ``C_t / p_ref``, ``C_t ~ Xi * (error of
#: lam_t)``, pass Newton's test with ``lam_t`` off by ``rtol S p_ref / Xi^2``: with a
#: guess 1e5 times the bound (a pressing step of strain 1e-5) 1e-3 of the bound,
#: which the KKT check (1e-6) refuses at every cut alike.  With a direct solve a row
#: scale leaves Newton's iterates as they are and changes only its test (a line
#: search's residual norm and a Krylov solve's forcing term see it too).
P_REF_FIT = 2.0

#: the checkpoint entries of the tangential rows (beside the method's slip history,
#: :mod:`.pair_state`)
STATE = ("friction_status", "friction_p_ref")


class NoTangentialRows:
    """No tangential multipliers: the pair's rows are the normal ones alone."""

    per_node = 0
    symmetric = True
    changed = False

    def __init__(self, pair: Any, law: FrictionLaw):
        self.pair, self.friction = pair, law

    def state_keys(self) -> tuple[str, ...]:
        return ()

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool) -> Contribution:
        return assemble_normal(self.pair, z, load_factor, tangent)

    def begin_step(self, z: np.ndarray, load_factor: float) -> None:
        """Nothing to start."""

    def end_step(self, z: np.ndarray) -> None:
        """Nothing to keep."""

    def hint(self, hint: str) -> str:
        return hint

    def violation(self, z: np.ndarray, tol_g: float, tol_p: float) -> tuple[dict, dict]:
        """No tangential conditions."""
        return {}, {}

    def info(self) -> dict:
        return {}

    def state_dict(self) -> dict:
        return {}

    def check_state(self, state: dict) -> None:
        """No entries to check."""

    def load_state(self, state: dict, checked: None) -> None:
        """No entries to restore."""

    def columns(self, z: np.ndarray) -> dict:
        """No output columns of their own."""
        return {}

    def force(self, z: np.ndarray, ev: ContactEval) -> float:
        """No tangential force."""
        return 0.0


def tangential_rows(pair: Any, law: FrictionLaw, cycle_guard: bool
                    ) -> TangentialRows | NoTangentialRows:
    """The rows of ``law``: :class:`TangentialRows` when it has tangential multipliers."""
    if law.tangential_multipliers:
        return TangentialRows(pair, law, cycle_guard)
    return NoTangentialRows(pair, law)


class TangentialRows:
    """The stick/slip rows of a friction law (module doc).

    Attributes
    ----------
    friction : FrictionLaw
        The law the pair was given.
    law : FrictionLaw
        The law of the current step (``friction.at(load_factor)``).
    statuses : StatusSet
        The stick/slip statuses through a step.
    slip_history : dict or None
        The slip history of the last converged step.
    p_ref : float or None
        The tangential rows' pressure of the step.
    slip_pattern_widenings : int
        Times the slip's reserved pattern was widened (a slip across more master
        segments than reserved within a step; no error).
    """

    symmetric = False

    def __init__(self, pair: Any, law: FrictionLaw, cycle_guard: bool):
        self.pair, self.friction = pair, law
        if not isinstance(pair.discretization, FrictionDiscretization):
            raise ValueError(f"friction: method {pair.method!r} has no slip hooks "
                             f"(FrictionDiscretization); use friction=None")
        dim = pair.slave.X.shape[0]
        if dim != 2:
            raise ValueError(f"friction: the stick/slip rows are written for 2D surfaces "
                             f"(one tangent a node), got a surface in {dim}D")
        #: tangential multipliers per slave node: one per tangent direction (d - 1)
        self.per_node = law.tangential_multipliers * (dim - 1)
        self.law = law.at(0.0)
        slave = pair.slave
        self.statuses = StatusSet(slave.n_nodes, pair.name, cycle_guard=cycle_guard)
        self.slip_history: dict[str, np.ndarray] | None = None
        self.p_ref: float | None = None
        self.p_ref_guess = True  # p_ref not from a converged bound (step_p_ref)
        self.reserved: tuple[Any, Any, FrictionReservation] | None = None
        self.converged: tuple | None = None  # (xs, xm, lam_t, data, history)
        self.slip_pattern_widenings = 0

    @property
    def area0(self) -> np.ndarray:
        """The slave nodes' tributary weights in the reference configuration (the
        pair's measure: lengths in plane, ``2 pi int N_A r dGamma`` in axisymmetry)."""
        slave = self.pair.slave
        return tributary_weights(slave.X, slave.segments, surface_cell(slave), self.pair.measure)

    def symmetric_nodes(self) -> np.ndarray:
        """Slave nodes on the axis of the pair's measure (within
        :data:`~.surfaces.AXIS_TOL` of the slave's size, reference coordinates): they
        cannot slip, symmetry holds them (a body of revolution holds ``u_r = 0``
        there), so their tangential rows are open (``lam_t = 0``); a stick row would
        constrain the held dof again and leave the system singular.  None in a
        plane model."""
        measure, X = self.pair.measure, self.pair.slave.X
        if measure.axis is None:
            return np.zeros(X.shape[1], dtype=bool)
        return np.abs(X[measure.axis]) <= AXIS_TOL * float(np.ptp(X, axis=1).max())

    @property
    def changed(self) -> bool:
        return self.statuses.changed

    def state_keys(self) -> tuple[str, ...]:
        return STATE + tuple(self.pair.discretization.slip_history_keys)

    @property
    def moving_bound(self) -> bool:
        """Whether the step's slip bound moves with the slave: a bound per unit area
        (``dXi/dw != 0``) in a space whose nodal weight moves (NTS's Tresca)."""
        return self.pair.space.bound_moves and self.law.weight_derivative() != 0

    def state_dict(self) -> dict[str, np.ndarray]:
        return tangential_state(self)

    def check_state(self, state: dict[str, np.ndarray]) -> dict | None:
        return check_tangential_state(self, state)

    def load_state(self, state: dict[str, np.ndarray], checked: dict | None) -> None:
        load_tangential_state(self, state, checked)

    # -- the pressure of the rows ----------------------------------------------
    def p_reference(self, ev: ContactEval, c: float, xi: np.ndarray | None = None) -> float:
        """The tangential rows' pressure ``p_ref`` of the step (:meth:`step_p_ref`;
        before any: the space's guess ``c h^k``, ``k = 1`` force multipliers, ``2``
        traction ones).  In a step whose start carries no slip bound that is a
        guess, and the bounds ``xi`` of a Newton iteration re-fix it (:data:`P_REF_FIT`)."""
        pair = self.pair
        if self.p_ref is None:
            self.p_ref = pair.space.p_ref(c, ev.area)
        top = float(xi.max(initial=0.0)) if xi is not None else 0.0
        if self.p_ref_guess and top > 0 and not (
                top / P_REF_FIT <= self.p_ref <= top * P_REF_FIT):
            log.debug("%s: p_ref %.3g re-fixed to the iterate's largest slip bound %.3g",
                      pair.name, self.p_ref, top)
            self.p_ref = top
        return self.p_ref

    def step_p_ref(self, z: np.ndarray) -> None:
        """Fix ``p_ref`` for the step starting at ``z``: the largest slip bound
        ``Xi`` there, or the guess of :meth:`p_reference` where no node carries a
        bound yet.  Constant within a step that starts with a bound; a step
        without one re-fixes its guess to the iterates' bounds (:data:`P_REF_FIT`)."""
        pair = self.pair
        self.p_ref_guess = True
        if pair.c is None:
            return
        lam = np.asarray(z)[pair._normal]
        weight = pair.space.bound_weight(tributary_weights(
            pair.slave.x(z), pair.slave.segments, surface_cell(pair.slave), pair.measure))
        conv = pair.state.converged
        xi, _, _ = self.law.slip_bound(np.where(conv, lam, 0.0), np.zeros_like(lam), pair.c,
                                       weight)
        xi = np.where(conv, xi, 0.0)
        if xi.max(initial=0.0) > 0:
            self.p_ref = float(xi.max())
            self.p_ref_guess = False

    def history(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """The slip history of the last converged step (at the first step: of ``z``)."""
        if self.slip_history is None:
            pair = self.pair
            ev = pair.evaluate(z, tangent=False, with_lam=False)
            self.slip_history = pair.discretization.slip_history(
                pair.slave.x(z), pair.master.x(z), ev)
        return self.slip_history

    # -- the rows ----------------------------------------------------------------
    def rows(self, z: np.ndarray, tangent: bool = False, track: bool = False,
             ev: ContactEval | None = None, active: np.ndarray | None = None,
             history: dict[str, np.ndarray] | None = None
             ) -> tuple[ContactEval, Any, FrictionRows]:
        """:meth:`~skfem_mortar.contact.pair.ContactPair.friction_rows`."""
        pair = self.pair
        zz = np.asarray(z)
        lam, lam_t = zz[pair._normal], zz[pair._tangential]
        xs, xm = pair.slave.x(z), pair.master.x(z)
        if ev is None:
            ev = pair.space.evaluate(pair.discretization, xs, xm, lam if tangent else None,
                                     tangent)
        c = pair._c(z, 1.0, ev) if pair.c is None else pair.c
        active = pair.active if active is None else active
        sl = pair.space.slip(pair.discretization, xs, xm,
                             self.history(z) if history is None else history,
                             lam_t if tangent else None, tangent, ev)
        weight = pair.space.bound_weight(ev.area)  # its derivative in assemble
        on = active & sl.mask & ~self.symmetric_nodes()
        jac = pair.friction_jacobian
        fr = complementarity(self.law, lam, lam_t, ev.g, sl.u, c, c, on, weight, jacobian=jac)
        st = self.statuses.update(fr.status, track)
        if not np.array_equal(st, fr.status):
            fr = complementarity(self.law, lam, lam_t, ev.g, sl.u, c, c, on, weight,
                                 status=st, jacobian=jac)
        return ev, sl, fr

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool) -> Contribution:
        """The pair's rows with friction (docs/friction.md): body rows
        ``-G_n^T lam_n - G_t^T lam_t``, normal rows as without, tangential rows
        ``s_t C_t`` (``s_t = row_scale / p_ref``); tangent ``K_u,lam_t = -G_t^T``,
        ``K_uu = -(H_n + H_t)``, ``K_lam_t,u = s_t (diag(dC/du_t) G_t +
        diag(dC/dg_n) G_n)``, ``s_t dC/dlam_t`` and ``s_t dC/dlam_n`` diagonal."""
        pair = self.pair
        zz = np.asarray(z)
        lam, lam_t = zz[pair._normal], zz[pair._tangential]
        xs, xm = pair.slave.x(z), pair.master.x(z)
        ev = pair.space.evaluate(pair.discretization, xs, xm, lam if tangent else None, True)
        c = pair._c(z, load_factor, ev)
        active = pair._active_set(lam, ev, c, track=tangent)
        ev, sl, fr = self.rows(z, tangent=True, track=tangent, ev=ev, active=active)
        if tangent:
            pair.discretization.after_iteration(ev)
        gd = pair.global_dofs()
        n = pair.slave.n_nodes
        rs = pair._row_scale
        st = rs / self.p_reference(ev, c, fr.bound if tangent else None)
        keep = gd >= 0
        fu = ev.G.T @ lam + sl.G.T @ lam_t
        idx = pair.offset + np.arange(n)
        out = Contribution(np.concatenate([gd[keep], idx, idx + n]),
                           np.concatenate([-fu[keep], np.where(active, c * ev.g, lam) * rs,
                                           st * fr.C]))
        if not tangent:
            return out
        B = sp.diags(fr.d_u) @ sl.G + sp.diags(fr.d_g) @ ev.G
        if self.moving_bound:
            B = B + sp.diags(fr.d_bound * self.law.weight_derivative()) @ tributary_jacobian(
                xs, pair.slave.segments, sl.G.shape[1], surface_cell(pair.slave), pair.measure)
        B = B.tocsr()
        res = pair._friction_reservation(z, gd)
        if res is not None:  # the triplets over the reserved patterns (explicit zeros)
            out.k_rows, out.k_cols, out.k_vals = res.rows, res.cols, self._reserved_values(
                z, gd, res, (ev.G, ev.H, sl.G, B, sl.H, active, c, rs, st, fr), ev, sl)
            out.reserved = True
            return out
        return self._plain(out, gd, ev, sl, B, fr, active, c, rs, st)

    def _reserved_values(self, z: np.ndarray, gd: np.ndarray, res: FrictionReservation,
                         args: tuple, ev: ContactEval, sl: Any) -> np.ndarray:
        """The tangent values over the reservation ``res``, widened where it misses."""
        pair = self.pair
        active, c, rs = args[5:8]
        kv = res.values(*args)
        if kv is None and res.normal.values(ev.G, ev.H, active, c, rs) is None:
            pair._widen(ev)  # the method's pattern missed G_n or H_n: says so
            res = pair._friction_reservation(z, gd)
            kv = res.values(*args)
        if kv is None:  # e.g. NTS: a slip across more segments than reserved
            res = res.widened(ev.G, ev.H, sl.G, sl.H)
            self.reserved = (*self.reserved[:2], res)
            self.slip_pattern_widenings += 1
            log.debug("%s: the slip's pattern widened", pair.name)
            kv = res.values(*args)
        return kv

    def _plain(self, out: Contribution, gd: np.ndarray, ev: ContactEval, sl: Any,
               B: sp.spmatrix, fr: FrictionRows, active: np.ndarray, c: float, rs: float,
               st: float) -> Contribution:
        """The tangent triplets as ``G_n``, ``G_t``, ``B``, ``H_n``, ``H_t`` come
        (a method without a reserved pattern)."""
        pair = self.pair
        n, off = pair.slave.n_nodes, pair.offset
        idx = off + np.arange(n)

        def glob(M: sp.spmatrix, row0: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            C = M.tocoo()
            ok = gd[C.col] >= 0
            return row0 + C.row[ok], gd[C.col[ok]], C.data[ok]

        rn, cn, vn = glob(ev.G, off)
        rt, ct, vt = glob(sl.G, off + n)
        rb, cb, vb = glob(B, off + n)
        act = active[rn - off]
        inact = np.flatnonzero(~active)
        kr = [cn, ct, rn[act], off + inact, rb, idx + n, idx + n]
        kc = [rn, rt, cn[act], off + inact, cb, idx + n, idx]
        kv = [-vn, -vt, c * rs * vn[act], np.full(inact.size, rs), st * vb,
              st * fr.d_lam_t, st * fr.d_lam_n]
        return with_triplets(out, kr, kc, kv, gd, (ev.H, sl.H))  # K_uu = -(H_n + H_t)

    def reservation(self, z: np.ndarray, gd: np.ndarray) -> FrictionReservation | None:
        """The triplets over the method's reserved pattern and the slip's
        (:class:`FrictionReservation`), built anew when either changes (the
        normal reservation, or the slip history at a new step)."""
        pair = self.pair
        res_n = pair._reservation(z, gd)
        if res_n is None:
            return None
        h = self.slip_history
        if self.reserved is None or self.reserved[0] is not res_n or self.reserved[1] is not h:
            P_t = pair.discretization.slip_pattern(h)
            if self.moving_bound:   # the bound's columns: the slave segments' nodes
                P_t = P_t + tributary_pattern(pair.slave.segments, pair.slave.n_nodes,
                                              P_t.shape[1])
            self.reserved = (res_n, h, FrictionReservation(res_n, P_t))
        return self.reserved[2]

    # -- the step ----------------------------------------------------------------
    def begin_step(self, z: np.ndarray, load_factor: float) -> None:
        """The law of the step (frictionless in the steps ending at or before its
        ``start``), the statuses from the last converged ones, the slip history
        (the first step: measured from its start) and ``p_ref``."""
        self.law = self.friction.at(load_factor)
        self.statuses.begin()
        self.history(z)
        self.step_p_ref(z)

    def end_step(self, z: np.ndarray) -> None:
        """Open nodes' multipliers exactly zero; the step's data for the outputs
        of the converged state; the slip history of the next step."""
        pair = self.pair
        lam_t = z[pair._tangential]
        lam_t[self.statuses.status == OPEN] = 0.0
        self.statuses.end()
        # what the step did (its slip from the history it was measured from)
        data = self.data(z)
        data["status"] = self.statuses.converged.copy()
        self.converged = (pair.slave.x(z), pair.master.x(z), lam_t.copy(), data,
                          self.slip_history)
        ev = pair.evaluate(z, tangent=False, with_lam=False)
        self.slip_history = pair.discretization.slip_history(pair.slave.x(z),
                                                             pair.master.x(z), ev)

    def at_converged(self, z: np.ndarray) -> tuple | None:
        """``(xs, xm, lam_t, data, history)`` of the last converged step if ``z``
        is its state (the history its slip was measured from), else None."""
        pair, conv = self.pair, self.converged
        if conv is not None and all(np.array_equal(a, b) for a, b in zip(
                conv[:3], (pair.slave.x(z), pair.master.x(z),
                           np.asarray(z)[pair._tangential]))):
            return conv
        return None

    def data(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """:meth:`~skfem_mortar.contact.pair.ContactPair.tangential_data`."""
        pair = self.pair
        lam_t = np.asarray(z)[pair._tangential]
        conv = self.at_converged(z)
        if conv is not None:
            return {k: v.copy() for k, v in conv[3].items()}
        ev, sl, fr = self.rows(z, tangent=False, track=False)
        sp_ = pair.space
        t, b = sp_.pressure(lam_t, ev.area), sp_.pressure(fr.bound, ev.area)
        u = sp_.slip_length(sl.u, ev.area)
        return {"tangential_traction": t, "slip": np.where(sl.mask, u, 0.0), "bound": b,
                "status": fr.status.copy(), "tangent": sl.tangent}

    def columns(self, z: np.ndarray) -> dict:
        """The output columns ``tangential_traction``, ``slip``, ``status`` (names)."""
        t = self.pair.tangential_data(z)
        return {"tangential_traction": t["tangential_traction"], "slip": t["slip"],
                "status": np.asarray(STATUS_NAMES)[t["status"]]}

    def force(self, z: np.ndarray, ev: ContactEval) -> np.ndarray:
        """``G_t^T lam_t`` of the step (local dofs)."""
        pair = self.pair
        conv = self.at_converged(z)
        _, sl, _ = self.rows(z, tangent=True, ev=ev, history=None if conv is None else conv[4])
        return sl.G.T @ np.asarray(z)[pair._tangential]

    def hint(self, hint: str) -> str:
        """``hint`` and, when the last converged step's tangential force was within
        2 % of its bound or every active node slides in the failed attempt, that
        the tangential load may exceed the friction bound."""
        pair = self.pair
        act = pair.active
        st = self.statuses.status
        near = False  # the last converged tangential force within 2 % of its bound
        if self.converged is not None:
            d = self.converged[3]
            bound = float(np.sum(d["bound"] * self.area0))
            near = bound > 0 and abs(float(np.sum(d["tangential_traction"] * self.area0))
                                     ) >= NEAR_BOUND * bound
        if near or (act.any() and np.all(st[act] == SLIP)):
            more = (f"{pair.name}: the contact slides as a whole (tangential force at the "
                    f"friction bound): the tangential load exceeds the friction bound "
                    f"({self.friction.describe()}), which has no "
                    f"equilibrium under load control; keep the tangential load below the "
                    f"bound or prescribe the tangential displacement instead")
            hint = "; ".join(h for h in (hint, more) if h)
        return hint

    def violation(self, z: np.ndarray, tol_g: float, tol_p: float) -> tuple[dict, dict]:
        """The friction conditions of a converged state (:func:`~.kkt.friction_violation`)."""
        return friction_violation(self.pair.tangential_data(z), tol_g, tol_p)

    def info(self) -> dict:
        """``n_stick``, ``n_slip`` nodes, ``friction_status_changes``,
        ``friction_status_cycles`` of the step."""
        st = self.statuses.status
        return {"n_stick": int(np.sum(st == STICK)), "n_slip": int(np.sum(st == SLIP)),
                "friction_status_changes": self.statuses.changes,
                "friction_status_cycles": self.statuses.cycles}
