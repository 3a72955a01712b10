"""Facet cell types as data: the table every contact kernel reads its cells from.

A contact surface is nodes + connectivity + a :class:`CellType`; nothing infers the
cell type from the number of connectivity columns (in 3D three columns are a linear
triangle, in 2D a quadratic line).  A cell type is a row of this table: its shape
functions and their first and second derivatives on the reference cell, its corners
and edges, its reference nodes and a quadrature rule of any requested degree.  A new
cell type (tri6, quad8, a test's piecewise-linear ``line2x2``) is a new row, made with
:class:`CellType` and :func:`register_cell`, not a new code path.

Reference cells:

* lines (``dim`` 1): ``xi in [-1, 1]``, the coordinate the 2D kernels use;
* the triangle: the unit triangle ``(0, 0), (1, 0), (0, 1)`` (area 1/2);
* the quadrilateral: ``[-1, 1]^2`` (area 4).

Node orders, as the package uses them:

* ``line2``: (start, end), ``N_1 = (1 - xi)/2``, ``N_2 = (1 + xi)/2``;
* ``line3``: (start, end, mid), ``N_1 = xi (xi - 1)/2``, ``N_2 = xi (xi + 1)/2``,
  ``N_3 = 1 - xi^2`` (columns 0 and 1 are the two ends, as in
  :mod:`~skfem_mortar.core.chain`);
* ``tri3``: counter-clockwise, ``N = (1 - xi - eta, xi, eta)``;
* ``quad4``: counter-clockwise from ``(-1, -1)``,
  ``N_i = (1 + xi_i xi)(1 + eta_i eta)/4``.

Corners of a line cell are ``(start, end)``: what walks a chain reads the ends there.
Edges list the local nodes of each edge of the cell in order along it, running
counter-clockwise around a surface cell (``tri3``: ``(0, 1), (1, 2), (2, 0)``).  A line
cell is its own one edge: ``line2`` ``((0, 1),)``, ``line3`` ``((0, 2, 1),)`` (start,
mid, end).

Quadrature rules (``quadrature(degree) -> (points (dim, nq), weights (nq,))``, exact
for every polynomial of total degree at most ``degree``, on the quadrilateral of degree
at most ``degree`` in each variable): Gauss-Legendre on lines
(``n = ceil((degree + 1)/2)`` points, exact to ``2n - 1``), its tensor product on the
quadrilateral, and on the triangle the collapsed (Duffy) product of Gauss-Legendre and
Gauss-Jacobi(1, 0) rules (``n^2`` points, exact to ``2n - 1``, positive weights).  A
cell whose shape functions are only piecewise smooth supplies its own composite rule.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

__all__ = ["CellType", "CELLS", "register_cell", "cell_type", "gauss_points",
           "line_quadrature", "quad_quadrature", "tri_quadrature"]


@dataclass(frozen=True, eq=False)
class CellType:
    """One facet cell type: a row of the cell table.

    Attributes
    ----------
    name : str
        ``"line2"``, ``"line3"``, ``"tri3"``, ``"quad4"``, ...
    dim : int
        Reference dimension: 1 (curves, the contact surfaces of 2D bodies) or 2
        (surfaces, those of 3D bodies).
    n_nodes : int
        Nodes per cell (the connectivity's column count; it does not identify the type).
    corners : tuple of int
        Local indices of the corner nodes (``line3``: ``(0, 1)``).
    edges : tuple of tuple of int
        Local nodes of each edge, in order along it (see the module docstring).
    ref_nodes : ndarray (dim, n_nodes)
        Reference coordinates of the nodes.
    shape : callable
        ``shape(xi (dim, ...)) -> N (n_nodes, ...)``.
    dshape : callable
        ``dshape(xi (dim, ...)) -> dN/dxi (n_nodes, dim, ...)``.
    d2shape : callable
        ``d2shape(xi (dim, ...)) -> d2N/dxi2 (n_nodes, dim, dim, ...)``.
    quadrature : callable
        ``quadrature(degree) -> (points (dim, nq), weights (nq,))``, exact for
        polynomials of total degree at most ``degree`` on the reference cell.
    order : int
        Lagrange order: 1 for line2, tri3 and quad4 (bilinear), 2 for line3.  The
        shape functions have degree ``order`` in each reference variable, what a kernel
        adds to its integrand's degree when it picks a rule (the quadrilateral's tensor
        rule of degree ``p`` is exact to degree ``p`` in each variable).
    hull : callable or None
        ``hull(P (d, n_cell, n_nodes)) -> (d, n_cell, n_h)``: points whose convex hull
        holds the whole cell (the Bezier control points of a curved cell, e.g. line3's
        ``x_start, x_end, 2 x_mid - (x_start + x_end)/2``); None when the nodes' hull
        holds it (straight and bilinear cells).  The contact search boxes cells by it.
    vtk : str or None
        The meshio / VTK cell type with this node order (``"line"``, ``"line3"``,
        ``"triangle"``, ``"quad"``), or None: outputs then write the cell as the straight
        pieces of its edges (:func:`~skfem_mortar.contact.cell_map.output_cells`).
    """

    name: str
    dim: int
    n_nodes: int
    corners: tuple[int, ...]
    edges: tuple[tuple[int, ...], ...]
    ref_nodes: np.ndarray
    shape: Callable[[np.ndarray], np.ndarray]
    dshape: Callable[[np.ndarray], np.ndarray]
    d2shape: Callable[[np.ndarray], np.ndarray]
    quadrature: Callable[[int], tuple[np.ndarray, np.ndarray]]
    order: int = 1
    hull: Callable[[np.ndarray], np.ndarray] | None = None
    vtk: str | None = None

    @property
    def affine(self) -> bool:
        """Whether the cell's geometry is an affine map of its reference cell: order 1
        with ``dim + 1`` nodes (``line2``, ``tri3``; not the bilinear ``quad4`` nor a
        piecewise cell such as a registered ``line2x2``).  Straight lines pair with the
        closed-form segmentation and its search; the projections onto them have closed
        forms."""
        return self.order == 1 and self.n_nodes == self.dim + 1

    def __repr__(self) -> str:
        return f"CellType({self.name!r}, dim={self.dim}, n_nodes={self.n_nodes})"


# --- quadrature rules ---------------------------------------------------------------

def gauss_points(degree: int) -> int:
    """Points of the Gauss rule exact to ``degree``: ``max(1, ceil((degree + 1)/2))``."""
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 0:
        raise ValueError(f"degree must be an integer >= 0, got {degree!r}")
    return max(1, (int(degree) + 2) // 2)


def _frozen(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    for a in arrays:
        a.setflags(write=False)
    return arrays


@lru_cache(maxsize=None)
def line_quadrature(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre on ``[-1, 1]``: points (1, n), weights (n,), exact to ``2n - 1``
    with ``n = ceil((degree + 1)/2)`` (read-only arrays, computed once per degree)."""
    x, w = np.polynomial.legendre.leggauss(gauss_points(degree))
    return _frozen(x[None, :].copy(), w.copy())


