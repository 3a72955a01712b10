"""A contact pair: Lagrange multipliers per slave node, active set by semi-smooth Newton.

The pair adds to the potential energy the term ``-lam . g(x)`` (``g`` the gaps
of the slave nodes from a contact discretization, ``lam >= 0`` compression), so

    R_u   += -G^T lam               (G = dg/dx)
    K_uu  += -H                     (H = sum_A lam_A d^2 g_A/dx^2)
    K_ulam = -G^T

and closes the Karush-Kuhn-Tucker conditions ``g >= 0, lam >= 0, lam g = 0``
with the semi-smooth complementarity function (primal-dual active set)

    C(lam, g) = lam - max(0, lam - c g)  =  c g   (active:   lam - c g >= 0)
                                         =  lam   (inactive: lam - c g <  0)

as the multiplier rows of the same linear system, so inactive multipliers are
set to zero by the Newton step itself.  ``c`` is a stiffness taken from the
bodies' tangent diagonals at the contact dofs (their harmonic mean over the
two bodies: the series stiffness, set by the softer body) (divided by the squared mean
tributary length when the multipliers are tractions, as in mortar), so the
choice is unit-free; it steers only the path of the iteration, not the
solution.  At ``lam = 0`` a node with ``g <= 0`` is active (``>=`` above):
a zero initial gap starts active.  Slave nodes without a master partner
(``mask`` False) are inactive.  The initial active set (first load step)
also holds nodes that touch within ``touch_tolerance``.  Every step (and every
retry of a cut step) starts from the last converged active set, which its
first iteration uses as it is.

The active set through the iterations of a step (extrapolated release of a
too-wide zone, cycling guard) is :class:`~skfem_mortar.contact.active_set.ActiveSet`'s.

With a friction law (``friction=Coulomb(mu)`` or ``Tresca(bound)``) every
slave node also carries a tangential multiplier, after the normal ones, with
the semi-smooth stick/slip rows of :mod:`skfem_mortar.contact.friction` on the
slip of :mod:`skfem_mortar.contact.slip`; the statuses through a step are
:class:`~skfem_mortar.contact.active_set.StatusSet`'s (docs/friction.md).
Without one the pair is frictionless and runs none of that.

The gaps and their derivatives, and whatever state the method keeps for them,
are the contact discretization's (:class:`~skfem_mortar.contact.discretization.ContactDiscretization`,
looked up by ``method`` in the registry of :mod:`skfem_mortar.contact.discretization`);
the pair is method-neutral.
"""
from __future__ import annotations

import logging
from typing import Any

import numpy as np
import scipy.sparse as sp

from .active_set import ActiveSet, StatusSet, chain_order, touching_nodes
from .contact_eval import ContactEval
from ..core.binding import rebind
from ..core.validate import real
from .discretization import FrictionDiscretization, PatternedDiscretization, check_entries
from .methods import METHODS, make_method  # METHODS: the registry's names, the built-ins in it
from .friction import (NO_FRICTION, OPEN, SLIP, STATUS_NAMES, STICK, Coulomb, FrictionRows,
                       Tresca, complementarity)
from . import preflight as _preflight  # noqa: F401 (registers the checks Model.preflight runs)
from ..core.item import Contribution, Item
from ..output.contact_output import ContactOutput
from .search import distance_to_polyline
from .surfaces import segment_lengths, tributary_lengths
from .tributary import tributary_jacobian, tributary_pattern

__all__ = ["ContactPair", "METHODS"]

log = logging.getLogger(__name__)

#: KKT tolerances of a converged state (:meth:`ContactPair.violation`): gaps to
#: ``K_GAP`` times the median slave segment length, pressures to ``K_LAM`` times
#: the step's pressure scale (force scale / contact length).  Newton meets the
#: gap rows to ``rtol`` (1e-10) of the force scale and the pressures to about
#: ``rtol * S / h``, so 1e-6 leaves four decades above what a converged state
#: carries, and is far below any penetration or tension that matters (the
#: discretization error of a gap is O(h^2 / R), 1e-4 h at h = R / 100).
K_GAP = 1e-6
K_LAM = 1e-6

#: a failed step is put down to a tangential load above the friction bound
#: (:meth:`ContactPair.failure_hint`) when every active node slides in the failed
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

#: the pair's own checkpoint entries (:meth:`ContactPair.state_dict`; the
#: discretization's are beside them)
_PAIR_STATE = ("started", "active", "c", "row_scale", "x0_slave", "x0_master", "tol_p")
#: ... and those of a pair with friction (beside the discretization's slip history)
_FRICTION_STATE = ("friction_status", "friction_p_ref")

# -- the tangent over a reserved pattern ---------------------------------------
# A contact pair's tangent triplets over a reserved pattern (explicit zeros).
#
# With the reserved pattern ``P`` of a contact discretization
# (:meth:`~skfem_mortar.contact.discretization.PatternedDiscretization.pattern`:
# row ``A`` holds the local dofs ``S_A`` multiplier ``A`` can couple to), the
# pair's tangent blocks have the fixed sparsity
#
#     K_ulam = -G^T        on  {(d, A) : d in S_A}
#     K_lamu = c G         on  {(A, d) : d in S_A}   (zero on inactive rows)
#     K_lamlam = I         on  the diagonal          (zero on active rows)
#     K_uu = -H            on  union_A S_A x S_A     (the structure of P^T P)
#
# mapped to global unknowns (dofs of a rigid master dropped).  The triplet index
# arrays are built once per reservation and returned as the same objects, so the
# model's sparsity pattern repeats while the reservation does; the values of
# ``G`` and ``H`` are scattered into it each evaluation (entries the reservation
# lacks are reported, and :meth:`Reservation.widened` takes them in).


