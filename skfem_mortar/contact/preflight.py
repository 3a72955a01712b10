"""Checks before the first load step: refuse a model that cannot work.

:meth:`Model.preflight <skfem_mortar.core.model.Model.preflight>` calls :func:`run`
once, on the initial state, before :func:`~skfem_mortar.solver.stepping.solve` takes
its first load step.  Each check either passes silently or raises a
ValueError that names the item and the fix (issue 13: a converged answer is a
right answer; a model that cannot give one is refused before any work):

1. :func:`check_surface` / :func:`check_orientation`: the surfaces of a contact
   pair face each other (a pair pointing the same way converges to a
   penetration).
2. :func:`check_rigid_modes`: every rigid mode of every body is held by the
   Dirichlet data, the normals of the touching contact nodes, or a stiffness
   other than the solids' and cables' own (a spring); otherwise the tangent
   is singular or the answer drifts.
3. :func:`warn_methods`: where a method is known not to work for the
   configuration (NTS with a slave coarser than the master, NTS on
   non-matching deformable meshes: off the patch test) or two bodies in
   contact lie beyond the measured stiffness ratio, a
   :class:`PreflightWarning` before the solve, naming the fix.

Tolerances (all scale-free)
---------------------------
``FACING = 0.5``
    ``|n_s . n_m|`` above which a near slave node counts as facing (< -0.5) or
    pointing the same way (> 0.5) as the master: within 60 degrees of
    (anti)parallel.  Facing surfaces have ``n_s . n_m`` near -1 where they meet,
    wrongly oriented ones near +1; the nodes between (a corner, a side wall
    within one element of the master) decide nothing.
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
from ..core.errors import warn_at_user
from ..core.model import Dirichlet, register_check
from . import nts
from .surfaces import RigidCircle, RigidPlane, segment_normals, tributary_lengths

__all__ = ["PreflightWarning", "run", "check_surface", "check_orientation",
           "check_rigid_modes", "warn_methods", "FACING", "HOLD", "SPRING"]

FACING = 0.5
HOLD = 1e-8
SPRING = 1e-10
_CHUNK = 4096  # rows per block of the streamed QR (memory O(_CHUNK x 3 n_bodies))


class PreflightWarning(UserWarning):
    """A configuration a method is known to handle badly (the solve still runs)."""


def run(model: Any, z: np.ndarray, load_factor: float, fixed: np.ndarray) -> None:
    """All checks on the initial state ``z`` (ValueError on the first failing one)."""
    pairs = _contact_pairs(model)
    for pair in pairs:
        check_surface(pair.slave)
        check_surface(pair.master)
    for pair in pairs:
        check_orientation(pair, z)
    check_rigid_modes(model, z, load_factor, fixed)
    warn_methods(model, z, load_factor)


register_check(run)  # Model.preflight runs it (the core names no layer below it)


def _contact_pairs(model: Any) -> list:
    from .pair import ContactPair  # contact imports nts, which this module imports
    return [it for it in model.items if isinstance(it, ContactPair)]


# --------------------------------------------------------------------------- orientation
def _solid_mesh(surface: Any):
    """The skfem mesh of the solid owning ``surface`` (None for a cable or rigid surface)."""
    mesh = getattr(surface.body, "mesh", None)
    return mesh if mesh is not None and surface.nodes is not None else None


def check_surface(surface: Any) -> None:
    """A surface on a solid must have its normals pointing out of the solid.

    For each segment that is a boundary facet of the solid's mesh, with
    ``n`` its right-hand normal, ``m`` its midpoint and ``c`` the centroid of
    the element it bounds, ``n . (m - c) > 0`` outward.  More than half of the
    facet length pointing inward (a boundary traced clockwise) raises
    ValueError.  Cables and rigid surfaces have no inside: nothing to check.
    """
    mesh = _solid_mesh(surface)
    if mesh is None:
        return
    ends = surface.nodes[surface.segments[:, :2]]              # body vertex indices
    nv = mesh.p.shape[1]
    fac = np.sort(mesh.facets[:2], axis=0)
    fkeys = fac[0].astype(np.int64) * nv + fac[1]
    order = np.argsort(fkeys)
    e = np.sort(ends, axis=1)
    keys = e[:, 0].astype(np.int64) * nv + e[:, 1]
    pos = np.clip(np.searchsorted(fkeys[order], keys), 0, len(order) - 1)
    found = fkeys[order][pos] == keys
    if not found.any():
        return
    elem = mesh.f2t[0, order[pos[found]]]
    t = mesh.t[:4] if mesh.t.shape[0] >= 4 and "Quad" in type(mesh).__name__ else mesh.t[:3]
    centroid = mesh.p[:, t[:, elem]].mean(axis=1)
    nrm, l = segment_normals(mesh.p, ends[found])
    mid = 0.5 * (mesh.p[:, ends[found, 0]] + mesh.p[:, ends[found, 1]])
    inward = np.sum(nrm * (mid - centroid), axis=0) < 0
    if l[inward].sum() > 0.5 * l.sum():
        raise ValueError(
            f"contact surface {surface.name!r} of body {surface.body.name!r}: its normals "
            f"point into the body ({int(inward.sum())} of {int(found.sum())} segments; the "
            f"outward normal is the right-hand normal of each segment, so a boundary must "
            f"run counter-clockwise): reverse its segments ({_reversed(surface)}) or build it "
            f"with ContactSurface.from_solid(body, tag), which orients the facets outward")


def _reversed(surface: Any) -> str:
    """The segments of ``surface`` run the other way, as an expression."""
    return ("surface.reversed(), i.e. segments[:, [1, 0, 2]]" if surface.segments.shape[1] == 3
            else "surface.reversed(), i.e. segments[:, ::-1]")


def nodal_normals(x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Unit nodal normals ``(2, n)``: the normalized sum of the unit normals of the
    (one or two) segments at each node, ``n_k = sum_e n_e / |sum_e n_e|``."""
    ne, _ = segment_normals(x, seg)
    acc = np.zeros((2, x.shape[1]))
    for j in (0, 1):
        np.add.at(acc.T, seg[:, j], ne.T)
    s = np.hypot(*acc)
    return acc / np.where(s > 0, s, 1.0)


