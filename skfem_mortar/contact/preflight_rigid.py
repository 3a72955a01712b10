"""Preflight, rigid modes: every rigid mode of every body is held by the Dirichlet data,
the normals of the touching contact nodes, or a stiffness other than the solids' and
cables' own (a spring); otherwise the tangent is singular or the answer drifts
(:func:`check_rigid_modes`).  :func:`free_combinations` also serves the failure
diagnosis (:func:`~skfem_mortar.contact.diagnosis.pulled_off`).

Tolerances (all scale-free)
---------------------------
``HOLD = 1e-8``
    Rigid modes are scaled so that the largest nodal motion of each is 1 (a
    translation by one unit, a rotation by 1 / L about the node centroid, L
    the largest distance of a node from it).  A combination of modes counts as
    held by the Dirichlet rows or the contact rows (unit normal rows) when
    they see it at least ``HOLD``: the mode entries are O(1) numbers
    computed from the coordinates, with round-off ``eps max|X| / L``; a mode
    that moves a constrained dof by less than 1e-8 of its largest motion
    (a support within 1e-8 L of the rotation centre) holds nothing.
``SPRING = 1e-10``
    A stiffness other than that of the solids and cables (a user's spring
    item or body, a load stiffness) holds a mode when ``|K m|`` is at least 1e-10 of the bodies'
    mean diagonal stiffness: a spring that soft leaves the saddle-point
    system with a condition number above 1e10 (its rigid part then carries
    round-off of order 1e-6); round-off of ``K m`` for a mode it does not
    see is ``eps |K|``, far below.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterator

import numpy as np
import scipy.sparse as sp

from ..bodies.cable import Cable
from ..bodies.solid import Solid
from ..core.chain import polyline
from ..core.dirichlet import Dirichlet
from . import nts
from .nts_faces import face_sizes
from .preflight_pairs import is_contact_pair
from .surface_kinds import CURVE, FACE, entry
from .surfaces import segment_normals

#: by surface kind (:mod:`.surface_kinds`), the cells of :func:`_touching_rows`' NTS
#: evaluation (curves on their chords: line2, the default cells; faces themselves) and
#: the sizes of those cells
_NORMAL_CELLS = {
    CURVE: (lambda pair: (polyline(pair.slave.segments), polyline(pair.master.segments), None),
            lambda x, seg: segment_normals(x, seg)[1]),
    FACE: (lambda pair: (pair.slave.segments, pair.master.segments,
                         (pair.slave.cell, pair.master.cell)),
           face_sizes)}

__all__ = ["check_rigid_modes", "free_combinations", "HOLD", "SPRING"]

HOLD = 1e-8
SPRING = 1e-10
_CHUNK = 4096  # rows per block of the streamed QR (memory O(_CHUNK x n_modes))

#: the planes ``(a, b)`` of the rotations of a body in ``d`` dimensions, in the order of
#: their axes: 2D the rotation about z; 3D about x, y and z
ROTATION_PLANES = {2: ((0, 1),), 3: ((1, 2), (2, 0), (0, 1))}


@dataclass
class _Body:
    item: Any
    modes: np.ndarray      # (n_dofs, d (d + 1)/2) local: the translations, the rotations
    center: np.ndarray     # (d,) node centroid
    L: float               # largest distance of a node from the centroid

    @property
    def n_modes(self) -> int:
        return int(self.modes.shape[1])


def _mode_functions(d: int, c: np.ndarray, L: float) -> list:
    """The ``d (d + 1)/2`` rigid motions as functions of points ``P (d, n)``: the unit
    translations, then the rotations in the planes :data:`ROTATION_PLANES`,
    ``u_a = -(P_b - c_b)/L``, ``u_b = (P_a - c_a)/L``."""
    def translation(k):
        return lambda P: np.vstack([np.full(P.shape[1], float(a == k)) for a in range(d)])

    def rotation(a, b):
        def f(P):
            u = [np.zeros(P.shape[1])] * d
            u[a], u[b] = -(P[b] - c[b]), P[a] - c[a]
            return np.vstack(u) / L
        return f
    return [translation(k) for k in range(d)] + [rotation(a, b) for a, b in ROTATION_PLANES[d]]


def _rigid_modes(body: Any, geometry: str = "plane") -> _Body:
    """The body's rigid modes on its local dofs, each of largest nodal motion 1: in an
    axisymmetric model (``geometry``) the axial translation ``t_z = (0, 1)`` alone (a
    radial motion strains the hoop, a rotation leaves the meridian plane), else the
    ``d (d + 1)/2`` rigid motions (``d`` read from its coordinates ``X (d, n)``); in 2D

        t_x = (1, 0),  t_y = (0, 1),  r = (-(Y - c_y), X - c_x) / L ,

    in 3D the three translations and the rotations about x, y and z likewise
    (:func:`_mode_functions`); ``c`` the node centroid and ``L = max |X - c|``.
    Interpolated on all the body's dofs where it can (``interpolate``: quadratic
    elements, MINI bubbles and pressures), else on its nodal dofs (other dofs 0).
    """
    X = np.asarray(body.X, dtype=float)
    d = X.shape[0]
    if d not in ROTATION_PLANES:
        raise ValueError(f"body {getattr(body, 'name', '')!r}: coordinates X must have 2 or "
                         f"3 rows (a 2D or 3D body), got {d}")
    c = X.mean(axis=1)
    L = float(np.max(np.hypot.reduce(X - c[:, None], axis=0), initial=0.0)) or 1.0
    funs = _mode_functions(d, c, L)
    if geometry == "axisymmetric":
        funs = funs[1:2]
    if hasattr(body, "interpolate"):
        modes = np.column_stack([body.interpolate(f) for f in funs])
    else:
        modes = np.zeros((int(body.n_dofs), len(funs)))
        nd = np.asarray(body.node_dofs)
        for j, f in enumerate(funs):
            v = f(X)
            for a in range(d):
                modes[nd[a], j] = v[a]
    return _Body(body, modes, c, L)


def _columns(bodies: list[_Body]) -> list[slice]:
    """The columns of each body's modes in the global mode basis."""
    ends = np.cumsum([0] + [bd.n_modes for bd in bodies])
    return [slice(int(a), int(b)) for a, b in zip(ends[:-1], ends[1:])]


