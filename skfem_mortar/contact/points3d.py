"""The 3D segmentation's integration points on jets: what the one mortar kernel integrates.

From the values of a :class:`~skfem_mortar.contact.segmentation3d.FaceSegmentation`
(each cell's parents, its three vertices' origins and their converged coordinates)
this module rebuilds every geometric quantity of an integration cell as a
:class:`~skfem_mortar.contact.jets.Jet` of the cell's local variables, so the kernel's
integrals get exact first and second derivatives:

1. **Local variables** (the kernel's contract, node-major): ``[x of the slave face's
   k_s nodes (3 k_s), x of the master face's k_m nodes (3 k_m), the slave face's
   nodal normals (3 k_s)]``, ``n_loc = 3 (2 k_s + k_m)`` (27 tri3/tri3, 36
   quad4/quad4).  Nothing here depends on the nodal normals: their block is zero
   (``pad=True`` appends it; ``pad=False`` returns the ``3 (k_s + k_m)`` first).
2. **The auxiliary plane** of the slave face, as in
   :func:`~skfem_mortar.contact.segmentation3d.auxiliary_planes`: through the face's
   centre, normal to ``v = T_1 x T_2`` at the centre (the face's own normal, Popp
   et al. and 4C: not the interpolated nodal normals, which only the gap uses).
   Only its direction enters, so ``v`` is never normalized: projections along
   ``v`` use the plane's two directions ``B_1 = v x T_1``, ``B_2 = v x T_2``.
3. **Clip vertices** from their origins, ``p`` before projection (a point ``p``
   and its projection ``P(p)`` on the plane have the same back-projection, and
   the same ``B_a . p``):
   a slave vertex ``X_s,i``; a master vertex ``X_m,j``; the intersection of slave
   line ``(a, b)`` and master line ``(c, d)``,
   ``p = a + t (b - a)``, ``t = [(c - a) x (d - c)].v / [(b - a) x (d - c)].v``.
4. **Gauss points** of each cell on the plane: a triangle rule of degree
   ``n_gauss`` (:func:`~skfem_mortar.contact.cells.tri_quadrature`, 5 by default)
   at barycentric points ``L``, ``p_g = sum_k L_k p_k``.
5. **Back-projection to the slave face** along ``v``: the ``xi`` with
   ``F_a(xi) = B_a . (x_s(xi) - p_g) = 0``, ``a = 1, 2``.  Newton in values to
   convergence from the segmentation's vertex coordinates interpolated, then **one
   Newton step in jet arithmetic** with the converged (value) Jacobian and the
   **curvature term** of the implicit function theorem (:func:`_curvature`).  With
   the start's error ``e_0 = O(eps)`` in the variables' perturbation ``eps`` (zero in
   value), each step gains one order,
   ``e_{k+1} = (I - J^-1 F'(xi*(eps))) e_k + O(e_k^2) = O(eps) e_k``: one step makes
   the first derivatives exact, and the curvature term is what a second step adds to
   the second derivatives (``O(eps^3)`` after it), at the cost of four outer products
   instead of a second evaluation of the face point on jets (tested against finite
   differences and against a further full step).
6. **Weights**: the rule's weight times the Jacobian of the map from the unit
   triangle to the slave reference plane, through the plane cell and the
   back-projection: ``w = w_rule [(p_1 - p_0) x (p_2 - p_0)].v / [T_1(xi) x
   T_2(xi)].v`` (twice the cell's area on the plane over the plane area of the
   face's reference element at ``xi``; ``|v|`` cancels).  The kernel multiplies the
   face's own Jacobian ``J_s(xi)``, so ``sum w J_s`` over a fully covered face is
   ``int J_s dxi``, the face's area, to the rule's accuracy on the smooth integrand
   ``J_s / (T_1 x T_2).n_0`` (exactly on a planar face of any shape, trapezoids
   included: the ratio is then 1).  The cells are exact on the plane, so their
   Gauss points cover the overlap exactly, warped or not.
7. **Master coordinates** of each Gauss point by projection along ``v``:
   ``B_a . (x_m(xi_m) - p_g) = 0`` (``B_a . x_s(xi) = B_a . p_g`` at the slave
   point), Newton in values from the cell's vertex values interpolated, then two
   jet steps (step 5).

Memory: a jet of ``n`` cells at ``n_gp`` points holds ``n n_gp nv^2`` Hessian
entries, ``nv = 3 (k_s + k_m)``; :func:`point_chunks` cuts the cells so that one
such Hessian stays below :data:`CHUNK_BYTES` (the peak of a chunk is measured at
about 31 of them: 61 MB, tests/test_points3d.py).
"""
from __future__ import annotations

