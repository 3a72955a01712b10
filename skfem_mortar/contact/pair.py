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

The pair wires small parts and asks none of them which kind it is: the
multiplier space of its method (:mod:`.multiplier_spaces`: pressure and gap
readings, row scale, ``c``), the normal rows (:mod:`.normal_rows`), the
tangential rows of its friction law (:mod:`.tangential_rows`: a law with
tangential multipliers, e.g. ``friction=Coulomb(mu)`` or ``Tresca(bound)``,
gives every slave node ``d - 1`` of them after the normal ones, with the
semi-smooth stick/slip rows of :mod:`skfem_mortar.contact.friction` on the slip
of :mod:`skfem_mortar.contact.slip`; ``friction=None`` none, and the pair runs
none of that), the reserved tangent pattern (:mod:`.reservation`), the
checkpoint (:mod:`.pair_state`), the KKT check (:mod:`.kkt`) and the outputs
(:mod:`.pair_output`).

The gaps and their derivatives, and whatever state the method keeps for them,
are the contact discretization's (:class:`~skfem_mortar.contact.discretization.ContactDiscretization`,
looked up by ``method`` in the registry of :mod:`skfem_mortar.contact.discretization`);
the pair is method-neutral.
"""
from __future__ import annotations

import logging
from typing import Any

import numpy as np

from . import pair_output, pair_state
from . import preflight as _preflight  # noqa: F401 (registers the checks Model.preflight runs)
from .active_set import ActiveSet, chain_order, touching_nodes
from .contact_eval import ContactEval
from .discretization import (MeasuredDiscretization, PatternedDiscretization,
                             SymmetricDiscretization)
from .friction import FRICTIONLESS, FrictionLaw, FrictionRows, as_law
from .kkt import K_GAP, K_LAM, violation
from .measures import PLANE, Measure, measure_for
from .methods import METHODS, make_method  # METHODS: the registry's names, the built-ins in it
from .nts_faces import FACE_CELLS
from .search import cell_sizes
from .symmetry import check_planes, planes_from_fixed
from .multiplier_spaces import MultiplierSpace, space_for
from .reservation import Reservation
from .segmentation import surface_cell
from .surfaces import check_geometry
from .tangential_rows import NEAR_BOUND, P_REF_FIT, tangential_rows
from ..core.binding import rebind
from ..core.item import Contribution, Item
from ..core.validate import real
from ..output.contact_output import ContactOutput

__all__ = ["ContactPair", "METHODS", "K_GAP", "K_LAM", "NEAR_BOUND", "P_REF_FIT"]

log = logging.getLogger(__name__)

#: the components of :mod:`.symmetry`'s planes (``check_planes``, ``planes_from_fixed``)
PLANE_COMPONENTS = 3


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


def _check_offered(slave: Any, master: Any, friction: Any) -> None:
    """Refuse what a pair of these surfaces does not offer: a slave and a master of
    cells of two dimensions (a curve and a face surface), and on faces (tri3, quad4:
    :data:`~.nts_faces.FACE_CELLS`) self-contact and friction; each ValueError names
    the feature and the alternative.  Which method takes which cells is the method's
    to say (quadratic faces: refused by every built-in method)."""
    cs, cm = surface_cell(slave), surface_cell(master)
    if cs.dim != cm.dim:
        raise ValueError(f"{slave.name!r} is a surface of {cs.name} cells and "
                         f"{master.name!r} one of {cm.name} cells: the slave and the master "
                         f"of a contact pair must both be faces or both be curves; in 3D "
                         f"use RigidPlane3D, RigidSphere or RigidCylinder for a rigid master")
    if cs.name not in FACE_CELLS:
        return
    if slave.body is not None and slave.body is master.body:
        raise ValueError("self-contact in 3D (slave and master on the same body) is not "
                         "offered yet; split the body into two bodies tied by a TiePair, "
                         "or use a plane model")
    if as_law(friction) is not FRICTIONLESS:
        raise ValueError("friction in 3D is not offered yet; use frictionless contact "
                         "(friction=None), or a plane or axisymmetric model")


def _chain_order(slave: Any) -> np.ndarray | None:
    """The slave nodes in chain order where its cells chain (two corners each: a curve),
    else None (:class:`~.active_set.ActiveSet` then releases no tail in order)."""
    cell = surface_cell(slave)
    if len(cell.corners) != 2:
        return None
    return chain_order(slave.segments, slave.closed, slave.n_nodes, cell)


class ContactPair(Item):
    """Contact between a slave and a master surface with Lagrange multipliers,
    frictionless or with Coulomb or Tresca friction, in plane and axisymmetric models;
    frictionless between the faces of 3D bodies (tri3, quad4) in 3D models: NTS,
    mortar and mortar-dual (:mod:`.mortar_faces`), NTS also against a rigid plane,
    sphere or cylinder (:mod:`.rigid3d`).

    In an axisymmetric model (``Model(..., geometry="axisymmetric")``, ``(r, z) =
    (x, y)``) every integral over the slave weighs ``2 pi r dGamma`` (the measure
    the pair tells its method at bind, :attr:`measure`): the multipliers' forces
    and :meth:`total_force` are totals over the revolution, NTS's tributary weights
    ``2 pi int N_A r dGamma`` (``2 pi h^2 / 6`` at an axis node of a flat ``line2``
    cell); a rigid master is a plate normal to the axis, a cylinder about it or a
    sphere centred on it (:func:`~.surfaces.check_geometry`); friction acts along
    the meridian, and slave nodes on the axis cannot slip (their tangential rows
    are open).

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
        :func:`skfem_mortar.contact.mortar_kernel.evaluate`; lines only: refused between faces).
    accelerate : bool
        When the tensile tail of a too-wide contact zone is released, release
        as many nodes again beyond the tail as the sign change of the
        multipliers extrapolates (default True; see
        :class:`~skfem_mortar.contact.active_set.ActiveSet`).  Steers only the path of
        the iteration.
    friction : FrictionLaw, optional
        A friction law (:mod:`skfem_mortar.contact.friction`: ``Coulomb(mu)``,
        ``Tresca(bound)`` or a registered subclass of ``FrictionLaw``); None (default):
        frictionless, exactly the pair without it.  With a law every slave node
        gets a tangential multiplier (the tangential traction, NTS: force, on
        the slave along the node's tangent) after the normal ones, the slip
        within the load step (:mod:`skfem_mortar.contact.slip`) and the
        semi-smooth stick/slip rows of
        :func:`~skfem_mortar.contact.friction.complementarity` (docs/friction.md);
        on 2-node and 3-node (quadratic) segments alike.  Not in 3D yet.
    symmetry : list of (normal, offset), optional
        3D only: the symmetry planes ``normal . x = offset`` of a quarter or half
        model (:mod:`.symmetry`), told to a method with the hook
        (:class:`~.discretization.SymmetricDiscretization`): NTS takes a master face
        edge on one for no free border, mortar gives the slave nodes on one the mirror
        normal.  None
        (default): read from the Dirichlet data (a coordinate plane bounding the
        slave surface on which every slave node's normal dof is held).
    **options
        The discretization's options (e.g. ``margin``), checked when it is built.

    Attributes
    ----------
    discretization : ContactDiscretization
        The method's gaps, derivatives and state.
    friction : FrictionLaw or None
        The friction law as given.
    space : MultiplierSpace
        The method's multiplier space (:mod:`.multiplier_spaces`).
    rows : TangentialRows or NoTangentialRows
        The tangential rows of the law (:mod:`.tangential_rows`).
    """

    dof_kind = "lam"
    geometries = ("plane", "axisymmetric", "3d")
    _geometry = "plane"
    loaded = False  # its residual does not depend on the load factor
    #: K_lamu = c G on active rows against K_ulam = -G^T (and H): not symmetric
    symmetric = False
    phase = "contact"

    def __init__(self, slave: Any, master: Any, method: str = "mortar-dual", name: str = "contact",
                 c: float | None = None, cycle_guard: bool = True,
                 touch_tolerance: float = 1e-2, segmentation: str = "iteration",
                 accelerate: bool = True, friction: FrictionLaw | None = None,
                 symmetry: Any = None, **options: Any):
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
        _check_surface("slave", slave)
        _check_surface("master", master)
        _check_offered(slave, master, friction)
        #: declared symmetry planes ``(unit normal, offset)`` (:mod:`.symmetry`)
        self.symmetry = check_planes(symmetry)
        if self.symmetry and self.symmetry[0][0].size != slave.X.shape[0]:
            raise ValueError(f"symmetry planes have {self.symmetry[0][0].size} components "
                             f"(contact between 3D bodies), the slave's nodes "
                             f"{slave.X.shape[0]}; a plane model's symmetry line is a "
                             f"Dirichlet condition")
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
        law = as_law(friction)
        self.discretization = make_method(method, slave, master, pair_name=name, **options)
        if isinstance(self.discretization, MeasuredDiscretization):
            self.discretization.set_measure(PLANE)  # until a model of another geometry binds it
        #: the multiplier space of the method (:func:`~.multiplier_spaces.space_for`)
        self.space: MultiplierSpace = space_for(self.discretization)
        #: the friction law as given (None: frictionless, one multiplier per slave node)
        self.friction = friction
        #: the slip branch's derivatives (:func:`~skfem_mortar.contact.friction.complementarity`):
        #: ``"projected"`` (default) or ``"exact"`` (the finite-difference tests)
        self.friction_jacobian = "projected"
        self.c = c
        lengths = cell_sizes(slave.X, slave.segments, surface_cell(slave))
        self._touch = float(touch_tolerance) * float(np.mean(lengths))
        self._h = float(np.median(lengths))  # the gap tolerance's length
        self._tol_p = 0.0  # pressure tolerance of the last converged check
        self._row_scale: float | None = None
        self._reference: tuple[np.ndarray, np.ndarray] | None = None  # converged_positions
        #: the tangential rows of the law (:mod:`.tangential_rows`)
        self.rows = tangential_rows(self, law, cycle_guard)
        self.n_dofs = slave.n_nodes * (1 + self.rows.per_node)
        clash = set(self.discretization.state_dict()) & (set(pair_state.PAIR_STATE)
                                                         | set(self.rows.state_keys()))
        if clash:
            raise ValueError(f"method {method!r} names its state {sorted(clash)}, which the "
                             f"pair's state uses; rename them")
        self.state = ActiveSet(slave.n_nodes, _chain_order(slave), name,
                               cycle_guard=cycle_guard, accelerate=accelerate)
        self._started = False
        #: (the discretization's pattern, the triplets over it) and how often a
        #: pattern missed an entry of G or H (:meth:`_widen`)
        self._reserved: tuple[Any, Reservation] | None = None
        self.pattern_misses = 0

    # -- geometry ------------------------------------------------------------

    @property
    def geometry(self) -> str:
        """The model's geometry (:attr:`~skfem_mortar.core.item.Item.geometry`),
        written by the model at bind; setting another tells the method its
        measure (:meth:`~.discretization.MeasuredDiscretization.set_measure`)."""
        return self._geometry

    @geometry.setter
    def geometry(self, value: str) -> None:
        if value == self._geometry:
            return
        measure = measure_for(value)
        if self._started:
            raise ValueError(f"contact pair {self.name!r} has taken load steps in a "
                             f"{self._geometry!r} model; it cannot move to a {value!r} one: "
                             f"build a new ContactPair for that model")
        if not isinstance(self.discretization, MeasuredDiscretization):
            raise ValueError(f"method {self.method!r} has no set_measure hook "
                             f"(MeasuredDiscretization): it integrates over plane surfaces "
                             f"only, and contact pair {self.name!r} is in a {value!r} model; "
                             f"use one of the built-in methods (nts, mortar, mortar-dual) or "
                             f"give the method set_measure")
        for role, surface in (("slave", self.slave), ("master", self.master)):
            check_geometry(surface, value, role)
        self.discretization.set_measure(measure)
        self._geometry = value

    @property
    def measure(self) -> Measure:
        """The weight of ``dGamma`` in the pair's geometry (:func:`~.measures.measure_for`):
        1 in a plane model, ``2 pi r`` in an axisymmetric one."""
        return measure_for(self._geometry)

    # -- helpers -------------------------------------------------------------

    @property
    def _normal(self) -> slice:
        """Global slice of the normal multipliers (the first ``n_s`` of the pair's)."""
        return slice(self.offset, self.offset + self.slave.n_nodes)

    @property
    def _tangential(self) -> slice:
        """Global slice of the tangential multipliers (after the normal ones; empty
        without tangential rows)."""
        n = self.slave.n_nodes
        return slice(self.offset + n, self.offset + (1 + self.rows.per_node) * n)

    @property
    def statuses(self) -> Any:
        """The stick/slip statuses of the tangential rows
        (:class:`~skfem_mortar.contact.active_set.StatusSet`; AttributeError without)."""
        return self.rows.statuses

    @property
    def slip_pattern_widenings(self) -> int:
        """Times the slip's reserved pattern was widened (tangential rows only)."""
        return self.rows.slip_pattern_widenings

    @property
    def _area0(self) -> np.ndarray:
        return self.rows.area0

    @property
    def multipliers_per_node(self) -> int:
        """1 (frictionless: the normal multiplier) or 2 (with friction: normal
        multipliers at ``offset .. offset + n_s``, tangential ones after them)."""
        return 1 + self.rows.per_node

    @property
    def symmetrizable(self) -> bool:
        """Its multiplier rows can be scaled to a symmetric system (active rows
        ``c s G`` against the columns ``-G^T``, inactive rows the identity) when
        ``H`` is symmetric (the discretization's ``symmetric``) and its triplets
        lie on a reserved pattern (the same structure for rows and columns).
        Never with tangential rows: they are no multiple of their columns."""
        return bool(self.rows.symmetric and self.discretization.symmetric
                    and isinstance(self.discretization, PatternedDiscretization))

    def referenced_bodies(self) -> list:
        """The bodies of the slave and (unless rigid) the master surface."""
        return [b for b in (self.slave.body, self.master.body) if b is not None]

    @property
    def multiplier_kind(self) -> str:
        """"force" (NTS) or "traction" (mortar): the multiplier space's."""
        return self.space.kind

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
        dm = (np.full(self.slave.X.shape[0] * self.master.n_nodes, -1, dtype=np.int64)
              if dm is None else dm.T.ravel())
        return np.concatenate([ds, dm]).astype(np.int64)

    def evaluate(self, z: np.ndarray, tangent: bool = True, with_lam: bool = True) -> ContactEval:
        """The discretization's :class:`ContactEval` at ``z`` (in the multiplier space)."""
        lam = np.asarray(z)[self._normal] if with_lam else None
        return self.space.evaluate(self.discretization, self.slave.x(z), self.master.x(z), lam,
                                   tangent)

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
            ds = self.slave.dofs()  # (d, n)
            pinned = np.all(np.isin(ds, np.asarray(fixed)), axis=0)
        self.discretization.set_pinned(pinned)
        if isinstance(self.discretization, SymmetricDiscretization):
            self.discretization.set_symmetry(self._planes(fixed))

    def _planes(self, fixed: np.ndarray) -> list:
        """The symmetry planes: declared, else read from the Dirichlet data (:mod:`.symmetry`,
        planes of as many components as the slave's coordinates; none otherwise)."""
        if self.symmetry:
            return self.symmetry
        X = np.asarray(self.slave.X, dtype=float)
        if X.shape[0] != PLANE_COMPONENTS:
            return []
        return planes_from_fixed(X, self.slave.dofs(), fixed)

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
        """``c`` (from the bodies' stiffness through the space, once) and the row
        scale (the space's: rows of tractions times a length are forces, like the
        body rows, so the residual norm and Newton's test are unit-free)."""
        if self._row_scale is None:
            self._row_scale = self.space.row_scale(ev.area)
        if self.c is None:
            k = self.space.complementarity(self._stiffness(z, load_factor), ev.area)
            self.c = k
            log.debug("%s: complementarity parameter c = %.6g", self.name, k)
        return self.c

    # -- assembly --------------------------------------------------------------

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True) -> Contribution:
        """The pair's rows and tangent: the tangential rows' (which hold the normal
        rows of :mod:`.normal_rows`)."""
        return self.rows.assemble(z, load_factor, tangent)

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
        nrm, length = self.slave.normals(z)   # (d, n_cells)
        k = seg.shape[1]   # nodes a cell
        share = length / k
        v = np.stack([np.bincount(seg.ravel(), weights=np.repeat(nrm[i] * share, k),
                                  minlength=self.slave.n_nodes) for i in range(nrm.shape[0])])
        rows = np.repeat(self.offset + np.arange(self.slave.n_nodes, dtype=np.int64),
                         nrm.shape[0])
        return rows, dofs.T.ravel().astype(np.int64), v.T.ravel()

    def friction_rows(self, z: np.ndarray, tangent: bool = False, track: bool = False,
                      ev: ContactEval | None = None, active: np.ndarray | None = None,
                      history: dict[str, np.ndarray] | None = None
                      ) -> tuple[ContactEval, Any, FrictionRows]:
        """The normal evaluation, the slip (:class:`~skfem_mortar.contact.slip.SlipEval`)
        and the tangential complementarity rows
        (:func:`~skfem_mortar.contact.friction.complementarity`, with the
        statuses of :class:`~skfem_mortar.contact.active_set.StatusSet`) at ``z``
        (tangential rows only).

        ``Xi`` is the law's slip bound (Coulomb ``mu (lam_n - c g_n)``, Tresca
        ``bound`` times the space's nodal weight: the current tributary length
        for force multipliers, 1 for traction ones), ``c_t = c``; nodes outside
        the normal active set or the slip's ``mask`` are open.  ``track``: a
        Newton iteration (the statuses are updated); ``active`` defaults to the
        current normal set; ``history`` to the slip history of the last converged step.
        """
        return self.rows.rows(z, tangent, track, ev, active, history)

    def _friction_reservation(self, z: np.ndarray, gd: np.ndarray) -> Any:
        """The tangential rows' triplets over the reserved patterns
        (:meth:`~.tangential_rows.TangentialRows.reservation`)."""
        return self.rows.reservation(z, gd)

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
        """Gaps as lengths (the space's: the gaps of force multipliers, or the
        weighted gaps of traction multipliers over the tributary lengths)."""
        return self.space.gap_length(ev.g, ev.area)

    _gap_length = gap_length

    def failure_hint(self) -> str:
        """A likely cause to add to a :class:`ConvergenceError` ("" if none known):
        the discretization's, and the tangential rows' (a tangential load above
        the friction bound)."""
        return self.rows.hint(self.discretization.failure_hint())

    def settled(self) -> bool:
        """The normal active set (and the tangential statuses) did not change."""
        if self.rows.changed:
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
                               self.master.segments, self._touch,
                               (surface_cell(self.slave), surface_cell(self.master)))
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
        self.rows.begin_step(z, load_factor)

    def pressure_and_gap(self, z: np.ndarray, ev: ContactEval | None = None
                         ) -> tuple[np.ndarray, np.ndarray, ContactEval]:
        """Per slave node the pressure (traction) and the gap (length) in the
        method's own discrete form, read by the multiplier space: NTS ``lam / a_A``
        and the nodal gap; mortar ``lam`` and the weighted gap over ``D_AA``."""
        lam = np.asarray(z)[self._normal]
        if ev is None:
            ev = self.evaluate(z, tangent=False, with_lam=False)
        return self.space.pressure(lam, ev.area), self.gap_length(ev), ev

    def violation(self, z: np.ndarray, scale: float) -> str:
        """The KKT conditions at a state whose residual passed ("" if they hold):
        :func:`~skfem_mortar.contact.kkt.violation` (tolerances ``K_GAP``, ``K_LAM``)."""
        return violation(self, z, scale)

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
        return self.rows.data(z)

    def end_step(self, z: np.ndarray, load_factor: float) -> None:
        lam = z[self._normal]  # a view: inactive multipliers are exactly zero from here
        lam[~self.active] = 0.0
        self.state.end()
        self.rows.end_step(z)
        self.converged_positions = (self.slave.x(z), self.master.x(z))
        self.discretization.end_step(*self.converged_positions)
        if self.state.cycles:
            log.info("%s: step converged after the cycling guard acted %d time(s); the "
                     "KKT conditions were checked", self.name, self.state.cycles)

    # -- checkpoint --------------------------------------------------------------

    def state_dict(self) -> dict[str, np.ndarray]:
        """What shapes the next load step (:func:`~.pair_state.state_dict`): the
        converged active set, ``c`` and the row scale, the contact node positions
        at the last converged state (the search reach), the discretization's state
        (NTS: the segment preferences and locks ``prefer``, ``lock``) and the
        tangential rows' (statuses, ``p_ref``, slip history).  Missing entries are
        ``[]`` (not set yet)."""
        return pair_state.state_dict(self)

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state_dict` (ValueError naming the entry that does not
        fit; nothing is restored then)."""
        pair_state.load_state_dict(self, state)

    def step_info(self) -> dict:
        """``n_active`` nodes, ``active_set_changes`` (node status flips summed over the
        step's iterations), ``active_set_cycles`` (times the cycling guard acted),
        ``segment_locks`` (NTS nodes locked by the vertex-trap guard; 0 for a
        method without), what else the discretization counts, and with tangential
        rows ``n_stick``, ``n_slip``, ``friction_status_changes``, ``friction_status_cycles``."""
        return {"n_active": int(self.active.sum()), "active_set_changes": self.state.changes,
                "active_set_cycles": self.state.cycles, "segment_locks": 0,
                **self.discretization.step_info(), **self.rows.info()}

    # -- results -----------------------------------------------------------------

    def outputs(self) -> list:
        """The slave surface as one output series (pressure, gap, ``has_master``
        per slave node): a :class:`~skfem_mortar.output.contact_output.ContactOutput`."""
        return [ContactOutput(self)]

    def contact_data(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """Per slave node: ``x, y`` (current; in an axisymmetric model also as ``r, z``),
        ``gap`` (length) and ``pressure`` (traction).

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
        return pair_output.contact_data(self, z)

    def _along_surface(self) -> np.ndarray:
        """Surface node indices in the order of :meth:`contact_data`'s rows."""
        return pair_output.along_surface(self.slave)

    def __repr__(self) -> str:
        """One line: name, method, the two surfaces and the active nodes."""
        def side(s: Any) -> str:
            return f"{getattr(s, 'name', type(s).__name__)!r} ({s.n_nodes} nodes)"
        return (f"ContactPair({self.name!r}, {self.method}: slave {side(self.slave)} on "
                f"master {side(self.master)}, {int(np.sum(self.active))} active)")

    def forces(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Contact forces ``(d, n)`` on the slave and on the master nodes: ``H G^T lam``
        split into the two surfaces (the force the other body exerts; the residual
        term is its negative), totals over the model's thickness ``H``
        (:attr:`~skfem_mortar.core.item.Item.thickness`)."""
        return pair_output.forces(self, z)

    def total_force(self, z: np.ndarray) -> np.ndarray:
        """Resultant (2,) of the contact force on the slave surface (a total over
        the model's thickness, as :meth:`forces`; in an axisymmetric model, whose
        thickness factor is 1, a total over the revolution: ``[1]`` the axial
        resultant, ``[0]`` the radial total ``sum_A f_r,A``, the work of the force
        on a unit radial displacement, whose vector resultant is zero)."""
        rebind(self)  # this pair's model's layout, if another model was used since
        return self.forces(z)[0].sum(axis=1)
