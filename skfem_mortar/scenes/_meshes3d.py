"""Meshes of the 3D scenes: a box of tetrahedra or hexahedra with random interior
moves, and an eighth of a thick spherical shell whose quadratic nodes lie on the spheres.

Element names (the solids' names, :data:`MESH_OF`): ``tet1``/``tet2`` and
``hex1``/``hex2`` get linear/quadratic meshes of their cells; the mixed and
mean-dilatation elements get the mesh of their displacement field's cells.

The shell ``a <= |x| <= b``, ``x, y, z >= 0`` is three mapped hexahedral patches
(a cube-sphere map): the points ``q`` of the region between the cube surfaces
``max(q) = 1`` and ``max(q) = 2`` in the positive octant go to

    x(q) = (a + (b - a) (m - 1)) d / |d| ,   m = max(q),   d_i = tan(pi q_i / (4 m)) ,

which sends the inner cube face to the inner sphere, the outer one to the outer
sphere and each coordinate plane ``q_i = 0`` to the plane ``x_i = 0``; each of
the cube's three faces ``q_i = m`` is a patch whose grid spacing is
equiangular on the sphere.  The mesh is built in ``q`` (hexahedra, or each
hexahedron split into six tetrahedra about the diagonal from its lowest to its
highest corner, a split that matches across every face whatever the patch),
made quadratic there by scikit-fem, and then every node (vertices, mid-edge,
mid-face and centre nodes) is mapped by ``x(q)``: the quadratic nodes on the
inner and outer faces lie on the spheres up to round-off, those on the
symmetry planes on the planes.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from skfem import MeshHex1, MeshHex2, MeshTet1, MeshTet2

__all__ = ["MESH_OF", "box_mesh", "shell_octant", "shell_dofs", "box_dofs", "mesh_kind",
           "SHELL_TAGS"]

#: element name -> (linear mesh class, quadratic mesh class or None)
MESH_OF: dict[str, tuple[type, type | None]] = {
    "tet1": (MeshTet1, None), "tet2": (MeshTet1, MeshTet2),
    "hex1": (MeshHex1, None), "hex2": (MeshHex1, MeshHex2),
    "hex1-md": (MeshHex1, None), "p2p1": (MeshTet1, MeshTet2),
}

#: the shell's boundary tags: inner and outer sphere, the symmetry planes x = 0, y = 0, z = 0
SHELL_TAGS = ("inner", "outer", "x0", "y0", "z0")

#: the hexahedron's corners in scikit-fem's order (``MeshHex1.init_tensor``): offsets
#: along the (first, second, third) grid axis; with a right-handed triple of axes the
#: cells have scikit-fem's orientation (a negative Jacobian determinant, as its own)
_HEX_CORNERS = np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0], [0, 0, 1],
                         [1, 1, 0], [0, 1, 1], [1, 0, 1], [1, 1, 1]])

#: the six tetrahedra of a cube about its diagonal from (0, 0, 0) to (1, 1, 1): the
#: corners visited by the paths that raise one axis after the other (each face of
#: the cube is split by its diagonal from its lowest to its highest corner)
_KUHN = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]


def mesh_kind(element: str) -> tuple[type, type | None]:
    """The (linear, quadratic or None) mesh classes of ``element`` (ValueError listing
    the known names otherwise)."""
    if element not in MESH_OF:
        raise ValueError(f"element must be one of {', '.join(MESH_OF)}, got {element!r}")
    return MESH_OF[element]


def _kuhn_tets(corner: np.ndarray) -> np.ndarray:
    """Tetrahedra ``(4, 6 n)`` of the cells whose corners are ``corner[(i, j, k)]``
    (arrays of node indices, ``(2, 2, 2, n)``), positively oriented where the grid
    axes are right-handed."""
    tets = []
    for order in _KUHN:
        at, path = np.zeros(3, dtype=int), [corner[0, 0, 0]]
        for axis in order:
            at[axis] = 1
            path.append(corner[tuple(at)])
        # the path along (0, 1, 2) is right-handed; odd permutations swap two corners
        if order in ((0, 2, 1), (1, 0, 2), (2, 1, 0)):
            path[1], path[2] = path[2], path[1]
        tets.append(np.array(path))
    return np.hstack(tets)


def _cells(index: np.ndarray, simplices: bool, reflect: int | None = None) -> np.ndarray:
    """Hexahedra ``(8, n)`` or Kuhn tetrahedra ``(4, 6 n)`` of a structured block of
    nodes ``index`` (node numbers, ``(n1 + 1, n2 + 1, n3 + 1)``, right-handed axes).

    ``reflect`` (an axis): the cells of odd index along it are split as the mirror
    image of the Kuhn split (the diagonal from their highest to their lowest corner
    along that axis), so that every other layer is the mirror image of its
    neighbours (conforming: a layer's mirror image across a shared face splits that
    face alike).  Mirrored cells are negatively oriented: callers reorient."""
    n1, n2, n3 = (s - 1 for s in index.shape)
    corner = np.empty((2, 2, 2, n1 * n2 * n3), dtype=np.int64)
    for a in (0, 1):
        for b in (0, 1):
            for c in (0, 1):
                corner[a, b, c] = index[a:a + n1, b:b + n2, c:c + n3].ravel()
    if reflect is not None:
        layer = np.indices((n1, n2, n3))[reflect].ravel()
        corner = np.where(layer % 2 == 1, np.flip(corner, axis=reflect), corner)
    if simplices:
        return _kuhn_tets(corner)
    return np.array([corner[tuple(o)] for o in _HEX_CORNERS])


def _finish(p: np.ndarray, t: np.ndarray, element: str) -> tuple:
    """The linear mesh of ``element``'s cells on ``(p, t)`` and its quadratic form
    (None for a linear element)."""
    linear, quadratic = mesh_kind(element)
    mesh = linear(p, t)
    return mesh, (None if quadratic is None else quadratic.from_mesh(mesh))


def _distorted(mesh, quad, distort: float, h: float, seed: int):
    """Interior nodes of the mesh (and of its quadratic form) moved at random, each by
    at most ``distort h`` (vertices) or ``distort h / 4`` (the quadratic nodes),
    uniformly in the ball."""
    rng = np.random.default_rng(seed)

    def moves(n: int, size: float) -> np.ndarray:
        v = rng.normal(size=(3, n))
        return v / np.linalg.norm(v, axis=0) * size * rng.random(n) ** (1.0 / 3.0)

    target = mesh if quad is None else quad
    p = target.doflocs.copy()
    nv = mesh.nvertices
    inner = np.setdiff1d(np.arange(nv), mesh.boundary_nodes())
    p[:, inner] += moves(inner.size, distort * h)
    if quad is not None:
        # the quadratic nodes follow their vertices, then move a little on their own
        fresh = type(quad).from_mesh(replace(mesh, doflocs=p[:, :nv]))
        p = fresh.doflocs.copy()
        on_boundary = np.unique(quad.dofs.get_facet_dofs(quad.boundary_facets()).all())
        extra = np.setdiff1d(np.arange(nv, p.shape[1]), on_boundary)
        p[:, extra] += moves(extra.size, 0.25 * distort * h)
    return replace(target, doflocs=p)


def box_mesh(element: str, n: tuple[int, int, int], lengths: tuple[float, float, float]
             = (1.0, 1.0, 1.0), distort: float = 0.0, seed: int = 0):
    """The box ``[0, L1] x [0, L2] x [0, L3]`` in ``n = (n1, n2, n3)`` cells a side
    (hexahedra, or each split into six tetrahedra), tagged by scikit-fem's names:
    ``left``/``right`` (``x = 0``/``L1``), ``bottom``/``top`` (y), ``front``/``back`` (z).

    ``distort`` moves every interior node at random, by at most ``distort h``
    (``h`` the smallest cell edge; the quadratic nodes by at most a quarter of that);
    below 0.15 no cell inverts (the tests check the Jacobians).
    """
    n = tuple(int(k) for k in n)
    axes = [np.linspace(0.0, float(L), k + 1) for L, k in zip(lengths, n)]
    grid = np.meshgrid(*axes, indexing="ij")
    p = np.array([g.ravel() for g in grid])
    index = np.arange(p.shape[1]).reshape(tuple(k + 1 for k in n))
    mesh, quad = _finish(p, _cells(index, mesh_kind(element)[0] is MeshTet1),
                         element)
    if distort > 0.0:
        h = min(float(L) / k for L, k in zip(lengths, n))
        out = _distorted(mesh, quad, distort, h, seed)
    else:
        out = mesh if quad is None else quad
    return out.with_defaults()


def box_dofs(element: str, n: tuple[int, int, int]) -> int:
    """Displacement dofs of :func:`box_mesh` (no mesh built): 3 per node; a quadratic
    mesh has the nodes of the twice finer grid (hexahedra: a node on every edge, face
    and cell; the six tetrahedra of a cell: on its edges, face diagonals and diagonal)."""
    n1, n2, n3 = (int(k) for k in n)
    if mesh_kind(element)[1] is not None:
        return 3 * (2 * n1 + 1) * (2 * n2 + 1) * (2 * n3 + 1)
    return 3 * (n1 + 1) * (n2 + 1) * (n3 + 1)


def _shell_q(n: int, n_radial: int, simplices: bool) -> tuple[np.ndarray, np.ndarray]:
    """Points ``q`` and cells of the three patches between the cube surfaces
    ``max q = 1`` and ``2``: ``n x n`` cells a patch, ``n_radial`` through the wall."""
    grid = np.stack(np.meshgrid(*(np.arange(n + 1),) * 3, indexing="ij")).reshape(3, -1)
    surface = grid[:, grid.max(axis=0) == n]             # integer points of the cube's faces
    number = -np.ones((n + 1,) * 3, dtype=np.int64)
    number[tuple(surface)] = np.arange(surface.shape[1])
    ns = surface.shape[1]
    levels = 1.0 + np.arange(n_radial + 1) / n_radial
    q = (surface[:, None, :] / n * levels[None, :, None]).reshape(3, -1)
    cells = []
    for d in range(3):
        s, t = (d + 1) % 3, (d + 2) % 3                   # (s, t, radial) right-handed
        ij = np.zeros((3, n + 1, n + 1), dtype=np.int64)
        ij[d] = n
        ij[s], ij[t] = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        on_face = number[tuple(ij)]                        # (n + 1, n + 1)
        index = on_face[:, :, None] + ns * np.arange(n_radial + 1)[None, None, :]
        cells.append(_cells(index, simplices))
    return q, np.hstack(cells)


def _sphere_map(q: np.ndarray, a: float, b: float) -> np.ndarray:
    """The cube-sphere map ``x(q)`` of the module docstring."""
    m = q.max(axis=0)
    d = np.tan(0.25 * np.pi * q / m)
    r = a + (b - a) * (m - 1.0)
    return r * d / np.linalg.norm(d, axis=0)


def shell_octant(element: str, a: float, b: float, n: int, n_radial: int | None = None):
    """An eighth of the thick spherical shell ``a <= |x| <= b`` (module docstring):
    ``n x n`` cells on each of the three patches of a sphere, ``n_radial`` (default
    ``n``) through the wall, tagged :data:`SHELL_TAGS`.

    Raises
    ------
    ValueError
        Unless ``0 < a < b`` and ``n, n_radial >= 1``.
    """
    n_radial = int(n if n_radial is None else n_radial)
    if not (math.isfinite(a) and math.isfinite(b) and 0.0 < a < b):
        raise ValueError(f"the radii must satisfy 0 < a < b, got a = {a!r}, b = {b!r}")
    if int(n) < 1 or n_radial < 1:
        raise ValueError(f"n and n_radial must be integers >= 1, got {n!r}, {n_radial!r}")
    q, t = _shell_q(int(n), n_radial, mesh_kind(element)[0] is MeshTet1)
    mesh_q, quad_q = _finish(q, t, element)
    target = mesh_q if quad_q is None else quad_q
    qall = target.doflocs
    mesh = replace(target, doflocs=_sphere_map(qall, float(a), float(b)))
    m = q.max(axis=0)
    on = {"inner": m == 1.0, "outer": m == 2.0,
          "x0": q[0] == 0.0, "y0": q[1] == 0.0, "z0": q[2] == 0.0}
    bf = mesh.boundary_facets()
    fv = mesh.facets[:, bf]
    return mesh.with_boundaries({tag: bf[np.all(mask[fv], axis=0)] for tag, mask in on.items()})


def shell_dofs(element: str, n: int, n_radial: int | None = None) -> int:
    """Displacement dofs of :func:`shell_octant` (no mesh built): ``3 (n_r + 1)
    (3 n^2 + 3 n + 1)`` on the vertices; a quadratic mesh has the nodes of the twice
    finer grid (as :func:`box_dofs`)."""
    n = int(n)
    nr = int(n if n_radial is None else n_radial)
    if mesh_kind(element)[1] is not None:   # the nodes of the twice finer grid
        return 3 * (2 * nr + 1) * (12 * n * n + 6 * n + 1)
    return 3 * (nr + 1) * (3 * n * n + 3 * n + 1)
