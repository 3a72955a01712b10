"""The model: its items, the global unknown layout and the assembly of residual and tangent.

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
from typing import Sequence

import numpy as np
import scipy.sparse as sp

from .binding import bind, claim, layout
from .geometry import model_geometry
from .checks import _MODEL_CHECKS, _check_items, check_thickness, register_check
from .item import Body, ContactTable, Contribution, Item, ItemProtocol, Output
from .pattern import _Pattern, _cat, _same

# the item protocols (core.item) and register_check (core.checks) are offered here too
__all__ = ["Contribution", "Item", "ItemProtocol", "Output", "Body", "ContactTable", "Model",
           "register_check"]


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
    geometry : {None, "plane", "axisymmetric", "3d"}
        The geometry (:mod:`~skfem_mortar.core.geometry`), handed to the items
        like the thickness (:attr:`Item.geometry`).  Default: ``"3d"`` when a
        body is on a 3D mesh, else ``"plane"``.  An item built for another
        geometry is refused, naming it.

    Raises
    ------
    ValueError
        For an item that is not an :class:`Item` or is listed twice, a body an
        item acts on that is missing, repeated body or pair names, a
        ``thickness`` that is not finite and > 0, a ``geometry`` not allowed
        (:func:`~skfem_mortar.core.geometry.model_geometry`); at any use, for a model one
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

    def __init__(self, items: Sequence[Item], thickness: float = 1.0,
                 geometry: str | None = None):
        self.thickness = check_thickness(thickness)
        items = list(items)
        _check_items(items)
        self.geometry = model_geometry(geometry, items, self.thickness)
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
        self._layout, self.n_u, self.n = layout(items, self.thickness, self.geometry)
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
        system symmetric (:func:`~skfem_mortar.solver.symmetrization.symmetrize`)."""
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