@dataclass
class _Facing:
    near: np.ndarray       # slave nodes nearest the master (bool)
    proj: dict             # nts.nearest_nodes' projection
    cos: np.ndarray        # n_s . n_m per slave node
    weight: np.ndarray     # tributary length per slave node


def _facing(pair: Any, z: np.ndarray) -> _Facing:
    xs, xm = pair.slave.x(z), pair.master.x(z)
    seg_s, seg_m = polyline(pair.slave.segments), polyline(pair.master.segments)
    near, pr = nts.nearest_nodes(xs, seg_s, xm, seg_m, band=1.0)
    cos = np.sum(nodal_normals(xs, seg_s) * pr["n"], axis=0)
    return _Facing(near, pr, cos, tributary_lengths(xs, seg_s))


def check_orientation(pair: Any, z: np.ndarray) -> None:
    """The slave and the master of ``pair`` must face each other where they meet.

    Over the slave nodes nearest the master (:func:`skfem_mortar.contact.nts.nearest_nodes`,
    one slave element length deep), with ``n_s`` the slave nodal normal and
    ``n_m`` the normal of the master segment the node projects on, facing
    surfaces have ``n_s . n_m < 0``.  When the tributary length of the nodes
    with ``n_s . n_m > FACING`` exceeds that of the nodes with
    ``n_s . n_m < -FACING``, the surfaces point the same way: ValueError
    naming the pair, the surface to turn and how.

    Skipped for NTS with a slave on a body that is neither a solid nor a cable
    (a user's item, e.g. springs): such a surface has no outside, and NTS uses
    only the master's normal (mortar uses the slave's, so it is checked).
    """
    if (pair.method == "nts" and _solid_mesh(pair.slave) is None
            and _cable_side(pair.slave) is None):
        return
    f = _facing(pair, z)
    if not f.near.any():
        return
    w = f.weight[f.near]
    c = f.cos[f.near]
    same, facing = w[c > FACING].sum(), w[c < -FACING].sum()
    if not same > facing:
        return
    wrong, why = _blame(pair, f)
    n_same = int(np.sum(c > FACING))
    raise ValueError(
        f"contact pair {pair.name!r}: the slave {pair.slave.name!r} and the master "
        f"{pair.master.name!r} point the same way where they meet (n_s . n_m > {FACING:g} at "
        f"{n_same} of the {int(f.near.sum())} slave nodes nearest the master; surfaces in "
        f"contact face each other, else the solve converges to a penetration): {why}"
        + "".join(f"; {_turn(pair, s)}" for s in wrong))


