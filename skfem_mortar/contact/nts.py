"""Node-to-segment (NTS) contact: one evaluation of the nodal gap and its derivatives
over every cell type of the cell table (:mod:`.cells`), lines and faces alike.

:func:`evaluate` takes a surface kind's projection and choice among neighbouring
cells (:data:`KIND_ENTRIES`, by :mod:`.surface_kinds`: lines in
:mod:`.nts_projection`, faces in :mod:`.nts_faces`) and its tributary weights, then
the one gap of every cell (:mod:`.nts_gap`)::

    g = n(xi) . (x_s - x(xi)),   n = c / |c|   (c = (t_y, -t_x) on a line, T_1 x T_2 on a face)

at the closest point ``xi`` of the slave node ``x_s`` on its master cell, with its
exact first and second derivatives (``dg/dxi = 0`` at the closest point: only the
exact gradient of ``xi`` enters, from one Newton step in jets), in closed form on
``line2`` (cross-tested, tests/test_nts_cells.py), and scattered by the one routine
(:func:`~.contact_eval.node_gap_eval`).  On a straight ``line2`` master cell
``(x_1, x_2)``::

    t  = x_2 - x_1,   l = |t|,   e = t / l,   n = (t_y, -t_x) / l   (outward master normal)
    xi = (x - x_1) . t / l^2                                      (closest-point parameter)
    g  = [x - (1 - xi) x_1 - xi x_2] . n = (x - x_1) . n          (normal gap, > 0 open)

``info["xi"]`` on a line is ``(1 + xi) / 2`` of the cell's coordinate, ``[0, 1]``
along it, so the method's segment memory is the same for every line cell.  A
slave node of any cell weighs ``int N_A w dGamma``
(:func:`~.curves.tributary_weights`, :func:`~.nts_faces.face_weights`; ``line3``,
``w = 1``: ``L/6, L/6, 2L/3`` on a straight cell), ``w`` the weight of the model's
measure (:meth:`NTS.set_measure`: ``2 pi r`` in an axisymmetric model, where the
multiplier is a nodal force totalled over the revolution; the gap is not weighted).

Projection and partner search: :mod:`.nts_projection`.


Two-pass NTS is left out on purpose: with both surfaces acting as slave and
master, a matching (or nearly matching) interface gets two nearly identical
constraints per node pair, the multiplier block becomes rank deficient and the
saddle-point system singular (or ill-conditioned) -- exactly the case of the
patch test.  Single pass with the finer surface as slave is the usual remedy.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

from .cells import CellType, cell_type
from .measures import PLANE, Measure
from .curves import cell_lengths, check_line, polyline, tributary_weights
from .segmentation import surface_cell
from .contact_eval import ContactEval
from .discretization import (ContactDiscretization, OptionTable, check_entries, check_options,
                             covers, pattern_matrix, register_method, reserved_keys)
from .nts_faces import (check_face, face_candidates, face_rows, face_sizes, face_weights,
                        project_faces)
from .nts_friction import NTSFriction
from .nts_gap import gap_eval
from .rigid3d import RigidSurface3D, exact_gaps
from .nts_projection import (LOCK_STICK, candidates, choose_segments, curve_arrays, curve_rows,
                             project, project_curves)
from .surfaces import AXIS_TOL, segment_lengths, segment_normals
from .surface_kinds import CURVE, FACE, entry
from .symmetry import on_planes

__all__ = ["NTS", "evaluate", "project", "candidates", "choose_segments", "RESERVE_MARGIN", "RESERVE_HALO", "LOCK_STICK", "COARSE_RATIO", "failure_hints",
           "nearest_nodes", "vertex_trap"]

log = logging.getLogger("skfem_mortar.contact.pair")  # the pair's log, as before the split


#: the reserved pattern (:meth:`NTS.pattern`) holds the master segments whose boxes,
#: inflated by this many search margins, hold a slave node: a node may move one
#: more margin (a median master segment length) before the search finds a new pair
RESERVE_MARGIN = 2.0
#: ... and this many chain neighbours on each side of the two segments at the
#: node's nearest master vertex (a node far from every box slides by a segment)
RESERVE_HALO = 1


def evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
             lam: np.ndarray | None = None, tangent: bool = True,
             margin: float | None = None, end_tolerance: float = 1e-8,
             prefer: np.ndarray | None = None, stick: float = 0.05,
             lock: np.ndarray | None = None,
             cells: "tuple[str | CellType, str | CellType] | None" = None,
             measure: Measure = PLANE, mirrored: np.ndarray | None = None) -> ContactEval:
    """NTS gaps ``g_N`` of the slave nodes, ``G = dg/dx`` and ``H = sum_k lam_k d^2 g_k/dx^2``.

    One evaluation for every cell type: the kind's projection and choice among
    neighbouring cells (:data:`KIND_ENTRIES`: :func:`~.nts_projection.project` on
    lines, :func:`~.nts_faces.project_faces` on faces) and tributary weights, then
    the one gap ``g = n(xi) . (x_s - x(xi))`` with its exact derivatives
    (:func:`~.nts_gap.gap_eval`).

    Parameters
    ----------
    xs, seg_s : slave coordinates (d, n_s) and cells (n_seg_s, n_nodes of the slave
        cell) (the cells set the tributary weights ``area = int N_A dGamma``)
    xm, seg_m : master coordinates (d, n_m) and cells (n_seg_m, n_nodes of the master cell)
    lam : ndarray (n_s,), optional
        Nodal contact forces (multipliers); needed for ``H``.
    tangent : bool
        Whether to build ``G`` (and ``H`` when ``lam`` is given).
    margin, end_tolerance, prefer, stick, lock : see :func:`project` (lines) and
        :func:`~.nts_faces.project_faces` (faces).
    cells : (slave, master) cell types, optional
        Line cells of degree at most 2 (:func:`~.curves.check_line`) or faces
        (:data:`~.nts_faces.FACE_CELLS`); default:
        :func:`~skfem_mortar.contact.segmentation.line_cells`.
    measure : Measure
        The weight ``w`` of ``dGamma`` (:mod:`~.measures`) in the tributary weights
        ``area = int N_A w dGamma`` (default :data:`~.measures.PLANE`, ``w = 1``; an
        axisymmetric model's ``2 pi r``); the gap does not depend on it.
    mirrored : bool ndarray (n_m,), optional
        Master nodes on a symmetry line or plane (a chain end or face edge there is
        no free end; :class:`NTS` passes those on the axis of its measure or on its
        symmetry planes).

    Returns
    -------
    ContactEval
        Local dof order: slave node k -> d k + c; master node j -> d n_s + d j + c.
        ``area`` is the tributary weight of each slave node; ``info`` holds
        ``xi`` (lines: in ``[0, 1]`` along the cell; faces: the face's coordinates),
        ``segment`` and ``normal``.
    """
    kind = KIND_ENTRIES[CURVE] if cells is None else entry(KIND_ENTRIES, cells[1],
                                                             "nts.evaluate")
    xs, seg_s, xm, seg_m, cs, cm = kind.arrays(xs, seg_s, xm, seg_m, cells)
    if lam is not None:
        lam = np.asarray(lam, dtype=float).ravel()
        if lam.shape != (xs.shape[1],):
            raise ValueError(f"lam must have shape ({xs.shape[1]},), got {lam.shape}")
    pr = kind.project(xs, xm, seg_m, cm, margin, end_tolerance, prefer, stick, lock, mirrored)
    area = kind.weights(xs, seg_s, cs, measure)
    info = {"xi": pr["xi"], "segment": pr["segment"], "normal": pr["n"]}
    if not tangent:
        return ContactEval(g=pr["g"], G=None, H=None, area=area, mask=pr["mask"], info=info)
    return gap_eval(xs, xm, seg_m, cm, pr, kind.rows(pr), lam, area, info)


def _lengths(surface) -> np.ndarray:
    return cell_lengths(surface.X, surface.segments, surface_cell(surface))


def nearest_nodes(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                  band: float = 1.0) -> tuple[np.ndarray, dict]:
    """The slave nodes nearest the master, with their closest-point projections.

    With ``d_k`` the distance of slave node ``k`` from its clipped closest point
    on the master (:func:`project`) and ``h_k`` the length of its longest
    slave segment, the nearest nodes are those with a master partner and

        d_k <= min_j d_j + band * h_k ,

    the part of the slave that faces the master first (about ``band`` slave
    element lengths deep).

    Returns
    -------
    near : bool ndarray (n_s,)
    projection : dict
        :func:`project`'s output plus ``dist`` (n_s,) (``inf`` without a partner).
    """
    pr = project(xs, xm, seg_m)
    k = np.flatnonzero(pr["mask"])
    es = pr["segment"][k]
    x1 = xm[:, seg_m[es, 0]]
    xp = x1 + np.clip(pr["xi"][k], 0.0, 1.0) * (xm[:, seg_m[es, 1]] - x1)
    dist = np.full(xs.shape[1], np.inf)
    dist[k] = np.hypot(*(xs[:, k] - xp))
    _, ls = segment_normals(xs, seg_s)
    h = np.zeros(xs.shape[1])
    np.maximum.at(h, seg_s.ravel(), np.repeat(ls, 2))
    near = pr["mask"] & (dist <= (dist[k].min() if k.size else 0.0) + band * h)
    pr["dist"] = dist
    return near, pr


#: slave / master segment length ratio near the contact above which single-pass NTS is flagged
COARSE_RATIO = 1.2


def failure_hints(slave, master, name: str = "contact") -> str:
    """Likely causes of an NTS failure that the geometry shows ("" if none).

    A slave surface coarser than a deformable master where they face each
    other: over the slave nodes nearest the master (:func:`nearest_nodes`,
    two slave element lengths deep, reference configuration), the median of
    the slave nodes' longest segment length ``h_s`` is more than
    :data:`COARSE_RATIO` times the median length ``h_m`` of the master segments they
    project on.  Single-pass NTS then pushes point forces into dents of the
    master and lets master nodes pass through the slave.  (Compared where the
    surfaces meet, not over the whole surfaces: graded meshes, fine only in
    the contact zone, would otherwise be compared by their coarse parts.)
    Slave segments of nearly coincident nodes (shorter than 1e-4 of the
    median): their constraints are nearly redundant, the saddle-point system
    nearly singular.
    """
    hints = []
    ls = _lengths(slave)
    if master.body is not None:
        seg_s = polyline(slave.segments, surface_cell(slave))  # curved cells: their chords
        near, pr = nearest_nodes(slave.X, seg_s, master.X,
                                 polyline(master.segments, surface_cell(master)), band=2.0)
        if near.any():
            h = np.zeros(slave.n_nodes)
            np.maximum.at(h, seg_s[:, :2].ravel(), np.repeat(segment_lengths(slave.X, seg_s), 2))
            hs, hm = float(np.median(h[near])), float(np.median(pr["l"][near]))
            if hs > COARSE_RATIO * hm:
                hints.append(f"{name}: the NTS slave surface is coarser than the master "
                             f"where they meet (median segment lengths {hs:.3g} > {hm:.3g}); "
                             f"single-pass NTS then pushes point forces into dents of the "
                             f"master and lets master nodes pass through the slave: make the "
                             f"finer surface the slave, or refine the slave, or use "
                             f"method=\"mortar-dual\" (the default)")
    if ls.min() < 1e-4 * np.median(ls):
        hints.append(f"{name}: slave segments of nearly coincident nodes (shortest "
                     f"{ls.min():.3g}, median {np.median(ls):.3g}): their NTS constraints are "
                     f"nearly redundant and the saddle-point system nearly singular; merge "
                     f"the nodes or use method=\"mortar-dual\" (the default)")
    return "; ".join(hints)


def vertex_trap(history: list[np.ndarray], lock: np.ndarray | None) -> np.ndarray | None:
    """Slave nodes caught in a vertex trap and not yet locked (None before three
    iterations).

    ``history`` holds the master segment of every slave node in the last
    iterations (oldest first, -1 for none).  At a reflex vertex of the deformed
    master (the master body locally concave, e.g. dented by the slave), the
    equilibrium of a slave node with the normal of segment ``a`` can lie beyond
    the vertex on ``b`` and the one with the normal of ``b`` before the vertex
    on ``a``: the single-segment NTS gap has no solution there, the node's
    projection jumps between the two segments in every Newton iteration (the
    ``seed`` scene, nts, ``refine_cushion=3``: residual alternating 0.42 / 0.29
    for 25 iterations).  A node whose segment repeats that of two iterations
    ago (a, b, a) is returned; the caller locks it onto it for the rest of the
    step attempt and the following steps, while its parameter on that segment
    stays in ``[-0.5, 1.5]`` (:data:`LOCK_STICK`); its projection continues on
    the segment's extension line, so its gap is that of the extended segment,
    off by at most the overshoot times the kink angle.
    """
    if len(history) < 3:
        return None
    s2, s1, s0 = history[-3:]
    trap = (s0 == s2) & (s0 != s1) & (s0 >= 0) & (s1 >= 0)
    return trap if lock is None else trap & ~lock


@dataclass(frozen=True)
class KindEntries:
    """What NTS does differently on a surface kind (:mod:`.surface_kinds`).

    ``check(cell, pair_name)`` the cell (raises ValueError); ``hints(slave,
    master, pair_name)`` the failure hints; ``sizes(x, cells, cell)`` the cell
    sizes (the search margin is their median); ``candidates(xs, xm, cells,
    cell, margin, halo)`` the candidate keys; ``symmetry_mirrors``: a master
    node on a symmetry plane is mirrored (no free border there).  For
    :func:`evaluate`: ``arrays(xs, seg_s, xm, seg_m, cells)`` the checked arrays and
    cell types; ``project(xs, xm, seg_m, cell, margin, end_tolerance, prefer, stick,
    lock, mirrored)`` the projection and choice (a dict with ``segment``, ``xi``,
    ``mask``, ``n``, ``g``); ``rows(projection)`` the gap's rows
    (:func:`~.nts_gap.gap_eval`); ``weights(x, cells, cell, measure)`` the tributary
    weights.
    """
    check: Callable[[CellType, str], CellType]
    hints: Callable[[Any, Any, str], str]
    sizes: Callable[[np.ndarray, np.ndarray, CellType], np.ndarray]
    candidates: Callable[..., np.ndarray]
    symmetry_mirrors: bool
    arrays: Callable[..., tuple]
    project: Callable[..., dict]
    rows: Callable[[dict], tuple]
    weights: Callable[..., np.ndarray]


#: the NTS entries of each surface kind: curves (line cells), faces (of 3D bodies)
KIND_ENTRIES = {
    CURVE: KindEntries(
        check=lambda c, name: check_line(c, "nts"), hints=failure_hints, sizes=cell_lengths,
        candidates=lambda xs, xm, seg, c, margin, halo: candidates(xs, xm, seg, margin, halo,
                                                                   cell=c),
        symmetry_mirrors=False, arrays=curve_arrays, project=project_curves,
        rows=curve_rows, weights=tributary_weights),
    FACE: KindEntries(
        check=lambda c, name: check_face(c, f"{name}: nts"), hints=lambda s, m, name: "",
        sizes=lambda x, seg, c: face_sizes(x, seg),
        candidates=lambda xs, xm, seg, c, margin, halo: face_candidates(xs, xm, seg, c, margin),
        symmetry_mirrors=True,
        arrays=lambda xs, ss, xm, sm, cells: (xs, ss, xm, sm, *map(cell_type, cells)),
        project=project_faces, rows=face_rows, weights=face_weights)}


class NTS(NTSFriction, ContactDiscretization):
    """Node-to-segment contact (:func:`evaluate`) as a
    :class:`~skfem_mortar.contact.discretization.ContactDiscretization`.

    Owns the state between Newton iterations and load steps: the master
    segment of every slave node at the last iteration (``prefer``, the
    hysteresis of :func:`project`) and at the last converged step, the nodes
    locked at a reflex vertex (:func:`vertex_trap`, ``lock``) and the segment
    history that finds them, the number of locks in the step, the failure hints
    (:func:`failure_hints`, from the reference geometry) and the pinned nodes
    (out of ``mask``).

    Options (checked here): ``margin``, ``end_tolerance``, ``stick`` of :func:`project`.
    """

    method = "nts"
    multiplier_kind = "force"
    multipliers_per_node = 1
    symmetric = True
    has_history = True  # segment preferences and locks carry over to the next step

    OPTIONS: OptionTable = {
        "margin": (lambda v: v is None or (np.isfinite(v) and v > 0), "a finite number > 0"),
        "end_tolerance": (lambda v: np.isfinite(v) and 0 <= v < 0.5, "a number in [0, 0.5)"),
        "stick": (lambda v: np.isfinite(v) and 0 <= v <= 0.5, "a number in [0, 0.5]")}

    def __init__(self, slave: Any, master: Any, pair_name: str = "contact", **options: Any):
        check_options(self.method, options, self.OPTIONS)
        self.slave, self.master, self.pair_name = slave, master, pair_name
        #: the two surfaces' cell types (:func:`~.segmentation.surface_cell`)
        self.cells = (surface_cell(slave), surface_cell(master))
        #: the kind of the slave's cells (:func:`~.surface_kinds.surface_kind`): its entries
        #: (:data:`KIND_ENTRIES`) check the cells, search, measure and hint
        self.kind = entry(KIND_ENTRIES, self.cells[0], "nts")
        for c in self.cells:
            self.kind.check(c, pair_name)
        self.options = dict(options)
        self._hint = self.kind.hints(slave, master, pair_name)
        self._pinned: np.ndarray | None = None
        #: the weight of ``dGamma`` (:meth:`set_measure`)
        self.measure: Measure = PLANE
        self._mirrored: np.ndarray | None = None   # master nodes on the measure's axis
        self._prefer: np.ndarray | None = None
        self._prefer_converged: np.ndarray | None = None
        self._lock: np.ndarray | None = None
        self._lock_converged: np.ndarray | None = None
        self._seg_hist: list[np.ndarray] = []
        self._locks = 0
        #: (held candidate keys, pattern) of :meth:`pattern`; reservations made
        self._reserved: tuple[np.ndarray, sp.csr_matrix] | None = None
        self.reservations = 0

    def set_measure(self, measure: Measure) -> None:
        """The weight of ``dGamma`` (:class:`~.discretization.MeasuredDiscretization`):
        the tributary weights ``area`` (the nodal force over it is the pressure) are
        ``int N_A w dGamma`` over the current slave surface; the gaps are not weighted.
        A measure with an axis (``2 pi r``) makes the master nodes on it (within
        :data:`~.surfaces.AXIS_TOL` of the master's size, in its reference
        coordinates) mirrored: a chain end there is no free end (:func:`project`)."""
        self.measure = measure
        self._mirrored = None
        if measure.axis is not None and self.master.n_nodes:
            X = np.asarray(self.master.X, dtype=float)
            self._mirrored = np.abs(X[measure.axis]) <= AXIS_TOL * float(np.ptp(X, axis=1).max())

    def set_pinned(self, pinned: np.ndarray | None) -> None:
        self._pinned = pinned

    def set_symmetry(self, planes: list) -> None:
        """The symmetry planes of a 3D pair (:mod:`.symmetry`,
        :class:`~.discretization.SymmetricDiscretization`): a master face edge between
        two master nodes on one is no free border (:func:`~.nts_faces.project_faces`)."""
        if self.kind.symmetry_mirrors:
            X = np.asarray(self.master.X, dtype=float)
            self._mirrored = on_planes(X, planes, float(np.ptp(X, axis=1).max()))

    def _margin(self, xm: np.ndarray) -> float:
        """The search margin of :func:`project` (default: the median master segment length)."""
        margin = self.options.get("margin")
        if margin is None:
            lm = self.kind.sizes(xm, self.master.segments, self.cells[1])
            margin = float(np.median(lm)) if lm.size else 0.0
        return margin

    def _reserve(self, xs: np.ndarray, xm: np.ndarray, need: np.ndarray) -> None:
        """Reserve the candidates :data:`RESERVE_MARGIN` search margins and
        :data:`RESERVE_HALO` chain neighbours wide (and ``need``)."""
        held = np.union1d(self._candidates(xs, xm, RESERVE_MARGIN * self._margin(xm),
                                           RESERVE_HALO), need)
        self._reserved = (held, self._pattern_of(held))
        self.reservations += 1

    def _candidates(self, xs: np.ndarray, xm: np.ndarray, margin: float,
                    halo: int = 0) -> np.ndarray:
        """The candidate keys of the projection (:func:`candidates`; on faces
        :func:`~.nts_faces.face_candidates`, whose nearest-vertex faces are the halo)."""
        return self.kind.candidates(xs, xm, self.master.segments, self.cells[1], margin, halo)

    def _pattern_of(self, held: np.ndarray) -> sp.csr_matrix:
        """Row ``k``: the dofs of slave node ``k`` and of its held master segments."""
        seg_m = self.master.segments
        n_s, n_seg = self.slave.n_nodes, len(seg_m)
        d = int(np.shape(self.slave.X)[0])           # dofs per node
        k, e = held // n_seg, held % n_seg
        own = np.arange(n_s)
        nm = d * self.cells[1].n_nodes               # master dofs of a segment: 4, 6 (3-node), 9, 12
        rows = np.concatenate([np.repeat(k, nm)] + [own] * d)
        mdofs = (d * n_s + d * seg_m[e][:, :, None] + np.arange(d)).reshape(-1, nm)
        cols = np.concatenate([mdofs.ravel()] + [d * own + c for c in range(d)])
        return pattern_matrix(rows, cols, (n_s, d * n_s + d * self.master.n_nodes))

    def pattern(self, xs: np.ndarray, xm: np.ndarray) -> sp.csr_matrix:
        """The reserved pattern (:class:`~skfem_mortar.contact.discretization.PatternedDiscretization`).

        Row ``k`` holds the dofs of slave node ``k`` and of every reserved master
        segment of it: the candidates of :func:`candidates` with the margin
        :data:`RESERVE_MARGIN` times the search margin and :data:`RESERVE_HALO`
        chain neighbours of the nearest vertex's segments.  The gap ``g_k``
        depends on node ``k`` and the segment it projects on, which
        :func:`project` picks among its candidates; so while those candidates
        (search margin, no halo) lie in the reservation, it holds ``G`` and
        ``H``, and the same object is returned; reserved anew only when they
        leave it.  The reservation carries over to the next step and into
        checkpoints (:meth:`state_dict`), so a resumed run reserves as the
        uninterrupted one.
        """
        need = self._candidates(xs, xm, self._margin(xm))
        if self._reserved is None or not covers(self._reserved[0], need):
            self._reserve(xs, xm, need)
        return self._reserved[1]

    def begin_step(self, xs: np.ndarray, xm: np.ndarray, first: bool) -> None:
        """Restore the segment choices and locks of the last converged step."""
        if first:
            self._prefer_converged = None
        self._prefer = self._prefer_converged
        self._lock = None if self._lock_converged is None else self._lock_converged.copy()
        self._seg_hist = []
        self._locks = 0

    def evaluate(self, xs: np.ndarray, xm: np.ndarray, lam: np.ndarray | None,
                 tangent: bool) -> ContactEval:
        extra: dict = {}
        if self._prefer is not None:
            extra["prefer"] = self._prefer
            if self._lock is not None and self._lock.any():
                extra["lock"] = self._lock
        if isinstance(self.master, RigidSurface3D):   # an exact surface (faces)
            area = face_weights(xs, self.slave.segments, self.cells[0], self.measure)
            ev = exact_gaps(self.master, xs, lam, tangent, area, xm.shape[1])
        else:
            ev = evaluate(xs, self.slave.segments, xm, self.master.segments, lam=lam,
                          tangent=tangent, **extra, **self.options, cells=self.cells,
                          measure=self.measure, mirrored=self._mirrored)
        if self._pinned is not None and self._pinned.any():
            ev.mask = ev.mask & ~self._pinned
        return ev

    def after_iteration(self, ev: ContactEval) -> None:
        """Segment hysteresis: the next iteration prefers these segments; vertex
        trap: lock a node whose master segment alternates a, b, a
        (:func:`vertex_trap`)."""
        self._prefer = np.asarray(ev.info["segment"])
        self._seg_hist = (self._seg_hist + [self._prefer.copy()])[-3:]
        new = vertex_trap(self._seg_hist, self._lock)
        if new is None:
            return
        if self._lock is None:
            self._lock = np.zeros(new.shape, dtype=bool)
        if new.any():
            self._locks += int(new.sum())
            log.info("%s: %d slave node(s) alternate between two master segments; "
                     "locked onto one for the rest of the step", self.pair_name, int(new.sum()))
            self._lock |= new

    def end_step(self, xs: np.ndarray, xm: np.ndarray) -> None:
        self._prefer_converged = self._prefer
        if self._lock is not None and self._prefer is not None:
            # a lock lasts while the node stays on its segment (LOCK_STICK)
            self._lock_converged = self._lock & (self._prefer >= 0)

    def step_info(self) -> dict:
        """``segment_locks``: nodes locked by the vertex-trap guard in the step."""
        return {"segment_locks": self._locks}

    def failure_hint(self) -> str:
        """:func:`failure_hints` of the reference geometry."""
        return self._hint

    def state_dict(self) -> dict[str, np.ndarray]:
        """The converged segment preferences and locks, and the reserved candidate
        pairs of :meth:`pattern` (``[]``: not set yet)."""
        def arr(a, dtype):
            return np.zeros(0, dtype=dtype) if a is None else np.asarray(a, dtype=dtype).copy()
        return {"prefer": arr(self._prefer_converged, np.int64),
                "lock": arr(self._lock_converged, bool),
                "reserved": arr(None if self._reserved is None else self._reserved[0], np.int64)}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        ns = self.slave.n_nodes
        check_entries(self.pair_name, state, {"prefer": [(0,), (ns,)], "lock": [(0,), (ns,)]})
        reserved_keys(self.pair_name, state["reserved"], ns * len(self.master.segments))
        if state["prefer"].size and (state["prefer"].min() < -1
                                     or state["prefer"].max() >= len(self.master.segments)):
            raise ValueError(f"{self.pair_name}: checkpoint entry 'prefer' indexes no master "
                             "segment")
        reserved = reserved_keys(self.pair_name, state["reserved"],
                                 ns * len(self.master.segments))
        self._reserved = None if reserved is None else (reserved, self._pattern_of(reserved))
        self._prefer_converged = (np.array(state["prefer"], dtype=np.int64)
                                  if state["prefer"].size else None)
        self._lock_converged = (np.array(state["lock"], dtype=bool)
                                if state["lock"].size else None)


# -- registered where it is defined (:mod:`.methods` imports this module)
def _nts(slave: Any, master: Any, **options: Any) -> ContactDiscretization:
    return NTS(slave, master, **options)


register_method("nts", _nts)
