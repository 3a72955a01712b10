"""The item protocol: what every part of a model (a body, a load, a boundary
condition, a contact pair) offers the solver, and what it returns.

:class:`Contribution` is an item's share of the global residual and tangent,
:class:`Item` the declared hooks with their defaults (:class:`ItemProtocol` the
same contract as a structural type); :class:`Output`, :class:`Body` and
:class:`ContactTable` are what the output layer and the solver read of some
items besides.  The items are summed by :class:`~skfem_mortar.core.model.Model`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable, Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp

from .coo import element_coo

__all__ = ["Contribution", "Item", "ItemProtocol", "Output", "Body", "ContactTable"]


@dataclass
class Contribution:
    """One item's share of the global residual and tangent, in global indices.

    Residual entries ``(r_index, r_value)`` are summed (duplicates add up);
    the tangent is given as COO triplets ``(k_rows, k_cols, k_vals)``.
    ``reserved``: the triplet indices are a reservation (a contact pair over its
    reserved pattern): they repeat, as the same arrays, until the reservation
    changes, so the model rebuilds its fixed pattern when they change instead of
    summing them apart (:meth:`Model._tangent`).
    ``k_elements``: optional, the element dofs ``(n_loc, n_el)`` the triplet
    indices were made of, ``element_coo(k_elements, elements_last=True)``
    (:func:`~skfem_mortar.core.coo.element_coo`): the model then finds their
    pattern per node instead of per triplet (:func:`_element_keys`).
    """

    r_index: np.ndarray
    r_value: np.ndarray
    k_rows: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    k_cols: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    k_vals: np.ndarray = field(default_factory=lambda: np.zeros(0))
    reserved: bool = False
    k_elements: np.ndarray | None = None

    @classmethod
    def empty(cls) -> "Contribution":
        return cls(np.zeros(0, dtype=np.int64), np.zeros(0))

    @classmethod
    def from_local(cls, offset: int, r: np.ndarray,
                   K: sp.spmatrix | None = None) -> "Contribution":
        """Wrap a residual vector and a sparse tangent on a contiguous block.

        ``r`` and ``K`` are numbered locally (0 .. n-1) and shifted by ``offset``.
        """
        idx = offset + np.arange(len(r), dtype=np.int64)
        if K is None:
            return cls(idx, np.asarray(r, dtype=float))
        K = K.tocoo()
        return cls(idx, np.asarray(r, dtype=float),
                   K.row.astype(np.int64) + offset,
                   K.col.astype(np.int64) + offset, K.data)

    @classmethod
    def from_dofs(cls, dofs: np.ndarray, r: np.ndarray, k: np.ndarray | None = None
                  ) -> "Contribution":
        """Element-wise arrays: ``dofs`` (n_el, n_loc) global indices,
        ``r`` (n_el, n_loc) and ``k`` (n_el, n_loc, n_loc) element residuals and tangents.
        """
        dofs = np.asarray(dofs, dtype=np.int64)
        out = cls(dofs.ravel(), np.asarray(r, dtype=float).ravel())
        if k is not None:
            out.k_rows, out.k_cols = element_coo(dofs)
            out.k_vals = np.asarray(k, dtype=float).ravel()
        return out

    @classmethod
    def concat(cls, parts: Iterable["Contribution"]) -> "Contribution":
        parts = list(parts)
        if not parts:
            return cls.empty()
        return cls(*(np.concatenate([getattr(p, a) for p in parts])
                     for a in ("r_index", "r_value", "k_rows", "k_cols", "k_vals")))


class Item:
    """Base class of everything a model is made of: the declared item protocol.

    The solver (:class:`Model`, :mod:`~skfem_mortar.solver.newton`,
    :mod:`~skfem_mortar.solver.stepping`) calls only the hooks declared here, never
    a method it has to look for; every hook has a default, so an item
    overrides only what it needs (a load: :meth:`assemble`; a boundary
    condition: :meth:`prescribed`; a contact pair: most of them).
    :class:`ItemProtocol` states the same contract as a ``typing.Protocol``.

    The order of the calls in one solve::

        Model(items)                  referenced_bodies, dof_kind, n_dofs -> offset
                                      (written again at each use: Model.bind)
        solve: prescribed(start)      the fixed dofs of the start state
               preflight              reads the items (skfem_mortar.contact.preflight)
               per attempt of a step:
                   set_fixed(fixed)   the dofs prescribed in this step
                   begin_step(z, lf)
                   assemble(z, lf, tangent)   every Newton iteration, line search
                   settled()          until the discrete state stops changing
                   violation(z, scale)        once the residual has converged
               per converged step: end_step(z, lf), step_info()
               per checkpoint:     state_dict() / load_state_dict(state)
               step given up:      failure_hint()

    Attributes
    ----------
    name : str
        Unique name within the model (used in output file names and logs).
    dof_kind : {"u", "lam", None}
        Whether the item owns displacement unknowns, multiplier unknowns or none.
    n_dofs : int
        How many unknowns the item owns.
    offset : int
        Global index of the item's first unknown (set by :class:`Model`:
        by the model used last when the item is in several, :meth:`Model.bind`).
    phase : str
        Timing bucket of its assembly: "bulk", "contact" or "loads".
    symmetric : bool
        Declaration: the tangent the item assembles is symmetric (a
        hyperelastic body: yes; a follower load or a contact pair with its
        complementarity rows: no).  Default True.
    loaded : bool
        Declaration: the item's residual depends on the load factor (a load;
        a user's item by default).  Bodies and contact pairs declare False, so
        the step's load increment (:func:`~skfem_mortar.solver.newton.step_scale`)
        assembles only the loads.
    per_thickness : bool
        Declaration: the item's residual and tangent are per unit reference
        thickness (bodies, tractions, pressures, contact), so the model
        multiplies them by its thickness ``H``; False for forces that are
        totals already (:class:`~skfem_mortar.loads.traction.PointLoad`).
        Default True.
    thickness : float
        Set by the :class:`Model` the item is in: the model's thickness ``H``
        for a :attr:`per_thickness` item, else 1.  Items whose helpers report
        forces (``ContactPair.forces``, ``FollowerPressure.resultant``,
        ``TiePair.forces``) multiply them by it, so that those are totals over
        ``H`` like the model's residual and reactions.  Default 1 (an item in
        no model); an item in several models has that of the one used last.
    geometry : str
        Set by the :class:`Model` the item is in: its geometry, ``"plane"``,
        ``"axisymmetric"`` or ``"3d"`` (:mod:`~skfem_mortar.core.geometry`).
        Default ``"plane"`` (an item in no model).  A body whose integrals
        depend on it rebuilds what it caches when it changes.
    geometries : tuple of str or None
        Declaration: the geometries the item works in; a model of another
        geometry refuses it, naming it.  Default None: any (a user's item).
    has_history : bool
        Declaration: the item carries state from one load step to the next
        (an active set), i.e. it keeps a :meth:`state_dict`.  Default: whether
        the class overrides :meth:`state_dict`.
    """

    name: str = ""
    dof_kind: str | None = None
    n_dofs: int = 0
    offset: int = 0
    phase: str = "bulk"
    symmetric: bool = True
    loaded: bool = True
    per_thickness: bool = True
    thickness: float = 1.0
    geometry: str = "plane"
    geometries: tuple[str, ...] | None = None

    @property
    def has_history(self) -> bool:
        # a class declares it with ``has_history = True/False`` (an instance may
        # set it too); the default reads what the class does: a state to
        # checkpoint is a history
        declared = self.__dict__.get("_has_history")
        return type(self).state_dict is not Item.state_dict if declared is None else declared

    @has_history.setter
    def has_history(self, value: bool) -> None:
        self.__dict__["_has_history"] = bool(value)

    # -- assembly ---------------------------------------------------------
    def assemble(self, z: np.ndarray, load_factor: float,
                 tangent: bool = True) -> Contribution:
        """Residual contribution and (if ``tangent``) its derivative at ``z``.

        A call with ``tangent=False`` is a trial evaluation (line search) and
        must not change the item's state (e.g. an active set).
        """
        return Contribution.empty()

    def prescribed(self, load_factor: float) -> tuple[np.ndarray, np.ndarray] | None:
        """Global dofs fixed by this item and their values at ``load_factor``."""
        return None

    def referenced_bodies(self) -> list["Item"]:
        """The bodies this item acts on (its ``body``), which must be in the same
        :class:`Model`.  The preflight (:mod:`skfem_mortar.contact.preflight`) also reads
        them, with :attr:`dof_kind`, :meth:`prescribed` and the contact pairs'
        surfaces, to refuse a model that cannot work before the first step."""
        body = getattr(self, "body", None)
        return [body] if isinstance(body, Item) else []

    # -- hooks of the load stepping --------------------------------------
    def set_fixed(self, fixed: np.ndarray) -> None:
        """The global dofs prescribed in the coming step, before each attempt
        (a contact pair drops its slave nodes that are pinned)."""

    def begin_step(self, z: np.ndarray, load_factor: float) -> None:
        """Called before each attempt of a load step (``z`` is the last converged state)."""

    def end_step(self, z: np.ndarray, load_factor: float) -> None:
        """Called once a load step has converged.  May clean its own unknowns in
        ``z`` in place (a contact pair sets its inactive multipliers to exact 0)."""

    def settled(self) -> bool:
        """False while the item's discrete state (an active set) still changes."""
        return True

    def step_info(self) -> dict:
        """Numbers to keep per converged step (e.g. ``n_active``); summed over
        the items into the step's record."""
        return {}

    def violation(self, z: np.ndarray, scale: float) -> str:
        """Why ``z`` violates the item's own conditions ("" if it does not).

        Asked by Newton once the residual has passed its test; a non-empty
        answer makes the attempt fail (the step is cut), never a converged
        step.  ``scale`` is the step's force scale (newton module docstring).
        """
        return ""

    def failure_hint(self) -> str:
        """What to try when a step cannot converge even at the smallest
        increment ("" for nothing to say); added to the ConvergenceError."""
        return ""

    # -- checkpoint ---------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """Everything of the item that shapes the next load step (active sets,
        segment preferences, scales), as named arrays for a checkpoint; ``{}``
        for a stateless item.  ``load_state_dict(state_dict())`` restores it."""
        return {}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`state_dict` returned (ValueError if it does not fit)."""
        if state:
            raise ValueError(f"{self.name}: this item keeps no state, got {sorted(state)}")

    # -- output (read by the output layer only) ----------------------------
    def outputs(self) -> list["Output"]:
        """What the output layer writes and draws for this item, as
        :class:`Output` objects (one series each).

        Default: the item itself if it is an :class:`Output` (a body), else
        nothing; a contact pair offers its slave surface
        (:meth:`skfem_mortar.contact.pair.ContactPair.outputs`).
        """
        return [self] if isinstance(self, Output) else []

    @property
    def dofs(self) -> slice:
        """Global slice of the unknowns this item owns."""
        return slice(self.offset, self.offset + self.n_dofs)