def _blame(pair: Any, f: _Facing) -> tuple[list[str], str]:
    """Which surface(s) of ``pair`` to turn, and why.

    A solid's surface has been checked outward (:func:`check_surface`), so the
    other one is wrong; two solid surfaces that both point outward the same way
    are the wrong faces.  Otherwise the side the slave lies on decides: with
    ``g`` the mean normal gap ``(x_s - x_m) . n_m`` of the nearest nodes and
    ``h`` their mean slave segment length, ``g > h / 2``: the master's normal
    points at the slave, the slave's away from the master (turn the slave);
    ``g < -h / 2``: the other way round; in between (touching, penetrating) both
    are possible.
    """
    s_solid, m_solid = _solid_mesh(pair.slave) is not None, _solid_mesh(pair.master) is not None
    w = f.weight[f.near]
    g = float(np.sum(f.proj["g"][f.near] * w) / w.sum())
    h = float(np.mean(w))
    if s_solid and m_solid:
        away = "slave" if g > 0 else "master"
        surf = pair.slave if away == "slave" else pair.master
        return [], (f"both are outward boundaries of their solids, so the {away} "
                    f"{surf.name!r} is the face turned away from the other body: choose "
                    f"the boundary (tag) that faces it")
    if s_solid:
        return ["master"], f"the slave {pair.slave.name!r} is a solid's outward boundary"
    if m_solid:
        return ["slave"], f"the master {pair.master.name!r} is a solid's outward boundary"
    if g > 0.5 * h:
        return ["slave"], (f"the slave lies on the side the master's normal points to "
                           f"(mean gap {g:.3g}), so the slave's normal points away")
    if g < -0.5 * h:
        return ["master"], (f"the slave lies behind the master's normal (mean gap "
                            f"{g:.3g}), so the master's normal points away from it")
    return ["master", "slave"], (f"the surfaces touch (mean gap {g:.3g}), so either may "
                                 f"be the wrong one")


def _turn(pair: Any, which: str) -> str:
    """How to turn the ``which`` ("slave" or "master") surface of ``pair``."""
    s = pair.slave if which == "slave" else pair.master
    head = f"to turn the {which} {s.name!r}: "
    if isinstance(s, RigidPlane):
        n = -np.asarray(s.normal) + 0.0  # + 0.0: no '-0'
        return head + (f"flip the plane's normal, RigidPlane(point, normal=({n[0]:.3g}, "
                       f"{n[1]:.3g}))")
    if isinstance(s, RigidCircle):
        if getattr(s, "inside", False):
            return head + "drop inside=True (the body is outside the circle)"
        return head + "RigidCircle(..., inside=True) (the body is inside the circle)"
    side = _cable_side(s)
    if side is not None:
        other = "right" if side == "left" else "left"
        return head + (f"take the cable's other side, ContactSurface.from_cable(cable, "
                       f"side={other!r}) instead of side={side!r}")
    return head + f"reverse its segments ({_reversed(s)})"


def _cable_side(surface: Any) -> str | None:
    """``"left"`` or ``"right"`` for a surface built on a cable's elements, else None."""
    el = getattr(surface.body, "elements", None)
    if el is None or surface.nodes is None or _solid_mesh(surface) is not None:
        return None
    el = np.asarray(el, dtype=np.int64).reshape(-1, 2)
    first = surface.nodes[surface.segments[0]]
    if np.any(np.all(el == first, axis=1)):
        return "right"
    if np.any(np.all(el == first[::-1], axis=1)):
        return "left"
    return None


