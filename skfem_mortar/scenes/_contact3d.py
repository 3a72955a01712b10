"""Meshes of the 3D contact scenes (``patch3d``, ``tied3d``, ``hertz3d``).

* :func:`grid_mesh`: a structured block on given grid lines (hexahedra, or each
  split into six tetrahedra), its x-lines optionally tilted in y so that the faces
  normal to z are trapezoids;
* :func:`graded_octant`: an eighth of a ball (the quarter of a hemisphere of
  ``hertz3d``) and :func:`graded_quarter_cylinder` (its elastic base): a structured
  grid of the cube graded towards the contact point (:func:`graded_axis`), mapped
  smoothly onto the body, hexahedra or Kuhn tetrahedra (every other layer mirrored).
  Structured, because the nodal pressure of linear tetrahedra (a nodal reaction over
  its tributary area) depends on the node's patch: on the meshes graded by
  bisection the patches under the contact came in several kinds (4, 8 and 12
  surface triangles) and the nodal pressures scattered by +-10 % about Hertz at
  ``h = a / 7.5``, while the fitted radius was within 0.8 %;
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
           "graded_axis", "octant_axes", "mirrored", "nodes_on_plane", "tagged",
           "octant_planes", "cylinder_planes", "symmetry_planes", "plane_grid", "plane_on_lines",
           "GROWTH"]

#: element size growth from one cell to the next beyond the fine zone (1.5 keeps the
#: default hertz3d at 2.8e4 dofs a body; 1.3 gives the same readings to 0.1 % of p0
#: at twice the dofs)
GROWTH = 1.5


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


def _smooth_ball(q: np.ndarray) -> np.ndarray:
    """The smooth map of the unit cube's octant ``[0, 1]^3`` onto the unit ball's::

        x_i = q_i sqrt(1 - q_j^2 / 2 - q_k^2 / 2 + q_j^2 q_k^2 / 3)

    (``j, k`` the other two axes): the planes ``q_i = 0`` onto themselves, the faces
    ``q_i = 1`` onto the sphere; smooth inside (no crease where thin graded cells
    could fold), its Jacobian singular only on the cube's outer edges."""
    s2 = q * q
    out = np.empty_like(q)
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        out[i] = q[i] * np.sqrt(1.0 - 0.5 * (s2[j] + s2[k]) + s2[j] * s2[k] / 3.0)
    return out


def graded_axis(h: float, fine: float, growth: float = GROWTH) -> np.ndarray:
    """Grid points on ``[0, 1]`` from 0: ``ceil(fine / h)`` equal cells of size at most
    ``h`` up to ``fine``, then each cell ``growth`` times the one before, the last one
    ending at 1 (merged into the one before when it would be under half of it)."""
    if not (h > 0.0 and growth > 1.0):
        raise ValueError(f"h must be > 0 and growth > 1, got {h!r}, {growth!r}")
    fine = min(max(float(fine), h), 1.0)
    k = int(np.ceil(fine / h - 1e-9))
    near = np.linspace(0.0, fine, k + 1)
    if fine == 1.0:
        return near
    c = fine / k                            # cells c g, c g^2, ... until they reach 1
    n = int(np.ceil(np.log1p((1.0 - fine) * (growth - 1.0) / (c * growth)) / np.log(growth)))
    far = fine + np.cumsum(c * growth ** np.arange(1, n + 2))
    far = far[:int(np.searchsorted(far, 1.0)) + 1]
    far[-1] = 1.0
    before = np.concatenate([[fine], far])
    if far.size > 1 and far[-1] - far[-2] < 0.5 * (before[-2] - before[-3]):
        far = np.delete(far, -2)
    return np.concatenate([near, far])


def _structured(P: np.ndarray, index: np.ndarray, element: str):
    """The mesh of ``element`` (``tet1`` or ``hex1``) on the structured grid of nodes
    ``P`` numbered ``index``: hexahedra, or each split into six Kuhn tetrahedra, every
    other layer along the third axis mirrored (:func:`~._meshes3d._cells`), all
    positively oriented."""
    if element == "hex1":
        H = _cells(index, False)
        flip = MeshHex1(P, H)._mapping().detDF(np.full((3, 1), 0.5))[:, 0] < 0.0
        H[:, flip] = H[_SWAP01][:, flip]
        return MeshHex1(np.ascontiguousarray(P), np.ascontiguousarray(H))
    if element != "tet1":
        raise ValueError(f"element must be tet1 or hex1, got {element!r}")
    return MeshTet1(np.ascontiguousarray(P), _orient(P, _cells(index, True, reflect=2)))


def octant_planes(R: float) -> tuple[list, tuple]:
    """The planes and names of :func:`graded_octant`'s flat boundaries."""
    return [(0, 0.0), (1, 0.0), (2, R)], ("x0", "y0", "top")


