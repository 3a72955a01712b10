"""Line cells read from the cell table: the curve of a 2D contact surface's cell, its
closest-point projection, arc length and tributary weights, for any registered line
cell type (:mod:`~skfem_mortar.contact.cells`; ``dim`` 1, the reference line
``xi in [-1, 1]`` with its corners at ``-1`` and ``+1``).

A line cell with nodes ``x_a`` is the curve

    x(xi) = sum_a N_a(xi) x_a,   x'(xi) = sum_a N_a'(xi) x_a,   x'' = sum_a N_a''(xi) x_a,

``N`` the cell's shape functions (``line3``: ``xi (xi - 1)/2, xi (xi + 1)/2,
1 - xi^2``; a test's piecewise-linear ``line2x2`` is a new row of the table, not a
new code path here).  The closest point of ``x_s`` solves ::

    f(xi) = (x_s - x(xi)) . x'(xi) = 0,   f'(xi) = (x_s - x(xi)) . x'' - |x'|^2,

by safeguarded Newton from the chord's projection (:func:`project_values`).  The
kernels take jets (:class:`~skfem_mortar.contact.jets.Jet`) of the closest-point
parameter from two Newton steps in jets (:func:`projection_jets`): with ``xi`` a jet,
``N_a(xi)`` and ``N_a'(xi)`` are composed from the table's values at ``xi.v``
(``N, N', N''`` and ``N', N'', N'''``), where ``N''' = 0``: the kernels accept the line
cells of degree at most 2 (:func:`check_line`; piecewise-linear cells too), for
which the composed jets are exact.

The chain of a surface runs through the cells' corners (``seg[:, corners]``, start
and end, :func:`ends`), whatever the other columns hold; :func:`polyline` follows
the cell's edge through every node.  An *affine* cell (degree 1, ``dim + 1`` nodes:
``line2``) has the closed forms the NTS kernels use where they are faster
(:func:`is_affine`, a declared property of the cell, never a column count).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .cells import CellType, cell_type
from .jets import Jet, at_gauss, sqrt, value

__all__ = ["is_affine", "check_line", "ends", "polyline", "chain_nodes", "shape_values",
           "curve", "newton_step", "project_values", "projection_jets", "arc_length",
           "cell_nodes", "tributary_weights", "N_NEWTON", "XI_LIMIT", "N_ARC",
           "N_TRIBUTARY", "VTK_LINES", "output_cells", "cell_lengths"]

#: Newton steps of the closest-point projection on values (quadratic convergence
#: from the chord's projection: 1e-15 in ~6 steps on a segment bent by 10 % of its length)
N_NEWTON = 30
#: the projection's ``xi`` stays in ``[-XI_LIMIT, XI_LIMIT]`` (the curve's extension
#: beyond the ends, far enough for any candidate that can win)
XI_LIMIT = 3.0
#: Gauss points of :func:`arc_length` (the slip of friction along curved segments)
N_ARC = 8
#: Gauss points of the tributary weights of a curved cell (that of
#: :data:`~skfem_mortar.core.chain.N_GAUSS_CURVE`: exact on a straight ``line3``)
N_TRIBUTARY = 5


#: the VTK cell of each line cell type VTK has one for (the others are written as
#: their chords, :func:`output_cells`)
VTK_LINES = {"line2": "line", "line3": "line3"}


def output_cells(seg: np.ndarray, cell: "str | CellType") -> list[tuple[str, np.ndarray]]:
    """The cells of a surface for the VTU writer: ``[(vtk_type, connectivity)]``, the
    cells themselves where VTK has their type (:data:`VTK_LINES`; ``line3`` (start,
    end, mid) is VTK's quadratic edge), else their chords through every node
    (:func:`polyline`, ``line``)."""
    cell = cell_type(cell)
    seg = np.asarray(seg, dtype=np.int64)
    vtk = VTK_LINES.get(cell.name)
    return [(vtk, seg)] if vtk is not None else [("line", polyline(seg, cell))]


def cell_lengths(x: np.ndarray, seg: np.ndarray, cell: "str | CellType") -> np.ndarray:
    """Length (n_seg,) of each cell: ``|x_end - x_start|`` of an affine cell, else
    ``int |x'| dxi`` by the cell's rule of :data:`N_TRIBUTARY` points."""
    cell = cell_type(cell)
    seg = np.asarray(seg, dtype=np.int64)
    if is_affine(cell):
        e = ends(seg, cell)
        return np.hypot(*(x[:, e[:, 1]] - x[:, e[:, 0]]))
    eta, w = cell.quadrature(2 * N_TRIBUTARY - 1)
    dN = shape_values(cell, eta[0])[1]
    t = np.einsum("dsk,kq->dsq", x[:, seg], dN)
    return np.hypot(t[0], t[1]) @ w


def is_affine(cell: "str | CellType") -> bool:
    """Whether ``cell``'s geometry is affine (its row's :attr:`~.cells.CellType.affine`:
    ``line2``, ``tri3``), the cells with closed-form projections."""
    return cell_type(cell).affine


def check_line(cell: "str | CellType", what: str) -> CellType:
    """``cell`` as a :class:`CellType`, a line cell of degree at most 2.

    Raises
    ------
    ValueError
        Naming ``what`` and the cell when it is not a line (``dim`` 1) or its degree
        is above 2 (the composed jets need ``N''' = 0``, module doc).
    """
    cell = cell_type(cell)
    if cell.dim != 1 or cell.order > 2:
        raise ValueError(f"{what}: cell must be a line cell (dim 1) of degree at most 2, "
                         f"got {cell.name!r} (dim {cell.dim}, order {cell.order})")
    return cell


def ends(seg: np.ndarray, cell: "str | CellType") -> np.ndarray:
    """The chain's (start, end) of each cell: ``seg[:, corners]``, (n_seg, 2)."""
    return np.asarray(seg, dtype=np.int64)[:, list(cell_type(cell).corners)]


def polyline(seg: np.ndarray, cell: "str | CellType") -> np.ndarray:
    """The chords through every node along each cell's edge, (n, 2), in chain order
    (``line2`` as it is; ``line3``: ``(start, mid), (mid, end)``)."""
    e = cell_type(cell).edges[0]
    seg = np.asarray(seg, dtype=np.int64)
    return np.stack([seg[:, [e[i], e[i + 1]]] for i in range(len(e) - 1)],
                    axis=1).reshape(-1, 2)


def chain_nodes(seg: np.ndarray, cell: "str | CellType", closed: bool) -> np.ndarray:
    """Every node of a chain of cells in chain order (with duplicates where the chain
    does not visit each node once): each cell's edge nodes but its last, then (open
    chain) the last cell's end."""
    e = cell_type(cell).edges[0]
    seg = np.asarray(seg, dtype=np.int64)
    first = seg[:, list(e[:-1])].ravel()
    return first if closed else np.r_[first, seg[-1, e[-1]]]


def shape_values(cell: CellType, xi: np.ndarray) -> tuple:
    """``N``, ``N'`` and ``N''`` of a line cell at ``xi`` (any shape S), each (n_nodes,) + S."""
    x = np.asarray(xi, dtype=float)[None]
    return cell.shape(x), cell.dshape(x)[:, 0], cell.d2shape(x)[:, 0, 0]


def _sum(P: tuple, N, c: int):
    """``sum_a P_a[c] N_a`` in node order (arrays or jets)."""
    acc = P[0][c] * N[0]
    for a in range(1, len(P)):
        acc = acc + P[a][c] * N[a]
    return acc


def curve(cell: CellType, P: tuple, xi) -> tuple:
    """``x(xi)``, ``x'(xi)`` and ``x''(xi)`` of cells with nodes ``P = (x_1, ..., x_n)``
    (each a pair of arrays or jets), at ``xi`` (array or jet), each a pair."""
    N, dN, d2N = shape_values(cell, value(xi))
    if isinstance(xi, Jet):                        # N''' = 0 (check_line)
        zero = np.zeros_like(xi.v)
        N = [xi._chain(N[a], dN[a], d2N[a]) for a in range(cell.n_nodes)]
        dN = [xi._chain(dN[a], d2N[a], zero) for a in range(cell.n_nodes)]
    return tuple(tuple(_sum(P, F, c) for c in (0, 1)) for F in (N, dN, d2N))


def newton_step(cell: CellType, xs: tuple, P: tuple, xi) -> tuple:
    """``xi - f / f'`` of the closest-point condition, ``f`` and ``f'`` (arrays or jets)."""
    x, t, tt = curve(cell, P, xi)
    rx, ry = xs[0] - x[0], xs[1] - x[1]
    f = rx * t[0] + ry * t[1]
    df = rx * tt[0] + ry * tt[1] - (t[0] * t[0] + t[1] * t[1])
    return xi - f / df, f, df


def cell_nodes(x: np.ndarray, seg: np.ndarray, cells: np.ndarray) -> tuple:
    """The nodes ``P`` of the cells ``cells`` of ``(x, seg)``: a pair of (m,) arrays each."""
    return tuple((x[0, seg[cells, a]], x[1, seg[cells, a]]) for a in range(seg.shape[1]))


def project_values(cell: CellType, xs: np.ndarray, P: tuple) -> tuple[np.ndarray, bool]:
    """Closest-point ``xi`` (n,) of the points ``xs (2, n)`` on the cells ``P``,
    by safeguarded Newton from the chord's projection (each step at most 0.5, ``xi``
    within ``[-XI_LIMIT, XI_LIMIT]``); and whether it converged."""
    c0, c1 = cell.corners
    (x1, y1), (x2, y2) = P[c0], P[c1]
    tx, ty = x2 - x1, y2 - y1
    xi = 2.0 * ((xs[0] - x1) * tx + (xs[1] - y1) * ty) / np.maximum(tx * tx + ty * ty, 1e-300) - 1.0
    xi = np.clip(xi, -XI_LIMIT, XI_LIMIT)
    done = False
    for _ in range(N_NEWTON):
        new, f, df = newton_step(cell, (xs[0], xs[1]), P, xi)
        # f' > 0 is a distance maximum (the node far inside the curve's bend): step
        # against f instead, towards the minimum along the curve
        step = np.where(df < 0, new - xi, -np.sign(f) * 0.5)
        step = np.clip(step, -0.5, 0.5)
        xi_new = np.clip(xi + step, -XI_LIMIT, XI_LIMIT)
        change = np.abs(xi_new - xi)
        xi = xi_new
        if np.all(change <= 1e-14 * (1.0 + np.abs(xi))):
            done = True
            break
    return xi, done


def projection_jets(cell: CellType, xs: np.ndarray, P: tuple, xi: np.ndarray, second: bool
                    ) -> tuple[tuple, tuple, Jet]:
    """The slave points, the cell nodes and the closest-point parameter as jets of the
    ``2 + 2 n_nodes`` local coordinates ``[x_s, x_1, ..., x_n]`` (x, y each): ``xi``
    (the converged value) refined by two Newton steps in jets, exact to second order
    (each step doubles the order of agreement).  Returns ``(js, JP, xi)``."""
    vals = [xs[0], xs[1]] + [c for p in P for c in p]
    nv = len(vals)
    var = [Jet.variable(v, i, nv, second) for i, v in enumerate(vals)]
    js = (var[0], var[1])
    JP = tuple((var[2 + 2 * a], var[3 + 2 * a]) for a in range(len(P)))
    z = Jet.constant(xi, nv, second)
    for _ in range(2):
        z, _, _ = newton_step(cell, js, JP, z)
    return js, JP, z


def arc_length(cell: CellType, P: tuple, a, b, n_gauss: int = N_ARC):
    """The arc length ``int_a^b |x'(xi)| dxi`` along cells (signed: negative for
    ``b < a``), by an ``n_gauss``-point Gauss rule on ``[a, b]``.

    ``P`` the nodes (pairs of arrays or jets, shape (n,)), ``a``, ``b`` the cell
    parameters (arrays or jets, (n,)); a jet when any input is one, with the exact
    derivatives of the rule.  ``|x'|`` is constant on a straight cell with evenly
    placed nodes (the rule is exact there, ``(b - a) L / 2``) and smooth otherwise on
    a smooth cell (8 points: 2e-14 relative against adaptive quadrature on a
    ``line3`` whose mid node sits 10 % of the chord off it; the rule defines the slip,
    its derivatives are those of the rule, so this is accuracy, not consistency).
    """
    eta, w = np.polynomial.legendre.leggauss(n_gauss)
    PE = tuple((at_gauss(p[0]), at_gauss(p[1])) for p in P)
    xi = at_gauss(a) * ((1.0 - eta) * 0.5) + at_gauss(b) * ((1.0 + eta) * 0.5)
    _, t, _ = curve(cell, PE, xi)
    speed = sqrt(t[0] * t[0] + t[1] * t[1]) * w
    return speed.sum(1) * ((b - a) * 0.5)


def tributary_weights(x: np.ndarray, seg: np.ndarray, cell: "str | CellType",
                      measure: Any = None) -> np.ndarray:
    """Tributary weight of each node, ``a_k = int N_k w dGamma`` over its cells.

    ``w`` is the weight of ``measure`` (:mod:`~skfem_mortar.contact.measures`; None or
    a unit measure: ``w = 1``, the tributary length).  Unit weight on affine cells:
    half the length of each cell at each of its two nodes; otherwise the cell's rule
    of :data:`N_TRIBUTARY` points (``cell.quadrature``, a composite one for a
    piecewise-smooth cell)::

        a_k = sum_e sum_q w_q N_k(eta_q) |x'(eta_q)| w(x(eta_q))

    (``line3``, ``w = 1``: ``L/6, L/6, 2L/3`` on a straight cell with a centred mid
    node; ``w = 2 pi r`` on a ``line2`` cell from the axis, ``r`` from 0 to ``h``:
    ``2 pi h^2 / 6`` at the axis node, exact: the rule integrates degree 9).
    """
    cell = cell_type(cell)
    seg = np.asarray(seg, dtype=np.int64)
    if measure is not None and not measure.unit:
        N, J, xq = _rule_points(x, seg, cell)
        wJ = J * measure.weight(xq) * cell.quadrature(2 * N_TRIBUTARY - 1)[1]
        return np.bincount(seg.ravel(), weights=(wJ @ N.T).ravel(), minlength=x.shape[1])
    if is_affine(cell):
        e = ends(seg, cell)
        l = np.hypot(*(x[:, e[:, 1]] - x[:, e[:, 0]]))
        return np.bincount(e.ravel(), weights=np.repeat(0.5 * l, 2), minlength=x.shape[1])
    eta, w = cell.quadrature(2 * N_TRIBUTARY - 1)
    N, dN, _ = shape_values(cell, eta[0])
    t = np.einsum("dsk,kq->dsq", x[:, seg], dN)      # (2, n_seg, q)
    J = np.hypot(t[0], t[1])
    return np.bincount(seg.ravel(), weights=((J * w) @ N.T).ravel(), minlength=x.shape[1])


def _rule_points(x: np.ndarray, seg: np.ndarray, cell: CellType) -> tuple:
    """At the cell's rule of :data:`N_TRIBUTARY` points: ``N`` (n_nodes, q), the
    speed ``|x'|`` (n_seg, q) and the points ``x(eta_q)``, a pair of (n_seg, q)."""
    eta, _ = cell.quadrature(2 * N_TRIBUTARY - 1)
    N, dN, _ = shape_values(cell, eta[0])
    t = np.einsum("dsk,kq->dsq", x[:, seg], dN)
    xq = np.einsum("dsk,kq->dsq", x[:, seg], N)
    return N, np.hypot(t[0], t[1]), (xq[0], xq[1])