# --------------------------------------------------------------------------- rigid modes
@dataclass
class _Body:
    item: Any
    modes: np.ndarray      # (n_dofs, 3) local: translation x, translation y, rotation
    center: np.ndarray     # (2,) node centroid
    L: float               # largest distance of a node from the centroid


def _rigid_modes(body: Any) -> _Body:
    """The body's rigid modes on its local dofs, each of largest nodal motion 1:

        t_x = (1, 0),  t_y = (0, 1),  r = (-(Y - c_y), X - c_x) / L ,

    ``c`` the node centroid and ``L = max |X - c|``.  Interpolated on all the
    body's dofs where it can (``interpolate``: quadratic elements, MINI bubbles
    and pressures), else on its nodal dofs (other dofs 0).
    """
    X = np.asarray(body.X, dtype=float)
    c = X.mean(axis=1)
    L = float(np.max(np.hypot(*(X - c[:, None])), initial=0.0)) or 1.0
    funs = (lambda P: np.vstack([np.ones(P.shape[1]), np.zeros(P.shape[1])]),
            lambda P: np.vstack([np.zeros(P.shape[1]), np.ones(P.shape[1])]),
            lambda P: np.vstack([-(P[1] - c[1]), P[0] - c[0]]) / L)
    if hasattr(body, "interpolate"):
        modes = np.column_stack([body.interpolate(f) for f in funs])
    else:
        modes = np.zeros((int(body.n_dofs), 3))
        nd = np.asarray(body.node_dofs)
        for j, f in enumerate(funs):
            v = f(X)
            modes[nd[0], j], modes[nd[1], j] = v[0], v[1]
    return _Body(body, modes, c, L)


