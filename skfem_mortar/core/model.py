"""Model items, the global unknown layout and the assembly of residual and tangent.

The global unknown vector is ``z = [u; lam]``: first the displacement blocks of
all bodies, then the multiplier blocks of all contact pairs.  Every *item* of a
model (a body, a load, a boundary condition, a contact pair) contributes to the
residual ``R(z, load_factor)`` and to its tangent ``K = dR/dz``.  Equilibrium is
``R = 0`` with the sign convention

    R = f_int(u) - f_ext(u, load_factor) + (contact forces) ,

so that loads enter with a minus sign and ``K`` is the usual stiffness.  The
solver knows nothing about what an item is: adding a new kind of body, load or
contact pair means adding one item class.
"""
from __future__ import annotations

import time
import weakref
from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Protocol, Sequence, runtime_checkable

import numpy as np
import scipy.sparse as sp

from .binding import bind, claim, layout
from .coo import element_coo
from .validate import real

# Dirichlet (core.dirichlet) is still offered here, lazily (module __getattr__)
__all__ = ["Contribution", "Item", "ItemProtocol", "Output", "Body", "ContactTable", "Model",
           "register_check"]


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


def __getattr__(name: str) -> Any:
    # Dirichlet lives in .dirichlet (it subclasses Item); imported from here as before
    if name == "Dirichlet":
        from .dirichlet import Dirichlet
        return Dirichlet
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _check_items(items: list[Item]) -> None:
    """Every entry an Item, none listed twice (its load or stiffness would count
    twice), every body an item refers to in the list."""
    for k, it in enumerate(items):
        if not isinstance(it, Item):
            raise ValueError(f"items[{k}] is not a model item (a body, load, boundary "
                             f"condition or contact pair), got {type(it).__name__}")
    seen: dict[int, int] = {}
    for k, it in enumerate(items):
        if id(it) in seen:
            raise ValueError(f"items[{seen[id(it)]}] and items[{k}] are the same item "
                             f"{it.name!r}: list each item once (twice would count it twice)")
        seen[id(it)] = k
    for it in items:
        for body in it.referenced_bodies():
            if id(body) not in seen:
                raise ValueError(f"item {it.name!r} acts on body {body.name!r}, which is not "
                                 f"in the model: add the body to the items")


#: the model-wide checks :meth:`Model.preflight` runs (see :func:`register_check`)
_MODEL_CHECKS: list[Callable[["Model", np.ndarray, float, np.ndarray], None]] = []


def register_check(check: Callable[["Model", np.ndarray, float, np.ndarray], None]) -> None:
    """Add ``check(model, z, load_factor, fixed)`` to what :meth:`Model.preflight`
    runs (once: registering the same function again does nothing).  A check
    raises ValueError to refuse the model and may warn."""
    if check not in _MODEL_CHECKS:
        _MODEL_CHECKS.append(check)


def check_thickness(thickness: float) -> float:
    """``thickness`` as a float, ValueError unless a finite real number > 0 (a
    string such as ``"2"`` or a bool is refused, not converted)."""
    return real("thickness", thickness, 0.0, low_open=True)


def _times(c: Contribution, H: float) -> Contribution:
    """``c`` with its residual and tangent values multiplied by ``H`` (the same index arrays)."""
    return Contribution(c.r_index, H * c.r_value, c.k_rows, c.k_cols, H * c.k_vals,
                        k_elements=c.k_elements)


