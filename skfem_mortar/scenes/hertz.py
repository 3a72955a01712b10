"""Scene ``hertz``: Hertz line contact of a cylinder on a flat body (reference problem 6).

A half cylinder of radius ``R`` (axis on ``x = 0``, centre ``(0, R)``, touching
``y = 0`` at the origin) is pressed by the line load ``P`` (per unit thickness,
the FULL load of the whole cylinder) against an elastic block or a rigid plane
(``base``).  By symmetry only ``x >= 0`` is modelled: ``u_x = 0`` on ``x = 0``
for both bodies, and the quarter disk carries ``P / 2`` as a uniform dead
traction ``P / (2 R)`` on its flat top face ``y = R``.  The elastic base is a
block ``[0, W] x [-W, 0]`` with ``W = 30 a`` (at least 20 a wide and deep), its
bottom clamped.  The slave surface is the cylinder's arc, the master the top of
the base (or the rigid plane, a chain of collinear segments on ``|x| <= 3 a``,
see :func:`rigid_plane`).  ``segmentation`` (mortar only) rebuilds the mortar
segments in every Newton iteration or once per load step.
With ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`` (a
rigid base has ``1/E2 = 0``):

    a = sqrt(4 P R / (pi E*)),   p0 = 2 P / (pi a),   p(x) = p0 sqrt(1 - x^2 / a^2) .

Meshes (linear triangles) are graded: element edges are at most
``h0 = (a / 30) 2^-refine`` within ``1.2 a`` of the contact point (the coarse
start meshes are refined adaptively, new arc nodes are projected onto the
circle) and grow by 0.3 times the distance beyond.  The right-angled corner
triangle at the origin, which longest-edge refinement never splits, is
bisected from the origin (:func:`split_corner`): left single, it made the node
carrying the peak pressure too stiff (+1.2 % in the peak at h = a/30 with NTS
and dual multipliers, +2.0 % with standard ones).

``element`` picks the bodies' element on these meshes: ``tri1`` (default),
``tri2`` (the same triangles, quadratic and isoparametric: the mid nodes of the
arc's facets lie on the circle, :func:`graded_quarter_disk`), ``quad1`` and
``quad2`` (each triangle of a mesh graded to ``2 h0`` split into three
quadrilaterals, :func:`triangles_to_quads`, so element edges are again about
``h0``), or ``mini``.  The quadratic ones give 3-node contact segments (the slave
surface's mid nodes carry multipliers too).

Accuracy: the peak nodal pressure lies ~1 % above ``p0`` at the default load
however fine the mesh: the model deviates from linear Hertz theory by O(a/R)
(measured at the interior nodes 0.2 a < x < 0.5 a, ``pressure_offset``:
0.79 % at a/R = 0.048, 0.43 % at 0.024, 0.24 % at 0.012, all at h = a/30);
the rest of the error is O(h).  Measured peak errors at h = a/30: rigid
1.30 % (NTS, dual), 1.45 % (standard mortar); elastic 1.04 % (dual), 1.21 %
(standard), 15 % (NTS, whose nodal pressure oscillates between non-matching
meshes).

Where the O(a/R) comes from (``kinematics``, rigid base, NTS, h = a/30):
linear Hertz theory reads the pressure per unit *reference* length at the
*reference* positions, and so do the ``*_ref`` metrics
(:func:`linearized_metrics`; for NTS on the rigid plane they are the
linearized contact's answer exactly).  The Cauchy pressure on the current
surface (``peak_pressure``) lies above that by the surface strain,
``1 / (1 + eps_xx) - 1 = (1 - 2 nu) / (2 (1 - nu)) a/R`` at the peak (plane
strain): 0.54 % at a/R = 0.019, 1.38 % at 0.048.  With ``kinematics="small"``
(linear elasticity in the bulk, contact still on the current configuration)
what is left in the reference reading is the discretization error and a
floor: ``peak_pressure_ref_error`` 0.51, 0.35, 0.22, 0.14 % at h = a/15 ...
a/120 (a/R = 0.019; order ~0.7), ``pressure_ref_offset`` 0.03-0.04 % (the
finite body and the circle instead of the parabola).  The finite-strain
difference is ``finite - small`` in one reading: -0.12 % in the interior
offset, -0.14 % in the peak at a/R = 0.019 (-0.31 % and -0.39 % at 0.048).

Nearly incompressible bodies: ``element="mini"`` builds them of MINI mixed
u-p triangles (:class:`~skfem_mortar.bodies.mixed.MixedSolid`) on the same meshes;
linear triangles lock as ``nu -> 0.5`` (peak 63 % off at ``nu = 0.499``,
``refine = -2``; MINI 0.6 %).

Metrics: ``peak_pressure`` (largest nodal pressure), ``half_width`` (midway
between the last slave node in compression and the next one) with ``_exact``
and ``_error``; ``pressure_l2_error``, the relative L2 error of the nodal
pressure over ``[0, 1.5 a]`` (trapezoidal rule on the slave nodes);
``pressure_oscillation``, the total variation of the nodal pressure over
``[0, 1.5 a]`` beyond that of a unimodal profile, divided by ``p0`` (0 without
oscillations); ``pressure_offset`` (:func:`interior_offset`); and the same in
the reference reading of linear theory, ``peak_pressure_ref`` (with
``_error``), ``pressure_ref_l2_error``, ``pressure_ref_offset``.
"""
from __future__ import annotations

