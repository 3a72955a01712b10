"""The active set of a contact pair through the Newton iterations of a load step.

:class:`ActiveSet` takes, in every iteration, the plain primal-dual update

    A = { mask and lam - c g >= 0 }

(computed by :class:`~skfem_mortar.contact.pair.ContactPair`, which owns ``lam``,
``g`` and ``c``) and decides the set the next Newton step uses:

* the first iteration of a step keeps the last converged set (less the nodes
  out of ``mask``);
* **extrapolated release** (``accelerate``): releasing only the tensile nodes
  of a too-wide zone halves its overshoot per iteration (Hertz: forcing contact
  over ``|x| < b`` where the answer is ``a < b`` puts the pressure's sign change
  at ``x0^2 = (a^2 + b^2) / 2``), so a mesh of size h needs ``O(log((b - a)/h))``
  iterations; beyond the tensile tail of a run of active nodes as many nodes
  again are released as the sign change of a *tail signal* extrapolates (the
  multipliers; for standard mortar the normal nodal forces, see
  :func:`normal_nodal_force`), until a node released so penetrates again (then
  plain updates for the rest of the step);
* **cycling guard**: the sets of the step's iterations are kept; when an
  iteration returns to a set seen before (other than the last), only one node
  changes per iteration from then on, the first violated one (Murty's
  least-index rule, which terminates for linear complementarity problems with a
  P-matrix); should a set repeat even so, the set is frozen to the union of the
  sets of the cycle for the rest of the step attempt.

A KKT point (no tensile active node, no penetrating inactive node) is a fixed
point of every rule here; Newton stops only once the set repeats
(:attr:`ActiveSet.changed` False).
"""
from __future__ import annotations

import logging
from typing import Callable

import numpy as np
import scipy.sparse as sp

from .cells import CellType, cell_type
from .curves import chain_nodes, polyline
from .nts_faces import touching_faces
from .search import node_segment_pairs
from .surface_kinds import CURVE, FACE, entry

__all__ = ["ActiveSet", "StatusSet", "chain_order", "extrapolated_release", "normal_nodal_force",
           "touching_nodes"]

log = logging.getLogger("skfem_mortar.contact.pair")


def chain_order(segments: np.ndarray, closed: bool, n_nodes: int,
                cell: "str | CellType") -> np.ndarray | None:
    """Nodes in chain order from chained cells of type ``cell`` (None when the cells
    do not visit every node once): along each cell's edge (``line3`` (start, end,
    mid): start, mid, start, mid, ..., end; :func:`~.curves.chain_nodes`)."""
    seg = np.asarray(segments)
    if seg.size == 0:
        return None
    order = chain_nodes(seg, cell, closed)
    if order.size != n_nodes or np.unique(order).size != order.size:
        return None
    return order