@lru_cache(maxsize=None)
def quad_quadrature(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Tensor Gauss rule on ``[-1, 1]^2``, exact to ``degree`` in each variable (so for
    total degree ``degree``)."""
    x, w = np.polynomial.legendre.leggauss(gauss_points(degree))
    X, Y = np.meshgrid(x, x, indexing="ij")
    return _frozen(np.vstack([X.ravel(), Y.ravel()]), np.outer(w, w).ravel())


@lru_cache(maxsize=None)
def tri_quadrature(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Collapsed Gauss rule on the unit triangle, exact to total degree ``2n - 1``.

    ``y = (1 + v)/2``, ``x = (1 - y)(1 + u)/2``, ``dx dy = (1 - v)/8 du dv``: Gauss-Legendre
    in ``u`` and Gauss-Jacobi with weight ``(1 - v)`` in ``v``, ``n`` points each.
    """
    n = gauss_points(degree)
    u, wu = np.polynomial.legendre.leggauss(n)
    if n == 1:       # scipy's one-point answer to the bit, without importing scipy.special
        v, wv = np.array([-1.0 / 3.0]), np.array([2.0])     # (25 ms; cell registration asks)
    else:
        from scipy.special import roots_jacobi
        v, wv = roots_jacobi(n, 1.0, 0.0)
    U, V = np.meshgrid(u, v, indexing="ij")
    y = 0.5 * (1.0 + V)
    x = 0.5 * (1.0 - y) * (1.0 + U)
    return _frozen(np.vstack([x.ravel(), y.ravel()]), np.outer(wu, wv).ravel() / 8.0)


# --- the shape functions ------------------------------------------------------------

def _line2(xi):
    x = np.asarray(xi, dtype=float)[0]
    return np.stack([0.5 * (1.0 - x), 0.5 * (1.0 + x)])


def _line2_d(xi):
    x = np.asarray(xi, dtype=float)[0]
    h = np.full_like(x, 0.5)
    return np.stack([-h, h])[:, None]


def _zeros(n_nodes: int, dim: int):
    def d2(xi):
        x = np.asarray(xi, dtype=float)
        return np.zeros((n_nodes, dim, dim) + x.shape[1:])
    return d2


def _line3(xi):
    x = np.asarray(xi, dtype=float)[0]
    return np.stack([0.5 * x * (x - 1.0), 0.5 * x * (x + 1.0), 1.0 - x * x])


def _line3_d(xi):
    x = np.asarray(xi, dtype=float)[0]
    return np.stack([x - 0.5, x + 0.5, -2.0 * x])[:, None]


def _line3_d2(xi):
    x = np.asarray(xi, dtype=float)[0]
    one = np.ones_like(x)
    return np.stack([one, one, -2.0 * one])[:, None, None]


def _line3_hull(P):
    """line3's Bezier control points: the ends and ``2 x_mid - (x_start + x_end)/2``."""
    a, b = P[..., 0], P[..., 1]
    return np.stack([a, b, 2.0 * P[..., 2] - 0.5 * (a + b)], axis=-1)


def _tri3(xi):
    x, y = np.asarray(xi, dtype=float)[:2]
    return np.stack([1.0 - x - y, x, y])


def _tri3_d(xi):
    x = np.asarray(xi, dtype=float)[0]
    o, z = np.ones_like(x), np.zeros_like(x)
    return np.stack([np.stack([-o, -o]), np.stack([o, z]), np.stack([z, o])])


_Q4 = np.array([[-1.0, 1.0, 1.0, -1.0], [-1.0, -1.0, 1.0, 1.0]])


def _quad4(xi):
    x, y = np.asarray(xi, dtype=float)[:2]
    sx, sy = (_Q4[k].reshape((4,) + (1,) * x.ndim) for k in (0, 1))
    return 0.25 * (1.0 + sx * x) * (1.0 + sy * y)


def _quad4_d(xi):
    x, y = np.asarray(xi, dtype=float)[:2]
    sx, sy = (_Q4[k].reshape((4,) + (1,) * x.ndim) for k in (0, 1))
    return np.stack([0.25 * sx * (1.0 + sy * y), 0.25 * sy * (1.0 + sx * x)], axis=1)


def _quad4_d2(xi):
    x = np.asarray(xi, dtype=float)[0]
    c = 0.25 * _Q4[0] * _Q4[1]
    cross = c.reshape((4,) + (1,) * x.ndim) * np.ones_like(x)
    z = np.zeros_like(cross)
    return np.stack([np.stack([z, cross], axis=1), np.stack([cross, z], axis=1)], axis=1)


# --- the table ----------------------------------------------------------------------

#: the registered cell types by name
CELLS: dict[str, CellType] = {}


def _check_cell(cell: CellType) -> None:
    """ValueError naming the first inconsistency of ``cell``'s arrays."""
    if cell.dim not in (1, 2):
        raise ValueError(f"cell {cell.name!r}: dim must be 1 or 2, got {cell.dim!r}")
    if cell.n_nodes < cell.dim + 1:
        raise ValueError(f"cell {cell.name!r}: n_nodes must be at least dim + 1 = "
                         f"{cell.dim + 1}, got {cell.n_nodes!r}")
    ref = np.asarray(cell.ref_nodes, dtype=float)
    if ref.shape != (cell.dim, cell.n_nodes):
        raise ValueError(f"cell {cell.name!r}: ref_nodes must have shape (dim, n_nodes) = "
                         f"{(cell.dim, cell.n_nodes)}, got {ref.shape}")
    local = [k for k in cell.corners] + [k for e in cell.edges for k in e]
    if not local or any(not 0 <= int(k) < cell.n_nodes for k in local):
        raise ValueError(f"cell {cell.name!r}: corners and edges must be local node "
                         f"indices in [0, {cell.n_nodes - 1}]")
    if cell.dim == 1 and len(cell.corners) != 2:
        raise ValueError(f"cell {cell.name!r}: a line cell has two corners (start, end), "
                         f"got {cell.corners!r}")
    N = np.asarray(cell.shape(ref))
    if N.shape != (cell.n_nodes, cell.n_nodes) or not np.allclose(N, np.eye(cell.n_nodes),
                                                                      atol=1e-12):
        raise ValueError(f"cell {cell.name!r}: shape(ref_nodes) must be the identity "
                         f"(n_nodes, n_nodes): each shape function is 1 at its own node")
    dN, d2N = np.asarray(cell.dshape(ref)), np.asarray(cell.d2shape(ref))
    n, d = cell.n_nodes, cell.dim
    if dN.shape != (n, d, n) or d2N.shape != (n, d, d, n):
        raise ValueError(f"cell {cell.name!r}: dshape and d2shape must give (n_nodes, dim, "
                         f"n) and (n_nodes, dim, dim, n), got {dN.shape}, {d2N.shape}")
    pts, w = cell.quadrature(0)
    if np.ndim(pts) != 2 or np.shape(pts)[0] != d or np.shape(w) != (np.shape(pts)[1],):
        raise ValueError(f"cell {cell.name!r}: quadrature(degree) must give points "
                         f"(dim, nq) and weights (nq,)")


def register_cell(cell: CellType) -> None:
    """Add ``cell`` to :data:`CELLS`.

    Raises
    ------
    ValueError
        When ``cell`` is not a :class:`CellType`, its name is empty or already
        registered, or its arrays are inconsistent (reference nodes not of shape
        ``(dim, n_nodes)``, shape functions not the identity at the reference nodes,
        derivative or quadrature arrays of the wrong shape, local indices out of range).
    """
    if not isinstance(cell, CellType):
        raise ValueError(f"cell must be a CellType, got {type(cell).__name__}")
    if not isinstance(cell.name, str) or not cell.name:
        raise ValueError(f"cell name must be a non-empty string, got {cell.name!r}")
    if cell.name in CELLS:
        raise ValueError(f"cell {cell.name!r} is already registered (names: "
                         f"{sorted(CELLS)})")
    _check_cell(cell)
    CELLS[cell.name] = cell


def cell_type(name: "str | CellType") -> CellType:
    """The registered cell type ``name`` (a :class:`CellType` is returned as it is).

    Raises
    ------
    ValueError
        When ``name`` is not a registered name, naming the registered ones.
    """
    if isinstance(name, CellType):
        return name
    cell = CELLS.get(name) if isinstance(name, str) else None
    if cell is None:
        raise ValueError(f"cell must be one of the registered cell types {sorted(CELLS)}, "
                         f"got {name!r}")
    return cell


def _ref(*cols) -> np.ndarray:
    a = np.array(cols, dtype=float).T
    a.setflags(write=False)
    return a


for _cell in (
    CellType("line2", 1, 2, (0, 1), ((0, 1),), _ref([-1.0], [1.0]),
             _line2, _line2_d, _zeros(2, 1), line_quadrature, 1, None, "line"),
    CellType("line3", 1, 3, (0, 1), ((0, 2, 1),), _ref([-1.0], [1.0], [0.0]),
             _line3, _line3_d, _line3_d2, line_quadrature, 2, _line3_hull, "line3"),
    CellType("tri3", 2, 3, (0, 1, 2), ((0, 1), (1, 2), (2, 0)),
             _ref([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]),
             _tri3, _tri3_d, _zeros(3, 2), tri_quadrature, 1, None, "triangle"),
    CellType("quad4", 2, 4, (0, 1, 2, 3), ((0, 1), (1, 2), (2, 3), (3, 0)),
             _ref(*_Q4.T), _quad4, _quad4_d, _quad4_d2, quad_quadrature, 1, None, "quad"),
):
    register_cell(_cell)
del _cell