import math
from dataclasses import replace
from functools import partial

import numpy as np
from skfem import MeshQuad, MeshQuad2, MeshTri, MeshTri2

from ..contact.pair import ContactPair
from ..bodies.materials import NeoHooke
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..bodies.solid import KINEMATICS, Solid
from ..contact.surfaces import ContactSurface, tributary_lengths
from ..loads.traction import Traction
from . import METHODS, Param, Scene, Setup, lame_quantities, positive, ratio

__all__ = ["SCENE", "build", "hertz_exact", "graded_quarter_disk", "graded_block",
           "triangles_to_quads", "ELEMENTS"]

#: the bodies' elements: linear and quadratic triangles and quadrilaterals
#: (quadratic ones isoparametric: the arc's mid nodes on the circle), and MINI
ELEMENTS = ("tri1", "tri2", "quad1", "quad2", "mini")

FINE_ZONE = 1.2   # in units of a: uniform fine elements in this radius
GRADING = 0.3     # element size growth per unit distance beyond it


def hertz_exact(radius: float, load: float, E: float, nu: float,
                E_base: float | None, nu_base: float) -> dict:
    """Half-width ``a``, peak pressure ``p0`` and ``E*`` of the Hertz line contact
    (``E_base=None``: rigid base)."""
    inv = (1 - nu * nu) / E + (0.0 if E_base is None else (1 - nu_base ** 2) / E_base)
    Es = 1.0 / inv
    a = math.sqrt(4 * load * radius / (math.pi * Es))
    return {"E_star": Es, "half_width": a, "peak_pressure": 2 * load / (math.pi * a)}


def _longest_edges(mesh: MeshTri) -> tuple[np.ndarray, np.ndarray]:
    e = mesh.p[:, mesh.t]  # (2, 3, n_el)
    h = np.max([np.hypot(*(e[:, (k + 1) % 3] - e[:, k])) for k in range(3)], axis=0)
    return h, e.mean(axis=1)


def _refine_graded(mesh: MeshTri, h0: float, fine: float, project=None) -> MeshTri:
    """Adaptive refinement near the origin until ``h_e <= h0 + GRADING max(d - fine, 0)``
    (``d`` the distance of the element from the origin); at most 40 passes."""
    for _ in range(40):
        h, c = _longest_edges(mesh)
        d = np.maximum(np.hypot(c[0], c[1]) - h, 0.0)
        marked = np.flatnonzero(h > 1.5 * h0 + GRADING * np.maximum(d - fine, 0.0))
        if marked.size == 0:
            return mesh
        mesh = mesh.refined(marked)
        if project is not None:
            mesh = MeshTri(project(mesh), mesh.t)
    raise ValueError("graded mesh did not converge: refine is too large")


