"""Meshes of the 3D contact scenes (``patch3d``, ``tied3d``, ``hertz3d``).

* :func:`grid_mesh`: a structured block on given grid lines (hexahedra, or each
  split into six tetrahedra), its x-lines optionally tilted in y so that the faces
  normal to z are trapezoids;
* :func:`graded_octant`: an eighth of a ball (the quarter of a hemisphere of
  ``hertz3d``) and :func:`graded_quarter_cylinder` (its elastic base), tetrahedra
  refined by longest-edge bisection towards the contact point, the new nodes of the
  curved boundary moved onto it after every pass; :func:`tets_to_hexes` makes
  hexahedra of them (each tetrahedron split into four);
* :func:`mirrored`: a mesh and its mirror image across a coordinate plane, glued
  there (the half model of a quarter);
* :func:`symmetry_planes`: the symmetry planes that rollers declare;
* :func:`plane_grid`: a rigid plane as quad4 faces.
"""
from __future__ import annotations

import numpy as np
from skfem import MeshHex1, MeshTet1

from ._meshes3d import _cells, mesh_kind

__all__ = ["grid_mesh", "tilted_lines", "graded_octant", "graded_quarter_cylinder",
           "tets_to_hexes", "mirrored", "nodes_on_plane", "tagged", "octant_planes",
           "cylinder_planes", "symmetry_planes", "plane_grid", "GRADING"]

#: element size growth per unit distance beyond the fine zone (``hertz``'s is 0.3;
#: 0.5 in 3D keeps the cell count of the default mesh near 3e4)
GRADING = 0.5


def grid_mesh(element: str, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray,
              tilt: np.ndarray | None = None):
    """The block on the grid lines ``xs x ys x zs`` (increasing), hexahedra
    (``hex1``) or each hexahedron split into six Kuhn tetrahedra (``tet1``).

    ``tilt`` (one value per x-line, default 0) moves the x-line ``i`` to
    ``x = xs[i] + tilt[i] (y - yc) / (Ly / 2)`` (``yc`` the middle of ``ys``, ``Ly``
    its span): every face normal to z becomes a trapezoid whose parallel sides run
    along x (a parallelogram only where two neighbouring lines tilt alike).  The
    cells stay valid while ``|tilt[i]| + |tilt[i + 1]| < xs[i + 1] - xs[i]``.
    """
    xs, ys, zs = (np.asarray(v, dtype=float) for v in (xs, ys, zs))
    grid = np.meshgrid(xs, ys, zs, indexing="ij")
    p = np.array([g.ravel() for g in grid])
    if tilt is not None:
        yc, half = 0.5 * (ys[0] + ys[-1]), 0.5 * (ys[-1] - ys[0])
        shift = np.asarray(tilt, dtype=float)[:, None, None] * (grid[1] - yc) / half
        p[0] += shift.ravel()
    index = np.arange(p.shape[1]).reshape(xs.size, ys.size, zs.size)
    linear, _ = mesh_kind(element)
    return linear(p, _cells(index, linear is MeshTet1))


def tilted_lines(n: int, h: float, distort: float, fixed: set[int]) -> np.ndarray:
    """Tilts for :func:`grid_mesh` of ``n + 1`` x-lines ``h`` apart: ``+-distort h``
    alternating, 0 on the lines in ``fixed`` (the block's ends, its mid-plane, the
    footprint's edges: lines whose nodes must stay where they are)."""
    t = distort * h * (-1.0) ** np.arange(n + 1)
    t[sorted(fixed)] = 0.0
    return t


def nodes_on_plane(mesh, axis: int, value: float, tol: float) -> np.ndarray:
    """The vertices of ``mesh`` with ``|X[axis] - value| <= tol``."""
    return np.flatnonzero(np.abs(mesh.p[axis] - value) <= tol)


