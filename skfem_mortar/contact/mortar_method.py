"""Mortar contact (:func:`skfem_mortar.contact.mortar.evaluate`) as a contact discretization.

:class:`Mortar` is the method behind ``ContactPair(method="mortar")`` (standard
multipliers ``Phi_A = N_A``) and ``method="mortar-dual"`` (biorthogonal ones):
the kernel is :mod:`skfem_mortar.contact.mortar`, the segmentation
:mod:`skfem_mortar.contact.mortar_segmentation`; this class holds what the kernel is
told from one call to the next (the segmentation policy and a frozen
segmentation, the search reach, the crosspoints).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from . import mortar
from .active_set import normal_nodal_force
from .contact_eval import ContactEval
from .discretization import ContactDiscretization, OptionTable, check_options
from .mortar_segmentation import Segmentation, segment

__all__ = ["Mortar"]


class Mortar(ContactDiscretization):
    """Mortar weighted gaps with standard (``dual=False``) or dual multipliers.

    Parameters
    ----------
    slave, master : ContactSurface
    dual : bool
        Dual (biorthogonal) multiplier shape functions.
    pair_name : str
        The pair's name (in messages).
    segmentation : {"iteration", "step"}
        Rebuild the mortar segments at every evaluation (default, exact), or
        once per load step attempt from its start positions, frozen during the
        step (see :func:`skfem_mortar.contact.mortar.evaluate`).
    **options
        ``margin`` (global search margin; default local, the two element
        lengths plus the reach) and ``n_gauss`` (Gauss points per mortar
        segment), passed to :func:`skfem_mortar.contact.mortar.evaluate`.

    The search reach: without a ``margin``, the local margin of the search
    grows by the motion of the contact nodes since the last converged state
    (:meth:`set_reference`), so a node that penetrates deeply within one step
    is still paired.  Pinned slave nodes (:meth:`set_pinned`) are crosspoints:
    their multiplier is merged into the neighbour's, so the multipliers still
    sum to one on their elements.
    """

    multiplier_kind = "traction"
    multipliers_per_node = 1
    symmetric = True
    has_history = False  # all it keeps is rebuilt at each step from the positions it is told

    OPTIONS: OptionTable = {
        "margin": (lambda v: v is None or (np.isfinite(v) and v > 0), "a finite number > 0"),
        "n_gauss": (lambda v: isinstance(v, (int, np.integer)) and 1 <= v <= 10,
                    "an integer in [1, 10]")}

    def __init__(self, slave: Any, master: Any, dual: bool = False, pair_name: str = "contact",
                 segmentation: str = "iteration", **options: Any):
        self.method = "mortar-dual" if dual else "mortar"
        check_options(self.method, options, self.OPTIONS)
        if segmentation not in ("iteration", "step"):
            raise ValueError(f"segmentation must be 'iteration' or 'step', got {segmentation!r}")
        self.slave, self.master, self.pair_name = slave, master, pair_name
        self.dual = bool(dual)
        self.segmentation = segmentation
        self.options = dict(options)
        self._kernel_options = {"dual": self.dual, **options}
        self._sg: Segmentation | None = None
        self._x0: tuple[np.ndarray, np.ndarray] | None = None
        self._pinned: np.ndarray | None = None

    def set_pinned(self, pinned: np.ndarray | None) -> None:
        self._pinned = pinned

    def set_reference(self, xs0: np.ndarray | None, xm0: np.ndarray | None) -> None:
        self._x0 = None if xs0 is None else (xs0, xm0)

    def begin_step(self, xs: np.ndarray, xm: np.ndarray, first: bool) -> None:
        """Policy ``step``: segment the step's start positions, frozen."""
        if self.segmentation == "step":
            self._sg = None
            self._sg = segment(xs, self.slave.segments, xm, self.master.segments,
                               margin=self.options.get("margin"), frozen=True)

    def reach(self, xs: np.ndarray, xm: np.ndarray) -> float:
        """Largest motion of a slave node plus that of a master node since the last
        converged state (times sqrt 2): a node open there can penetrate at most
        this deep, so the search adds it to its local margin (the element lengths)."""
        xs0, xm0 = self._x0
        ds = np.abs(xs - xs0).max(initial=0.0)
        dm = np.abs(xm - xm0).max(initial=0.0)
        return float(np.sqrt(2.0) * (ds + dm))

    def evaluate(self, xs: np.ndarray, xm: np.ndarray, lam: np.ndarray | None,
                 tangent: bool) -> ContactEval:
        extra: dict = {}
        if self._sg is not None:
            extra["segmentation"] = self._sg
        elif "margin" not in self.options and self._x0 is not None:
            extra["reach"] = self.reach(xs, xm)
        pinned = self._pinned is not None and self._pinned.any()
        if pinned:
            extra["crosspoints"] = np.flatnonzero(self._pinned)
        ev = mortar.evaluate(xs, self.slave.segments, xm, self.master.segments, lam=lam,
                             tangent=tangent, **extra, **self._kernel_options)
        if pinned:
            ev.mask = ev.mask & ~self._pinned
        return ev

    def tail_signal(self, lam: np.ndarray, ev: Any) -> tuple[np.ndarray | None, bool]:
        """Dual: the multipliers; standard: the normal nodal forces (its
        multipliers alternate in sign at a too-wide edge)."""
        if self.dual:
            return lam, False
        if ev.G is None:
            return None, True
        return normal_nodal_force(ev.G, lam, self.slave.n_nodes), True