from typing import Any, Iterator

import numpy as np

from .cells import CellType, cell_type, tri_quadrature
from .integration_points import IntegrationCells, IntegrationPoints, LocalVariables
from .jets import Jet, _outer, _zero, _zeros
from .segmentation import EDGE_INTERSECTION, MASTER_VERTEX, SLAVE_VERTEX
from .segmentation3d import FACES, FaceSegmentation, line_corners, segment_faces

__all__ = ["FacePoints", "integration_points", "face_points", "point_chunks", "check_rule",
           "CHUNK_BYTES", "JET_STEPS", "N_GAUSS", "N_GAUSS_BILINEAR", "AFFINE_TOL"]

#: the default degree of the cells' triangle rule (issue 38: >= 5)
N_GAUSS = 5
#: the lowest degree of the cells' rule when a quad4 face is not a parallelogram
#: (:func:`check_rule`)
N_GAUSS_BILINEAR = 4
#: a quad4 face is a parallelogram when ``|x_0 - x_1 + x_2 - x_3|`` is at most this
#: fraction of its longest diagonal (:func:`check_rule`)
AFFINE_TOL = 1e-10
#: Newton steps in jet arithmetic after the values converged (module docstring, step 5):
#: the second is the curvature term (:func:`_curvature`), further ones full steps
JET_STEPS = 2
#: bytes of one Hessian jet of a chunk of cells (:func:`point_chunks`)
CHUNK_BYTES = 2_000_000
_VALUE_STEPS = 30
_VALUE_TOL = 1e-14


def _interpolate(f: np.ndarray, df: np.ndarray, d2f: np.ndarray | None, xi: tuple,
                 X: list) -> list:
    """``y(xi) = sum_k f_k(xi) X_k`` (three jets) at jet points ``xi`` (two jets), given
    ``f``, its derivatives ``df (k, 2) + S`` and ``d2f (k, 2, 2) + S`` (None: zero) at
    ``xi``'s values, for node jets ``X[k][d]`` that are local variables
    (:func:`_node_jets`).  By the chain rule, with ``T_ad = sum_k f_k,a X_kd`` and
    ``W_abd = sum_k f_k,ab X_kd``::

        g = sum_a T_ad g_a + f_k e_kd,
        h = sum_a T_ad h_a + sum_ab W_abd g_a g_b^T + (f_k' e_kd^T + e_kd f_k'^T),

    the last term written into the rows of the node's variables only (stored
    unsymmetrized, as :class:`Jet` does), ``f_k' = sum_a f_k,a g_a``."""
    Xv = [[X[k][d].v for d in range(3)] for k in range(len(X))]
    second = xi[0].h is not None
    fg = [sum(df[k, a] * xi[a].g for a in range(2)) for k in range(len(X))]
    outer = {}
    if second and d2f is not None:
        for a, b in ((0, 0), (0, 1), (1, 1)):
            if np.any(d2f[:, a, b] + d2f[:, b, a]):
                outer[a, b] = _outer(xi[a].g, xi[b].g)
    out = []
    for d in range(3):
        v = sum(f[k] * Xv[k][d] for k in range(len(X)))
        T = [sum(df[k, a] * Xv[k][d] for k in range(len(X))) for a in range(2)]
        g = T[0] * xi[0].g + T[1] * xi[1].g
        h = None
        if second:
            h = np.zeros(xi[0].g.shape[:1] * 2 + v.shape)
            for a in range(2):
                if not _zero(xi[a].h):
                    h += T[a] * xi[a].h
            for (a, b), o in outer.items():
                c = d2f[:, a, b] + (d2f[:, b, a] if a != b else 0.0)
                h += sum(c[k] * Xv[k][d] for k in range(len(X))) * o
        for k in range(len(X)):
            i = X[k][d].var                 # a local variable's number (Jet.variable)
            g[i] += f[k]
            if h is not None:
                h[i] += 2.0 * fg[k]
        out.append(Jet(v, g, h))
    return out