def _times_modes(S: sp.spmatrix, bodies: list[_Body]) -> np.ndarray:
    """``S M`` (dense, rows x n_modes) for a sparse ``S`` with global columns, ``M``
    the global mode basis (body b's modes in its columns, :func:`_columns`, zero
    elsewhere), one body block at a time: O(nnz(S) + rows x n_modes), ``M`` never formed."""
    S = S.tocsc()
    cols = _columns(bodies)
    out = np.zeros((S.shape[0], cols[-1].stop if cols else 0))
    for b, bd in enumerate(bodies):
        off = bd.item.offset
        out[:, cols[b]] = S[:, off:off + bd.modes.shape[0]] @ bd.modes
    return out


@dataclass
class _Touch:
    rows: sp.csr_matrix    # unit normal rows (n_touch, n) of the touching slave nodes
    normals: np.ndarray    # (2, n_touch) master normals there
    min_gap: float         # smallest gap (a length) of a node with a master partner
    tolerance: float       # the pair's touch tolerance (a length)
    h: float               # mean slave segment length


def _touching_rows(pair: Any, z: np.ndarray, load_factor: float, n: int,
                   facing: bool = False) -> _Touch:
    """Unit normal rows of the pair's touching slave nodes (global columns).

    Touching: the nodes of the pair's initial active set
    (:meth:`ContactPair.initial_active`; on a resumed run its converged set);
    with ``facing``, every slave node that faces the master, touching or not.  Row of node ``k`` projecting on
    master segment ``(1, 2)`` at ``xi``: ``n_m . (du_k - (1 - xi) du_1 - xi du_2)``
    (the NTS gap's derivative: what the frictionless normal holds), divided
    by its norm; a pair with friction adds the same rows along the tangent.
    """
    ev = pair.evaluate(z, tangent=False, with_lam=False)
    glen = pair.gap_length(ev)
    touch = ev.mask if facing else pair.initial_active(z, load_factor) & ev.mask
    xs, xm = pair.slave.x(z), pair.master.x(z)
    # on the chords of 3-node segments (polyline): a check's normal rows, not the gap
    normal_cells, sizes = entry(_NORMAL_CELLS, pair.slave.cell, "the normal rows")
    seg_s, seg_m, cells = normal_cells(pair)
    nv = nts.evaluate(xs, seg_s, xm, seg_m, tangent=True, cells=cells)
    on = touch & nv.mask
    G = nv.G[np.flatnonzero(on)]
    if getattr(pair, "multipliers_per_node", 1) > 1:   # tangential rows
        # friction also holds the tangential motion of the touching nodes: the
        # rows turned from the normal n to the tangent e = (-n_y, n_x)
        turn = sp.kron(sp.identity(G.shape[1] // 2), np.array([[0.0, 1.0], [-1.0, 0.0]]))
        G = sp.vstack([G, G @ turn])
    G = G.tocoo()
    gd = pair.global_dofs()
    keep = gd[G.col] >= 0
    C = sp.csr_matrix((G.data[keep], (G.row[keep], gd[G.col[keep]])), shape=(G.shape[0], n))
    norm = np.sqrt(np.asarray(C.multiply(C).sum(axis=1)).ravel())
    C = sp.diags(1.0 / np.where(norm > 0, norm, 1.0)) @ C
    ls = sizes(xs, seg_s)
    return _Touch(C.tocsr(), nv.info["normal"][:, on],
                  float(np.min(glen[ev.mask], initial=np.inf)), float(pair.touch_distance),
                  float(np.mean(ls)))


def _chunks(A: np.ndarray, scale: float) -> Iterator[np.ndarray]:
    for i in range(0, A.shape[0], _CHUNK):
        yield A[i:i + _CHUNK] / scale


def _r_factor(blocks: Iterator[np.ndarray], ncols: int) -> np.ndarray:
    """``R`` of the QR factorization of the stacked blocks, streamed (TSQR):
    ``R_{i+1} = qr([R_i; B_i])``, so ``R^T R = sum_i B_i^T B_i`` without ever
    forming the products (which would square the condition number)."""
    R = np.zeros((0, ncols))
    for B in blocks:
        if B.size:
            R = np.linalg.qr(np.vstack([R, B]), mode="r")
    return R


def _continuum(body: Any) -> bool:
    """A solid or a cable: a body whose own energy is invariant under rigid motions."""
    return isinstance(body, (Solid, Cable))


def _stiffness_rows(model: Any, z: np.ndarray, load_factor: float, free_u: np.ndarray,
                    n: int) -> tuple[sp.csr_matrix | None, float]:
    """The tangent ``K_x`` of the items that are neither solids, cables, multiplier
    items nor Dirichlet data (springs, loads, a user's own body), on the free
    displacement rows, and the tolerance ``SPRING * k_b`` (``k_b``: the largest
    over the bodies of their mean absolute tangent diagonal).  ``(None, 0)``
    when those items add no stiffness.

    The tangents of solids and cables are left out: they never hold a rigid
    mode (their energy is invariant under rigid motions), except through
    tangent-only regularizations (a cable's tension floor) or the rotation of
    their stresses in a loaded state, which must not count.
    """
    parts = [it.assemble(z, load_factor, tangent=True) for it in model.items
             if (it.dof_kind is None and not isinstance(it, Dirichlet))
             or (it.dof_kind == "u" and not _continuum(it))]
    parts = [p for p in parts if p.k_vals.size and np.any(p.k_vals != 0)]
    if not parts:
        return None, 0.0
    K = sp.csr_matrix((np.concatenate([p.k_vals for p in parts]),
                       (np.concatenate([p.k_rows for p in parts]),
                        np.concatenate([p.k_cols for p in parts]))), shape=(n, n))
    kb = 0.0
    for body in model.bodies:
        cb = body.assemble(z, load_factor, tangent=True)
        on = cb.k_rows == cb.k_cols
        d = np.abs(np.bincount(cb.k_rows[on], weights=cb.k_vals[on], minlength=n)[body.dofs])
        if d.size:
            kb = max(kb, float(d.mean()))
    return K[free_u], SPRING * (kb if kb > 0 else float(np.abs(K.data).max()))


def check_rigid_modes(model: Any, z: np.ndarray, load_factor: float, fixed: np.ndarray) -> None:
    """Every rigid mode of every body must be held by something.

    With ``M`` the global basis of the bodies' rigid modes (:func:`_rigid_modes`,
    ``d (d + 1)/2`` columns per body: 3 in 2D, 6 in 3D; zero on the other bodies; applied block by block,
    :func:`_times_modes`), the constraints seen by a
    combination ``M a`` are stacked, each group divided by its tolerance:

        A = [ M[fixed] / HOLD ;  C M / HOLD ;  B M / HOLD ;  K_x[free] M / (SPRING k_b) ]

    with ``C`` the unit normal rows of the touching contact nodes
    (:func:`_touching_rows`), ``B`` the unit-normalized rows of other
    multiplier items (ties) and ``K_x`` the stiffness of springs and loads
    (:func:`_stiffness_rows`).  The combinations with ``|A a| < |a|`` (right
    singular vectors of ``A`` with singular value below 1, from the streamed QR
    factor of ``A``: cost O(rows x n_modes^2), no dense n x n) are held by
    nothing: ValueError naming each body, its free modes and the fix.
    Modes of several bodies combine: a body held by contact with a free body
    is free with it.
    """
    bodies, N, touching = free_combinations(model, z, load_factor, fixed)
    if N.shape[1]:
        raise ValueError(_free_message(bodies, N, np.asarray(fixed, dtype=np.int64), touching))


def free_combinations(model: Any, z: np.ndarray, load_factor: float, fixed: np.ndarray,
                      contact: bool = True) -> tuple[list[_Body], np.ndarray, dict]:
    """The bodies' rigid modes (:func:`_rigid_modes`), the basis ``N`` (n_modes, k)
    of the combinations held by nothing (:func:`check_rigid_modes`) and the
    touching rows of each contact pair by name; ``contact=False`` counts no
    contact pair as holding anything (what holds the bodies besides contact)."""
    geometry = getattr(model, "geometry", "plane")
    bodies = [_rigid_modes(b, geometry) for b in model.bodies
              if hasattr(b, "X") and hasattr(b, "node_dofs") and np.size(b.X)]
    if not bodies:
        return bodies, np.zeros((0, 0)), {}
    n, ncols = int(model.n), sum(bd.n_modes for bd in bodies)
    fixed = np.asarray(fixed, dtype=np.int64)
    free = np.ones(model.n_u, dtype=bool)
    free[fixed[fixed < model.n_u]] = False
    select = sp.csr_matrix((np.ones(fixed.size), (np.arange(fixed.size), fixed)),
                           shape=(fixed.size, n))
    blocks = [_chunks(_times_modes(select, bodies), HOLD)]
    touching: dict[str, tuple[Any, _Touch]] = {}
    for it in model.items:
        if is_contact_pair(it):
            if contact:
                tc = _touching_rows(it, z, load_factor, n)
                touching[it.name] = (it, tc)
                blocks.append(_chunks(_times_modes(tc.rows, bodies), HOLD))
        elif it.dof_kind == "lam":
            c = it.assemble(z, load_factor, tangent=True)
            on = (c.k_rows >= it.offset) & (c.k_rows < it.offset + it.n_dofs) & (c.k_cols < model.n_u)
            B = sp.csr_matrix((c.k_vals[on], (c.k_rows[on] - it.offset, c.k_cols[on])),
                              shape=(it.n_dofs, n))
            norm = np.sqrt(np.asarray(B.multiply(B).sum(axis=1)).ravel())
            B = sp.diags(1.0 / np.where(norm > 0, norm, 1.0)) @ B
            blocks.append(_chunks(_times_modes(B, bodies), HOLD))
    K, tol_k = _stiffness_rows(model, z, load_factor, np.flatnonzero(free), n)
    if K is not None:
        blocks.append(_chunks(_times_modes(K, bodies), tol_k))
    R = _r_factor((b for g in blocks for b in g), ncols)
    _, s, Vt = np.linalg.svd(R, full_matrices=True) if R.size else (None, np.zeros(0),
                                                                     np.eye(ncols))
    s_all = np.zeros(ncols)
    s_all[:s.size] = s
    return bodies, Vt[s_all < 1.0].T, touching


def _free_message(bodies: list[_Body], N: np.ndarray, fixed: np.ndarray,
                  touching: dict[str, tuple[Any, _Touch]]) -> str:
    """The ValueError text: per body (or group of bodies moving together) its free
    modes, what holds it now, and the fix."""
    P = N @ N.T                                             # projector on the free space
    nb = len(bodies)
    cols = _columns(bodies)
    in_free = [np.linalg.norm(P[cols[b], cols[b]]) > 1e-6 for b in range(nb)]
    parts = []
    for b, bd in enumerate(bodies):
        if not in_free[b]:
            continue
        modes = _describe(bd, N[cols[b]])
        with_ = [bodies[c].item.name for c in range(nb) if c != b and in_free[c]
                 and np.linalg.norm(P[cols[b], cols[c]]) > 1e-6]
        name = bd.item.name
        n_fix = int(np.sum((fixed >= bd.item.offset) & (fixed < bd.item.offset + bd.item.n_dofs)))
        held = [f"{n_fix} prescribed dofs" if n_fix else "no Dirichlet data"]
        for pname, (pair, tc) in touching.items():
            if bd.item in (pair.slave.body, pair.master.body):
                held.append(_touch_text(pname, tc))
        together = f", moving together with {', '.join(map(repr, with_))}" if with_ else ""
        open_ = [p for p, (pair, tc) in touching.items() if tc.normals.shape[1] == 0
                 and np.isfinite(tc.min_gap) and bd.item in (pair.slave.body, pair.master.body)]
        also = f", or let contact {', '.join(map(repr, open_))} touch (above)" if open_ else ""
        parts.append(f"body {name!r}: {modes} held by nothing{together} ({'; '.join(held)}; "
                     f"frictionless contact holds only the normal motion of the touching "
                     f"nodes): {_fix(bd, modes)}{also}")
    return ("rigid modes held by nothing before the first step (the tangent would be "
            "singular, or the answer drift along them): " + " | ".join(parts))


def _touch_text(name: str, tc: _Touch) -> str:
    """What contact ``name`` holds at the start; for a pair touching nowhere, how to
    make it touch: a touch tolerance of 1.5 times its smallest gap (rounded up)
    where that gap is below 0.1 of the mean slave segment length (the weighted
    mortar gap of a curved surface touching at one node is of order ``h^2 / R``),
    else close the gap."""
    k = tc.normals.shape[1]
    if k == 0:
        if not np.isfinite(tc.min_gap):
            return f"contact {name!r} touches at no node (no slave node faces the master)"
        if tc.min_gap > 0.1 * tc.h:  # a real gap, not the weighted gap of a curved surface
            return (f"contact {name!r} touches at no node: it starts open (smallest gap "
                    f"{tc.min_gap:.3g}); close the gap in the mesh, or drive the body onto "
                    f"the other (a Dirichlet path) until it touches")
        need = 1.5 * tc.min_gap / tc.h
        sug = float(f"{need:.1g}") if float(f"{need:.1g}") >= need else float(f"{2 * need:.1g}")
        return (f"contact {name!r} touches at no node: its smallest gap {tc.min_gap:.3g} "
                f"exceeds its touch tolerance {tc.tolerance:.3g}; if the bodies are meant "
                f"to touch, ContactPair(..., touch_tolerance={sug:g}) makes that node active "
                f"(a curved surface touching at one node has a positive mortar gap there)")
    nm = tc.normals.mean(axis=1)
    spread = "" if np.allclose(tc.normals, tc.normals[:, :1], atol=1e-6) else " on average"
    return (f"contact {name!r} touches at {k} node(s), normal{spread} "
            f"({nm[0]:.3g}, {nm[1]:.3g})")


def _describe(bd: _Body, Nb: np.ndarray) -> str:
    """Name the free modes of one body from its rows ``Nb`` (n_modes, k) of the free
    basis: translations (x, y or a direction), rotation (about a point when it is
    unique); in 3D how many translations and rotations."""
    U, sv, _ = np.linalg.svd(Nb, full_matrices=False)
    B = U[:, sv > 1e-3]                                     # basis of the body's free space
    r = B.shape[1]
    if r == 0:
        return "a combination of modes is"
    if bd.n_modes == 1:
        return "translation along the axis (z) is"
    if bd.n_modes != 3:
        return _describe_3d(B)
    if r >= 3:
        return "translations in x and y and rotation are"
    rot = B[2]
    has_rot = np.linalg.norm(rot) > 1e-6
    if has_rot:  # translations: the combinations without rotation
        T = B[:2] @ np.linalg.svd(rot[None, :])[2][1:].T if r > 1 else np.zeros((2, 0))
    else:
        T = B[:2]
    names = [_direction(T[:, j]) for j in range(T.shape[1])]
    if len(names) == 2:
        names = ["translations in x and y"]
    if has_rot:
        if r == 1:  # u = t + (a / L) e_z x (x - c) = (a / L) e_z x (x - p)
            t, a = B[:2, 0], B[2, 0]
            p = bd.center + bd.L * np.array([-t[1], t[0]]) / a
            p = np.where(np.abs(p) < 1e-9 * bd.L, 0.0, p)  # round-off: (0, 2), not (5e-18, 2)
            names.append(f"rotation about ({p[0]:.3g}, {p[1]:.3g})")
        else:
            names.append("rotation")
    return " and ".join(names) + (" are" if len(names) > 1 else " is")


def _describe_3d(B: np.ndarray) -> str:
    """The free space ``B`` (6, r) of a 3D body named by its dimension ``r``, the
    rotations in it (the rank of its rotation rows: a rotation about any point counts
    once) and the pure translations (the rest)."""
    n_r = int(np.sum(np.linalg.svd(B[3:], compute_uv=False) > 1e-3))
    return (f"{B.shape[1]} of its 6 rigid modes ({B.shape[1] - n_r} translation(s), "
            f"{n_r} rotation(s)) are")


def _direction(t: np.ndarray) -> str:
    t = t / np.linalg.norm(t)
    if abs(t[1]) < 1e-6:
        return "translation in x"
    if abs(t[0]) < 1e-6:
        return "translation in y"
    return f"translation along ({t[0]:.3g}, {t[1]:.3g})"


def _fix(bd: _Body, modes: str) -> str:
    """The fix for the free modes named in ``modes``."""
    name = bd.item.name
    cx, cy = np.where(np.abs(bd.center) < 1e-9 * bd.L, 0.0, bd.center)[:2]  # as in _describe
    how = (f"{name}.dofs_at_nodes(nodes, component=c)" if hasattr(bd.item, "dofs_at_nodes")
           else f"{name}.support_dofs(nodes)" if hasattr(bd.item, "support_dofs")
           else "its dofs at those nodes")
    if "rigid modes" in modes:   # a 3D body
        what = "pin three nodes that are not on one line"
    elif "along the axis" in modes:   # an axisymmetric body
        what = "hold the z-dofs of a node"
    elif "in x and y" in modes:
        what = "pin a node in x and y, and for the rotation hold a second node"
    elif "in x" in modes:
        what = (f"hold the x-dofs of the nodes on a symmetry axis (e.g. x = {cx:.3g}), "
                f"which also stops the rotation")
    elif "in y" in modes:
        what = (f"hold the y-dofs of the nodes on a symmetry axis (e.g. y = {cy:.3g}), "
                f"which also stops the rotation")
    elif "translation along" in modes:
        what = "hold the dofs of a node along that direction"
    else:
        what = "hold a second node, away from the rotation centre"
    return (f"add a support (Dirichlet: {what}; {how}) or a soft spring to ground on "
            f"{name!r}")