def _orient(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Tetrahedra ``t`` with two corners swapped where their volume is negative."""
    a, b, c, d = (p[:, t[k]] for k in range(4))
    vol = np.einsum("ij,ij->j", np.cross(b - a, c - a, axis=0), d - a)
    t = np.array(t, dtype=np.int64)
    t[[1, 2]] = np.where(vol < 0.0, t[[2, 1]], t[[1, 2]])
    return np.ascontiguousarray(t)


def _cube_to_ball(q: np.ndarray) -> np.ndarray:
    """The radial map of the cube ``[0, 1]^3`` onto the ball's octant: ``q max|q_i| / |q|``
    (the cube's faces ``q_i = 1`` onto the sphere, the planes ``q_i = 0`` onto themselves)."""
    n2 = np.linalg.norm(q, axis=0)
    scale = np.divide(q.max(axis=0), n2, out=np.zeros_like(n2), where=n2 > 0.0)
    return q * scale


def _kuhn_block(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and Kuhn tetrahedra of the unit cube in ``n`` cells a side."""
    ax = np.linspace(0.0, 1.0, n + 1)
    g = np.meshgrid(ax, ax, ax, indexing="ij")
    p = np.array([v.ravel() for v in g])
    return p, _cells(np.arange(p.shape[1]).reshape(n + 1, n + 1, n + 1), True)


def _curved_nodes(mesh: MeshTet1, planes: list[tuple[int, float]], tol: float) -> np.ndarray:
    """The vertices of the boundary faces that lie on none of the ``planes``
    (``(axis, value)``): the nodes of the curved boundary."""
    f = mesh.facets[:, mesh.boundary_facets()]
    on_plane = np.zeros(f.shape[1], dtype=bool)
    for axis, value in planes:
        on_plane |= np.all(np.abs(mesh.p[axis, f] - value) <= tol, axis=0)
    return np.unique(f[:, ~on_plane])


def _graded(mesh: MeshTet1, h0: float, fine: float, snap, planes, tol: float,
            growth: float = GRADING) -> MeshTet1:
    """Longest-edge bisection of the tetrahedra until ``h_e <= 1.5 h0 + growth
    max(d - fine, 0)`` (``d`` the distance of a tetrahedron from the origin, ``h_e``
    its longest edge), the curved boundary's nodes moved by ``snap`` after each
    pass (ValueError after 60 passes)."""
    pairs = [(i, j) for i in range(4) for j in range(i + 1, 4)]
    for _ in range(60):
        e = mesh.p[:, mesh.t]                                    # (3, 4, n)
        h = np.max([np.linalg.norm(e[:, i] - e[:, j], axis=0) for i, j in pairs], axis=0)
        d = np.maximum(np.linalg.norm(e.mean(axis=1), axis=0) - h, 0.0)
        marked = np.flatnonzero(h > 1.5 * h0 + growth * np.maximum(d - fine, 0.0))
        if marked.size == 0:
            return mesh
        mesh = mesh.refined(marked)
        p = mesh.p.copy()
        on = _curved_nodes(mesh, planes, tol)
        p[:, on] = snap(p[:, on])
        mesh = MeshTet1(np.ascontiguousarray(p), _orient(p, mesh.t))
    raise ValueError("graded mesh did not converge: refine is too large")


def _finish(mesh: MeshTet1, element: str, snap, planes, names, curved: str, tol: float):
    """The graded tetrahedra as ``element``'s mesh (``hex1``: :func:`tets_to_hexes`, the
    new nodes of the curved faces snapped), tagged by :func:`tagged`."""
    if element == "hex1":
        on = tagged(mesh, planes, names, curved, tol).boundaries[curved]
        mesh = tets_to_hexes(mesh, snap, on)
    return tagged(mesh, planes, names, curved, tol)


def _coarser(h0: float, element: str) -> tuple[float, float]:
    """The tetrahedron size and growth to grade: :func:`tets_to_hexes` halves both."""
    return (2.0 * h0, 2.0 * GRADING) if element == "hex1" else (h0, GRADING)


def octant_planes(R: float) -> tuple[list, tuple]:
    """The planes and names of :func:`graded_octant`'s flat boundaries."""
    return [(0, 0.0), (1, 0.0), (2, R)], ("x0", "y0", "top")


def graded_octant(R: float, h0: float, fine: float, element: str = "tet1"):
    """The quarter of the hemisphere ``|X - C| <= R``, ``Z <= R``, ``X, Y >= 0``
    (``C = (0, 0, R)``: it touches ``Z = 0`` at the origin), tetrahedra (or
    hexahedra, ``element="hex1"``) of edge about ``h0`` within ``fine`` of the
    origin, growing by :data:`GRADING` beyond; boundaries ``x0`` (``X = 0``),
    ``y0``, ``top`` (``Z = R``), ``sphere``."""
    p, t = _kuhn_block(2)
    x = _cube_to_ball(p)
    P = np.array([[0.0], [0.0], [R]]) + R * np.vstack([x[0], x[1], -x[2]])
    tol = 1e-9 * R
    C = np.array([[0.0], [0.0], [R]])

    def snap(q: np.ndarray) -> np.ndarray:
        v = q - C
        return C + R * v / np.linalg.norm(v, axis=0)

    planes, names = octant_planes(R)
    size, growth = _coarser(h0, element)
    mesh = _graded(MeshTet1(P, _orient(P, t)), size, fine, snap, planes, tol, growth)
    return _finish(mesh, element, snap, planes, names, "sphere", tol)


def cylinder_planes(W: float) -> tuple[list, tuple]:
    """The planes and names of :func:`graded_quarter_cylinder`'s flat boundaries."""
    return [(0, 0.0), (1, 0.0), (2, 0.0), (2, -W)], ("x0", "y0", "top", "bottom")


def graded_quarter_cylinder(W: float, h0: float, fine: float, element: str = "tet1"):
    """The quarter cylinder ``X, Y >= 0``, ``X^2 + Y^2 <= W^2``, ``-W <= Z <= 0``,
    graded towards the origin as :func:`graded_octant`; boundaries ``x0``, ``y0``,
    ``top`` (``Z = 0``), ``bottom`` (``Z = -W``), ``side``."""
    p, t = _kuhn_block(2)
    xy = _cube_to_ball(np.vstack([p[:2], np.zeros(p.shape[1])]))[:2]
    P = np.vstack([W * xy, -W * p[2]])
    tol = 1e-9 * W

    def snap(q: np.ndarray) -> np.ndarray:
        out = q.copy()
        out[:2] *= W / np.linalg.norm(q[:2], axis=0)
        return out

    planes, names = cylinder_planes(W)
    size, growth = _coarser(h0, element)
    mesh = _graded(MeshTet1(P, _orient(P, t)), size, fine, snap, planes, tol, growth)
    return _finish(mesh, element, snap, planes, names, "side", tol)


def tagged(mesh, planes, names, curved: str, tol: float):
    """``mesh`` with its boundary faces tagged by the plane they lie on, the rest
    ``curved``."""
    bf = mesh.boundary_facets()
    f = mesh.facets[:, bf]
    tags, rest = {}, np.ones(bf.size, dtype=bool)
    for (axis, value), name in zip(planes, names):
        on = np.all(np.abs(mesh.p[axis, f] - value) <= tol, axis=0)
        tags[name] = bf[on]
        rest &= ~on
    tags[curved] = bf[rest]
    return mesh.with_boundaries(tags)


#: the four hexahedra of a tetrahedron (scikit-fem's corner order ``(0,0,0), (0,1,0),
#: (1,0,0), (0,0,1), (1,1,0), (0,1,1), (1,0,1), (1,1,1)``): at its vertex ``k`` with the
#: local axes along the edges to ``i``, ``j``, ``l``, the corners are the vertex, the
#: midpoints of ``kj``, ``ki``, ``kl``, the centroids of the faces without ``l``, ``i``,
#: ``j``, and the tetrahedron's centroid
_SPLIT = [(0, 1, 2, 3), (1, 0, 2, 3), (2, 0, 1, 3), (3, 0, 1, 2)]

#: the corner permutation that swaps a hexahedron's local axes 0 and 1 (reverses it)
_SWAP01 = [0, 2, 1, 3, 4, 6, 5, 7]


def _lookup(keys: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Positions of the rows ``keys`` (sorted corner tuples, ``(m, ...)``) in ``table``."""
    n = int(max(keys.max(), table.max())) + 1
    code = lambda a: np.ravel_multi_index(tuple(a), (n,) * a.shape[0])  # noqa: E731
    t = code(np.sort(table, axis=0))
    order = np.argsort(t)
    return order[np.searchsorted(t, code(np.sort(keys, axis=0)), sorter=order)]


def tets_to_hexes(mesh: MeshTet1, snap=None, curved: np.ndarray | None = None) -> MeshHex1:
    """Every tetrahedron split into four hexahedra by its edge midpoints, face
    centroids and centroid (the element size halves), each hexahedron positively
    oriented; ``snap`` moves the new nodes of the curved boundary faces ``curved``
    (facet indices) onto that boundary."""
    p, t, edges, facets = mesh.p, mesh.t, mesh.edges, mesh.facets
    n, ne, nf = p.shape[1], edges.shape[1], facets.shape[1]
    P = np.hstack([p, 0.5 * (p[:, edges[0]] + p[:, edges[1]]), p[:, facets].mean(axis=1),
                   p[:, t].mean(axis=1)])

    def edge(a, b):
        return n + _lookup(np.vstack([t[a], t[b]]), edges)

    def face(out):
        return n + ne + _lookup(t[[m for m in range(4) if m != out]], facets)

    centre = n + ne + nf + np.arange(t.shape[1])
    H = np.hstack([np.vstack([t[k], edge(k, j), edge(k, i), edge(k, l_), face(l_), face(i),
                              face(j), centre]) for k, i, j, l_ in _SPLIT])
    if snap is not None and curved is not None:
        f = facets[:, curved]
        mids = [_lookup(f[[a, b]], edges) for a, b in ((0, 1), (1, 2), (0, 2))]
        new = np.unique(np.concatenate([n + np.concatenate(mids), n + ne + curved]))
        P[:, new] = snap(P[:, new])
    centre_detJ = MeshHex1(P, H)._mapping().detDF(np.full((3, 1), 0.5))[:, 0]
    H[:, centre_detJ < 0.0] = H[_SWAP01][:, centre_detJ < 0.0]
    return MeshHex1(np.ascontiguousarray(P), np.ascontiguousarray(H))


def mirrored(mesh, axis: int):
    """``mesh`` and its mirror image across the plane ``X[axis] = 0``, the nodes on
    that plane shared (each mirrored cell's corners reordered to stay positively
    oriented: the image of a cell is the cell with its coordinate ``axis`` reversed)."""
    p, t = mesh.p, mesh.t
    tol = 1e-9 * float(np.ptp(p))
    on = np.abs(p[axis]) <= tol
    new = np.flatnonzero(~on)
    number = np.arange(p.shape[1])
    number[new] = p.shape[1] + np.arange(new.size)
    q = p[:, new].copy()
    q[axis] *= -1.0
    t2 = number[t]
    if isinstance(mesh, MeshTet1):
        t2[[1, 2]] = t2[[2, 1]]
    else:                              # hexahedra: swap the corners across local axis 0
        t2 = t2[[2, 4, 0, 6, 1, 7, 3, 5]]
    return type(mesh)(np.hstack([p, q]), np.hstack([t, t2]))


def symmetry_planes(items) -> list[tuple[int, float]]:
    """The symmetry planes ``(axis, value)`` declared by rollers among ``items``: a
    :class:`~skfem_mortar.core.dirichlet.Dirichlet` of value 0 on one component ``k``
    of a body's vertices that all lie on one plane ``X[k] = c`` (within ``1e-9`` of
    the body's size) and span it (three of them not on a line)."""
    from ..core.dirichlet import Dirichlet

    found = []
    for item in items:
        if not isinstance(item, Dirichlet) or item.path is not None:
            continue
        body, dofs = item.body, np.asarray(item.local_dofs)
        nd = np.asarray(body.node_dofs)
        where = np.full(int(nd.max()) + 1, -1, dtype=np.int64)
        where[nd.ravel()] = np.arange(nd.size)
        at = where[dofs[dofs < where.size]]
        if at.size != dofs.size or np.any(at < 0) or np.any(np.asarray(item.value) != 0.0):
            continue
        comp, node = np.divmod(at, nd.shape[1])
        if np.unique(comp).size != 1:
            continue
        k, X = int(comp[0]), body.X[:, node]
        size = float(np.ptp(body.X))
        if np.ptp(X[k]) > 1e-9 * size or node.size < 3:
            continue
        inplane = np.delete(X, k, axis=0)
        spread = np.linalg.svd(inplane - inplane.mean(axis=1, keepdims=True),
                               compute_uv=False)
        if spread[-1] > 1e-9 * size:
            found.append((k, float(X[k].mean())))
    return sorted(set(found))


def plane_grid(x_range: tuple[float, float], y_range: tuple[float, float], level: float,
               h: float) -> tuple[np.ndarray, np.ndarray]:
    """A rigid plane ``Z = level`` over ``x_range x y_range`` as quad4 faces about ``h``
    a side (a master's faces should be about the slave's size: the mortar clipping
    and the closest-point search work face by face): nodes ``(3, n)`` and faces
    ``(n_faces, 4)``, each counter-clockwise seen from ``+z`` (outward normal ``+z``:
    a body rests on it)."""
    nx = max(1, int(np.ceil((x_range[1] - x_range[0]) / h)))
    ny = max(1, int(np.ceil((y_range[1] - y_range[0]) / h)))
    gx, gy = np.meshgrid(np.linspace(*x_range, nx + 1), np.linspace(*y_range, ny + 1),
                         indexing="ij")
    X = np.vstack([gx.ravel(), gy.ravel(), np.full(gx.size, float(level))])
    k = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    faces = np.column_stack([k[:-1, :-1].ravel(), k[1:, :-1].ravel(), k[1:, 1:].ravel(),
                             k[:-1, 1:].ravel()])
    return X, faces