def _face_point(cell: CellType, xi: tuple, X: list) -> list:
    """``x(xi) = sum_k N_k(xi) X_k`` (:func:`_interpolate`)."""
    v = np.stack([c.v for c in xi])
    return _interpolate(cell.shape(v), cell.dshape(v), cell.d2shape(v), xi, X)


def _face_tangents(cell: CellType, xi: tuple, X: list) -> list:
    """``T_a(xi) = sum_k N_k,a(xi) X_k``, ``a = 1, 2`` (:func:`_interpolate`; the shape
    functions' third derivatives vanish on tri3 and quad4)."""
    v = np.stack([c.v for c in xi])
    dN, d2N = cell.dshape(v), cell.d2shape(v)
    return [_interpolate(dN[:, a], d2N[:, a], None, xi, X) for a in range(2)]


def _cross(a, b) -> list:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a: list, b: list) -> Jet:
    """``a . b`` of two 3-vectors of jets, fused: one pass for the three products'
    gradient outer products, ``h = sum_d (a_d'' b_d + a_d b_d'' + 2 a_d' b_d'^T)``."""
    v = sum(a[d].v * b[d].v for d in range(3))
    g = sum(a[d].g * b[d].v + b[d].g * a[d].v for d in range(3))
    h = None
    if a[0].h is not None:
        ga = np.stack([np.broadcast_to(a[d].g, g.shape) for d in range(3)])
        gb = np.stack([np.broadcast_to(b[d].g, g.shape) for d in range(3)])
        h = 2.0 * np.einsum("di...,dj...->ij...", ga, gb)
        for d in range(3):
            if not _zero(a[d].h):
                h += a[d].h * b[d].v
            if not _zero(b[d].h):
                h += b[d].h * a[d].v
    return Jet(v, g, h)


def _node_jets(X: np.ndarray, offset: int, nv: int, second: bool) -> list:
    """``X[k][d]``: coordinate ``d`` of node ``k`` (values ``X (n, k, 3)``), the local
    variable ``offset + 3 k + d``, with a trailing value axis ``(n, 1)``."""
    return [[Jet.variable(X[:, k, d][:, None], offset + 3 * k + d, nv, second)
             for d in range(3)] for k in range(X.shape[1])]


def _pick(X: list, idx: np.ndarray) -> list:
    """``X[idx]`` per entry (``idx`` (n, K) of node numbers; ``X[k][d]`` local
    variables), three jets (n, K) of zero Hessian."""
    out = []
    for d in range(3):
        v = np.choose(idx, [np.broadcast_to(X[k][d].v, idx.shape) for k in range(len(X))])
        g = np.choose(idx, [np.broadcast_to(X[k][d].g, X[k][d].g.shape[:1] + idx.shape)
                            for k in range(len(X))])
        h = X[0][d].h
        out.append(Jet(v, g, None if h is None else _zeros(h.shape[:2] + idx.shape)))
    return out


def _plane(cell: CellType, X: list) -> tuple[list, list, list]:
    """``v = T_1 x T_2`` at the face's reference centre and ``B_a = v x T_a``."""
    ref = np.asarray(cell.ref_nodes, dtype=float)
    centre = ref[:, list(cell.corners)].mean(axis=1)
    G = cell.dshape(centre[:, None])[..., 0]                             # (k, 2)
    T = [[sum(X[k][d] * float(G[k, a]) for k in range(len(X)) if G[k, a] != 0)
          for d in range(3)] for a in range(2)]
    v = _cross(T[0], T[1])
    return v, _cross(v, T[0]), _cross(v, T[1])