def _point_segment(xp: np.ndarray, xq: np.ndarray, seg_q: np.ndarray, tol: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points ``xp`` within ``tol`` of a segment of ``(xq, seg_q)``: point index,
    segment index and the clipped parameter ``t`` in [0, 1] of the closest point."""
    i_p, i_e = node_segment_pairs(xp, xq, seg_q, tol)
    x1, x2 = xq[:, seg_q[i_e, 0]], xq[:, seg_q[i_e, 1]]
    d = x2 - x1
    l2 = np.sum(d * d, axis=0)
    t = np.clip(np.sum((xp[:, i_p] - x1) * d, axis=0) / np.where(l2 > 0, l2, 1.0), 0.0, 1.0)
    near = np.hypot(*(xp[:, i_p] - x1 - t * d)) <= tol
    return i_p[near], i_e[near], t[near]


def touching_nodes(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                   tol: float, cells: tuple = ("line2", "line2")) -> np.ndarray:
    """Slave nodes whose own part of the slave surface the master touches within ``tol``.

    A node's own part is its half of each of its segments (the points nearer to it
    than to the segment's other node).  The distance between two polylines is
    attained at a vertex of one of them, so a node touches when it lies within
    ``tol`` of a master segment, or a master vertex lies within ``tol`` of its own
    part of a slave segment (the nearer node of that segment; both at the midpoint).

    This is the closest approach, not a weighted gap: a polygon resting on a line
    at one vertex has, at that vertex, the mortar weighted gap over the tributary
    length ``h^2 / (6 R)`` (the chords leave the line linearly), far above
    ``1e-2 h`` unless ``h < 0.06 R``; a flat slave under a master vertex between
    two of its nodes has positive gaps at both nodes.  ``cells``: the (slave, master)
    cell types (curved cells: their chords through every node). Bool ``(n_s,)``.
    """
    xs, xm = np.asarray(xs, dtype=float), np.asarray(xm, dtype=float)
    touching = entry(_TOUCHING, cells[0], "touching_nodes")   # the slave cell's kind
    return touching(xs, np.asarray(seg_s), xm, np.asarray(seg_m), cell_type(cells[0]),
                    cell_type(cells[1]), tol)


def _touching_curves(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                     cs: CellType, cm: CellType, tol: float) -> np.ndarray:
    """:func:`touching_nodes` between curves: the polylines' vertices."""
    cells = (cs, cm)
    # curved cells: their chords through every node (the touch tolerance is far
    # above the sag of a cell that can touch flat)
    seg_s = polyline(np.asarray(seg_s, dtype=np.int64).reshape(len(seg_s), -1), cells[0])
    seg_m = polyline(np.asarray(seg_m, dtype=np.int64).reshape(len(seg_m), -1), cells[1])
    out = np.zeros(xs.shape[1], dtype=bool)
    if not (seg_s.size and seg_m.size):
        return out
    k, _, _ = _point_segment(xs, xm, seg_m, tol)   # slave vertices on the master
    out[k] = True
    _, e, t = _point_segment(xm, xs, seg_s, tol)   # master vertices on the slave
    out[seg_s[e[t <= 0.5], 0]] = True
    out[seg_s[e[t >= 0.5], 1]] = True
    return out


#: the touching test of each surface kind (:mod:`.surface_kinds`)
_TOUCHING = {CURVE: _touching_curves, FACE: touching_faces}


def normal_nodal_force(G: sp.spmatrix, lam: np.ndarray, n_slave: int, d: int = 2
                       ) -> np.ndarray:
    """The normal contact force on each slave node: ``G^T lam`` at the node
    projected on the node's own gap gradient ``G[A, x_A]`` (``d`` coordinates per
    node: 2, or 3 in 3D) (for flat
    standard mortar ``D^T lam``), ``(n_slave,)``.

    Standard mortar multipliers alternate in sign at the edge of a too-wide
    zone (e.g. -0.35, -0.90, -0.34, -3.14, +2.15, -12.7 from inside to the
    edge); these forces keep one sign, so their tail and sign change are the
    ones to extrapolate.
    """
    G = G.tocsr()
    f = (G.T @ lam)[:d * n_slave].reshape(-1, d)
    j = np.arange(n_slave)
    gd = np.column_stack([np.asarray(G[j, d * j + c]).ravel() for c in range(d)])
    nrm = np.hypot(gd[:, 0], gd[:, 1]) if d == 2 else np.sqrt(np.sum(gd * gd, axis=1))
    return np.where(nrm > 0, np.sum(f * gd, axis=1) / np.where(nrm > 0, nrm, 1.0), 0.0)


def extrapolated_release(prev: np.ndarray, new: np.ndarray, chain: np.ndarray,
                         signal: np.ndarray, signal_tail: bool) -> tuple[np.ndarray, np.ndarray]:
    """Release beyond the tensile tail of each run of active nodes.

    At each end of a run of ``prev``-active nodes (along ``chain``) whose outer
    neighbour stays inactive in ``new`` and whose end node ``new`` releases,
    the tail is the ``m`` released nodes from the end inwards (with
    ``signal_tail``: the nodes whose ``signal`` is negative, at most half of the
    run); the sign change of ``signal`` between the tail and the next node,
    linearly interpolated, is ``t0`` nodes from the end, and the nodes up to
    ``2 t0`` from the end (rounded, at most ``2 m``, keeping at least half of
    the run) are released: the secant ``x^2 = 2 x0^2 - b^2`` of the halving,
    linearised (a little less).  One Python loop over runs, none over nodes.

    Parameters
    ----------
    prev, new : bool ndarray (n,)
        The set of the last iteration and the plain update.
    chain : int ndarray (n,)
        The nodes in chain order.
    signal : ndarray (n,)
        Multipliers (or normal nodal forces), by node.
    signal_tail : bool
        Take the tail from the sign of ``signal`` (standard mortar) instead of
        from the plain release.

    Returns
    -------
    released : bool ndarray (n,)
        ``new`` less the extrapolated releases.
    extra : bool ndarray (n,)
        The nodes released by extrapolation only.
    """
    o = chain
    A, N, L = prev[o], new[o], signal[o]
    rel = A & ~N
    extra = np.zeros(A.size, dtype=bool)
    if not rel.any():
        return new.copy(), np.zeros(new.shape, dtype=bool)
    rel_tail = A & (L < 0) if signal_tail else rel
    n = A.size
    d = np.diff(np.r_[0, A.astype(np.int8), 0])
    out = N.copy()
    for s0, e0 in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)):  # runs A[s0:e0]
        length = e0 - s0
        for end in (0, 1):  # 0: the run's last node (outer neighbour e0), 1: its first
            if end == 0:
                if e0 >= n or N[e0]:
                    continue
                r, lr, r0 = rel_tail[s0:e0][::-1], L[s0:e0][::-1], rel[e0 - 1]
            else:
                if s0 == 0 or N[s0 - 1]:
                    continue
                r, lr, r0 = rel_tail[s0:e0], L[s0:e0], rel[s0]
            if not (r0 and r[0]):
                continue
            m = int(np.argmin(r)) if not r.all() else r.size  # the tensile tail
            if signal_tail:  # its nodes need not be tensile: keep at least half of the run
                m = min(m, max(1, length // 2))
            k = m
            if m < r.size and lr[m - 1] < 0 <= lr[m]:
                # the sign change, by linear interpolation (in nodes from the end)
                t0 = m - 1 + lr[m - 1] / (lr[m - 1] - lr[m])
                k = int(np.clip(np.rint(2.0 * t0) - m, 0, m))
            k = max(0, min(k, length // 2 - m))  # keep at least half of the run
            pos = np.arange(m + k)
            idx = (e0 - 1 - pos) if end == 0 else (s0 + pos)
            extra[idx] = out[idx]
            out[idx] = False
    released = new.copy()
    released[o] = out
    extra_nodes = np.zeros(new.shape, dtype=bool)
    extra_nodes[o] = extra
    return released, extra_nodes


class ActiveSet:
    """The active set of one contact pair during the iterations of a load step.

    Parameters
    ----------
    n : int
        Number of slave nodes (multipliers).
    chain : int ndarray or None
        The slave nodes in chain order (None: no extrapolated release).
    name : str
        The pair's name, in log messages.
    cycle_guard, accelerate : bool
        Switch the cycling guard and the extrapolated release.

    Attributes
    ----------
    active : bool ndarray (n,)
        The current set.
    converged : bool ndarray (n,)
        The set of the last converged step (the start of the next).
    changed : bool
        Whether the last tracked update changed the set.
    changes, cycles : int
        Node status flips and cycling-guard actions in this step.
    """

    def __init__(self, n: int, chain: np.ndarray | None, name: str = "contact",
                 cycle_guard: bool = True, accelerate: bool = True):
        self.n, self.chain, self.name = int(n), chain, name
        self.cycle_guard, self.accelerate = bool(cycle_guard), bool(accelerate)
        self.converged = np.zeros(self.n, dtype=bool)
        self.extra = np.zeros(self.n, dtype=bool)   # released by extrapolation
        self.frozen: np.ndarray | None = None
        self.begin()
        self.initial = False

    def begin(self) -> None:
        """Start (or retry) a step from the last converged set."""
        self.active = self.converged.copy()
        self.initial = True
        self.history = [self.active.copy()]
        self.frozen = None
        self.single_flip = False
        self.extra[:] = False
        self.accel_off = False
        self.changed = False
        self.changes = 0
        self.cycles = 0

    def end(self) -> None:
        """The step converged: its set starts the next."""
        self.converged = self.active.copy()

    def update(self, plain: np.ndarray, mask: np.ndarray, track: bool,
               signal: Callable[[], tuple[np.ndarray, bool]] | None = None) -> np.ndarray:
        """The set for the next Newton step.

        Parameters
        ----------
        plain : bool ndarray (n,)
            The plain primal-dual update ``mask and lam - c g >= 0``.
        mask : bool ndarray (n,)
            Nodes with a master partner.
        track : bool
            A Newton iteration (update the state); False for a trial evaluation
            (line search), which must not change it.
        signal : callable, optional
            Returns ``(signal, signal_tail)`` for :func:`extrapolated_release`
            (called only when a node is released); None: no extrapolation.
        """
        if self.frozen is not None:
            new = self.frozen & mask
            if track:
                self.changed = not np.array_equal(new, self.active)
                self.active = new
            return new
        if self.initial:
            # the last converged set, less the nodes no longer in mask (with
            # segmentation=step the segments are rebuilt at the step start: an
            # active node without support has a zero row, a singular tangent)
            if not track:
                return self.active & mask
            self.initial = False
            self.changed = False
            self.active = self.active & mask
            return self.active
        new = plain
        if not track:
            return new
        if (self.accelerate and not self.single_flip and not self.accel_off
                and self.chain is not None and signal is not None):
            new = self.release(new, signal)
        if self.single_flip:
            diff = np.flatnonzero(new != self.active)
            if diff.size:  # least-index rule: change only the first violated node
                new = self.active.copy()
                new[diff[0]] = ~new[diff[0]]
        n_flip = int(np.count_nonzero(new != self.active))
        self.changed = n_flip > 0
        self.changes += n_flip
        if self.changed and self.cycle_guard:
            new = self._guard(new)
            self.changed = not np.array_equal(new, self.active)
        self.history.append(new.copy())
        self.active = new
        return new

    def release(self, new: np.ndarray,
                signal: Callable[[], tuple[np.ndarray | None, bool]]) -> np.ndarray:
        """``new`` less the extrapolated releases from the current set (see
        :func:`extrapolated_release`); records them in :attr:`extra`.  Once one
        of them is back in ``new`` (it penetrated again), the extrapolation is
        off for the rest of the step attempt."""
        prev = self.active
        if np.any(self.extra & new):
            # the extrapolation went too far: plain updates from here; the sets
            # seen so far came from the extrapolation, not from a cycle of
            # primal-dual active set updates, so the cycling guard starts anew
            self.accel_off = True
            self.history = [prev.copy()]
            return new
        if not np.any(prev & ~new):
            return new
        values, signal_tail = signal()
        if values is None:
            return new
        out, extra = extrapolated_release(prev, new, self.chain, values, signal_tail)
        self.extra |= extra
        return out

    def _guard(self, new: np.ndarray) -> np.ndarray:
        seen = [i for i, a in enumerate(self.history[:-1]) if np.array_equal(a, new)]
        if not seen:
            return new
        self.cycles += 1
        if not self.single_flip:
            self.single_flip = True
            log.info("%s: active set cycling (a set of %d sets repeats); from now on "
                        "in this step change one node at a time (least-index rule)",
                        self.name, len(self.history) - seen[0])
            diff = np.flatnonzero(new != self.active)
            new = self.active.copy()
            new[diff[0]] = ~new[diff[0]]
            self.history = [self.active.copy()]  # cycles are now counted anew
            return new
        cycle = self.history[seen[0]:] + [new]
        frozen = np.logical_or.reduce(cycle)
        log.info("%s: active set still cycling; freezing it to the union of "
                    "the %d sets of the cycle (%d nodes) for the rest of the step",
                    self.name, len(cycle) - 1, int(frozen.sum()))
        self.frozen = frozen
        return frozen


class StatusSet:
    """The friction statuses (open, stick, slip) of a contact pair's slave nodes
    through the iterations of a load step.

    Each iteration the pair computes the plain statuses of
    :func:`~skfem_mortar.contact.friction.complementarity` (open where the normal
    row is inactive or the slip bound ``Xi <= 0``, stick where ``|s| < Xi``, slip
    elsewhere) and :meth:`update` returns the statuses the Newton step uses:

    * the first iteration of a step keeps the last converged stick/slip status
      of every node that is in contact now and was then;
    * **cycling guard** (as :class:`ActiveSet`'s): the status vectors of the
      step's iterations are kept; when one repeats (other than the last), only
      one node changes per iteration from then on (the least index), and should
      a vector repeat even so, the statuses are frozen to that vector for the
      rest of the step attempt (a frozen stick/slip node is still open when its
      normal row is inactive).

    A state whose statuses are those of its own plain update is a fixed point
    of every rule here.

    Parameters
    ----------
    n : int
        Number of slave nodes.
    name : str
        The pair's name, in log messages.
    cycle_guard : bool
        Switch the cycling guard.

    Attributes
    ----------
    status : int8 ndarray (n,)
        The statuses of the last update.
    converged : int8 ndarray (n,)
        The statuses of the last converged step.
    changed : bool
        Whether the last tracked update changed a status.
    changes, cycles : int
        Status changes and cycling-guard actions in this step.
    """

    def __init__(self, n: int, name: str = "contact", cycle_guard: bool = True):
        self.n, self.name, self.cycle_guard = int(n), name, bool(cycle_guard)
        self.converged = np.zeros(self.n, dtype=np.int8)
        self.begin()

    def begin(self) -> None:
        """Start (or retry) a step from the last converged statuses."""
        self.status = self.converged.copy()
        self.initial = True
        self.history = [self.status.copy()]
        self.single_flip = False
        self.frozen: np.ndarray | None = None
        self.changed = False
        self.changes = 0
        self.cycles = 0

    def end(self) -> None:
        """The step converged: its statuses start the next."""
        self.converged = self.status.copy()

    def update(self, plain: np.ndarray, track: bool) -> np.ndarray:
        """The statuses to use (int8 per node) given the plain ones; ``track``
        False (a trial evaluation) leaves the state unchanged."""
        plain = np.asarray(plain, dtype=np.int8)
        contact = plain != 0  # OPEN is 0: no contact or no slip bound, whatever is imposed
        if self.frozen is not None:
            new = np.where(contact, np.where(self.frozen != 0, self.frozen, plain), 0)
            return self._take(new.astype(np.int8), track, guard=False)
        if self.initial:
            keep = contact & (self.converged != 0)
            new = np.where(keep, self.converged, plain).astype(np.int8)
            if track:
                self.initial = False
                self.status = new
                self.changed = False
                self.history = [new.copy()]
            return new
        new = plain
        if track and self.single_flip:
            diff = np.flatnonzero(new != self.status)
            if diff.size:  # least-index rule
                one = self.status.copy()
                one[diff[0]] = new[diff[0]]
                new = one
        return self._take(new, track, guard=True)

    def _take(self, new: np.ndarray, track: bool, guard: bool) -> np.ndarray:
        if not track:
            return new
        n_flip = int(np.count_nonzero(new != self.status))
        self.changes += n_flip
        if n_flip and guard and self.cycle_guard:
            new = self._guard(new)
        self.changed = not np.array_equal(new, self.status)
        self.history.append(new.copy())
        self.status = new
        return new

    def _guard(self, new: np.ndarray) -> np.ndarray:
        if not any(np.array_equal(a, new) for a in self.history[:-1]):
            return new
        self.cycles += 1
        if not self.single_flip:
            self.single_flip = True
            log.info("%s: friction statuses cycling; from now on in this step change one "
                     "node at a time (least-index rule)", self.name)
            diff = np.flatnonzero(new != self.status)
            one = self.status.copy()
            one[diff[0]] = new[diff[0]]
            self.history = [self.status.copy()]
            return one
        log.info("%s: friction statuses still cycling; frozen for the rest of the step",
                 self.name)
        self.frozen = new.copy()
        return new