class ItemProtocol(Protocol):
    """The hooks the solver calls on every item, as a structural type (the
    contract :class:`Item` implements with defaults; see its docstring).
    A model still takes only :class:`Item` subclasses."""

    name: str
    dof_kind: str | None
    n_dofs: int
    offset: int
    phase: str
    symmetric: bool
    loaded: bool
    has_history: bool

    def assemble(self, z: np.ndarray, load_factor: float,
                 tangent: bool = True) -> Contribution: ...
    def prescribed(self, load_factor: float) -> tuple[np.ndarray, np.ndarray] | None: ...
    def referenced_bodies(self) -> list: ...
    def set_fixed(self, fixed: np.ndarray) -> None: ...
    def begin_step(self, z: np.ndarray, load_factor: float) -> None: ...
    def end_step(self, z: np.ndarray, load_factor: float) -> None: ...
    def settled(self) -> bool: ...
    def step_info(self) -> dict: ...
    def violation(self, z: np.ndarray, scale: float) -> str: ...
    def failure_hint(self) -> str: ...
    def state_dict(self) -> dict[str, np.ndarray]: ...
    def load_state_dict(self, state: dict[str, np.ndarray]) -> None: ...
    def outputs(self) -> list: ...


@runtime_checkable
class Output(Protocol):
    """The output protocol: something written as one PVD/VTU series and drawn
    (a body, a contact pair's slave surface).  Used only by the output layer
    (:mod:`skfem_mortar.solver.observers`, :mod:`skfem_mortar.output.plot`)."""

    name: str

    def output_mesh(self) -> tuple[np.ndarray, list[tuple[str, np.ndarray]]]:
        """Reference points (N, 2) and meshio cell blocks ``[(type, cells)]``."""
        ...

    def output_data(self, z: np.ndarray) -> tuple[dict, dict]:
        """``(point_data, cell_data)`` at the unknowns ``z``; point data may hold
        ``displacement`` (N, 2), which pictures add to the points."""
        ...


@runtime_checkable
class Body(Protocol):
    """The body protocol: what the solver and the contact layer read of an item
    with ``dof_kind == "u"`` besides the :class:`Item` hooks (a
    :class:`~skfem_mortar.bodies.solid.Solid`, a
    :class:`~skfem_mortar.bodies.cable.Cable`).  An item that does not offer it
    still solves; it just lends no length to the round-off floor
    (:func:`skfem_mortar.solver.newton.round_off_floor`).  A body that carries a
    contact surface also has ``X`` (reference vertex coordinates, ``(2, n_nodes)``)
    and ``node_dofs`` (:class:`~skfem_mortar.contact.surfaces.ContactSurface`)."""

    name: str

    def x(self, z: np.ndarray) -> np.ndarray:
        """Current vertex coordinates ``X + u`` at the unknowns ``z``, ``(2, n_nodes)``."""
        ...


@runtime_checkable
class ContactTable(Protocol):
    """An item that reports contact per slave node (``contact.csv``, the
    pressure in pictures): a contact pair.  Used only by the output layer."""

    name: str

    def contact_data(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """Arrays ``x, y, gap, pressure, ...`` per slave node at ``z``."""
        ...