def split_corner(mesh: MeshTri) -> MeshTri:
    """Bisect the triangle at the origin (and its neighbour across the bisected edge).

    The refinement by longest-edge splitting never cuts the right angle of the
    half model's corner at the origin (the symmetry axis meets the contact
    surface there), so the node that carries the peak pressure is held by a
    single constant-strain triangle (two in the mirrored full model).  That
    stiff node attracts an excess of contact force: measured +1.2 % in the peak
    nodal pressure at h = a/30 (+2.0 % with standard mortar multipliers, whose
    consistent inversion amplifies a nodal force error at the surface end),
    shrinking like h.  Bisecting the corner triangle from the origin gives the
    node two 45-degree triangles, the patch of a regular criss-cross mesh
    (measured: +1.3 % and +1.5 % at h = a/30, of which about +1.0 % is the
    O(a/R) finite-strain deviation from linear Hertz theory).
    """
    p, t = mesh.p, mesh.t
    o = int(np.argmin(np.hypot(p[0], p[1])))
    (e,) = np.flatnonzero((t == o).any(axis=0))
    A, B = (int(v) for v in t[:, e] if v != o)
    nb = [k for k in np.flatnonzero((t == A).any(axis=0) & (t == B).any(axis=0)) if k != e]
    M = p.shape[1]
    new = [[o, A, M], [o, M, B]]
    for k in nb:
        C = int(next(v for v in t[:, k] if v not in (A, B)))
        new += [[A, C, M], [M, C, B]]
    keep = np.ones(t.shape[1], dtype=bool)
    keep[[e] + nb] = False
    return MeshTri(np.hstack([p, 0.5 * (p[:, [A]] + p[:, [B]])]),
                   np.ascontiguousarray(np.hstack([t[:, keep], np.array(new).T])))