def _vertex_points(cs: CellType, cm: CellType, Xs: list, Xm: list, v: list,
                   seg: FaceSegmentation, rows: np.ndarray) -> list:
    """The clip vertices ``p`` before projection (module docstring, step 3), (n, 3)."""
    origin, src = seg.origin[rows], seg.src[rows]
    i, j = np.maximum(src[..., 0], 0), np.maximum(src[..., 1], 0)
    ls, lm = line_corners(len(cs.corners))[i], line_corners(len(cm.corners))[j]
    corners_s, corners_m = list(cs.corners), list(cm.corners)
    Cs, Cm = [Xs[k] for k in corners_s], [Xm[k] for k in corners_m]
    a, b = _pick(Cs, ls[..., 0]), _pick(Cs, ls[..., 1])
    c, d = _pick(Cm, lm[..., 0]), _pick(Cm, lm[..., 1])
    ab = [b[q] - a[q] for q in range(3)]
    dc = [d[q] - c[q] for q in range(3)]
    num = _dot(_cross([c[q] - a[q] for q in range(3)], dc), v)
    den = _dot(_cross(ab, dc), v)
    edge = origin == EDGE_INTERSECTION
    safe = edge & (den.v != 0)
    den = Jet.where(safe, den, Jet.constant(np.ones(den.v.shape), den.g.shape[0],
                                            den.h is not None))
    t = num / den
    p = [a[q] + t * ab[q] for q in range(3)]
    ps = _pick(Cs, np.where(origin == SLAVE_VERTEX, i, 0))       # i, j: line codes elsewhere
    pm = _pick(Cm, np.where(origin == MASTER_VERTEX, j, 0))
    for q in range(3):
        p[q] = Jet.where(origin == SLAVE_VERTEX, ps[q],
                         Jet.where(origin == MASTER_VERTEX, pm[q], p[q]))
    return p


