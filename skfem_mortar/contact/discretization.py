"""The contact discretization protocol and the registry of contact methods.

A :class:`~skfem_mortar.contact.pair.ContactPair` owns what every method shares:
the multipliers, the complementarity function ``C = c g`` (active) / ``lam``
(inactive) with its parameter and row scale, the active set, the KKT check and
the checkpoint of those.  What differs between methods -- how the gaps of the
slave nodes and their derivatives are computed from the positions, and what
state that needs between iterations and steps -- is a *contact
discretization*: an object with the hooks of :class:`ContactDiscretization`.
The pair calls exactly these hooks, in this order::

    d = make_method(method, slave, master, pair_name=name, **options)  # options checked here
    d.set_measure(measure)                # at bind, if the method has it (MeasuredDiscretization)
    d.set_pinned(mask)                    # before every step attempt (stepping: set_fixed)
    d.set_reference(xs0, xm0)             # positions of the last converged state
    d.begin_step(xs, xm, first)           # every attempt of a load step
    ev = d.evaluate(xs, xm, lam, tangent) # every residual / tangent evaluation
    d.after_iteration(ev)                 # after a Newton iteration's tangent evaluation
    d.tail_signal(lam, ev)                # when the active set releases a tensile tail
    d.end_step(xs, xm)                    # once a load step has converged
    d.step_info(), d.failure_hint(), d.state_dict(), d.load_state_dict(state)
    P = d.pattern(xs, xm)                 # optional (PatternedDiscretization): with a tangent

A pair with friction (``ContactPair(..., friction=Coulomb(mu))``) also calls the
hooks of :class:`FrictionDiscretization` (NTS and mortar have them)::

    h = d.slip_history(xs, xm, ev)        # at the first step's start and each converged step
    d.check_slip_history(h)               # a checkpoint's history (ValueError naming the entry)
    sl = d.slip(xs, xm, h, lam_t, tangent, ev)   # every evaluation, after evaluate
    E = d.slip_pattern(h)                 # columns the tangential rows add to the pattern

The optional hook :meth:`PatternedDiscretization.pattern` reserves the
tangent's sparsity: a superset of the local dofs each multiplier row can
couple to, which stays the same object while the search finds no new
candidate pairs.  The pair then emits its triplets over that reservation
(explicit zeros), so the global sparsity pattern repeats over Newton
iterations and load steps; a method without the hook still works (its
triplets follow ``G`` and ``H`` as they come, and the pattern changes with them).

A new method is one class and one :func:`register_method` call; nothing in
the pair changes.  The built-ins register where they are defined: ``"nts"``
(:class:`skfem_mortar.contact.nts.NTS`, in :mod:`.nts`), ``"mortar"`` and ``"mortar-dual"``
(:class:`skfem_mortar.contact.mortar_method.Mortar` with ``multiplier_space="standard"`` / ``"dual"``, in
:mod:`.mortar_method`); :mod:`.methods` imports both (the pair imports it), and this
module imports neither.
"""
from __future__ import annotations

import difflib
from typing import Any, Callable, Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp

from . import BUILTIN_METHODS
from .contact_eval import ContactEval
from .measures import Measure
from .multiplier_spaces import registered_spaces

__all__ = ["ContactDiscretization", "PatternedDiscretization", "MeasuredDiscretization", "FrictionDiscretization", "register_method", "unregister_method", "make_method",
           "registered_methods", "check_options", "check_entries", "METHODS",
           "BUILTIN_METHODS"]