def _keys(M: sp.spmatrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows, columns and sorted keys ``row * n_cols + col`` of a canonical csr matrix."""
    M = sp.csr_matrix(M)
    M.sum_duplicates()  # also sorts the indices
    rows = np.repeat(np.arange(M.shape[0], dtype=np.int64), np.diff(M.indptr))
    cols = M.indices.astype(np.int64)
    return rows, cols, rows * M.shape[1] + cols


def _scatter(M: sp.spmatrix | None, keys: np.ndarray, n_cols: int) -> np.ndarray | None:
    """The entries of ``M`` summed at their positions among ``keys`` (zeros
    elsewhere); None if an entry of ``M`` lies outside ``keys``."""
    if M is None:
        return np.zeros(keys.size)
    C = M.tocoo()
    nz = C.data != 0  # a stored zero needs no place
    k = C.row[nz].astype(np.int64) * n_cols + C.col[nz]
    if k.size == 0:
        return np.zeros(keys.size)
    if keys.size == 0:
        return None
    pos = np.minimum(np.searchsorted(keys, k), keys.size - 1)
    if not np.array_equal(keys[pos], k):
        return None
    return np.bincount(pos, weights=C.data[nz], minlength=keys.size)


def _diagonal(c: Contribution) -> tuple[np.ndarray, np.ndarray]:
    """Rows and values of the tangent triplets of ``c`` on the diagonal, in their
    order; of element triplets (:attr:`Contribution.k_elements`) the element
    matrices' diagonals, without a test of every triplet."""
    if c.k_elements is None:
        on = c.k_rows == c.k_cols
        return c.k_rows[on], c.k_vals[on]
    D = np.asarray(c.k_elements)
    local = np.arange(D.shape[0])
    return D.ravel(), c.k_vals.reshape(D.shape[0], D.shape[0], -1)[local, local].ravel()


def _ones(M: sp.spmatrix) -> sp.csr_matrix:
    """Ones at the nonzero entries of ``M``."""
    C = sp.csr_matrix(M, dtype=float, copy=True)
    C.eliminate_zeros()
    C.data[:] = 1.0
    return C


def _with_triplets(out: Contribution, kr: list, kc: list, kv: list, gd: np.ndarray,
                   hessians: tuple) -> Contribution:
    """``out`` with the triplets ``kr, kc, kv`` and ``-H`` of each local ``H`` in
    ``hessians`` (None skipped; dofs of a rigid master, ``gd < 0``, dropped)."""
    for H in hessians:
        if H is not None:
            H = H.tocoo()
            ok = (gd[H.row] >= 0) & (gd[H.col] >= 0)
            kr.append(gd[H.row[ok]])
            kc.append(gd[H.col[ok]])
            kv.append(-H.data[ok])
    out.k_rows = np.concatenate(kr).astype(np.int64)
    out.k_cols = np.concatenate(kc).astype(np.int64)
    out.k_vals = np.concatenate(kv)
    return out


class Reservation:
    """The tangent triplets of a contact pair over a reserved pattern.

    Parameters
    ----------
    P : sparse matrix (n_s, n_local)
        The reserved pattern (nonzero structure only).
    gd : int ndarray (n_local,)
        Global index of each local dof, ``-1`` for a rigid master's.
    offset : int
        Global index of the pair's first multiplier.
    extra_h : sparse matrix (n_local, n_local), optional
        Further ``K_uu`` entries to reserve (beyond ``P^T P``).

    Attributes
    ----------
    rows, cols : int ndarray
        The global triplet indices, blocks ``K_ulam, K_lamu, K_lamlam, K_uu`` in this order.
    """

    def __init__(self, P: sp.spmatrix, gd: np.ndarray, offset: int,
                 extra_h: sp.spmatrix | None = None):
        P = _ones(P)
        self.P, self.gd, self.offset = P, np.asarray(gd, dtype=np.int64), int(offset)
        n_s, n_loc = P.shape
        self.n_loc = n_loc
        prow, pcol, self.keys_g = _keys(P)
        S = (P.T @ P).tocsr()
        if extra_h is not None:
            S = S + _ones(extra_h)
        S.data[:] = 1.0
        self.S = S
        hrow, hcol, self.keys_h = _keys(S)
        self.keep_g = self.gd[pcol] >= 0
        self.keep_h = (self.gd[hrow] >= 0) & (self.gd[hcol] >= 0)
        self.row_g = prow[self.keep_g]  # the multiplier row of each kept G entry
        u = self.gd[pcol[self.keep_g]]
        lam = self.offset + self.row_g
        diag = self.offset + np.arange(n_s, dtype=np.int64)
        self.rows = np.concatenate([u, lam, diag, self.gd[hrow[self.keep_h]]])
        self.cols = np.concatenate([lam, u, diag, self.gd[hcol[self.keep_h]]])

    def fits(self, gd: np.ndarray, offset: int) -> bool:
        """Whether it was built for these global dofs and multiplier offset."""
        return offset == self.offset and np.array_equal(gd, self.gd)

    def values(self, G: sp.spmatrix, H: sp.spmatrix | None, active: np.ndarray, c: float,
               row_scale: float) -> np.ndarray | None:
        """The tangent values at :attr:`rows`, :attr:`cols`: ``-G^T``, ``c s G`` on
        active rows, ``s`` on the diagonal of inactive ones, ``-H`` (``s`` the row
        scale; explicit zeros elsewhere).  None if ``G`` or ``H`` has an entry
        outside the reservation."""
        Gd = _scatter(G, self.keys_g, self.n_loc)
        Hd = _scatter(H, self.keys_h, self.n_loc)
        if Gd is None or Hd is None:
            return None
        g = Gd[self.keep_g]
        return np.concatenate([-g, np.where(active[self.row_g], c * row_scale * g, 0.0),
                               np.where(active, 0.0, row_scale), -Hd[self.keep_h]])

    def widened(self, G: sp.spmatrix, H: sp.spmatrix | None) -> "Reservation":
        """The reservation that also holds every entry of ``G`` and ``H``."""
        P = self.P + _ones(G)
        extra = self.S if H is None else self.S + _ones(H)
        return Reservation(P, self.gd, self.offset, extra)

    def blocks(self, G_col: sp.spmatrix, G_row: sp.spmatrix, diag: np.ndarray,
               H: sp.spmatrix | None) -> np.ndarray | None:
        """The tangent values at :attr:`rows`, :attr:`cols` of general blocks:
        ``-G_col^T`` (columns), ``G_row`` (rows), ``diag`` on the multiplier
        diagonal, ``-H``; None if an entry lies outside the reservation."""
        Gc = _scatter(G_col, self.keys_g, self.n_loc)
        Gr = _scatter(G_row, self.keys_g, self.n_loc)
        Hd = _scatter(H, self.keys_h, self.n_loc)
        if Gc is None or Gr is None or Hd is None:
            return None
        return np.concatenate([-Gc[self.keep_g], Gr[self.keep_g], diag, -Hd[self.keep_h]])


class FrictionReservation:
    """The tangent triplets of a contact pair with friction over reserved patterns.

    The normal blocks are a :class:`Reservation` over the method's pattern
    ``P_n``; the tangential ones a :class:`Reservation` over
    ``P_t = P_n + E`` (``E`` the slip's further columns,
    :meth:`~skfem_mortar.contact.discretization.FrictionDiscretization.slip_pattern`)
    at the tangential multipliers, which holds ``K_u,lam_t = -G_t^T``,
    ``K_lam_t,u = s_t (diag(dC/du) G_t + diag(dC/dg) G_n)`` (``G_n``'s rows
    lie in ``P_n``), the diagonal ``s_t dC/dlam_t`` and ``K_uu = -H_t`` on
    ``P_t^T P_t``; and the diagonal ``K_lam_t,lam_n = s_t dC/dlam_n``.

    Parameters
    ----------
    normal : Reservation
        The normal rows' (offset: the pair's).
    P_t : sparse matrix (n_s, n_local)
        The tangential rows' pattern.
    extra_h : sparse matrix, optional
        Further ``K_uu`` entries of the tangential part.
    """

    def __init__(self, normal: Reservation, P_t: sp.spmatrix,
                 extra_h: sp.spmatrix | None = None):
        self.normal = normal
        n_s = normal.P.shape[0]
        self.tangential = Reservation(_ones(P_t) + normal.P, normal.gd, normal.offset + n_s,
                                      extra_h)
        idx = np.arange(n_s, dtype=np.int64) + normal.offset
        self.rows = np.concatenate([normal.rows, self.tangential.rows, idx + n_s])
        self.cols = np.concatenate([normal.cols, self.tangential.cols, idx])

    def values(self, G_n: sp.spmatrix, H_n: sp.spmatrix | None, G_t: sp.spmatrix,
               B: sp.spmatrix, H_t: sp.spmatrix | None, active: np.ndarray, c: float,
               row_scale: float, s_t: float, fr: FrictionRows) -> np.ndarray | None:
        """The values at :attr:`rows`, :attr:`cols` (None if an entry of a matrix
        lies outside its reservation)."""
        vn = self.normal.values(G_n, H_n, active, c, row_scale)
        vt = self.tangential.blocks(G_t, s_t * B, s_t * fr.d_lam_t, H_t)
        if vn is None or vt is None:
            return None
        return np.concatenate([vn, vt, s_t * fr.d_lam_n])

    def widened(self, G_n: sp.spmatrix, H_n: sp.spmatrix | None, G_t: sp.spmatrix,
                H_t: sp.spmatrix | None) -> "FrictionReservation":
        """The reservation that also holds every entry of the given matrices."""
        t = self.tangential
        extra = t.S if H_t is None else t.S + _ones(H_t)
        return FrictionReservation(self.normal.widened(G_n, H_n), t.P + _ones(G_t), extra)


def _check_surface(role: str, surface: Any) -> None:
    """ValueError naming ``role`` unless ``surface`` is a contact surface (a body,
    a mesh or an array is not: the pair needs its nodes, segments and dofs)."""
    if not (callable(getattr(surface, "dofs", None)) and hasattr(surface, "nodes")
            and hasattr(surface, "body")):
        what = type(surface).__name__
        named = f" {surface.name!r}" if isinstance(getattr(surface, "name", None), str) else ""
        raise ValueError(f"{role} must be a contact surface (ContactSurface.from_solid(body, "
                         f"boundary), ContactSurface.from_cable(cable), RigidPlane, "
                         f"RigidCircle), got {what}{named}")


class ContactPair(Item):
    """Contact between a slave and a master surface with Lagrange multipliers,
    frictionless or with Coulomb or Tresca friction.

    Parameters
    ----------
    slave : ContactSurface
        Deformable surface whose nodes carry the multipliers.
    master : ContactSurface
        Deformable or rigid surface.
    method : {"mortar-dual", "mortar", "nts"} or a registered name
        The contact discretization (:func:`~skfem_mortar.contact.discretization.make_method`);
        default ``"mortar-dual"`` (dual mortar: passes the non-matching patch
        test, pressures without standard mortar's alternating edge tail). NTS
        is the cheapest and fine against a rigid or matching master, but 6 to
        47 % off the patch test on non-matching deformable meshes.
    name : str
    c : float, optional
        Complementarity parameter (> 0); default from the bodies' stiffness.
    cycle_guard : bool
        Detect a repeating active set and act on it (default True).
    touch_tolerance : float
        The initial active set also holds the nodes whose gap (as a length; for
        mortar the weighted gap over the tributary length) is at most this
        fraction of the mean slave segment length (>= 0, default 1e-2), and
        the nodes that the master touches within that distance
        (:func:`~skfem_mortar.contact.active_set.touching_nodes`, the closest approach:
        a polygon resting on one vertex has the mortar gap ``h^2 / (6 R)``
        there, a master vertex between two slave nodes positive gaps at both);
        a body held only by contact needs them active.
    segmentation : {"iteration", "step"}
        Mortar only (``"step"`` is passed to the discretization as its option
        ``segmentation``): rebuild the mortar segments at every Newton iteration
        (default, exact), or build them once per load step from the last
        converged state and freeze them during the step (cheaper, see
        :func:`skfem_mortar.contact.mortar.evaluate`).
    accelerate : bool
        When the tensile tail of a too-wide contact zone is released, release
        as many nodes again beyond the tail as the sign change of the
        multipliers extrapolates (default True; see
        :class:`~skfem_mortar.contact.active_set.ActiveSet`).  Steers only the path of
        the iteration.
    friction : Coulomb or Tresca, optional
        A friction law (:mod:`skfem_mortar.contact.friction`); None (default):
        frictionless, exactly the pair without it.  With a law every slave node
        gets a tangential multiplier (the tangential traction, NTS: force, on
        the slave along the node's tangent) after the normal ones, the slip
        within the load step (:mod:`skfem_mortar.contact.slip`) and the
        semi-smooth stick/slip rows of
        :func:`~skfem_mortar.contact.friction.complementarity` (docs/friction.md);
        on 2-node and 3-node (quadratic) segments alike.
    **options
        The discretization's options (e.g. ``margin``), checked when it is built.

    Attributes
    ----------
    discretization : ContactDiscretization
        The method's gaps, derivatives and state.
    friction : Coulomb, Tresca or None
        The friction law.
    """

    dof_kind = "lam"
    geometries = ("plane",)   # the others in their own issues
    loaded = False  # its residual does not depend on the load factor
    #: K_lamu = c G on active rows against K_ulam = -G^T (and H): not symmetric
    symmetric = False
    phase = "contact"

    def __init__(self, slave: Any, master: Any, method: str = "mortar-dual", name: str = "contact",
                 c: float | None = None, cycle_guard: bool = True,
                 touch_tolerance: float = 1e-2, segmentation: str = "iteration",
                 accelerate: bool = True, friction: Coulomb | Tresca | None = None,
                 **options: Any):
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
        _check_surface("slave", slave)
        _check_surface("master", master)
        if slave.dofs() is None:
            raise ValueError("slave must be a deformable surface (a rigid surface is a master)")
        if slave is master or (slave.body is not None and slave.body is master.body
                               and np.array_equal(np.sort(slave.nodes), np.sort(master.nodes))):
            raise ValueError(f"slave and master must be two different surfaces, got the same "
                             f"surface {slave.name!r} twice")
        if c is not None:
            c = real("c", c, 0.0, low_open=True)
        self.slave, self.master, self.method, self.name = slave, master, method, name
        for flag, v in (("cycle_guard", cycle_guard), ("accelerate", accelerate)):
            if not isinstance(v, (bool, np.bool_)):
                raise ValueError(f"{flag} must be True or False, got {v!r}")
        if segmentation not in ("iteration", "step"):
            raise ValueError(f"segmentation must be 'iteration' or 'step', got {segmentation!r}")
        self.segmentation = segmentation
        touch_tolerance = real("touch_tolerance", touch_tolerance, 0.0)
        if segmentation != "iteration":
            options = {**options, "segmentation": segmentation}
        if friction is not None and not isinstance(friction, (Coulomb, Tresca)):
            raise ValueError(f"friction must be None, Coulomb(mu) or Tresca(bound), got "
                             f"{friction!r}")
        self.discretization = make_method(method, slave, master, pair_name=name, **options)
        if friction is not None and not isinstance(self.discretization, FrictionDiscretization):
            raise ValueError(f"friction: method {method!r} has no slip hooks "
                             f"(FrictionDiscretization); use friction=None")
        #: the friction law (None: frictionless, one multiplier per slave node)
        self.friction = friction
        #: the law of the current step: ``friction``, or :data:`NO_FRICTION` in
        #: the steps before its ``start`` (:meth:`begin_step`)
        self._law = friction if friction is None or friction.acts(0.0) else NO_FRICTION
        #: the slip branch's derivatives (:func:`~skfem_mortar.contact.friction.complementarity`):
        #: ``"projected"`` (default) or ``"exact"`` (the finite-difference tests)
        self.friction_jacobian = "projected"
        self.n_dofs = slave.n_nodes * (1 if friction is None else 2)
        self.c = c
        lengths = segment_lengths(slave.X, slave.segments)
        self._touch = float(touch_tolerance) * float(np.mean(lengths))
        self._h = float(np.median(lengths))  # the gap tolerance's length
        self._tol_p = 0.0  # pressure tolerance of the last converged check
        self._row_scale: float | None = None
        self._reference: tuple[np.ndarray, np.ndarray] | None = None  # converged_positions
        own = _PAIR_STATE if friction is None else (
            _PAIR_STATE + _FRICTION_STATE + tuple(self.discretization.slip_history_keys))
        clash = set(self.discretization.state_dict()) & set(own)
        if clash:
            raise ValueError(f"method {method!r} names its state {sorted(clash)}, which the "
                             f"pair's state uses; rename them")
        self.state = ActiveSet(slave.n_nodes, chain_order(slave.segments, slave.closed,
                                                        slave.n_nodes),
                               name, cycle_guard=cycle_guard, accelerate=accelerate)
        self._started = False
        #: (the discretization's pattern, the triplets over it) and how often a
        #: pattern missed an entry of G or H (:meth:`_widen`)
        self._reserved: tuple[Any, Reservation] | None = None
        self.pattern_misses = 0
        if friction is not None:
            #: stick/slip statuses through a step, the slip history of the last
            #: converged step, the tangential rows' fixed pressure (docs/friction.md)
            self.statuses = StatusSet(slave.n_nodes, name, cycle_guard=cycle_guard)
            self._slip_history: dict[str, np.ndarray] | None = None
            self._p_ref: float | None = None
            self._p_ref_guess = True  # p_ref not from a converged bound (_step_p_ref)
            self._reserved_t: tuple[Any, Any, FrictionReservation] | None = None
            self._converged_t: tuple | None = None  # (xs, xm, lam_t, data, history)
            #: times the slip's reserved pattern was widened (a slip across more
            #: master segments than reserved within a step; no error)
            self.slip_pattern_widenings = 0
            self._area0 = tributary_lengths(slave.X, slave.segments)

    # -- helpers -------------------------------------------------------------
    @property
    def _normal(self) -> slice:
        """Global slice of the normal multipliers (the first ``n_s`` of the pair's)."""
        return slice(self.offset, self.offset + self.slave.n_nodes)

    @property
    def _tangential(self) -> slice:
        """Global slice of the tangential multipliers (friction only: the last ``n_s``)."""
        n = self.slave.n_nodes
        return slice(self.offset + n, self.offset + 2 * n)

    @property
    def multipliers_per_node(self) -> int:
        """1 (frictionless: the normal multiplier) or 2 (with friction: normal
        multipliers at ``offset .. offset + n_s``, tangential ones after them)."""
        return 1 if self.friction is None else 2

    @property
    def symmetrizable(self) -> bool:
        """Its multiplier rows can be scaled to a symmetric system (active rows
        ``c s G`` against the columns ``-G^T``, inactive rows the identity) when
        ``H`` is symmetric (the discretization's ``symmetric``) and its triplets
        lie on a reserved pattern (the same structure for rows and columns).
        Never with friction: the tangential rows are no multiple of their columns."""
        return bool(self.friction is None and self.discretization.symmetric
                    and isinstance(self.discretization, PatternedDiscretization))

    def referenced_bodies(self) -> list:
        """The bodies of the slave and (unless rigid) the master surface."""
        return [b for b in (self.slave.body, self.master.body) if b is not None]

    @property
    def multiplier_kind(self) -> str:
        """"force" (NTS) or "traction" (mortar): the discretization's."""
        return self.discretization.multiplier_kind

    @property
    def options(self) -> dict:
        """The discretization's options."""
        return self.discretization.options

    @property
    def touch_distance(self) -> float:
        """``touch_tolerance`` times the mean slave segment length (a length)."""
        return self._touch

    @property
    def converged_positions(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Slave and master node positions at the last converged state (the step
        start before the first one converged; None before a step began), told
        to the discretization (:meth:`ContactDiscretization.set_reference`)."""
        return self._reference

    @converged_positions.setter
    def converged_positions(self, x0: tuple[np.ndarray, np.ndarray] | None) -> None:
        self._reference = x0
        self.discretization.set_reference(*((None, None) if x0 is None else x0))

    _x0 = converged_positions  # the name tests/test_search.py sets

    def global_dofs(self) -> np.ndarray:
        """Global index of every local dof of the pair (``-1`` for a rigid master)."""
        ds = self.slave.dofs().T.ravel()
        dm = self.master.dofs()
        dm = np.full(2 * self.master.n_nodes, -1, dtype=np.int64) if dm is None else dm.T.ravel()
        return np.concatenate([ds, dm]).astype(np.int64)

    def evaluate(self, z: np.ndarray, tangent: bool = True, with_lam: bool = True) -> ContactEval:
        """The discretization's :class:`ContactEval` at ``z``."""
        lam = np.asarray(z)[self._normal] if with_lam else None
        return self.discretization.evaluate(self.slave.x(z), self.master.x(z), lam, tangent)

    def set_fixed(self, fixed: np.ndarray) -> None:
        """Told the prescribed global dofs (by :func:`~skfem_mortar.solver.stepping.solve`).

        Pinned-node safeguard: a slave node whose two dofs are prescribed, against a
        rigid master, has a gap that no unknown can change; its multiplier row would
        be zero and the system singular (a cable pinned on the plane it is pressed
        onto: the contact zone reaching the supports).  Such nodes are kept out of
        contact (``mask`` False; for mortar they are crosspoints whose multiplier
        is merged into the neighbour's); their support carries the load.
        """
        pinned = None
        if self.master.body is None:
            ds = self.slave.dofs()  # (2, n)
            pinned = np.all(np.isin(ds, np.asarray(fixed)), axis=0)
        self.discretization.set_pinned(pinned)

    def _bodies(self):
        out = [self.slave.body]
        if self.master.body is not None and self.master.body is not self.slave.body:
            out.append(self.master.body)
        return out

    def _stiffness(self, z: np.ndarray, load_factor: float) -> float:
        """Harmonic mean over the bodies of the mean |diagonal| of each body's tangent
        at the contact dofs (force / length)."""
        vals = []
        gd = self.global_dofs()
        gd = gd[gd >= 0]
        at = np.zeros(len(z), dtype=bool)
        at[gd] = True  # a mask, not np.isin over every triplet (0.5 s at 6e6 triplets)
        for body in self._bodies():
            rows, diag = _diagonal(body.assemble(z, load_factor, tangent=True))
            on = at[rows]
            d = np.bincount(rows[on], weights=diag[on], minlength=len(z))[gd]
            d = np.abs(d[d != 0])
            if d.size:
                vals.append(d.mean())
        # series stiffness of the bodies (harmonic mean): the softer body sets the
        # interface compliance; the arithmetic mean let a 1000x stiffer die make c
        # so large that gaps of round-off size flipped nodes (ironing, die as slave)
        k = float(len(vals) / np.sum(1.0 / np.asarray(vals))) if vals else 0.0
        if not (np.isfinite(k) and k > 0):
            log.warning("%s: no stiffness found at the contact dofs, using c = 1", self.name)
            k = 1.0
        return k

    def _c(self, z: np.ndarray, load_factor: float, ev: ContactEval) -> float:
        if self._row_scale is None:
            # traction rows times a length are forces, like the body rows: the
            # residual norm (and Newton's test) is then unit-free
            self._row_scale = 1.0
            if self.multiplier_kind == "traction" and np.any(ev.area > 0):
                self._row_scale = float(np.mean(ev.area[ev.area > 0]))
        if self.c is None:
            k = self._stiffness(z, load_factor)
            if self.multiplier_kind == "traction":
                h = float(np.mean(ev.area[ev.area > 0])) if np.any(ev.area > 0) else 1.0
                k /= h * h
            self.c = k
            log.debug("%s: complementarity parameter c = %.6g", self.name, k)
        return self.c

    # -- assembly --------------------------------------------------------------
    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True) -> Contribution:
        if self.friction is not None:
            return self._assemble_friction(z, load_factor, tangent)
        lam = np.asarray(z)[self._normal]
        ev = self.evaluate(z, tangent=True, with_lam=tangent)
        c = self._c(z, load_factor, ev)
        active = self._active_set(lam, ev, c, track=tangent)
        if tangent:  # e.g. NTS: segment hysteresis between iterations, vertex trap
            self.discretization.after_iteration(ev)
        gd = self.global_dofs()
        # body rows: -G^T lam
        G = ev.G.tocoo()
        keep = gd[G.col] >= 0
        rows_u, cols_l, vals = gd[G.col[keep]], self.offset + G.row[keep], G.data[keep]
        # multiplier rows: C(lam, g)
        rs = self._row_scale
        Cval = np.where(active, c * ev.g, lam) * rs
        out = Contribution(np.concatenate([rows_u, self.offset + np.arange(self.n_dofs)]),
                           np.concatenate([-vals * lam[G.row[keep]], Cval]))
        if not tangent:
            return out
        res = self._reservation(z, gd)
        if res is not None:  # the triplets over the reserved pattern (explicit zeros)
            kv = res.values(ev.G, ev.H, active, c, rs)
            if kv is None:
                res = self._widen(ev)
                kv = res.values(ev.G, ev.H, active, c, rs)
            out.k_rows, out.k_cols, out.k_vals = res.rows, res.cols, kv
            out.reserved = True
            return out
        kr, kc, kv = [rows_u], [cols_l], [-vals]  # K_ulam = -G^T
        act_g = active[G.row[keep]]  # K_lamu = c G on active rows
        kr.append(cols_l[act_g])
        kc.append(rows_u[act_g])
        kv.append(c * rs * vals[act_g])
        inact = np.flatnonzero(~active)  # K_lamlam = I on inactive rows
        kr.append(self.offset + inact)
        kc.append(self.offset + inact)
        kv.append(np.full(inact.size, rs))
        return _with_triplets(out, kr, kc, kv, gd, (ev.H,))  # K_uu = -H

    def analysis_coupling(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What each normal multiplier row would couple to when active, for the
        linear solver's analysis only: row ``A`` to the slave node's own dofs,
        ``sum_e n_e l_e / k`` over its segments ``e`` (outward normal times an
        equal share of the length, ``k`` nodes a segment: for 2-node segments its
        tributary length times the length-weighted mean normal), as global
        ``(rows, cols, vals)``.  A row not yet
        reached by the search has no coupling values; its weighted matching
        then pairs it with the dof it will pivot on once active
        (:func:`~skfem_mortar.solver.linsolve.symmetrize`)."""
        dofs = self.slave.dofs()
        if dofs is None:
            return (np.zeros(0, np.int64),) * 2 + (np.zeros(0),)
        seg = self.slave.segments
        nrm, length = self.slave.normals(z)
        share = length / seg.shape[1]
        v = np.stack([np.bincount(seg.ravel(), weights=np.repeat(nrm[k] * share, seg.shape[1]),
                                  minlength=self.slave.n_nodes) for k in (0, 1)])
        rows = np.repeat(self.offset + np.arange(self.slave.n_nodes, dtype=np.int64), 2)
        return rows, dofs.T.ravel().astype(np.int64), v.T.ravel()

    # -- friction ----------------------------------------------------------------
    def _p_reference(self, ev: ContactEval, c: float, xi: np.ndarray | None = None) -> float:
        """The tangential rows' pressure ``p_ref`` of the step (:meth:`_step_p_ref`;
        before any: ``c h^k``, ``h`` the mean tributary length, ``k = 1`` force
        multipliers, ``2`` traction ones: the multiplier a gap of one element
        length would give).  In a step whose start carries no slip bound that
        is a guess, and the bounds ``xi`` of a Newton iteration re-fix it
        (:data:`P_REF_FIT`)."""
        if self._p_ref is None:
            h = float(np.mean(ev.area[ev.area > 0])) if np.any(ev.area > 0) else 1.0
            self._p_ref = float(c * h ** (1 if self.multiplier_kind == "force" else 2))
        top = float(xi.max(initial=0.0)) if xi is not None else 0.0
        if self._p_ref_guess and top > 0 and not (
                top / P_REF_FIT <= self._p_ref <= top * P_REF_FIT):
            log.debug("%s: p_ref %.3g re-fixed to the iterate's largest slip bound %.3g",
                      self.name, self._p_ref, top)
            self._p_ref = top
        return self._p_ref

    def _step_p_ref(self, z: np.ndarray) -> None:
        """Fix ``p_ref`` for the step starting at ``z``: the largest slip bound
        ``Xi`` there (the size of the tangential multipliers the step resolves,
        so its rows ``s_t C_t`` weigh a multiplier error like the normal rows
        do), or the default of :meth:`_p_reference` where no node carries a
        bound yet.  Constant within a step that starts with a bound; a step
        without one re-fixes its guess to the iterates' bounds (:data:`P_REF_FIT`).
        With a direct solve a row scale changes when Newton stops, not its
        iterates (a line search's or a Krylov solve's steps may change)."""
        self._p_ref_guess = True
        if self.c is None:
            return
        lam = np.asarray(z)[self._normal]
        weight = (tributary_lengths(self.slave.x(z), self.slave.segments)
                  if self.multiplier_kind == "force" else 1.0)
        xi, _, _ = self._law.slip_bound(np.where(self.state.converged, lam, 0.0),
                                            np.zeros_like(lam), self.c, weight)
        xi = np.where(self.state.converged, xi, 0.0)
        if xi.max(initial=0.0) > 0:
            self._p_ref = float(xi.max())
            self._p_ref_guess = False

    def _history(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """The slip history of the last converged step (at the first step: of ``z``)."""
        if self._slip_history is None:
            ev = self.evaluate(z, tangent=False, with_lam=False)
            self._slip_history = self.discretization.slip_history(
                self.slave.x(z), self.master.x(z), ev)
        return self._slip_history

    def friction_rows(self, z: np.ndarray, tangent: bool = False, track: bool = False,
                      ev: ContactEval | None = None, active: np.ndarray | None = None,
                      history: dict[str, np.ndarray] | None = None
                      ) -> tuple[ContactEval, Any, FrictionRows]:
        """The normal evaluation, the slip (:class:`~skfem_mortar.contact.slip.SlipEval`)
        and the tangential complementarity rows
        (:func:`~skfem_mortar.contact.friction.complementarity`, with the
        statuses of :class:`~skfem_mortar.contact.active_set.StatusSet`) at ``z``.

        ``Xi`` is the law's slip bound (Coulomb ``mu (lam_n - c g_n)``, Tresca
        ``bound`` times the current tributary length for force multipliers,
        times 1 for traction ones), ``c_t = c``; nodes outside the normal active set or
        the slip's ``mask`` are open.  ``track``: a Newton iteration (the
        statuses are updated); ``active`` defaults to the current normal set;
        ``history`` to the slip history of the last converged step.
        """
        zz = np.asarray(z)
        lam, lam_t = zz[self._normal], zz[self._tangential]
        xs, xm = self.slave.x(z), self.master.x(z)
        if ev is None:
            ev = self.discretization.evaluate(xs, xm, lam if tangent else None, tangent)
        c = self._c(z, 1.0, ev) if self.c is None else self.c
        active = self.active if active is None else active
        sl = self.discretization.slip(xs, xm, self._history(z) if history is None else history,
                                      lam_t if tangent else None, tangent, ev)
        # Tresca's nodal bound: the traction bound times the current tributary length
        # for force multipliers (its derivative in _assemble_friction), 1 for tractions
        weight = ev.area if self.multiplier_kind == "force" else 1.0
        on = active & sl.mask
        jac = self.friction_jacobian
        fr = complementarity(self._law, lam, lam_t, ev.g, sl.u, c, c, on, weight, jacobian=jac)
        st = self.statuses.update(fr.status, track)
        if not np.array_equal(st, fr.status):
            fr = complementarity(self._law, lam, lam_t, ev.g, sl.u, c, c, on, weight,
                                 status=st, jacobian=jac)
        return ev, sl, fr

    def _assemble_friction(self, z: np.ndarray, load_factor: float,
                           tangent: bool) -> Contribution:
        """:meth:`assemble` with friction (docs/friction.md): body rows
        ``-G_n^T lam_n - G_t^T lam_t``, normal rows as without, tangential rows
        ``s_t C_t`` (``s_t = row_scale / p_ref``); tangent ``K_u,lam_t = -G_t^T``,
        ``K_uu = -(H_n + H_t)``, ``K_lam_t,u = s_t (diag(dC/du_t) G_t +
        diag(dC/dg_n) G_n)``, ``s_t dC/dlam_t`` and ``s_t dC/dlam_n`` diagonal."""
        zz = np.asarray(z)
        lam, lam_t = zz[self._normal], zz[self._tangential]
        xs, xm = self.slave.x(z), self.master.x(z)
        ev = self.discretization.evaluate(xs, xm, lam if tangent else None, True)
        c = self._c(z, load_factor, ev)
        active = self._active_set(lam, ev, c, track=tangent)
        ev, sl, fr = self.friction_rows(z, tangent=True, track=tangent, ev=ev, active=active)
        if tangent:
            self.discretization.after_iteration(ev)
        gd = self.global_dofs()
        n = self.slave.n_nodes
        rs = self._row_scale
        st = rs / self._p_reference(ev, c, fr.bound if tangent else None)
        keep = gd >= 0
        fu = ev.G.T @ lam + sl.G.T @ lam_t
        idx = self.offset + np.arange(n)
        out = Contribution(np.concatenate([gd[keep], idx, idx + n]),
                           np.concatenate([-fu[keep], np.where(active, c * ev.g, lam) * rs,
                                           st * fr.C]))
        if not tangent:
            return out
        B = sp.diags(fr.d_u) @ sl.G + sp.diags(fr.d_g) @ ev.G
        if self._moving_bound:
            B = B + sp.diags(fr.d_bound * self._law.bound) @ tributary_jacobian(
                xs, self.slave.segments, sl.G.shape[1])
        B = B.tocsr()
        res = self._friction_reservation(z, gd)
        if res is not None:  # the triplets over the reserved patterns (explicit zeros)
            args = (ev.G, ev.H, sl.G, B, sl.H, active, c, rs, st, fr)
            kv = res.values(*args)
            if kv is None and res.normal.values(ev.G, ev.H, active, c, rs) is None:
                self._widen(ev)  # the method's pattern missed G_n or H_n: says so
                res = self._friction_reservation(z, gd)
                kv = res.values(*args)
            if kv is None:  # e.g. NTS: a slip across more segments than reserved
                res = res.widened(ev.G, ev.H, sl.G, sl.H)
                self._reserved_t = (*self._reserved_t[:2], res)
                self.slip_pattern_widenings += 1
                log.debug("%s: the slip's pattern widened", self.name)
                kv = res.values(*args)
            out.k_rows, out.k_cols, out.k_vals = res.rows, res.cols, kv
            out.reserved = True
            return out

        def glob(M: sp.spmatrix, row0: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            C = M.tocoo()
            ok = gd[C.col] >= 0
            return row0 + C.row[ok], gd[C.col[ok]], C.data[ok]

        rn, cn, vn = glob(ev.G, self.offset)
        rt, ct, vt = glob(sl.G, self.offset + n)
        rb, cb, vb = glob(B, self.offset + n)
        act = active[rn - self.offset]
        inact = np.flatnonzero(~active)
        kr = [cn, ct, rn[act], self.offset + inact, rb, idx + n, idx + n]
        kc = [rn, rt, cn[act], self.offset + inact, cb, idx + n, idx]
        kv = [-vn, -vt, c * rs * vn[act], np.full(inact.size, rs), st * vb,
              st * fr.d_lam_t, st * fr.d_lam_n]
        return _with_triplets(out, kr, kc, kv, gd, (ev.H, sl.H))  # K_uu = -(H_n + H_t)

    def _friction_reservation(self, z: np.ndarray, gd: np.ndarray
                              ) -> FrictionReservation | None:
        """The friction pair's triplets over the method's reserved pattern and the
        slip's (:class:`FrictionReservation`), built anew when either changes
        (the normal reservation, or the slip history at a new step)."""
        res_n = self._reservation(z, gd)
        if res_n is None:
            return None
        h = self._slip_history
        if (self._reserved_t is None or self._reserved_t[0] is not res_n
                or self._reserved_t[1] is not h):
            P_t = self.discretization.slip_pattern(h)
            if self._moving_bound:   # the bound's columns: the slave segments' nodes
                P_t = P_t + tributary_pattern(self.slave.segments, self.slave.n_nodes,
                                              P_t.shape[1])
            self._reserved_t = (res_n, h, FrictionReservation(res_n, P_t))
        return self._reserved_t[2]

    def _reservation(self, z: np.ndarray, gd: np.ndarray) -> Reservation | None:
        """The tangent triplets over the discretization's reserved pattern
        (:class:`~skfem_mortar.contact.discretization.PatternedDiscretization`),
        built once per reservation; None for a method without the hook."""
        if not isinstance(self.discretization, PatternedDiscretization):
            return None
        P = self.discretization.pattern(self.slave.x(z), self.master.x(z))
        if (self._reserved is None or self._reserved[0] is not P
                or not self._reserved[1].fits(gd, self.offset)):
            self._reserved = (P, Reservation(P, gd, self.offset))
        return self._reserved[1]

    def _widen(self, ev: ContactEval) -> Reservation:
        """A pattern that missed entries of ``G`` or ``H`` (a method's bug): take
        them in (this reservation only) and say so."""
        P, res = self._reserved
        self.pattern_misses += 1
        log.warning("%s: method %r reserved a pattern without some entries of its G or H; "
                    "they are added (its pattern() must return a superset)", self.name,
                    self.method)
        res = res.widened(ev.G, ev.H)
        self._reserved = (P, res)
        return res

    @property
    def _moving_bound(self) -> bool:
        """Whether the step's slip bound moves with the slave: Tresca on force
        multipliers (``bound`` times the current tributary length)."""
        return isinstance(self._law, Tresca) and self.multiplier_kind == "force"

    # -- active set --------------------------------------------------------------
    @property
    def active(self) -> np.ndarray:
        """The current active set (bool per slave node), see :class:`ActiveSet`."""
        return self.state.active

    @active.setter
    def active(self, value: np.ndarray) -> None:
        self.state.active = np.asarray(value, dtype=bool)

    def _active_set(self, lam: np.ndarray, ev: ContactEval, c: float, track: bool) -> np.ndarray:
        """``lam - c g >= 0`` on the masked nodes, then :meth:`ActiveSet.update`."""
        plain = ev.mask & (lam - c * ev.g >= 0)
        return self.state.update(plain, ev.mask, track, lambda: self._tail_signal(lam, ev))

    def _tail_signal(self, lam: np.ndarray, ev: ContactEval) -> tuple[np.ndarray | None, bool]:
        """What the extrapolated release reads (the discretization's ``tail_signal``)."""
        return self.discretization.tail_signal(lam, ev)

    def gap_length(self, ev: ContactEval) -> np.ndarray:
        """Gaps as lengths: the gaps of force multipliers (NTS), or the weighted
        gaps of traction multipliers (mortar) over the tributary lengths."""
        if self.multiplier_kind == "force":
            return ev.g
        return ev.g / np.where(ev.area > 0, ev.area, 1.0)

    _gap_length = gap_length

    def failure_hint(self) -> str:
        """A likely cause to add to a :class:`ConvergenceError` ("" if none known):
        the discretization's, and with friction, when the last converged step's
        tangential force was within 2 % of its bound or every active node slides in
        the failed attempt, that the tangential load may exceed the friction bound
        (the failed attempt may have lost the contact altogether)."""
        hint = self.discretization.failure_hint()
        if self.friction is None:
            return hint
        act = self.active
        st = self.statuses.status
        near = False  # the last converged tangential force within 2 % of its bound
        if self._converged_t is not None:
            d = self._converged_t[3]
            bound = float(np.sum(d["bound"] * self._area0))
            near = bound > 0 and abs(float(np.sum(d["tangential_traction"] * self._area0))
                                     ) >= NEAR_BOUND * bound
        if near or (act.any() and np.all(st[act] == SLIP)):
            law = (f"mu = {self.friction.mu:g} times the normal force"
                   if isinstance(self.friction, Coulomb) else
                   f"the Tresca bound {self.friction.bound:g} times the contact length")
            more = (f"{self.name}: the contact slides as a whole (tangential force at the "
                    f"friction bound): the tangential load exceeds the friction bound "
                    f"({law}), which has no "
                    f"equilibrium under load control; keep the tangential load below the "
                    f"bound or prescribe the tangential displacement instead")
            hint = "; ".join(h for h in (hint, more) if h)
        return hint

    def settled(self) -> bool:
        """The normal active set (and with friction the statuses) did not change."""
        if self.friction is not None and self.statuses.changed:
            return False
        return not self.state.changed

    def initial_active(self, z: np.ndarray, load_factor: float) -> np.ndarray:
        """The active set the first load step starts from (bool per slave node);
        after the first step, the last converged set.

        Nodes with a master partner where ``lam - c g >= 0``, or whose gap (as a
        length) is within the touch tolerance, or that the master touches
        within it (:func:`~skfem_mortar.contact.active_set.touching_nodes`).
        """
        if self._started:
            return self.state.converged.copy()
        ev = self.evaluate(z, tangent=False, with_lam=False)
        c = self._c(z, load_factor, ev)
        lam = np.asarray(z)[self._normal]
        touch = touching_nodes(self.slave.x(z), self.slave.segments, self.master.x(z),
                               self.master.segments, self._touch)
        return ev.mask & ((lam - c * ev.g >= 0) | touch | (self.gap_length(ev) <= self._touch))

    def begin_step(self, z: np.ndarray, load_factor: float) -> None:
        """Start (or retry) a step from the last converged active set; the first
        iteration uses it as it is (less the nodes out of mask).  Before the first
        step: the initial active set."""
        first = not self._started
        if first:
            self.state.converged = self.initial_active(z, load_factor)
            self._started = True
        xs, xm = self.slave.x(z), self.master.x(z)
        if self.converged_positions is None:  # later: kept from the last converged state (end_step)
            self.converged_positions = (xs, xm)
        self.state.begin()
        self.discretization.begin_step(xs, xm, first)
        if self.friction is not None:
            # frictionless in the steps ending at or before the law's start
            self._law = self.friction if self.friction.acts(load_factor) else NO_FRICTION
            self.statuses.begin()
            self._history(z)  # the first step: measured from its start
            self._step_p_ref(z)

    def pressure_and_gap(self, z: np.ndarray, ev: ContactEval | None = None
                         ) -> tuple[np.ndarray, np.ndarray, ContactEval]:
        """Per slave node the pressure (traction) and the gap (length) in the
        method's own discrete form: NTS ``lam / a_A`` and the nodal gap; mortar
        ``lam`` and the weighted gap over ``D_AA`` (the tributary length)."""
        lam = np.asarray(z)[self._normal]
        if ev is None:
            ev = self.evaluate(z, tangent=False, with_lam=False)
        area = np.where(ev.area > 0, ev.area, 1.0)
        p = lam / area if self.multiplier_kind == "force" else lam.copy()
        return p, self.gap_length(ev), ev

    def violation(self, z: np.ndarray, scale: float) -> str:
        """The KKT conditions at a state whose residual passed ("" if they hold).

        With ``tol_g = K_GAP * h`` (``h`` the median slave segment length) and
        ``tol_p = K_LAM * scale / L_c`` (``L_c`` the tributary length of the
        active nodes, at least ``h``): every node facing a master has
        ``g >= -tol_g``; every node has ``p >= -tol_p``; ``|g| <= tol_g``
        wherever ``p > tol_p``; a node facing no master carries no pressure.
        """
        p, g, ev = self.pressure_and_gap(z)
        m = ev.mask
        g = np.where(m, g, 0.0)
        act = self.active
        length = max(float(np.sum(np.where(act, ev.area, 0.0))), self._h)
        tol_g, tol_p = K_GAP * self._h, K_LAM * scale / length
        self._tol_p = tol_p
        bad = {"penetration": m & (g < -tol_g), "tension": p < -tol_p,
               "pressure on an open gap": m & (p > tol_p) & (np.abs(g) > tol_g),
               "pressure without a master": ~m & (np.abs(p) > tol_p)}
        worst = {"penetration": -g, "tension": np.abs(p)}
        if self.friction is not None:
            more, size = self._friction_violation(z, ev, tol_g, tol_p)
            bad.update(more)
            worst.update(size)
        msgs = []
        for what, nodes in bad.items():
            if nodes.any():
                k = np.flatnonzero(nodes)
                w = worst.get(what, np.abs(g) if "gap" in what else np.abs(p))[k].max()
                msgs.append(f"{what} at {k.size} node(s) (worst {w:.3g}, e.g. node {k[0]})")
        if not msgs:
            return ""
        return (f"{self.name}: KKT violated ({'; '.join(msgs)}; tolerances: gap "
                f"{tol_g:.3g}, pressure {tol_p:.3g})")

    def tangential_data(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """Friction only: per slave node (surface order) the tangential
        traction ``t_t`` (NTS ``lam_t / a_A``, mortar ``lam_t``; along the
        node's tangent ``tau``, on the slave), the slip within the step as a
        length (NTS ``u_t``, mortar ``u_t / area_A``), the slip bound as a
        traction (``Xi`` over the same weight), the status codes
        (:data:`~skfem_mortar.contact.friction.OPEN`, ``STICK``, ``SLIP``) and ``tangent``.

        At the state of the last converged step these are that step's (its slip
        from the step's start, the statuses it converged with); at any other
        state the slip is measured from the last converged step and the
        statuses are the plain ones of :func:`~skfem_mortar.contact.friction.complementarity`."""
        rebind(self)  # this pair's model's layout, if another model was used since
        lam_t = np.asarray(z)[self._tangential]
        conv = self._at_converged(z)
        if conv is not None:
            return {k: v.copy() for k, v in conv[3].items()}
        ev, sl, fr = self.friction_rows(z, tangent=False, track=False)
        area = np.where(ev.area > 0, ev.area, 1.0)
        if self.multiplier_kind == "force":
            t, u, b = lam_t / area, sl.u, fr.bound / area
        else:
            t, u, b = lam_t.copy(), sl.u / area, fr.bound.copy()
        return {"tangential_traction": t, "slip": np.where(sl.mask, u, 0.0), "bound": b,
                "status": fr.status.copy(), "tangent": sl.tangent}

    def _at_converged(self, z: np.ndarray) -> tuple | None:
        """``(xs, xm, lam_t, tangential_data, history)`` of the last converged step
        if ``z`` is its state (the history its slip was measured from), else None."""
        conv = self._converged_t
        if conv is not None and all(np.array_equal(a, b) for a, b in zip(
                conv[:3], (self.slave.x(z), self.master.x(z),
                           np.asarray(z)[self._tangential]))):
            return conv
        return None

    def _friction_violation(self, z: np.ndarray, ev: ContactEval, tol_g: float,
                            tol_p: float) -> tuple[dict, dict]:
        """The friction conditions of a converged state (:meth:`violation`):
        ``|t_t| <= Xi (1 + K_LAM) + tol_p`` everywhere; ``|u_t| <= tol_g`` on
        stick nodes; on slip nodes that slip (``|u_t| > tol_g``)
        ``t_t u_t <= 0`` and ``||t_t| - Xi| <= K_LAM Xi + tol_p``; ``|t_t| <= tol_p``
        on open nodes (``t_t``, ``u_t``, ``Xi`` as :meth:`tangential_data`'s)."""
        d = self.tangential_data(z)
        t, u, b, stt = d["tangential_traction"], d["slip"], d["bound"], d["status"]
        moving = (stt == SLIP) & (np.abs(u) > tol_g)
        bad = {"tangential traction above the slip bound":
               np.abs(t) > b * (1 + K_LAM) + tol_p,
               "slip of a stick node": (stt == STICK) & (np.abs(u) > tol_g),
               "slip along the tangential traction": moving & (t * u > 0),
               "sliding below the slip bound": moving & (np.abs(np.abs(t) - b)
                                                        > K_LAM * b + tol_p),
               "tangential traction on an open node": (stt == OPEN) & (np.abs(t) > tol_p)}
        size = {"tangential traction above the slip bound": np.abs(t) - b,
                "slip of a stick node": np.abs(u), "slip along the tangential traction": t * u,
                "sliding below the slip bound": np.abs(np.abs(t) - b),
                "tangential traction on an open node": np.abs(t)}
        return bad, size

    def end_step(self, z: np.ndarray, load_factor: float) -> None:
        lam = z[self._normal]  # a view: inactive multipliers are exactly zero from here
        lam[~self.active] = 0.0
        self.state.end()
        if self.friction is not None:
            lam_t = z[self._tangential]
            lam_t[self.statuses.status == OPEN] = 0.0
            self.statuses.end()
            # what the step did (its slip from the history it was measured from),
            # for the outputs of the converged state
            data = self.tangential_data(z)
            data["status"] = self.statuses.converged.copy()
            self._converged_t = (self.slave.x(z), self.master.x(z), lam_t.copy(), data,
                                 self._slip_history)
            ev = self.evaluate(z, tangent=False, with_lam=False)
            self._slip_history = self.discretization.slip_history(
                self.slave.x(z), self.master.x(z), ev)
        self.converged_positions = (self.slave.x(z), self.master.x(z))
        self.discretization.end_step(*self.converged_positions)
        if self.state.cycles:
            log.info("%s: step converged after the cycling guard acted %d time(s); the "
                     "KKT conditions were checked", self.name, self.state.cycles)

    # -- checkpoint --------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """What shapes the next load step: the converged active set, the
        complementarity parameter ``c`` and the row scale, the contact node
        positions at the last converged state (the search reach), and the
        discretization's state (NTS: the segment preferences and locks
        ``prefer``, ``lock``).  Missing entries are ``[]`` (not set yet)."""
        def arr(a, dtype=float):
            return np.zeros(0, dtype=dtype) if a is None else np.asarray(a, dtype=dtype).copy()
        x0 = self.converged_positions
        return {"started": np.array(self._started),
                "active": self.state.converged.copy(),
                "c": arr(None if self.c is None else [self.c]),
                "row_scale": arr(None if self._row_scale is None else [self._row_scale]),
                "x0_slave": arr(None if x0 is None else x0[0]),
                "x0_master": arr(None if x0 is None else x0[1]),
                "tol_p": np.array(self._tol_p),
                **self.discretization.state_dict(), **self._friction_state()}

    def _friction_state(self) -> dict[str, np.ndarray]:
        """Friction only: the converged statuses, ``p_ref`` and the slip history
        (``[]`` entries before it is set)."""
        if self.friction is None:
            return {}
        h = self._slip_history
        keys = self.discretization.slip_history_keys
        return {"friction_status": self.statuses.converged.copy(),
                "friction_p_ref": (np.zeros(0) if self._p_ref is None
                                   else np.array([self._p_ref])),
                **{k: (np.zeros(0) if h is None else np.asarray(h[k]).copy()) for k in keys}}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state_dict` (ValueError naming the entry that does not
        fit; nothing is restored then)."""
        need = set(self.state_dict())
        if set(state) != need:
            raise ValueError(f"{self.name}: checkpoint state has entries {sorted(state)}, "
                             f"expected {sorted(need)}")
        ns, nm = self.slave.n_nodes, self.master.n_nodes
        check_entries(self.name, state, {
            "active": [(ns,)], "c": [(0,), (1,)], "row_scale": [(0,), (1,)],
            "x0_slave": [(0,), (2, ns)], "x0_master": [(0,), (2, nm)], "started": [()],
            "tol_p": [()]})
        for k in ("c", "row_scale"):
            if state[k].size and not state[k][0] > 0:
                raise ValueError(f"{self.name}: checkpoint entry {k!r} must be > 0, "
                                 f"got {state[k][0]}")
        if not float(state["tol_p"]) >= 0:
            raise ValueError(f"{self.name}: checkpoint entry 'tol_p' must be >= 0")
        own = set(_PAIR_STATE)
        if self.friction is not None:
            own |= set(_FRICTION_STATE) | set(self.discretization.slip_history_keys)
            history = self._check_friction_state(state)
        # the discretization checks its entries before it takes any
        self.discretization.load_state_dict({k: state[k] for k in need - own})
        if self.friction is not None:
            self.statuses.converged = np.asarray(state["friction_status"], dtype=np.int8).copy()
            self._p_ref = (float(state["friction_p_ref"][0]) if state["friction_p_ref"].size
                           else None)
            self._slip_history = history
        self._started = bool(state["started"])
        self._tol_p = float(state["tol_p"])
        self.state.converged = np.asarray(state["active"], dtype=bool).copy()
        self.c = float(state["c"][0]) if state["c"].size else None
        self._row_scale = float(state["row_scale"][0]) if state["row_scale"].size else None
        self.converged_positions = ((np.array(state["x0_slave"], dtype=float),
                     np.array(state["x0_master"], dtype=float))
                    if state["x0_slave"].size else None)

    def _check_friction_state(self, state: dict[str, np.ndarray]) -> dict | None:
        """The friction entries of a checkpoint checked (ValueError naming the
        entry); the slip history they hold (None if not set yet)."""
        ns = self.slave.n_nodes
        check_entries(self.name, state, {"friction_status": [(ns,)],
                                         "friction_p_ref": [(0,), (1,)]})
        st = np.asarray(state["friction_status"])
        if not np.all(np.isin(st, (OPEN, STICK, SLIP))):
            raise ValueError(f"{self.name}: checkpoint entry 'friction_status' must hold the "
                             f"codes {OPEN}, {STICK}, {SLIP} ({', '.join(STATUS_NAMES)})")
        if state["friction_p_ref"].size and not state["friction_p_ref"][0] > 0:
            raise ValueError(f"{self.name}: checkpoint entry 'friction_p_ref' must be > 0")
        keys = self.discretization.slip_history_keys
        if all(np.asarray(state[k]).size == 0 for k in keys):
            return None
        history = {k: np.asarray(state[k]).copy() for k in keys}
        self.discretization.check_slip_history(history)
        return history

    def step_info(self) -> dict:
        """``n_active`` nodes, ``active_set_changes`` (node status flips summed over the
        step's iterations), ``active_set_cycles`` (times the cycling guard acted),
        ``segment_locks`` (NTS nodes locked by the vertex-trap guard; 0 for a
        method without) and what else the discretization counts."""
        return {"n_active": int(self.active.sum()), "active_set_changes": self.state.changes,
                "active_set_cycles": self.state.cycles, "segment_locks": 0,
                **self.discretization.step_info(), **self._friction_info()}

    def _friction_info(self) -> dict:
        """Friction only: ``n_stick``, ``n_slip`` nodes, ``friction_status_changes``,
        ``friction_status_cycles`` of the step."""
        if self.friction is None:
            return {}
        st = self.statuses.status
        return {"n_stick": int(np.sum(st == STICK)), "n_slip": int(np.sum(st == SLIP)),
                "friction_status_changes": self.statuses.changes,
                "friction_status_cycles": self.statuses.cycles}

    # -- results -----------------------------------------------------------------
    def outputs(self) -> list:
        """The slave surface as one output series (pressure, gap, ``has_master``
        per slave node): a :class:`~skfem_mortar.output.contact_output.ContactOutput`."""
        return [ContactOutput(self)]

    def contact_data(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """Per slave node: ``x, y`` (current), ``gap`` (length) and ``pressure`` (traction).

        The rows follow the slave surface: chain order, an open chain from its
        end with the smaller reference ``x`` (then ``y``), a closed one from the
        start of its first segment; ``node`` is the surface node of each row
        (``pair.active[d["node"]]``, ``pair.slave.X[:, d["node"]]`` line up
        with the rows).  NTS: ``pressure = lam / tributary length``; mortar: ``pressure = lam`` and
        ``gap = weighted gap / tributary length``.  ``has_master`` marks the
        nodes that face a master segment; elsewhere ``gap`` is NaN (undefined)
        and ``distance`` holds the node's distance to the master surface, a
        finite length that the output files write as the gap there (beside the
        ``has_master`` mask), so no file carries a NaN or a 0 that reads as
        touching; where ``has_master``, ``distance`` equals ``gap``.  Inactive multipliers of a
        converged state are exact zeros; a round-off tension within the KKT
        tolerance (:meth:`violation`) is written as 0.  With friction also
        ``tangential_traction``, ``slip`` (a length) and ``status`` (``"open"``,
        ``"stick"``, ``"slip"``) of :meth:`tangential_data`.
        """
        rebind(self)  # this pair's model's layout, if another model was used since
        p, g, ev = self.pressure_and_gap(z)
        # round-off tension of a converged state (within the KKT tolerance) is
        # written as 0: outputs never show a negative pressure that is not there
        p = np.where((p < 0) & (p >= -self._tol_p), 0.0, p)
        p[p == 0] = 0.0  # no -0.0
        x = self.slave.x(z)
        g = np.where(ev.mask, g, np.nan)
        dist = np.where(ev.mask, g, 0.0)
        if not ev.mask.all():
            far = ~ev.mask
            dist[far] = distance_to_polyline(x[:, far], self.master.x(z), self.master.segments)
        data = {"x": x[0], "y": x[1], "gap": g, "pressure": p, "has_master": ev.mask,
                "distance": dist}
        if self.friction is not None:
            t = self.tangential_data(z)
            data.update({"tangential_traction": t["tangential_traction"], "slip": t["slip"],
                         "status": np.asarray(STATUS_NAMES)[t["status"]]})
        k = self._along_surface()
        return {**{name: v[k] for name, v in data.items()}, "node": k}

    def _along_surface(self) -> np.ndarray:
        """Surface node indices in the order of :meth:`contact_data`'s rows."""
        s = self.slave
        order = chain_order(s.segments, s.closed, s.n_nodes)
        if order is None:  # not one chain through every node: the surface's order
            return np.arange(s.n_nodes)
        a, b = s.X[:, order[0]], s.X[:, order[-1]]
        if not s.closed and (a[0], a[1]) > (b[0], b[1]):
            order = order[::-1]
        return np.ascontiguousarray(order, dtype=np.int64)

    def __repr__(self) -> str:
        """One line: name, method, the two surfaces and the active nodes."""
        def side(s: Any) -> str:
            return f"{getattr(s, 'name', type(s).__name__)!r} ({s.n_nodes} nodes)"
        return (f"ContactPair({self.name!r}, {self.method}: slave {side(self.slave)} on "
                f"master {side(self.master)}, {int(np.sum(self.active))} active)")

    def forces(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Contact forces ``(2, n)`` on the slave and on the master nodes: ``H G^T lam``
        split into the two surfaces (the force the other body exerts; the residual
        term is its negative), totals over the model's thickness ``H``
        (:attr:`~skfem_mortar.core.item.Item.thickness`)."""
        rebind(self)  # this pair's model's layout, if another model was used since
        lam = np.asarray(z)[self._normal]
        ev = self.evaluate(z, tangent=True, with_lam=False)
        f = self.thickness * (ev.G.T @ lam)
        if self.friction is not None:  # and the tangential part G_t^T lam_t of the step
            conv = self._at_converged(z)
            _, sl, _ = self.friction_rows(z, tangent=True, ev=ev,
                                          history=None if conv is None else conv[4])
            f = f + self.thickness * (sl.G.T @ np.asarray(z)[self._tangential])
        n_s = self.slave.n_nodes
        return f[:2 * n_s].reshape(-1, 2).T, f[2 * n_s:].reshape(-1, 2).T

    def total_force(self, z: np.ndarray) -> np.ndarray:
        """Resultant (2,) of the contact force on the slave surface (a total over
        the model's thickness, as :meth:`forces`)."""
        rebind(self)  # this pair's model's layout, if another model was used since
        return self.forces(z)[0].sum(axis=1)