def _solve_values(cell: CellType, X: np.ndarray, p: np.ndarray, B: np.ndarray,
                  xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Newton in values for ``B_a . (x(xi) - p) = 0``: ``X (k, 3) + S`` node values,
    ``p (3,) + S``, ``B (2, 3) + S``, start ``xi (2,) + S``; the root and the inverse
    Jacobian ``(2, 2) + S`` there (identity where singular)."""
    for it in range(_VALUE_STEPS + 1):
        N, dN = cell.shape(xi), cell.dshape(xi)
        x = np.einsum("k...,kd...->d...", N, X)
        T = np.einsum("ka...,kd...->ad...", dN, X)
        F = np.einsum("ad...,d...->a...", B, x - p)
        J = np.einsum("ad...,bd...->ab...", B, T)
        det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
        ok = det != 0
        r = 1.0 / np.where(ok, det, 1.0)
        Ji = np.stack([np.stack([J[1, 1] * r, -J[0, 1] * r]),
                       np.stack([-J[1, 0] * r, J[0, 0] * r])])
        Ji = np.where(ok, Ji, np.eye(2).reshape((2, 2) + (1,) * det.ndim))
        if it == _VALUE_STEPS:
            break
        step = np.einsum("ab...,b...->a...", Ji, F)
        xi = xi - step
        if np.max(np.abs(step), initial=0.0) <= _VALUE_TOL:
            break
    return xi, Ji


def _project(cell: CellType, X: list, p: list, B: tuple, xi0: np.ndarray) -> list:
    """The reference coordinates (two jets) of the points ``p`` (three jets) projected
    along the plane onto the faces of node jets ``X``: values by :func:`_solve_values`
    from ``xi0``, then :data:`JET_STEPS` jet steps (module docstring, step 5)."""
    shape = np.broadcast_shapes(p[0].v.shape, xi0.shape[1:])
    val = lambda jets: np.stack([np.broadcast_to(j.v, shape) for j in jets])  # noqa: E731
    Xv = np.stack([val(Xk) for Xk in X])
    Bv = np.stack([val(B[0]), val(B[1])])
    xi, Ji = _solve_values(cell, Xv, val(p), Bv, np.broadcast_to(xi0, (2,) + shape).copy())
    nv, second = p[0].g.shape[0], p[0].h is not None
    xj = [Jet.constant(xi[a], nv, second) for a in range(2)]
    for step in range(JET_STEPS):
        if step == 1 and second:
            _curvature(cell, X, B, xi, Ji, xj)
            continue
        x = _face_point(cell, xj, X)
        d = [x[q] - p[q] for q in range(3)]
        F = [_dot(B[0], d), _dot(B[1], d)]
        xj = [xj[a] - (F[0] * Ji[a, 0] + F[1] * Ji[a, 1]) for a in range(2)]
    return xj


def _curvature(cell: CellType, X: list, B: tuple, xi: np.ndarray, Ji: np.ndarray,
               xj: list) -> None:
    """The second Newton step's work on the Hessians of ``xj`` (one jet step taken from
    the root ``xi``), added in place: by the implicit function theorem on
    ``F_c(xi, u) = B_c . (x(xi) - p) = 0`` (``u`` the local variables), with
    ``g_a = dxi_a/du`` the step's exact gradients and ``J = dF/dxi``::

        d2xi/du2 = -J^-1 (F_uu + 2 sym(sum_a dF_xi_a/du g_a^T) + sum_ab F_xi_a xi_b g_a g_b^T),

    the step's jet holding ``-J^-1 F_uu``; ``F_xi_a = B . T_a`` (its gradient from
    first-order jets at ``xi``), ``F_xi_a xi_b = B . x_,ab`` (values).  Stored
    unsymmetrized (:class:`~.jets.Jet`): ``sum_a g_a (2 U_ca + sum_b W_cab g_b)^T`` with
    ``U_ca = -sum_e Ji_ce dF_xi_a,e/du`` and ``W_cab = -sum_e Ji_ce F_xi_a xi_b,e``."""
    nv = xj[0].g.shape[0]
    first = [Jet.constant(xi[a], nv, False) for a in range(2)]
    T = _face_tangents(cell, first, X)                                  # T[a][q], first order
    Bf = [[b.first() for b in Be] for Be in B]
    dF = [[_dot(Bf[e], T[a]).g for a in range(2)] for e in range(2)]   # dF_xi_a,e/du
    d2N = cell.d2shape(xi)                                              # (k, 2, 2) + S
    Xab = [[[sum(d2N[k, a, b] * X[k][q].v for k in range(len(X))) for q in range(3)]
            for b in range(2)] for a in range(2)]
    g = [xj[a].g for a in range(2)]
    for c in range(2):
        for a in range(2):
            r = -2.0 * (Ji[c, 0] * dF[0][a] + Ji[c, 1] * dF[1][a])
            for b in range(2):
                W = -sum(Ji[c, e] * sum(B[e][q].v * Xab[a][b][q] for q in range(3))
                         for e in range(2))
                if np.any(W):
                    r = r + W * g[b]
            xj[c].h = xj[c].h + _outer(g[a], r)


def _check(cells, n_gauss) -> tuple[CellType, CellType]:
    cs, cm = cell_type(cells[0]), cell_type(cells[1])
    for name, c in (("cells[0]", cs), ("cells[1]", cm)):
        if c.name not in FACES:
            raise ValueError(f"{name} must be one of {list(FACES)}, got {c.name!r}")
    if isinstance(n_gauss, bool) or not isinstance(n_gauss, (int, np.integer)) or n_gauss < 1:
        raise ValueError(f"n_gauss must be an integer >= 1, got {n_gauss!r}")
    return cs, cm


def check_rule(cells: "tuple[str | CellType, str | CellType]", n_gauss: int,
               faces: "tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]",
               high: int | None = None) -> None:
    """Refuse a rule of degree ``n_gauss < 4`` (:data:`N_GAUSS_BILINEAR`) when a quad4
    face of either side is not a parallelogram in ``faces``, the sides' ``(X, segments)``
    (node coordinates ``(3, n)`` and faces ``(n_face, k)``, the reference ones);
    ``high``: the largest degree offered, for the message.

    A quad4 face is a parallelogram (an affine image of the reference square) when its
    bilinear term vanishes, ``|x_0 - x_1 + x_2 - x_3| <= AFFINE_TOL d`` with ``d`` its
    longest diagonal.  Otherwise ``N_A`` and the dual basis are rational on the
    auxiliary plane, and the rule's error on a cell depends on how the overlap is cut
    into cells.  Where slave and master edges lie on each other (patch3d's footprint,
    any mesh whose grid lines meet), they cross back and forth between iterations by
    the round-off of the solve, the cells change (37, then 40 on patch3d ``distort=0.3``)
    and with them the rule's error: the residual is not smooth there.  Measured on
    patch3d ``distort=0.3, n_lower=4, n_upper=2, margin=0``, lower slave, mortar-dual:
    at degree 2 the first step stalls (the residual near 4e-8 for 10 iterations, three
    cuts, done at load 0.125; pressure error 2.2e-4); degree 3 is the same rule
    (:func:`~skfem_mortar.contact.cells.tri_quadrature` of degree ``q`` has
    ``ceil((q + 1) / 2)^2`` points: 4 at 2 and 3, 9 at 4 and 5) and stalls alike;
    degrees 4 and 5 (9 points) converge in 4 iterations (pressure error 5.6e-7, the
    rule's).  That the 9-point rule's jump stays below Newton's floor on other meshes
    is not shown: the default is 5.

    Raises
    ------
    ValueError
        ``n_gauss`` below 4 with a quad4 face that is not a parallelogram, naming
        ``n_gauss``, the side and its allowed range.
    """
    if int(n_gauss) >= N_GAUSS_BILINEAR:
        return
    for side, cell, (X, seg) in zip(("slave", "master"), cells, faces):
        if cell_type(cell).name != "quad4":
            continue
        x = np.asarray(X, dtype=float).T[np.asarray(seg, dtype=np.int64)]   # (n, 4, 3)
        bilinear = np.linalg.norm(x[:, 0] - x[:, 1] + x[:, 2] - x[:, 3], axis=-1)
        diagonal = np.maximum(np.linalg.norm(x[:, 2] - x[:, 0], axis=-1),
                              np.linalg.norm(x[:, 3] - x[:, 1], axis=-1))
        bad = int(np.count_nonzero(bilinear > AFFINE_TOL * diagonal))
        if bad:
            allowed = f"in [{N_GAUSS_BILINEAR}, {high}]" if high else f">= {N_GAUSS_BILINEAR}"
            raise ValueError(f"n_gauss must be an integer {allowed} when a quad4 face is not "
                             f"a parallelogram ({bad} {side} faces are not), got {n_gauss}: "
                             f"the rule's error jumps where edges cross and Newton stalls")


def face_points(cells: "tuple[str | CellType, str | CellType]", Xs: np.ndarray,
                Xm: np.ndarray, seg: FaceSegmentation, rows: np.ndarray,
                n_gauss: int = N_GAUSS, second: bool = True, pad: bool = True
                ) -> IntegrationPoints:
    """The :class:`~skfem_mortar.contact.integration_points.IntegrationPoints` of the
    cells ``rows`` of ``seg`` from their faces' node values ``Xs (n, k_s, 3)``,
    ``Xm (n, k_m, 3)`` (module docstring, steps 1 to 7): jets of ``3 (2 k_s + k_m)``
    variables (``pad``), else of ``3 (k_s + k_m)``.  Parameters as in
    :func:`integration_points`."""
    cs, cm = _check(cells, n_gauss)
    rows = np.asarray(rows, dtype=np.int64)
    k_s = cs.n_nodes
    nv = 3 * (k_s + cm.n_nodes)
    Xs, Xm = _node_jets(Xs, 0, nv, second), _node_jets(Xm, 3 * k_s, nv, second)
    v, B1, B2 = _plane(cs, Xs)
    p = _vertex_points(cs, cm, Xs, Xm, v, seg, rows)
    pts, wq = tri_quadrature(int(n_gauss))
    L = np.stack([1.0 - pts[0] - pts[1], pts[0], pts[1]])                # (3, n_gp)
    col = [[_column(p[d], k) for k in range(3)] for d in range(3)]
    p_g = [sum(col[d][k].expand() * L[k] for k in range(3)) for d in range(3)]
    area = _dot(_cross([col[d][1] - col[d][0] for d in range(3)],
                       [col[d][2] - col[d][0] for d in range(3)]), [_column(c, 0) for c in v])
    xi_g = _project(cs, Xs, p_g, (B1, B2), np.einsum("nka,kq->anq", seg.xi[rows], L))
    T = _face_tangents(cs, xi_g, Xs)
    w = area.expand() * wq / _dot(_cross(T[0], T[1]), v)
    xi_m = _project(cm, Xm, p_g, (B1, B2), np.einsum("nka,kq->anq", seg.xi_m[rows], L))
    out = IntegrationPoints(seg.e_s[rows], seg.e_m[rows], tuple(xi_g), tuple(xi_m), w)
    return _padded(out, 3 * k_s) if pad else out


def integration_points(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray,
                       seg_m: np.ndarray, cells: "tuple[str | CellType, str | CellType]",
                       seg: FaceSegmentation, rows: np.ndarray | slice | None = None,
                       n_gauss: int = N_GAUSS, second: bool = True, pad: bool = True
                       ) -> IntegrationPoints:
    """The integration points of the cells ``rows`` of ``seg`` (all by default) with
    exact first and second derivatives over their local variables (module
    docstring: the variables, the plane, the vertices, the rule, the back-projection,
    the weights, the master coordinates).

    Parameters
    ----------
    xs, xm : ndarray (3, n_s), (3, n_m)
        Slave and master node coordinates (those ``seg`` was made from, or near them:
        only its origins are taken, and its coordinates as Newton's start).
    seg_s, seg_m : int ndarray (n_face, k)
        The faces.
    cells : (CellType or str, CellType or str)
        tri3 or quad4 each.
    seg : FaceSegmentation
    rows : index, optional
        The cells to evaluate (a chunk: :func:`point_chunks`).
    n_gauss : int
        Degree of the triangle rule on each cell, >= 1 (default 5).
    second : bool
        Track second derivatives.
    pad : bool
        Append the nodal normals' (zero) block to the variables.

    Raises
    ------
    ValueError
        When a cell is not tri3 or quad4, or ``n_gauss`` is not an integer >= 1.
    """
    _check(cells, n_gauss)
    rows = np.arange(seg.n)[slice(None) if rows is None else rows]
    Xs = np.asarray(xs, dtype=float).T[np.asarray(seg_s)[seg.e_s[rows]]]
    Xm = np.asarray(xm, dtype=float).T[np.asarray(seg_m)[seg.e_m[rows]]]
    return face_points(cells, Xs, Xm, seg, rows, n_gauss, second, pad)


class FacePoints:
    """The 3D segmentation's side of the one kernel's contract
    (:class:`~skfem_mortar.contact.integration_points.PointSegmentation`).

    Parameters
    ----------
    cells : (CellType or str, CellType or str)
        Slave and master faces, tri3 or quad4 each.
    n_gauss : int
        Degree of the triangle rule on each integration cell (default 5).
    options : dict
        Passed to :func:`~skfem_mortar.contact.segmentation3d.segment_faces`
        (``pairs``, ``margin``, ``reach``, ``frozen``).

    ``integration_cells`` keeps ``(seg, rows)`` as its ``data``: a kernel that takes a
    chunk ``r`` of the rows passes ``IntegrationCells(e_s[r], e_m[r], (seg, rows[r]))``.
    ``chunk_entries``: the kernel's chunk bound for these points
    (:func:`~skfem_mortar.contact.mortar_kernel.chunks`).
    """

    #: derivative entries per kernel chunk: 23 quad4/quad4 or 37 tri3/tri3 cells, whose
    #: Hessian jets at 7 points (1.7 MB each) stay in cache; measured on 64 quad4 and 128
    #: tri3 faces (CPU, 3 interleaved runs): 250,000 (the kernel's default) 2.6 / 3.3 s,
    #: 60,000 2.3 / 2.4, 30,000 2.0 / 2.3, 15,000 2.2 / 2.4, 8,000 2.5 / 2.7
    chunk_entries = 30_000

    def __init__(self, cells: "tuple[str | CellType, str | CellType]",
                 n_gauss: int = N_GAUSS, **options: Any):
        self.cells = _check(cells, n_gauss)
        self.n_gauss, self.options = int(n_gauss), options

    def integration_cells(self, xs: np.ndarray, conn_s: np.ndarray, xm: np.ndarray,
                          conn_m: np.ndarray, normals: np.ndarray | None = None
                          ) -> IntegrationCells:
        """The faces' integration cells (values; ``normals`` unused: the auxiliary
        planes are the faces' own)."""
        seg = segment_faces(xs, conn_s, xm, conn_m, self.cells, **self.options)
        return IntegrationCells(seg.e_s, seg.e_m, (seg, np.arange(seg.n)))

    def integration_points(self, cells: IntegrationCells, local: LocalVariables
                           ) -> IntegrationPoints:
        """The points of ``cells`` in jets of the leading ``3 (k_s + k_m)`` of ``local``'s
        ``3 (2 k_s + k_m)`` variables (the points do not depend on the nodal normals:
        the kernel's arithmetic pads them where they meet the normals, so the jets made
        from the points alone carry ``(k_s + k_m)^2 / (2 k_s + k_m)^2`` of the Hessian
        entries, 0.44 on quad4/quad4)."""
        seg, rows = cells.data
        Xs, Xm = (np.stack([np.stack([c.v for c in node], -1) for node in X], 1)
                  for X in (local.x_s, local.x_m))
        return face_points(self.cells, Xs, Xm, seg, rows, self.n_gauss,
                           local.x_s[0][0].h is not None, pad=False)


def _column(j: Jet, k: int) -> Jet:
    """Entry ``k`` of the second value axis: ``(n, K) -> (n,)``."""
    return Jet(j.v[:, k], j.g[:, :, k], None if j.h is None else j.h[:, :, :, k])


def _pad_jet(j: Jet, extra: int) -> Jet:
    nv = j.g.shape[0]
    g = np.concatenate([np.broadcast_to(j.g, j.g.shape), np.zeros((extra,) + j.g.shape[1:])])
    h = None
    if j.h is not None:
        h = np.zeros((nv + extra, nv + extra) + j.h.shape[2:])
        h[:nv, :nv] = j.h
    return Jet(j.v, g, h)


def _padded(p: IntegrationPoints, extra: int) -> IntegrationPoints:
    """The points with ``extra`` more (zero) variables: the nodal normals' block."""
    return IntegrationPoints(p.e_s, p.e_m, tuple(_pad_jet(c, extra) for c in p.xi_s),
                             tuple(_pad_jet(c, extra) for c in p.xi_m), _pad_jet(p.w, extra))


def point_chunks(seg: FaceSegmentation, cells: "tuple[str | CellType, str | CellType]",
                 n_gauss: int = N_GAUSS, budget: int = CHUNK_BYTES) -> Iterator[slice]:
    """Slices of ``seg``'s cells such that one Hessian jet of a chunk,
    ``n n_gp nv^2`` doubles (``nv = 3 (k_s + k_m)``), takes at most ``budget`` bytes
    (at least one cell a chunk)."""
    cs, cm = cell_type(cells[0]), cell_type(cells[1])
    nv = 3 * (cs.n_nodes + cm.n_nodes)
    n_gp = tri_quadrature(int(n_gauss))[1].size
    size = max(1, int(budget) // (8 * nv * nv * n_gp))
    for k in range(0, seg.n, size):
        yield slice(k, min(k + size, seg.n))