def triangles_to_quads(mesh: MeshTri) -> MeshQuad:
    """Split every triangle into three quadrilaterals (its vertices, edge midpoints
    and centroid: ``(v_k, m_k,k+1, c, m_k-1,k)``), counter-clockwise; the element
    size halves.  Any triangle mesh gives a valid quadrilateral mesh this way."""
    p, t = mesh.p, mesh.t.copy()
    area = ((p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
            - (p[0, t[2]] - p[0, t[0]]) * (p[1, t[1]] - p[1, t[0]]))
    t[1:, area < 0] = t[1:, area < 0][::-1]           # counter-clockwise triangles
    edges = np.sort(np.stack([t, np.roll(t, -1, axis=0)]), axis=0)  # (2, 3, n_t): edge k = (v_k, v_k+1)
    keys = edges[0] * p.shape[1] + edges[1]
    uniq, inv = np.unique(keys.ravel(), return_inverse=True)
    inv = inv.reshape(3, -1)
    a, b = uniq // p.shape[1], uniq % p.shape[1]
    n_p, n_e = p.shape[1], uniq.size
    P = np.hstack([p, 0.5 * (p[:, a] + p[:, b]), p[:, t].mean(axis=1)])
    mid = n_p + inv                                    # mid[k]: midpoint of edge (v_k, v_k+1)
    c = n_p + n_e + np.arange(t.shape[1])
    quads = [np.stack([t[k], mid[k], c, mid[(k - 1) % 3]]) for k in range(3)]
    return MeshQuad(P, np.ascontiguousarray(np.hstack(quads)))


def _boundary_nodes(t: np.ndarray, n: int) -> np.ndarray:
    """The sorted nodes of the edges that belong to one triangle of ``t`` (3, n_t):
    ``MeshTri.boundary_nodes`` without building the mesh's facet tables."""
    # int64 keys: skfem's refined meshes hold int32 triangles, and n * n overflows
    # int32 beyond 46,340 nodes (hertz refine=3 then refined without end)
    e = np.sort(np.hstack([t[[0, 1]], t[[1, 2]], t[[2, 0]]]), axis=0).astype(np.int64)
    keys, count = np.unique(e[0] * n + e[1], return_counts=True)
    b = keys[count == 1]
    return np.unique(np.concatenate([b // n, b % n]))


def _on_circle(p: np.ndarray, R: float, tol: float, nodes: np.ndarray) -> np.ndarray:
    """``p`` with the points ``nodes`` of the arc (``x > 0``, ``y < R``) moved radially onto
    the circle of radius ``R`` about ``(0, R)``."""
    p = p.copy()
    on = nodes[(p[0, nodes] > tol) & (p[1, nodes] < R - tol)]
    v = p[:, on] - np.array([[0.0], [R]])
    p[:, on] = np.array([[0.0], [R]]) + R * v / np.hypot(v[0], v[1])
    return p


def _quadratic(mesh, R: float | None, tol: float):
    """The isoparametric quadratic mesh (MeshTri2 / MeshQuad2) of a linear one, its
    boundary mid nodes on the circle of radius ``R`` (None: straight facets)."""
    M = (MeshTri2 if isinstance(mesh, MeshTri) else MeshQuad2).from_mesh(mesh)
    if R is None:
        return M
    mids = M.dofs.get_facet_dofs(M.boundary_facets()).flatten()
    return replace(M, doflocs=_on_circle(M.doflocs, R, tol, mids))


def _with_element(mesh: MeshTri, element: str, R: float | None, tol: float):
    """The linear triangle mesh as the ``element``'s mesh: quadrilaterals (each triangle
    split in three, arc vertices back on the circle) and/or quadratic."""
    if element.startswith("quad"):
        q = triangles_to_quads(mesh)
        p = q.p if R is None else _on_circle(q.p, R, tol, q.boundary_nodes())
        mesh = MeshQuad(p, q.t)
    if element.endswith("2"):
        mesh = _quadratic(mesh, R, tol)
    return mesh


def _coarser(h0: float, element: str) -> float:
    """The triangle size to grade: quadrilaterals halve it (:func:`triangles_to_quads`)."""
    return 2.0 * h0 if element.startswith("quad") else h0


def graded_quarter_disk(R: float, h0: float, fine: float, element: str = "tri1"):
    """Quarter disk ``x >= 0, y <= R`` of the circle of radius ``R`` centred at
    ``(0, R)``, graded towards the origin (element edges about ``h0`` there);
    boundaries ``axis``, ``top``, ``arc``.  ``element`` (:data:`ELEMENTS`) picks
    triangles or quadrilaterals, linear or quadratic (mid nodes on the circle)."""
    n = 6
    th = np.linspace(-np.pi / 2, 0.0, n + 1)
    r = R * np.arange(1, n + 1) / n
    P = np.hstack([[[0.0], [R]], np.vstack([np.outer(r, np.cos(th)).ravel(),
                                            R + np.outer(r, np.sin(th)).ravel()])])
    idx = 1 + np.arange(n * (n + 1)).reshape(n, n + 1)
    j = np.arange(n)
    tris = [np.column_stack([np.zeros(n, int), idx[0, j], idx[0, j + 1]])]
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    tris += [np.column_stack([a, c, d]), np.column_stack([a, d, b])]
    mesh = MeshTri(P, np.vstack(tris).T)
    tol = 1e-9 * R

    def project(m: MeshTri) -> np.ndarray:
        return _on_circle(m.p, R, tol, _boundary_nodes(m.t, m.p.shape[1]))

    mesh = split_corner(_refine_graded(mesh, _coarser(h0, element), fine, project))
    mesh = _with_element(mesh, element, R, tol)
    return mesh.with_boundaries({
        "axis": lambda x: x[0] < tol,
        "top": lambda x: x[1] > R - tol,
        "arc": lambda x: (x[0] > tol) & (x[1] < R - tol)})


def graded_block(W: float, h0: float, fine: float, element: str = "tri1"):
    """Block ``[0, W] x [-W, 0]`` graded towards the origin; boundaries
    ``axis`` (x = 0), ``top``, ``bottom``, ``right``; ``element`` as in
    :func:`graded_quarter_disk` (straight facets)."""
    mesh = MeshTri.init_tensor(np.linspace(0, W, 4), np.linspace(-W, 0, 4))
    mesh = split_corner(_refine_graded(mesh, _coarser(h0, element), fine))
    mesh = _with_element(mesh, element, None, 1e-9 * W)
    tol = 1e-9 * W
    return mesh.with_boundaries({
        "axis": lambda x: x[0] < tol, "top": lambda x: x[1] > -tol,
        "bottom": lambda x: x[1] < -W + tol, "right": lambda x: x[0] > W - tol})


def rigid_plane(half_length: float, h0: float) -> ContactSurface:
    """The rigid plane ``y = 0`` (outward normal ``+y``) on ``|x| <= half_length`` as a
    chain of collinear segments about ``sqrt(2) h0`` long (the same straight line as
    one long segment, but its nodes stay within a few slave elements of every slave
    element: :func:`~skfem_mortar.contact.mortar_segmentation.segment` projects the master
    nodes onto the slave elements along the interpolated slave normals, and the
    projection of a node many element lengths away can fail, see the notes)."""
    n = max(2, int(math.ceil(2.0 * half_length / (math.sqrt(2.0) * h0))))
    X = np.vstack([np.linspace(half_length, -half_length, n + 1), np.zeros(n + 1)])
    seg = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    return ContactSurface(None, None, seg, X=X, name="plane")


#: the interior window (in units of a) of :func:`interior_offset`: away from the
#: peak node (the corner refinement, O(h)) and from the edge (where the
#: square-root profile is resolved worst)
INTERIOR = (0.2, 0.5)


def interior_offset(x: np.ndarray, p: np.ndarray, a: float, p0: float) -> float:
    """Mean of ``p / p_Hertz(x) - 1`` over the nodes with ``0.2 a < x < 0.5 a``: the
    model's offset from linear Hertz theory, where the discretization error is
    smallest (0 if no node lies there)."""
    inner = (x > INTERIOR[0] * a) & (x < INTERIOR[1] * a)
    if not inner.any():
        return 0.0
    ph = p0 * np.sqrt(1.0 - (x[inner] / a) ** 2)
    return float(np.mean(p[inner] / ph - 1.0))


def linearized_metrics(pair: ContactPair, z: np.ndarray, p: np.ndarray, a: float,
                       p0: float) -> dict:
    """The pressures read as linear Hertz theory reads them: per unit *reference*
    length at the *reference* positions ``X`` of the slave nodes.

    ``p_ref,A = p_A D_A / L_A``: the node's contact force (pressure ``p_A`` times its
    current tributary length ``D_A``, the discretization's ``area``) over its
    reference tributary length ``L_A``.  For NTS on the rigid plane the gap
    ``y_A = Y_A + u_y,A`` and the contact force are those of the linearized
    contact (gap along the reference normal), so these metrics are the
    linearized contact's answer exactly; the Cauchy reading (``peak_pressure``,
    at the current ``x``) lies above it by the surface strain,
    ``p / p_ref = L_A / D_A = 1 / (1 + eps_xx)``.
    Returns ``peak_pressure_ref`` (``_error`` against ``p0``),
    ``pressure_ref_l2_error`` (over ``[0, 1.5 a]`` of ``X``) and
    ``pressure_ref_offset`` (:func:`interior_offset`).
    """
    _, _, ev = pair.pressure_and_gap(z)
    L = tributary_lengths(pair.slave.X, pair.slave.segments)
    pr = p * ev.area / L
    X = pair.slave.X[0]
    order = np.argsort(X)
    X, pr = X[order], pr[order]
    sel = X <= 1.5 * a
    pe = p0 * np.sqrt(np.clip(1 - (X[sel] / a) ** 2, 0.0, None))
    l2 = math.sqrt(np.trapezoid((pr[sel] - pe) ** 2, X[sel]) / np.trapezoid(pe ** 2, X[sel]))
    peak = float(pr.max())
    return {"peak_pressure_ref": peak, "peak_pressure_ref_error": abs(peak - p0) / p0,
            "pressure_ref_l2_error": l2,
            "pressure_ref_offset": interior_offset(X, pr, a, p0)}


def _body_class(element: str):
    """``Solid`` of the element, or the mixed ``MixedSolid`` (MINI, for nu -> 0.5)."""
    if element == "mini":
        from ..bodies.mixed import MixedSolid
        return MixedSolid
    return partial(Solid, element=element)


def build(params: dict, method: str | None = None) -> Setup:
    """Cylinder (+ base), load, symmetry and supports, contact pair; Hertz metrics."""
    R, P = float(params["radius"]), float(params["load"])
    E, nu = float(params["E"]), float(params["nu"])
    Eb, nub = float(params["E_base"]), float(params["nu_base"])
    rigid = params["base"] == "rigid"
    method = method or "nts"
    ex = hertz_exact(R, P, E, nu, None if rigid else Eb, nub)
    a = ex["half_width"]
    if a > 0.2 * R:
        raise ValueError(f"load must keep the contact half-width a = {a:.4g} below 0.2 radius "
                         f"(Hertz theory needs a << R); lower load or raise E")
    h0 = a / 30.0 * 2.0 ** (-int(params["refine"]))
    element = params.get("element", "tri1")
    body = _body_class(element)
    kin = {"kinematics": params.get("kinematics", "finite")}
    mesh_element = "tri1" if element == "mini" else element
    cyl = body(graded_quarter_disk(R, h0, FINE_ZONE * a, mesh_element), NeoHooke(E=E, nu=nu),
               name="cylinder", **kin)
    items = [cyl,
             Traction(cyl, "top", (0.0, -P / (2 * R)), name="load"),
             Dirichlet(cyl, cyl.dofs_on("axis", "x"), 0.0, name="cylinder_axis")]
    slave = ContactSurface.from_solid(cyl, "arc", name="cylinder_arc")
    if rigid:
        master = rigid_plane(3.0 * a, h0)
    else:
        W = 30.0 * a
        base = body(graded_block(W, h0, FINE_ZONE * a, mesh_element), NeoHooke(E=Eb, nu=nub), name="base",
                    **kin)
        master = ContactSurface.from_solid(base, "top", name="base_top")
        items += [base, Dirichlet(base, base.dofs_on("bottom"), 0.0, name="base_bottom"),
                  Dirichlet(base, base.dofs_on("axis", "x"), 0.0, name="base_axis")]
    options = {} if method == "nts" else {"segmentation": params["segmentation"]}
    pair = ContactPair(slave, master, method, name="contact", **options)
    items.append(pair)
    model = Model(items)

    def metrics(result) -> dict:
        d = pair.contact_data(result.z)
        x, p = d["x"], d["pressure"]
        # linearized_metrics reads p in the surface's node order
        out = linearized_metrics(pair, result.z, p[np.argsort(d["node"])], a,
                                 ex["peak_pressure"])
        order = np.argsort(x)
        x, p = x[order], p[order]
        comp = np.flatnonzero(p > 1e-8 * max(p.max(), 0.0))  # inactive: lam = 0 up to round-off
        peak = float(p.max())
        if comp.size:
            k = comp.max()
            half = float(0.5 * (x[k] + x[min(k + 1, len(x) - 1)]))
        else:
            half = 0.0
        sel = x <= 1.5 * a
        xs, ps = x[sel], p[sel]
        pe = ex["peak_pressure"] * np.sqrt(np.clip(1 - (xs / a) ** 2, 0.0, None))
        l2 = math.sqrt(np.trapezoid((ps - pe) ** 2, xs) / np.trapezoid(pe ** 2, xs))
        # variation of the nodal pressure beyond that of a unimodal profile, over p0:
        # 0 for a profile that rises then falls, > 0 for oscillations
        tv = float(np.abs(np.diff(ps)).sum()) if ps.size > 1 else 0.0
        excess = tv - ((ps.max() - ps[0]) + (ps.max() - ps[-1])) if ps.size else 0.0
        out.update({"n_active": int(pair.active.sum()), "pressure_l2_error": l2,
                    "pressure_oscillation": max(excess, 0.0) / ex["peak_pressure"],
                    "pressure_offset": interior_offset(x, p, a, ex["peak_pressure"]),
                    "element_size": h0, "E_star": ex["E_star"]})
        for q, val in (("peak_pressure", peak), ("half_width", half)):
            out[q] = val
            out[f"{q}_exact"] = ex[q]
            out[f"{q}_error"] = abs(val - ex[q]) / ex[q]
        return out

    return Setup(model=model, metrics=metrics)


#: the range of the contact half-width over the radius: Hertz theory needs
#: a << R (above 0.2 it does not hold); below 1e-3 the graded mesh spans more
#: than 1e3 contact widths and the indentation a^2 / R is lost in round-off
#: against the coordinates of the cylinder
A_OVER_R = (1e-3, 0.2)


def contact_derived(params: dict, exact, body: str, size: str, what: str) -> list:
    """Radius, load, both bodies' Lame parameters, ``E*`` and ``size / R`` of a Hertz scene.

    ``exact(R, P, E, nu, E_base or None, nu_base)`` is the scene's closed form (a dict with
    ``E_star`` and ``size``), ``body`` names the pressed body, ``what`` the ratio's words."""
    R, P = float(params["radius"]), float(params["load"])
    E, nu = float(params["E"]), float(params["nu"])
    Eb, nub = float(params["E_base"]), float(params["nu_base"])
    rigid = params["base"] == "rigid"
    out = [positive("radius", R, "radius"), positive("load", P, "load"),
           *lame_quantities(E, nu, "E", "nu", body),
           *lame_quantities(Eb, nub, "E_base", "nu_base", "the base")]
    if not all(d.ok() for d in out):
        return out
    ex = exact(R, P, E, nu, None if rigid else Eb, nub)
    moduli = ("E", "nu") if rigid else ("E", "nu", "E_base", "nu_base")
    return out + [positive("E*", ex["E_star"], *moduli),
                  ratio(what, ex[size] / R, ("load", "radius") + moduli, *A_OVER_R)]


def derived(params: dict) -> list:
    """Radius, load, both bodies' Lame parameters, ``E*`` and the half-width ratio ``a / R``."""
    return contact_derived(params, hertz_exact, "the cylinder", "half_width",
                           "the contact half-width over the radius a / R")


def one_step(params: dict, method: str | None) -> bool:
    """Frictionless contact of hyperelastic (or linear) bodies has a unique answer
    here and carries no history, so one load step reaches the answer of several
    (tests/test_hertz.py) -- with the mortar methods re-segmenting every
    iteration.  NTS keeps segment preferences and locks from step to step, and
    ``segmentation=step`` freezes the segments of the previous step: their
    answers depend on the steps."""
    return method in ("mortar", "mortar-dual") and params["segmentation"] == "iteration"


SCENE = Scene(
    name="hertz",
    summary="Hertz line contact: a half cylinder pressed by a line load on an elastic "
            "block or a rigid plane, symmetric half model (reference problem 6).",
    params=(
        Param("radius", 8.0, "cylinder radius R", float, low=0.0, low_inclusive=False),
        Param("load", 3.2032, "line load P per unit thickness (the full cylinder's, also "
              "in the half model)", float, low=0.0, low_inclusive=False),
        Param("E", 200.0, "Young's modulus of the cylinder", float, low=0.0,
              low_inclusive=False),
        Param("nu", 0.3, "Poisson's ratio of the cylinder", float, low=0.0, high=0.5,
              high_inclusive=False),
        Param("E_base", 200.0, "Young's modulus of the elastic base", float, low=0.0,
              low_inclusive=False),
        Param("nu_base", 0.3, "Poisson's ratio of the elastic base", float, low=0.0,
              high=0.5, high_inclusive=False),
        Param("base", "rigid", "what the cylinder is pressed on", str,
              choices=("rigid", "elastic")),
        Param("refine", 0, "mesh level: element size (a/30) 2^-refine in the contact zone "
              "(refine=3: 1.7e5 unknowns; 4: 6.5e5, 3.6 GB, about a minute on one core)",
              int, low=-3, high=4),
        Param("element", "tri1", "bodies' element: linear or quadratic triangles (tri1, tri2) "
              "or quadrilaterals (quad1, quad2; each graded triangle split in three), the "
              "quadratic ones isoparametric with the arc's mid nodes on the circle; or MINI "
              "mixed u-p triangles (P1 + bubble / P1 pressure) that do not lock as nu -> 0.5",
              str, choices=ELEMENTS),
        Param("segmentation", "iteration", "mortar only: rebuild the mortar segments every "
              "Newton iteration, or once per load step (frozen during the step)", str,
              choices=("iteration", "step")),
        Param("kinematics", "finite", "bodies' strain: finite (neo-Hooke) or small (linear "
              "elasticity, every element, mini included; contact on the current "
              "configuration)", str,
              choices=KINEMATICS),
    ),
    build=build,
    methods=METHODS,
    default_steps=4,
    derived=derived,
    one_step=one_step,
    one_step_text="with mortar or mortar-dual and segmentation=iteration",
)