def octant_axes(R: float, h0: float, fine: float) -> tuple[np.ndarray, np.ndarray]:
    """The grid of :func:`graded_octant` in the cube: the in-plane axis (``q_1``, ``q_2``:
    the map shrinks them by ``sqrt 2`` at the contact point, so they are graded from
    ``sqrt(2) h0 / R``) and the depth ``1 - q_3`` (from ``h0 / R``)."""
    r2 = np.sqrt(2.0)
    return graded_axis(r2 * h0 / R, r2 * fine / R), graded_axis(h0 / R, fine / R)


def graded_octant(R: float, h0: float, fine: float, element: str = "tet1"):
    """The quarter of the hemisphere ``|X - C| <= R``, ``Z <= R``, ``X, Y >= 0``
    (``C = (0, 0, R)``: it touches ``Z = 0`` at the origin): a structured grid of the
    cube ``[0, 1]^3`` graded towards its corner ``(0, 0, 1)`` (:func:`octant_axes`:
    cells of edge ``h0`` within ``fine`` of the contact point, growing by
    :data:`GROWTH` a cell beyond), mapped by :func:`_smooth_ball` onto the ball
    (``X = C + R (x_1, x_2, -x_3)``); hexahedra or Kuhn tetrahedra
    (:func:`_structured`).  Boundaries ``x0`` (``X = 0``), ``y0``, ``top``
    (``Z = R``), ``sphere``."""
    plane, depth = octant_axes(R, h0, fine)
    q = np.array([g.ravel() for g in np.meshgrid(plane, plane, 1.0 - depth, indexing="ij")])
    x = _smooth_ball(q)
    P = np.vstack([R * x[0], R * x[1], R - R * x[2]])
    index = np.arange(P.shape[1]).reshape(plane.size, plane.size, depth.size)
    planes, names = octant_planes(R)
    return tagged(_structured(P, index, element), planes, names, "sphere", 1e-9 * R)


def cylinder_planes(W: float) -> tuple[list, tuple]:
    """The planes and names of :func:`graded_quarter_cylinder`'s flat boundaries."""
    return [(0, 0.0), (1, 0.0), (2, 0.0), (2, -W)], ("x0", "y0", "top", "bottom")


def graded_quarter_cylinder(W: float, h0: float, fine: float, element: str = "tet1"):
    """The quarter cylinder ``X, Y >= 0``, ``X^2 + Y^2 <= W^2``, ``-W <= Z <= 0``: the
    cube's grid graded towards the origin as :func:`graded_octant`'s (:func:`graded_axis`
    from ``h0 / W`` in all three axes), ``(X, Y)`` by the 2D form of
    :func:`_smooth_ball` (``x = u sqrt(1 - v^2 / 2)``), ``Z = -W w``; boundaries
    ``x0``, ``y0``, ``top`` (``Z = 0``), ``bottom`` (``Z = -W``), ``side``."""
    ax = graded_axis(h0 / W, fine / W)
    u, v, w = (g.ravel() for g in np.meshgrid(ax, ax, ax, indexing="ij"))
    P = W * np.vstack([u * np.sqrt(1.0 - 0.5 * v * v), v * np.sqrt(1.0 - 0.5 * u * u), -w])
    index = np.arange(P.shape[1]).reshape(ax.size, ax.size, ax.size)
    planes, names = cylinder_planes(W)
    return tagged(_structured(P, index, element), planes, names, "side", 1e-9 * W)


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


#: the corner permutation that swaps a hexahedron's local axes 0 and 1 (reverses it)
_SWAP01 = [0, 2, 1, 3, 4, 6, 5, 7]


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
    and the closest-point search work face by face): :func:`plane_on_lines` on equally
    spaced lines."""
    lines = [np.linspace(lo, hi, max(1, int(np.ceil((hi - lo) / h))) + 1)
             for lo, hi in (x_range, y_range)]
    return plane_on_lines(lines[0], lines[1], level)


def plane_on_lines(xs: np.ndarray, ys: np.ndarray, level: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """A rigid plane ``Z = level`` on the grid lines ``xs x ys`` (increasing) as quad4
    faces: nodes ``(3, n)`` and faces ``(n_faces, 4)``, each counter-clockwise seen
    from ``+z`` (outward normal ``+z``: a body rests on it)."""
    xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    X = np.vstack([gx.ravel(), gy.ravel(), np.full(gx.size, float(level))])
    k = np.arange(xs.size * ys.size).reshape(xs.size, ys.size)
    faces = np.column_stack([k[:-1, :-1].ravel(), k[1:, :-1].ravel(), k[1:, 1:].ravel(),
                             k[:-1, 1:].ravel()])
    return X, faces