class Model:
    """A list of items with a global unknown layout.

    Items with ``dof_kind == "u"`` get the first blocks (in the given order),
    items with ``dof_kind == "lam"`` the blocks after them.

    Parameters
    ----------
    items : sequence of Item
    thickness : float
        The reference thickness ``H`` (finite, > 0; default 1), for plane strain
        and plane stress alike.  Every item that declares
        :attr:`Item.per_thickness` (bodies, tractions, follower pressures,
        contact pairs) works per unit reference thickness; the model multiplies
        its residual and tangent by ``H`` (:meth:`assemble`), so

            R = H (f_int - f_traction - f_pressure + G^T lam ; C(lam, g)) - f_point

        and point loads, reactions (the residual at prescribed dofs) and the
        contact forces in ``R`` are totals over ``H``, while stresses,
        tractions, follower and contact pressures stay per unit length per
        unit reference thickness (the out-of-plane stretch of plane stress
        changes no loaded area).  The multipliers keep their meaning: the
        multiplier rows ``C(lam, g) = 0`` are the same equations (times ``H``,
        a row scaling that leaves every Newton step unchanged and keeps all
        rows in total-force units); a mortar multiplier is a contact pressure,
        an NTS multiplier a nodal force per unit thickness (``H lam`` its
        total).  The model hands ``H`` to its items (:attr:`Item.thickness`),
        so their force helpers (``ContactPair.forces`` and ``total_force``,
        ``TiePair.forces``, ``FollowerPressure.resultant``) are totals too;
        a body's ``internal_force`` (its element residual) stays per unit
        thickness.  With ``H = 1`` nothing is multiplied.

    Raises
    ------
    ValueError
        For an item that is not an :class:`Item` or is listed twice, a body an
        item acts on that is missing, repeated body or pair names, or a
        ``thickness`` that is not finite and > 0; at any use, for a model one
        of whose items with a history (a contact pair) a later model took.

    Notes
    -----
    Bodies, loads and boundary conditions may be in several models (one model
    per contact method on the same bodies): each model writes its own layout
    (offsets, thickness) into its items whenever it is used (:meth:`bind`), so
    solving one model after building or solving another gives its own answer.
    An item with a history (:attr:`Item.has_history`: a contact pair) belongs
    to the model built last with it (:mod:`~skfem_mortar.core.binding`).
    """

    def __init__(self, items: Sequence[Item], thickness: float = 1.0):
        self.thickness = check_thickness(thickness)
        items = list(items)
        _check_items(items)
        # bodies and contact pairs name output files and blocks: their names are unique
        names = [it.name for it in items if it.dof_kind is not None]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"body and contact pair names must be unique, repeated: "
                             f"{sorted(dup)}")
        self._items = items
        self._ref = weakref.ref(self)  # the token of the layout the items hold
        claim(self._ref, items)  # an item with a history belongs to this model now
        # the model's own layout (offsets, thickness), written into the items
        # at every use (bind): a body may be in several models
        self._layout, self.n_u, self.n = layout(items, self.thickness)
        self.n_lam = self.n - self.n_u
        self.bind()
        self.timers: dict[str, float] = defaultdict(float)
        # tangent assembly cache (see _tangent): the last index arrays of every
        # item, and the CSR pattern of the items whose indices did not change
        self._last_idx: list[tuple[np.ndarray, np.ndarray] | None] = [None] * len(items)
        self._varying = np.zeros(len(items), dtype=bool)
        self._pattern: _Pattern | None = None
        #: how often the fixed pattern was built (the first time and at each
        #: change of a stable item's indices, e.g. a new contact reservation)
        self.pattern_builds = 0

    @property
    def items(self) -> list[Item]:
        """The items, in the order given; reading them makes this model's
        layout the items' own (:meth:`bind`), so every use of the model (the
        solve's hooks, assembly, preflight, outputs, checkpoints) sees it."""
        self.bind()
        return self._items

    def bind(self) -> "Model":
        """Write this model's layout into its items (each body's and contact
        pair's ``offset``, every item's ``thickness``) unless they hold it
        already (an identity check per item); returns the model.

        A body may be in several models (one per contact method, say): each
        model binds at every use, so solving one after building or solving
        another gives its own answer.  Call it before an item's own helper on
        a state of this model (``body.x(z)``) after another model sharing the
        item was used; a contact pair's helpers can bind their one model
        themselves (:func:`~skfem_mortar.core.binding.rebind`)."""
        bind(self, self._ref, self._layout)
        return self

    # -- checkpoint ---------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """Which items' tangent index arrays have varied (their triplets are summed
        apart from the fixed pattern): with it a resumed run sums every tangent
        in the same order as an uninterrupted one, so it repeats its solves to
        the last bit; and the ``thickness`` the states were computed with."""
        return {"varying": self._varying.copy(), "thickness": np.array(self.thickness)}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state_dict` (ValueError if it does not fit this model:
        other items, or another thickness; a state without ``thickness``, from
        before it existed, is one of thickness 1)."""
        v = np.asarray(state.get("varying", np.zeros(0)))
        if (not {"varying"} <= set(state) <= {"varying", "thickness"}
                or v.shape != self._varying.shape or v.dtype != bool):
            raise ValueError(f"model state must be {{'varying': bool ({len(self.items)},), "
                             f"'thickness': float}}, got {sorted(state)} with shape {v.shape}")
        H = float(np.asarray(state.get("thickness", 1.0)))
        if H != self.thickness:
            raise ValueError(f"model state was computed with thickness {H:g}, this model "
                             f"has thickness {self.thickness:g}")
        self._varying = v.copy()
        self._last_idx = [None] * len(self.items)
        self._pattern = None

    # -- queries -----------------------------------------------------------
    def item(self, name: str) -> Item:
        for it in self.items:
            if it.name == name:
                return it
        raise KeyError(name)

    @property
    def bodies(self) -> list[Item]:
        """The items with displacement unknowns (``dof_kind == "u"``), in order;
        those that are a :class:`Body` also give their vertex positions."""
        return [it for it in self.items if it.dof_kind == "u"]

    @property
    def symmetric(self) -> bool:
        """Whether every item declares a symmetric tangent (:attr:`Item.symmetric`)."""
        return all(it.symmetric for it in self.items)

    @property
    def symmetrizable(self) -> bool:
        """Whether the tangent is symmetric but for the multiplier rows of the
        contact pairs: every item declares a symmetric tangent, or (a contact
        pair) ``symmetrizable`` (its rows ``c G`` are a multiple of its columns
        ``-G^T`` and its ``H`` is symmetric), so scaling those rows makes the
        system symmetric (:func:`~skfem_mortar.solver.linsolve.symmetrize`)."""
        return all(it.symmetric or getattr(it, "symmetrizable", False) for it in self.items)

    def analysis_coupling(self, z: np.ndarray, free: np.ndarray
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The contact pairs' :meth:`~skfem_mortar.contact.pair.ContactPair.analysis_coupling`
        in the numbering of the free unknowns ``free`` (entries on prescribed
        unknowns dropped), or None without such items: for the linear solver's
        analysis of a symmetrized system only."""
        parts = [it.analysis_coupling(z) for it in self.items if hasattr(it, "analysis_coupling")]
        if not parts:
            return None
        at = np.full(self.n, -1, dtype=np.int64)
        at[free] = np.arange(free.size)
        r, c, v = (np.concatenate(a) for a in zip(*parts))
        keep = (at[r] >= 0) & (at[c] >= 0)
        return at[r[keep]], at[c[keep]], v[keep]

    def outputs(self) -> list[Output]:
        """Every item's :meth:`Item.outputs`, in the order of the items."""
        return [o for it in self.items for o in it.outputs()]

    def contact_tables(self) -> list[ContactTable]:
        """The items that report contact per slave node (the contact pairs)."""
        return [it for it in self.items if isinstance(it, ContactTable)]

    def zeros(self) -> np.ndarray:
        return np.zeros(self.n)

    def __repr__(self) -> str:
        """One line: the items by kind and the unknowns ``n = n_u + n_lam``."""
        kinds = [it.dof_kind for it in self._items]  # (no binding: a repr changes nothing)
        counts = {"u": kinds.count("u"), "lam": kinds.count("lam"), None: kinds.count(None)}
        tail = "" if self.thickness == 1.0 else f", thickness {self.thickness:g}"
        return (f"Model({len(self._items)} items: {counts['u']} with displacements, "
                f"{counts['lam']} with multipliers, {counts[None]} loads and constraints; "
                f"{self.n} unknowns = {self.n_u} displacements + {self.n_lam} multipliers{tail})")

    # -- checks --------------------------------------------------------------
    def preflight(self, z: np.ndarray, load_factor: float, fixed: np.ndarray) -> None:
        """Refuse, before the first load step, a model that cannot work (ValueError
        naming the item and the fix): contact surfaces that do not face each
        other, rigid modes held by nothing; warn where a method is known to fail.
        ``fixed``: the prescribed global dofs.

        Runs the model-wide checks of :func:`register_check`, in the order they
        were registered: the contact layer registers its own
        (:mod:`skfem_mortar.contact.preflight`) when it is imported, and
        :func:`skfem_mortar.solver.stepping.solve` imports it, so a solve runs
        them all (the core names no layer below it)."""
        z, fixed = np.asarray(z, dtype=float), np.asarray(fixed)
        for check in _MODEL_CHECKS:
            check(self, z, float(load_factor), fixed)

    # -- assembly ----------------------------------------------------------
    def prescribed(self, load_factor: float) -> tuple[np.ndarray, np.ndarray]:
        """All prescribed global dofs and their values (conflicts raise ValueError)."""
        dofs, vals = [np.zeros(0, dtype=np.int64)], [np.zeros(0)]
        for it in self.items:
            p = it.prescribed(load_factor)
            if p is not None:
                dofs.append(np.asarray(p[0], dtype=np.int64))
                vals.append(np.asarray(p[1], dtype=float))
        d, v = np.concatenate(dofs), np.concatenate(vals)
        ud, inv = np.unique(d, return_inverse=True)
        uv = np.zeros(len(ud))
        uv[inv] = v
        if len(ud) < len(d) and not np.allclose(uv[inv], v, rtol=1e-12, atol=0.0):
            raise ValueError("the same dof is prescribed twice with different values")
        return ud, uv

    def load_residual(self, z: np.ndarray, load_factor: float) -> np.ndarray:
        """The residual of the items whose residual depends on the load factor
        (``loaded``) at ``z``: ``-f_ext(z, load_factor)`` (trial evaluations)."""
        parts = [self._per_thickness(it, it.assemble(z, load_factor, tangent=False))
                 for it in self.items if it.loaded]
        if not parts:
            return np.zeros(self.n)
        return np.bincount(np.concatenate([p.r_index for p in parts]),
                           weights=np.concatenate([p.r_value for p in parts]),
                           minlength=self.n)

    def _per_thickness(self, item: Item, c: Contribution) -> Contribution:
        """``c`` times the thickness if ``item`` works per unit thickness (class doc)."""
        if self.thickness == 1.0 or not item.per_thickness:
            return c
        return _times(c, self.thickness)

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> tuple[np.ndarray, sp.csr_matrix | None, float]:
        """Sum all contributions (those of :attr:`Item.per_thickness` items times
        the thickness ``H``).

        Returns
        -------
        R : ndarray (n,)
            Global residual.
        K : csr_matrix (n, n) or None
            Global tangent dR/dz, built once from all COO triplets.
        scale : float
            The largest norm of a single item's residual: a force scale used by
            the solver for relative convergence checks (units-free).
        """
        parts = []
        scale = 0.0
        for it in self.items:
            t0 = time.perf_counter()
            c = self._per_thickness(it, it.assemble(z, load_factor, tangent))
            self.timers[it.phase] += time.perf_counter() - t0
            if c.r_value.size:
                scale = max(scale, float(np.linalg.norm(c.r_value)))
            parts.append(c)
        t0 = time.perf_counter()
        R = np.bincount(np.concatenate([p.r_index for p in parts]),
                        weights=np.concatenate([p.r_value for p in parts]), minlength=self.n)
        K = self._tangent(parts) if tangent else None
        self.timers["bulk"] += time.perf_counter() - t0
        return R, K, scale

    def _tangent(self, parts: list[Contribution]) -> sp.csr_matrix:
        """Sum the tangent triplets of all items into one CSR matrix.

        Items whose index arrays have equalled those of their previous call at
        every call so far (bodies, loads: a fixed mesh; every item at its first
        call), and items whose indices are a reservation
        (:attr:`Contribution.reserved`: a contact pair over its reserved
        pattern), are *stable*: their values are summed with one ``bincount``
        into a CSR pattern (no sorting of COO triplets per iteration), which is
        built again only when the indices of one of them change (each item's
        own sorted keys are kept, so a new reservation costs a merge, not a
        sort of every triplet).  An item whose indices changed without a
        reservation (a contact method without the pattern hook) is *varying*
        from then on; its triplets go through a COO to CSR conversion of their
        own, added at the end (and the sum's pattern changes with them).
        While no item varies, the returned matrix is the pattern's
        (:meth:`free_block` then gathers its free part from a cached index).
        """
        stable = []
        for i, c in enumerate(parts):
            if self._varying[i]:
                continue
            last = self._last_idx[i]
            self._last_idx[i] = (c.k_rows, c.k_cols)
            # an item is taken as stable from its first call on, so the order in
            # which entries are summed depends only on which items have varied
            # (the state a checkpoint keeps), not on how many calls came before
            if (last is None or c.reserved
                    or (_same(last[0], c.k_rows) and _same(last[1], c.k_cols))):
                stable.append(i)
            else:
                self._varying[i] = True
                self._last_idx[i] = None
        stable = tuple(i for i in stable if parts[i].k_vals.size)
        pat = self._pattern
        if stable and (pat is None or pat.items != stable
                       or any(not (_same(pat.idx[j][0], parts[i].k_rows)
                                   and _same(pat.idx[j][1], parts[i].k_cols))
                              for j, i in enumerate(stable))):
            pat = self._pattern = _Pattern(stable, [parts[i] for i in stable], self.n, pat)
            self.pattern_builds += 1
        elif stable:  # equal indices, maybe new arrays (a body bound again): keep
            # these, so that the next check is an identity test again
            pat.idx = [(parts[i].k_rows, parts[i].k_cols) for i in stable]
        if not stable:
            pat = None
        rest = [p for i, p in enumerate(parts) if pat is None or i not in pat.items]
        rest = [p for p in rest if p.k_vals.size]
        K = None
        if pat is not None:
            K = pat.matrix([parts[i].k_vals for i in pat.items])
        if rest or K is None:
            Kr = sp.coo_matrix((_cat([p.k_vals for p in rest], float),
                                (_cat([p.k_rows for p in rest], np.int64),
                                 _cat([p.k_cols for p in rest], np.int64))),
                               shape=(self.n, self.n)).tocsr()
            K = Kr if K is None else K + Kr
        return K

    def free_block(self, K: sp.csr_matrix, free: np.ndarray) -> sp.csr_matrix:
        """``K[free][:, free]``; for the matrix of the fixed pattern (no item
        varies) gathered with an index cached with the pattern and the free
        dofs, so its ``indptr`` and ``indices`` are the same (read-only) memory
        while both repeat (a linear solver then keeps its analysis)."""
        pat = self._pattern
        if pat is not None and pat.last is not None and K is pat.last:
            return pat.restrict(K, np.asarray(free))
        return K[free][:, free]


def _cat(arrays: list[np.ndarray], dtype) -> np.ndarray:
    return np.concatenate(arrays) if arrays else np.zeros(0, dtype=dtype)


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a is b or (a.shape == b.shape and np.array_equal(a, b))


def _unique_keys(rows: np.ndarray, cols: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Sorted unique keys ``row * n + col`` of triplets and the place of each
    triplet among them (``keys[inv] == row * n + col``).

    Our own counting sort instead of ``np.argsort`` of the keys: scipy's
    ``coo_tocsr`` buckets the triplet numbers by row (linear) and
    ``csr_sort_indices`` sorts each short row; the duplicates are then
    neighbours in each row, so no key of a triplet is formed (measured at
    6.1e6 triplets of hertz ``refine=3``: 0.30 s against 0.46 s for the
    same sort forming a key per triplet); ``np.unique`` where scipy's
    kernels are not there."""
    try:
        from scipy.sparse import _sparsetools
        coo_tocsr, sort_rows = _sparsetools.coo_tocsr, _sparsetools.csr_sort_indices
    except (ImportError, AttributeError):  # pragma: no cover (a scipy without them)
        keys, inv = np.unique(rows.astype(np.int64) * n + cols, return_inverse=True)
        return keys, inv.ravel()
    m = rows.size
    itype = np.int32 if max(n, m) < 2**31 - 1 else np.int64
    indptr = np.empty(n + 1, dtype=itype)
    indices = np.empty(m, dtype=itype)
    ids = np.empty(m, dtype=np.int64)  # each triplet's number, in row-major order
    coo_tocsr(n, n, m, rows.astype(itype, copy=False), cols.astype(itype, copy=False),
              np.arange(m, dtype=np.int64), indptr, indices, ids)
    sort_rows(n, indptr, indices, ids)
    new = np.empty(m, dtype=bool)  # a triplet that starts a key
    new[:1] = True
    np.not_equal(indices[1:], indices[:-1], out=new[1:])
    starts = indptr[:-1]
    new[starts[starts < m]] = True
    # (a cumsum of int8 is 7x faster than one of bool, which goes through a cast)
    count = np.cumsum(new.view(np.int8), dtype=np.int64)
    inv = np.empty(m, dtype=np.int64)
    inv[ids] = count - 1
    per_row = np.diff(np.concatenate([[0], count])[indptr.astype(np.int64)])
    keys = np.repeat(np.arange(n, dtype=np.int64) * n, per_row) + indices[new]
    return keys, inv


def _item_keys(c: Contribution, n: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_unique_keys` of an item's triplets, per node when it says how
    they were made (:attr:`Contribution.k_elements`)."""
    if c.k_elements is not None:
        return _element_keys(np.asarray(c.k_elements, dtype=np.int64), n)
    return _unique_keys(c.k_rows, c.k_cols, n)


def _element_keys(D: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_unique_keys` of ``element_coo(D, elements_last=True)``.

    Vector elements number their local dofs ``2 a + i`` and the global ones
    ``r0 + 2 s + i`` (``s`` the node, ``i`` the component): then the keys
    are those of the nodes' element triplets (a quarter as many) with each
    node pair ``(p, q)`` spread into its 2 x 2 dof pairs, row ``r0 + 2 p + i``
    holding the columns ``r0 + 2 q + k`` of the node row ``p`` in order.
    Other numberings go to :func:`_unique_keys`."""
    r = D[0::2]
    r0 = int(r.min()) if r.size else 0
    if (not r.size or D.shape[0] % 2 or not np.array_equal(D[1::2], r + 1)
            or np.any((r - r0) % 2)):
        return _unique_keys(*element_coo(D, elements_last=True), n)
    S = (r - r0) // 2                                    # (n_nodes_loc, n_el) nodes
    nn = int(S.max()) + 1
    node_keys, node_inv = _unique_keys(*element_coo(S, elements_last=True), nn)
    p, q = np.divmod(node_keys, nn)
    count = np.bincount(p, minlength=nn)
    first = np.cumsum(count) - count                     # each node row's first key
    # the dof key of node key t, components i, k: 2 t + 2 first[p] + 2 i count[p] + k
    at = 2 * np.arange(p.size) + 2 * first[p]
    keys = np.empty(4 * p.size, dtype=np.int64)
    for i in (0, 1):
        for k in (0, 1):
            keys[at + 2 * i * count[p] + k] = (r0 + 2 * p + i) * n + r0 + 2 * q + k
    b, e = S.shape
    base = 2 * node_inv.reshape(b, b, e) + (2 * first[S])[:, None, :]      # (a, b, e)
    inv = np.empty((b, 2, b, 2, e), dtype=np.int64)  # local dofs (2 a + i, 2 b + k)
    for i in (0, 1):
        shift = (2 * i * count[S])[:, None, :]
        for k in (0, 1):
            np.add(base, shift + k, out=inv[:, i, :, k, :])
    return keys, inv.reshape(-1)


def _union(sorted_keys: list[np.ndarray]) -> tuple[np.ndarray, list[np.ndarray]]:
    """The sorted union of sorted unique key arrays, and the place of each
    array's keys in it.

    The keys the largest array lacks are inserted into it (a search of the
    others in it; their own union by :func:`_merge`), so the usual case, a
    body's pattern and a contact pair's few keys, costs a copy of the body's
    keys, not a sort of all of them."""
    if not sorted_keys:
        return np.zeros(0, dtype=np.int64), []
    big = int(np.argmax([k.size for k in sorted_keys]))
    base = sorted_keys[big]
    rest = _merge([k for i, k in enumerate(sorted_keys) if i != big])
    pos = np.searchsorted(base, rest)
    found = pos < base.size
    found[found] = base[pos[found]] == rest[found]
    at = pos[~found]
    union = np.insert(base, at, rest[~found])
    places = []
    for i, k in enumerate(sorted_keys):
        if i != big:
            places.append(np.searchsorted(union, k))
        elif at.size:  # the places the inserted keys leave free
            free = np.ones(union.size, dtype=bool)
            free[at + np.arange(at.size)] = False
            places.append(np.flatnonzero(free))
        else:
            places.append(np.arange(base.size))
    return union, places


def _merge(sorted_keys: list[np.ndarray]) -> np.ndarray:
    """The sorted union of sorted unique key arrays (a stable sort merges the
    runs; ``np.unique`` hashes, which measured ten times slower here)."""
    if len(sorted_keys) <= 1:
        return sorted_keys[0] if sorted_keys else np.zeros(0, dtype=np.int64)
    k = np.sort(np.concatenate(sorted_keys), kind="stable")
    new = np.ones(k.size, dtype=bool)
    new[1:] = k[1:] != k[:-1]
    return k[new]


def _readonly(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


class _Pattern:
    """A fixed CSR pattern of the triplets of some items, where each triplet goes,
    and the gathers of its free block.

    Each item's sorted unique keys ``row * n + col`` (and the place of each of
    its triplets among them) are computed once per index arrays (taken from
    ``previous`` when the arrays are the same); the pattern is their union,
    ``indices`` and ``indptr`` read-only.  ``where[j]`` holds the place of the
    triplets of the ``j``-th item (of the first among its own keys, which
    ``_spread`` places): kept per item, so that neither the places nor the
    values are concatenated (:meth:`matrix`).
    """

    def __init__(self, items: tuple[int, ...], parts: list[Contribution], n: int,
                 previous: "_Pattern | None" = None):
        self.items = items
        self.idx = [(p.k_rows, p.k_cols) for p in parts]
        known = {} if previous is None else dict(zip(previous.items, zip(previous.idx,
                                                                        previous.local)))
        self.local = []
        for i, p in zip(items, parts):
            old = known.get(i)
            if old is not None and _same(old[0][0], p.k_rows) and _same(old[0][1], p.k_cols):
                self.local.append(old[1])
            else:
                self.local.append(_item_keys(p, n))
        keys, places = _union([uk for uk, _ in self.local])
        # the first item's values are summed among its own keys and then spread
        # to their places (no gather of a place per triplet: at hertz refine=3,
        # 6e6 triplets, that measured 0.2 s a build); the others' places per triplet
        self._spread = None if places[0].size == keys.size else places[0]
        self.where = [self.local[0][1]] + [pl[inv] for pl, (_, inv)
                                           in zip(places[1:], self.local[1:])]
        self.nnz = keys.size
        itype = np.int32 if n < 2**31 else np.int64
        # each row's first key by a search, not a division of every key (3x faster)
        indptr = np.searchsorted(keys, np.arange(n + 1, dtype=np.int64) * n)
        row_keys = np.repeat(np.arange(n, dtype=np.int64) * n, np.diff(indptr))
        self.indices = _readonly(np.subtract(keys, row_keys).astype(itype))
        self.indptr = _readonly(indptr.astype(itype))
        self.n = n
        self.last: sp.csr_matrix | None = None  # the last matrix made
        self._free: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None

    def matrix(self, vals: list[np.ndarray]) -> sp.csr_matrix:
        """The matrix of the items' values ``vals`` (one array per item).

        The sum of the triplets in their order, as one ``bincount`` of all
        of them would add them: the first item's by ``bincount`` (among its
        own keys, spread to theirs), every further item's added in order by
        ``np.add.at`` (the same sums, to the last bit, without concatenating
        the values)."""
        if self._spread is None:
            data = np.bincount(self.where[0], weights=vals[0], minlength=self.nnz)
        else:
            data = np.zeros(self.nnz)
            data[self._spread] = np.bincount(self.where[0], weights=vals[0],
                                             minlength=self._spread.size)
        for where, v in zip(self.where[1:], vals[1:]):
            np.add.at(data, where, v)
        K = sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))
        K.has_sorted_indices = True
        self.last = K
        return K

    def restrict(self, K: sp.csr_matrix, free: np.ndarray) -> sp.csr_matrix:
        """``K[free][:, free]`` of a matrix of this pattern, by a cached gather."""
        if self._free is None or not np.array_equal(self._free[0], free):
            M = sp.csr_matrix((np.arange(1.0, self.nnz + 1.0), self.indices, self.indptr),
                              shape=(self.n, self.n))[free][:, free]
            M.sort_indices()
            self._free = (free.copy(), M.data.astype(np.int64) - 1,
                          _readonly(M.indices), _readonly(M.indptr))
        _, gather, indices, indptr = self._free
        Kf = sp.csr_matrix((K.data[gather], indices, indptr), shape=(free.size, free.size))
        Kf.has_sorted_indices = True
        return Kf