def _times_modes(S: sp.spmatrix, bodies: list[_Body]) -> np.ndarray:
    """``S M`` (dense, rows x 3 n_bodies) for a sparse ``S`` with global columns, ``M``
    the global mode basis (body b's modes in columns 3b .. 3b+2, zero elsewhere),
    one body block at a time: O(nnz(S) + rows x 3 n_bodies), ``M`` never formed."""
    S = S.tocsc()
    out = np.zeros((S.shape[0], 3 * len(bodies)))
    for b, bd in enumerate(bodies):
        off = bd.item.offset
        out[:, 3 * b:3 * b + 3] = S[:, off:off + bd.modes.shape[0]] @ bd.modes
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
    nv = nts.evaluate(xs, polyline(pair.slave.segments), xm, polyline(pair.master.segments),
                      tangent=True)
    on = touch & nv.mask
    G = nv.G[np.flatnonzero(on)]
    if getattr(pair, "friction", None) is not None:
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
    _, ls = segment_normals(xs, polyline(pair.slave.segments))
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
    3 columns per body, zero on the other bodies; applied block by block,
    :func:`_times_modes`), the constraints seen by a
    combination ``M a`` are stacked, each group divided by its tolerance:

        A = [ M[fixed] / HOLD ;  C M / HOLD ;  B M / HOLD ;  K_x[free] M / (SPRING k_b) ]

    with ``C`` the unit normal rows of the touching contact nodes
    (:func:`_touching_rows`), ``B`` the unit-normalized rows of other
    multiplier items (ties) and ``K_x`` the stiffness of springs and loads
    (:func:`_stiffness_rows`).  The combinations with ``|A a| < |a|`` (right
    singular vectors of ``A`` with singular value below 1, from the streamed QR
    factor of ``A``: cost O(rows x (3 n_bodies)^2), no dense n x n) are held by
    nothing: ValueError naming each body, its free modes and the fix.
    Modes of several bodies combine: a body held by contact with a free body
    is free with it.
    """
    bodies, N, touching = free_combinations(model, z, load_factor, fixed)
    if N.shape[1]:
        raise ValueError(_free_message(bodies, N, np.asarray(fixed, dtype=np.int64), touching))


def free_combinations(model: Any, z: np.ndarray, load_factor: float, fixed: np.ndarray,
                      contact: bool = True) -> tuple[list[_Body], np.ndarray, dict]:
    """The bodies' rigid modes (:func:`_rigid_modes`), the basis ``N`` (3 n_bodies, k)
    of the combinations held by nothing (:func:`check_rigid_modes`) and the
    touching rows of each contact pair by name; ``contact=False`` counts no
    contact pair as holding anything (what holds the bodies besides contact)."""
    from .pair import ContactPair
    bodies = [_rigid_modes(b) for b in model.bodies
              if hasattr(b, "X") and hasattr(b, "node_dofs") and np.size(b.X)]
    if not bodies:
        return bodies, np.zeros((0, 0)), {}
    n, ncols = int(model.n), 3 * len(bodies)
    fixed = np.asarray(fixed, dtype=np.int64)
    free = np.ones(model.n_u, dtype=bool)
    free[fixed[fixed < model.n_u]] = False
    select = sp.csr_matrix((np.ones(fixed.size), (np.arange(fixed.size), fixed)),
                           shape=(fixed.size, n))
    blocks = [_chunks(_times_modes(select, bodies), HOLD)]
    touching: dict[str, tuple[Any, _Touch]] = {}
    for it in model.items:
        if isinstance(it, ContactPair):
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
    in_free = [np.linalg.norm(P[3 * b:3 * b + 3, 3 * b:3 * b + 3]) > 1e-6 for b in range(nb)]
    parts = []
    for b, bd in enumerate(bodies):
        if not in_free[b]:
            continue
        modes = _describe(bd, N[3 * b:3 * b + 3])
        with_ = [bodies[c].item.name for c in range(nb) if c != b and in_free[c]
                 and np.linalg.norm(P[3 * b:3 * b + 3, 3 * c:3 * c + 3]) > 1e-6]
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
    """Name the free modes of one body from its rows ``Nb`` (3, k) of the free basis:
    translations (x, y or a direction), rotation (about a point when it is unique)."""
    U, sv, _ = np.linalg.svd(Nb, full_matrices=False)
    B = U[:, sv > 1e-3]                                     # basis of the body's free space
    r = B.shape[1]
    if r == 0:
        return "a combination of modes is"
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
    cx, cy = np.where(np.abs(bd.center) < 1e-9 * bd.L, 0.0, bd.center)  # as in _describe
    how = (f"{name}.dofs_at_nodes(nodes, component=c)" if hasattr(bd.item, "dofs_at_nodes")
           else f"{name}.support_dofs(nodes)" if hasattr(bd.item, "support_dofs")
           else "its dofs at those nodes")
    if "in x and y" in modes:
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


# --------------------------------------------------------------------------- methods
def warn_methods(model: Any, z: np.ndarray | None = None, load_factor: float = 0.0) -> None:
    """A :class:`PreflightWarning` for every NTS pair with a known failure cause
    (:func:`skfem_mortar.contact.nts.failure_hints`: a slave coarser than the master
    where they meet, nearly coincident slave nodes) or whose deformable meshes
    do not match where they meet (:func:`.diagnosis.nts_patch_text`: off the
    patch test), and for every pair of bodies stiffer one than the other beyond
    the measured range (:func:`.diagnosis.stiffness_ratio_text`), naming the fix,
    before the solve rather than after a cascade of step cuts."""
    from .diagnosis import nts_patch_text, stiffness_ratio_text
    for pair in _contact_pairs(model):
        if pair.method == "nts":
            hints = [pair.discretization.failure_hint(),  # nts.failure_hints (geometry only)
                     nts_patch_text(pair)]
            if any(hints):
                warn_at_user("; ".join(h for h in hints if h), PreflightWarning)
    if z is not None:
        for text in stiffness_ratio_text(model, z, load_factor):
            warn_at_user(text, PreflightWarning)
