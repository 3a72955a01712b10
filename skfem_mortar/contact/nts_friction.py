"""NTS's friction (:class:`~.discretization.FrictionDiscretization`): the slip history of
a node (its converged master segment and parameter), the slip to the segment of the
current iteration (:func:`~.slip.nts_slip`) and the reserved pattern of its tangential
row; :class:`~.nts.NTS` takes them from :class:`NTSFriction`.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .contact_eval import ContactEval
from .curves import ends
from .discretization import check_entries, pattern_matrix
from .surfaces import segments_at_nodes

__all__ = ["NTSFriction", "SLIP_HALO"]

#: friction: the reserved tangential row of a node holds the segments this many
#: chain neighbours on each side of its converged segment (:meth:`NTSFriction.slip_pattern`)
SLIP_HALO = 2


class NTSFriction:
    """The friction methods of :class:`~.nts.NTS` (its ``slave``, ``master``, ``cells``
    and ``pair_name``)."""

    #: the names of :meth:`slip_history`'s arrays (a friction pair's checkpoint entries)
    slip_history_keys = ("xi_prev", "segment_prev")

    def slip_history(self, xs: np.ndarray, xm: np.ndarray, ev: ContactEval
                     ) -> dict[str, np.ndarray]:
        """``xi_prev`` (the parameters of the converged projections) and
        ``segment_prev`` (their master segments, -1 for a node out of ``mask``)."""
        return {"xi_prev": np.where(ev.mask, ev.info["xi"], 0.0).astype(float),
                "segment_prev": np.where(ev.mask, ev.info["segment"], -1).astype(np.int64)}

    def check_slip_history(self, history: dict[str, np.ndarray]) -> None:
        ns, n_seg = self.slave.n_nodes, len(self.master.segments)
        check_entries(self.pair_name, history, {"xi_prev": [(ns,)], "segment_prev": [(ns,)]})
        seg = np.asarray(history["segment_prev"])
        if not np.issubdtype(seg.dtype, np.integer) or (seg.size and (
                seg.min() < -1 or seg.max() >= n_seg)):
            raise ValueError(f"{self.pair_name}: checkpoint entry 'segment_prev' must be "
                             f"integers in [-1, {n_seg})")

    def slip(self, xs: np.ndarray, xm: np.ndarray, history: dict[str, np.ndarray],
             lam_t: np.ndarray | None, tangent: bool, ev: ContactEval):
        """:func:`~skfem_mortar.contact.slip.nts_slip` from the converged
        ``(segment_prev, xi_prev)`` to the segments of ``ev`` (with the
        hysteresis and locks of this iteration); ``mask`` also ``ev.mask``."""
        from .slip import nts_slip
        sl = nts_slip(xs, xm, self.master.segments, history["xi_prev"],
                      history["segment_prev"], segment=ev.info["segment"], lam_t=lam_t,
                      tangent=tangent, cell=self.cells[1])
        sl.mask = sl.mask & ev.mask
        return sl

    def slip_pattern(self, history: dict[str, np.ndarray]) -> sp.csr_matrix:
        """Row ``k``: the master dofs of ``segment_prev[k]`` and of the
        :data:`SLIP_HALO` segments before and after it along the chain (the
        arc length of the slip runs over the segments crossed in the step)."""
        seg_m = self.master.segments
        n_s, n_m = self.slave.n_nodes, self.master.n_nodes
        chain = ends(seg_m, self.cells[1])
        ending, starting = segments_at_nodes(chain, n_m)
        e0 = np.asarray(history["segment_prev"], dtype=np.int64)
        near, back, ahead = [e0], e0, e0
        for _ in range(SLIP_HALO):
            back = np.where(back >= 0, ending[chain[np.maximum(back, 0), 0]], -1)
            ahead = np.where(ahead >= 0, starting[chain[np.maximum(ahead, 0), 1]], -1)
            near += [back, ahead]
        e = np.concatenate(near)
        k = np.tile(np.arange(n_s), len(near))
        ok = e >= 0
        k, e = k[ok], e[ok]
        nm = 2 * self.cells[1].n_nodes               # master dofs of a segment: 4, or 6 (3-node)
        cols = (2 * n_s + 2 * seg_m[e][:, :, None] + np.arange(2)).reshape(-1, nm)
        return pattern_matrix(np.repeat(k, nm), cols.ravel(), (n_s, 2 * n_s + 2 * n_m))