@runtime_checkable
class ContactDiscretization(Protocol):
    """What a :class:`~skfem_mortar.contact.pair.ContactPair` asks of its contact method.

    Implement every attribute and method below (or subclass this class, whose
    methods are the defaults of a method without state).  Positions are the
    current coordinates ``xs (2, n_s)`` of the slave and ``xm (2, n_m)`` of the
    master nodes; local dof order as in :class:`~skfem_mortar.contact.contact_eval.ContactEval`.

    Attributes
    ----------
    method : str
        The registered name (used in messages).
    multiplier_kind : {"force", "traction"}
        What a multiplier is: a nodal force (NTS) or a traction (mortar: the
        weighted gap is a gap times a length).  The pair reads its multipliers
        through a multiplier space (:mod:`~skfem_mortar.contact.multiplier_spaces`:
        pressure, gap length, row scale, ``c``); the method names it with the
        optional attribute ``multiplier_space`` (a registered name), else the
        space follows from ``multiplier_kind``
        (:func:`~skfem_mortar.contact.multiplier_spaces.space_for`).
    multipliers_per_node : int
        Multipliers per slave node the method's gaps need (1: the normal; a
        pair with friction adds the tangential one itself).
    symmetric : bool
        Whether ``H`` of :meth:`evaluate` is symmetric (a second derivative of
        the gaps: True for the built-ins).
    has_history : bool
        Whether the method carries state from one load step to the next
        (then :meth:`state_dict` is not empty and a checkpoint keeps it).
    options : dict
        The user options it was built with, checked at construction
        (:func:`check_options`).
    """

    method: str
    multiplier_kind: str
    multipliers_per_node: int
    symmetric: bool
    has_history: bool
    options: dict

    def set_pinned(self, pinned: np.ndarray | None) -> None:
        """Slave nodes (bool per node) whose two dofs are prescribed against a
        rigid master: no unknown changes their gap, so they must be out of
        ``mask`` in every later :meth:`evaluate` (NTS masks them; mortar makes
        them crosspoints, their multiplier merged into the neighbour's).  None: none."""

    def set_reference(self, xs0: np.ndarray | None, xm0: np.ndarray | None) -> None:
        """The positions of the last converged state (at the first step: its
        start; None before).  Mortar's search reach is measured from them."""

    def begin_step(self, xs: np.ndarray, xm: np.ndarray, first: bool) -> None:
        """Start (or retry) a load step at these positions; ``first``: no step
        has converged before (no converged state to restore)."""

    def evaluate(self, xs: np.ndarray, xm: np.ndarray, lam: np.ndarray | None,
                 tangent: bool) -> ContactEval:
        """Gaps ``g`` of the slave nodes, ``G = dg/dx`` (if ``tangent``),
        ``H = sum_A lam_A d^2 g_A/dx^2`` (if ``tangent`` and ``lam`` is given),
        ``mask`` (nodes with a master partner), ``area`` (tributary lengths).
        Must not change the method's state (a line search calls it)."""
        raise NotImplementedError

    def after_iteration(self, ev: ContactEval) -> None:
        """Told the evaluation of a Newton iteration (with its tangent), after
        the active set's update (NTS: segment hysteresis, vertex trap)."""

    def tail_signal(self, lam: np.ndarray, ev: Any) -> tuple[np.ndarray | None, bool]:
        """What the extrapolated release of a tensile tail reads
        (:meth:`~skfem_mortar.contact.active_set.ActiveSet.update`): ``(signal per slave
        node, is_force)`` -- the multipliers ``(lam, False)``, or (standard mortar,
        whose multipliers alternate in sign at a too-wide edge) the normal nodal
        forces ``(f, True)``; ``(None, True)`` if ``ev`` has no ``G``."""
        return lam, False

    def end_step(self, xs: np.ndarray, xm: np.ndarray) -> None:
        """A load step has converged at these positions."""

    def step_info(self) -> dict:
        """Numbers to add to the step's record (e.g. NTS ``segment_locks``)."""
        return {}

    def failure_hint(self) -> str:
        """A likely cause of a failure that the geometry shows ("" if none known)."""
        return ""

    def state_dict(self) -> dict[str, np.ndarray]:
        """The state that shapes the next load step, as named arrays ({} if none)."""
        return {}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state_dict`: ValueError naming the entry that does not
        fit, and nothing changed then.  The pair has checked the key set."""


@runtime_checkable
class PatternedDiscretization(Protocol):
    """The optional hook of a :class:`ContactDiscretization`: a reserved pattern.

    Not part of :class:`ContactDiscretization` (a method without it still
    works); a :class:`~skfem_mortar.contact.pair.ContactPair` uses it when its
    method has it.
    """

    def pattern(self, xs: np.ndarray, xm: np.ndarray) -> sp.csr_matrix:
        """A superset of the local dofs each multiplier row can couple to.

        Returns a sparse matrix ``P (n_rows, 2 n_s + 2 n_m)`` (local dof order
        of :class:`~skfem_mortar.contact.contact_eval.ContactEval`) whose row
        ``A`` holds every dof ``d`` with ``G[A, d] != 0`` at any positions the
        iteration may reach before the search finds new candidate pairs, so

            nz(G) in nz(P),    nz(H) in union_A S_A x S_A,   S_A = nz(P[A, :]),

        (``H = sum_A lam_A d2 g_A / dx2`` couples only dofs ``g_A`` depends on).
        The method reserves with a margin beyond its search (e.g. the master
        segments within the search reach plus an element length) and returns
        the *same object* as long as the search at ``xs, xm`` finds no candidate
        pair outside the reservation; a new object means a new reservation.
        Called with the positions of a tangent evaluation, after :meth:`evaluate`;
        must not change what :meth:`evaluate` returns.
        """
        ...


@runtime_checkable
class MeasuredDiscretization(Protocol):
    """The optional hook of a :class:`ContactDiscretization` outside plane models.

    A method with it integrates with the weight ``w(x) dGamma`` of the model's
    geometry (:mod:`~skfem_mortar.contact.measures`: ``2 pi r`` in an
    axisymmetric model); a pair in a model of another geometry than plane
    refuses a method without it.
    """

    def set_measure(self, measure: Measure) -> None:
        """The weight of ``dGamma`` in the model's geometry, told by the pair
        when the model binds it, before any other hook."""
        ...


@runtime_checkable
class SymmetricDiscretization(Protocol):
    """The optional hook of a :class:`ContactDiscretization` for symmetry planes.

    A quarter or half model's symmetry planes ``normal . x = offset``
    (:mod:`~skfem_mortar.contact.symmetry`: declared on the pair, or read from the
    Dirichlet data), told by the pair once the prescribed dofs are known
    (``set_fixed``), before the first evaluation: a method with the hook treats the
    surfaces as mirrored there (NTS: a master edge on a plane is no free border;
    mortar: slave nodes on a plane take the mirror normal ``P s / |P s|``).  A method
    without it is told nothing.
    """

    def set_symmetry(self, planes: list) -> None:
        """The symmetry planes, a list of ``(unit normal, offset)`` (empty: none)."""
        ...


@runtime_checkable
class FrictionDiscretization(Protocol):
    """The hooks of a :class:`ContactDiscretization` that friction needs.

    The slip ``u_t`` of each slave node within the load step, relative to the
    converged state of the last step (:mod:`skfem_mortar.contact.slip`), and
    the history it is measured from.  Only a pair with a friction law calls
    them, so a frictionless pair keeps none of this.

    Attributes
    ----------
    slip_history_keys : tuple of str
        The names of :meth:`slip_history`'s arrays.
    """

    slip_history_keys: tuple

    def slip_history(self, xs: np.ndarray, xm: np.ndarray, ev: ContactEval
                     ) -> dict[str, np.ndarray]:
        """The history the slip of the next step is measured from, at a converged
        state (``ev`` the evaluation there), as named arrays (NTS ``xi_prev``,
        ``segment_prev``; mortar ``D_prev``, ``M_prev`` as COO triplets)."""
        ...

    def check_slip_history(self, history: dict[str, np.ndarray]) -> None:
        """ValueError naming the entry of ``history`` that does not fit."""
        ...

    def slip(self, xs: np.ndarray, xm: np.ndarray, history: dict[str, np.ndarray],
             lam_t: np.ndarray | None, tangent: bool, ev: ContactEval) -> Any:
        """The :class:`~skfem_mortar.contact.slip.SlipEval` at these positions with
        the same search results as ``ev`` (:meth:`ContactDiscretization.evaluate`'s
        at the same positions); its ``mask`` holds the nodes whose slip is
        defined.  Must not change the method's state."""
        ...

    def slip_pattern(self, history: dict[str, np.ndarray]) -> sp.csr_matrix:
        """Local dofs (``n_s x n_local``) the slip of each node couples to beyond
        the reserved normal row (:meth:`PatternedDiscretization.pattern`)."""
        ...


def covers(held: np.ndarray, needed: np.ndarray) -> bool:
    """Whether the sorted keys ``held`` (a reservation's candidate pairs) contain
    every key of ``needed`` (the current search's candidates)."""
    if needed.size == 0:
        return True
    if held.size == 0:
        return False
    pos = np.minimum(np.searchsorted(held, needed), held.size - 1)
    return bool(np.all(held[pos] == needed))


def reserved_keys(owner: str, keys: np.ndarray, n_keys: int) -> np.ndarray | None:
    """A checkpoint's reserved candidate keys: sorted unique integers in
    ``[0, n_keys)`` (ValueError naming the entry otherwise), None if empty."""
    a = np.asarray(keys)
    if a.size == 0:
        return None
    if (a.ndim != 1 or not np.issubdtype(a.dtype, np.integer) or a.min() < 0
            or a.max() >= n_keys or np.any(np.diff(a) <= 0)):
        raise ValueError(f"{owner}: checkpoint entry 'reserved' must be sorted unique "
                         f"integers in [0, {n_keys})")
    return a.astype(np.int64)


def pattern_matrix(rows: np.ndarray, cols: np.ndarray, shape: tuple[int, int]
                   ) -> sp.csr_matrix:
    """The 0/1 csr matrix (sorted, no duplicates) with ones at ``(rows, cols)``."""
    P = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=shape)
    P.sum_duplicates()
    P.data[:] = 1.0
    return P


#: factory(slave, master, pair_name=..., **options) -> ContactDiscretization
Factory = Callable[..., ContactDiscretization]

_REGISTRY: dict[str, Factory] = {}

#: the registered method names (a live view, in registration order)
METHODS = _REGISTRY.keys()


def register_method(name: str, factory: Factory) -> None:
    """Make ``ContactPair(..., method=name)`` build its discretization with
    ``factory(slave, master, pair_name=<the pair's name>, **options)``
    (``options``: the pair's extra keywords, plus ``segmentation`` when it
    is not the default).  A name is registered once (ValueError otherwise)."""
    if not isinstance(name, str) or not name:
        raise ValueError(f"a method name must be a non-empty string, got {name!r}")
    if name in _REGISTRY:
        raise ValueError(f"method {name!r} is registered already")
    if not callable(factory):
        raise ValueError(f"the factory of method {name!r} must be callable")
    _REGISTRY[name] = factory


def unregister_method(name: str) -> None:
    """Forget a registered method (KeyError if it is not registered)."""
    del _REGISTRY[name]


def registered_methods() -> tuple[str, ...]:
    return tuple(_REGISTRY)


def make_method(method: str, slave: Any, master: Any, pair_name: str = "contact",
                **options: Any) -> ContactDiscretization:
    """The discretization of the registered ``method`` (ValueError naming the
    registered ones if it is not; the method checks its options)."""
    if method not in _REGISTRY:
        raise ValueError(f"method must be one of {', '.join(_REGISTRY)}, got {method!r}")
    out = _REGISTRY[method](slave, master, pair_name=pair_name, **options)
    if not isinstance(out, ContactDiscretization):
        raise TypeError(f"the factory of method {method!r} returned {type(out).__name__}, "
                        "which lacks hooks of ContactDiscretization")
    if out.multiplier_kind not in ("force", "traction"):
        raise ValueError(f"method {method!r}: multiplier_kind must be 'force' or 'traction', "
                         f"got {out.multiplier_kind!r}")
    name = getattr(out, "multiplier_space", None)
    if name is not None and name not in registered_spaces():
        raise ValueError(f"method {method!r}: multiplier_space must be one of "
                         f"{', '.join(registered_spaces())}, got {name!r}")
    if out.multipliers_per_node != 1:
        raise ValueError(f"method {method!r}: {out.multipliers_per_node} multipliers per node; "
                         "a ContactPair takes 1 (the normal one; its friction law adds the "
                         "tangential ones)")
    return out


#: the keywords ``ContactPair`` takes itself (a misspelt one reaches the method's options)
PAIR_KEYWORDS = ("method", "name", "c", "cycle_guard", "touch_tolerance", "segmentation",
                 "accelerate", "friction")

#: option name -> (check, allowed range as said in the refusal)
OptionTable = dict[str, tuple[Callable[[Any], Any], str]]


def check_options(method: str, options: dict, allowed: OptionTable) -> None:
    """Refuse an unknown or out-of-range option (ValueError naming it)."""
    for k, v in options.items():
        if k in PAIR_KEYWORDS and k not in allowed:  # a pair keyword the pair hands on
            raise ValueError(f"{k}={v!r} does not apply to method {method!r} (its options "
                             f"are {sorted(allowed)})")
        if k not in allowed:
            close = difflib.get_close_matches(k, list(allowed) + list(PAIR_KEYWORDS), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ValueError(f"unknown option {k!r} for method {method!r}: ContactPair takes "
                             f"{', '.join(PAIR_KEYWORDS)}, and method {method!r} the options "
                             f"{sorted(allowed)}{hint}")
        check, what = allowed[k]
        try:
            ok = bool(check(v))
        except TypeError:
            ok = False
        if not ok:
            raise ValueError(f"{k} must be {what}, got {v!r}")


def check_entries(owner: str, state: dict[str, np.ndarray],
                  shapes: dict[str, list[tuple]]) -> None:
    """Checkpoint entries of the allowed shapes and finite (ValueError naming the entry)."""
    for k, ok in shapes.items():
        a = np.asarray(state[k])
        if a.shape not in ok:
            raise ValueError(f"{owner}: checkpoint entry {k!r} has shape {a.shape}, "
                             f"expected one of {ok}")
        if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
            raise ValueError(f"{owner}: checkpoint entry {k!r} is not finite")

