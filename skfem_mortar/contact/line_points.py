"""Integration points of 2D (line) segmentations for the one mortar kernel.

The 2D side of the contract of :mod:`~skfem_mortar.contact.integration_points`, for any
line cell of the table (line2, line3, a registered piecewise cell): the integration
cells are those of the registered segmentation
(:func:`~skfem_mortar.contact.segmentation.segmentation_for`, values), and their points
are made in jets of the local variables:

* the end points ``xi_a, xi_b``: a slave vertex keeps its parameter (a constant); an end
  made by master node ``c`` (``src`` of the segmentation: the master cell's local node,
  for line2 and line3 its vertex 0 or 1) is its projection onto the slave cell along the normal
  field, the root of ``f(xi) = (x_s(xi) - x_c) x n~(xi)`` (a frozen segmentation,
  policy ``step``: every end point is held, a constant);
* ``xi_s = (1 - eta)/2 xi_a + (1 + eta)/2 xi_b`` at the Gauss points ``eta_k``, with
  ``w = w_k (xi_b - xi_a)/2``;
* ``xi_m``: the root of ``f(eta) = (x_m(eta) - x_s(xi_s)) x n~(xi_s)`` on the master cell.

Each root is found by Newton in values from the segmentation's value, then one Newton
step in jet arithmetic from it, which gives the exact gradient, and the curvature term
of the implicit function theorem in values, which completes the exact Hessian
(:func:`_solve`).

Fast path, on affine cells (:func:`affine`, by the cell's order and corners, not by
columns): the slave end points by the closed form of the quadratic ``f`` (one jet step
and the implicit-function term, :func:`~skfem_mortar.contact.mortar_segmentation.
project_on_slave`), ``xi_m`` in closed form on an affine master,
``s = ((x_m1 - x_s) x n~) / (n~ x (x_m2 - x_m1))``, ``eta = 2 s - 1``; the same points
as the general path (tested to 1e-13).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .cells import CellType, line_quadrature
from .integration_points import IntegrationCells, IntegrationPoints, LocalVariables
from .jets import Jet
from .mortar_cells import shape_jets
from . import mortar_quadratic_segmentation  # noqa: F401 (registers the lines' default segmentation)
from .mortar_segmentation import project_on_slave, slave_element
from .segmentation import segmentation_for

__all__ = ["LineSegmentation", "NEWTON_STEPS", "affine"]

NEWTON_STEPS = 12
"""Newton steps in values (quadratic convergence from the segmentation's value)."""


def affine(cell: CellType) -> bool:
    """Whether ``cell`` is an affine line (:attr:`~.cells.CellType.affine`, dim 1: line2),
    the cells the closed forms take (a piecewise cell such as line2x2 is order 1 and not
    affine)."""
    return cell.dim == 1 and cell.affine


def _point(cell: CellType, xi, nodes: list, tangent: int = True):
    """``x(xi)`` and ``dx/dxi`` on a line cell (``xi`` a jet or an array; ``nodes[a][i]``;
    ``tangent`` False: ``x`` alone, for jets; 2: and ``d2x/dxi2``, for values)."""
    if isinstance(xi, Jet):
        N, dN = shape_jets(cell, (xi,), derivatives=True) if tangent else (
            shape_jets(cell, (xi,)), None)
        x = _interpolate(N, nodes)
        if not tangent:
            return x
        dN = [r[0] for r in dN]
        t = [sum((dN[a] * nodes[a][i] for a in range(1, len(N))), dN[0] * nodes[0][i])
             for i in range(2)]
        return x, t
    X = xi[None]
    N, dN, d2N = cell.shape(X), cell.dshape(X)[:, 0], cell.d2shape(X)[:, 0, 0]
    x = [sum(N[a] * nodes[a][i] for a in range(len(N))) for i in range(2)]
    t = [sum(dN[a] * nodes[a][i] for a in range(len(N))) for i in range(2)]
    if tangent == 2:                           # values: and d2x/dxi2
        return x, t, [sum(d2N[a] * nodes[a][i] for a in range(len(N))) for i in range(2)]
    return x, t


def _interpolate(N: list, nodes: list) -> list:
    """``sum_a N_a nodes[a][i]`` for ``i`` = 0, 1 (jets of the shape functions ``N``)."""
    return [sum((N[a] * nodes[a][i] for a in range(1, len(N))), N[0] * nodes[0][i])
            for i in range(2)]


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _solve(residual, x0: np.ndarray, like: Jet | None):
    """Root of ``residual(x) -> (f, f')`` (and, in values with ``second``, ``f''``):
    Newton in values from ``x0``; then (with a jet ``like`` giving the variables) one
    Newton step in jets from the root ``x0`` (a constant), ``x1 = x0 - f/f'``, which has
    the exact gradient ``-f_p/f_x`` and of the exact Hessian all but the curvature term
    (implicit function theorem)::

        x_pp = -(f_pp + f_xp x_p^T + x_p f_xp^T + f_xx x_p x_p^T) / f_x,

    added from ``f''`` in values: ``x_pp += -(f_xx/f_x) x_p x_p^T``."""
    x = np.array(x0, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(NEWTON_STEPS):
            f, df = residual(x)
            step = np.where(df != 0.0, f / np.where(df != 0.0, df, 1.0), 0.0)
            x = x - step
            if not np.any(np.abs(step) > 1e-15 * (1.0 + np.abs(x))):   # converged (or NaN)
                break
    if like is None:
        return x
    xj = Jet.constant(x, like.g.shape[0], like.h is not None)
    f, df = residual(xj)
    xj = xj - f * df.inv()
    if xj.h is not None:
        _, dfv, d2f = residual(x, second=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            corr = np.where(dfv != 0.0, -d2f / np.where(dfv != 0.0, dfv, 1.0), 0.0)
        xj = Jet(xj.v, xj.g, xj.h + xj.g[:, None] * (xj.g * corr)[None])
    return xj


class _Rows(NamedTuple):
    """The rows of a segmentation that a chunk of integration cells reads."""

    xi: np.ndarray
    src: np.ndarray
    xi_m: np.ndarray | None
    frozen: bool
    n: int

    @staticmethod
    def of(sg, rows: np.ndarray) -> "_Rows":
        """Rows ``rows`` of the segmentation ``sg``."""
        return _Rows(sg.xi[rows], sg.src[rows], None if sg.xi_m is None else sg.xi_m[rows],
                     sg.frozen, len(rows))


def _values(nodes: list, shape) -> list:
    return [[np.broadcast_to(c.v.reshape(c.v.shape + (1,) * (len(shape) - 1)), shape)
             for c in node] for node in nodes]


def _pick(jets: list, src: np.ndarray, shape: tuple) -> Jet:
    """``jets[src]`` entry by entry (jets of values ``(n,)``, ``src (n, m)``; -1: the first),
    values ``shape`` ``(n, m)``."""
    out = _spread_one(jets[0], shape)
    for c in range(1, len(jets)):
        out = Jet.where(src == c, _spread_one(jets[c], shape), out)
    return out


def _column(j: Jet, e: int) -> Jet:
    """Column ``e`` of a jet of values ``(n, m)``: values ``(n,)``, contiguous."""
    c = np.ascontiguousarray
    h = None if j.h is None else Jet.constant(j.v[:, e], j.h.shape[0], True).h if \
        j.h.strides[0] == 0 and not np.any(j.h) else c(j.h[..., e])
    return Jet(c(j.v[:, e]), c(j.g[:, :, e]), h)


def _placed(held: Jet, on: np.ndarray, root: Jet) -> list:
    """The ends ``xi_a, xi_b`` (jets of values ``(n,)``): ``held`` (a constant of values
    ``(n, 2)``) with the entries ``on`` replaced by ``root`` (values ``(n_on,)``)."""
    v = held.v.copy()
    v[on] = root.v
    g = np.zeros(root.g.shape[:1] + on.shape)
    g[:, on] = root.g
    h = None
    if root.h is not None:
        h = np.zeros(root.h.shape[:2] + on.shape)
        h[:, :, on] = root.h
    xi = Jet(v, g, h)
    return [_column(xi, 0), _column(xi, 1)]


def _spread(nodes: list, shape: tuple) -> list:
    """``Jet.spread`` of each local variable; an independent variable stays one (its
    gradient ``e_i`` a broadcast view, not a copy: products never read it)."""
    return [[_spread_one(c, shape) for c in node] for node in nodes]


def _spread_one(c: Jet, shape: tuple) -> Jet:
    if c.var is None:
        return c.spread(shape)
    v = np.ascontiguousarray(np.broadcast_to(c.v.reshape(c.v.shape + (1,) * (len(shape) - 1)),
                                             shape))
    return Jet.variable(v, c.var, c.g.shape[0], c.h is not None)


class LineSegmentation:
    """The line segmentation's side of the contract (module docstring).

    Parameters
    ----------
    cells : (CellType, CellType)
        Slave and master line cells.
    n_gauss : int
        Gauss points per integration cell.
    fast : bool
        Use the closed forms on affine cells (module docstring); False: Newton everywhere
        (the general path, what the fast one is tested against).
    n_mass : int, optional
        Gauss points per integration cell of a second rule for the slave-only mass
        integrals of a dual space (``IntegrationPoints.mass``); None: none.
    options : dict
        Passed to the registered segmentation (``pairs``, ``margin``, ``mirror``, ...).
    """

    def __init__(self, cells: tuple[CellType, CellType], n_gauss: int = 2, fast: bool = True,
                 n_mass: int | None = None, **options):
        if cells[0].dim != 1 or cells[1].dim != 1:
            raise ValueError(f"cells must be line cells (dim 1), got {cells[0].name}, "
                             f"{cells[1].name}")
        if isinstance(n_gauss, bool) or not isinstance(n_gauss, (int, np.integer)) or n_gauss < 1:
            raise ValueError(f"n_gauss must be an integer >= 1, got {n_gauss!r}")
        self.cells, self.n_gauss, self.options = cells, int(n_gauss), options
        self.n_mass = n_mass
        #: the closed forms of affine cells (:func:`affine`) on each side
        self.fast = tuple(bool(fast) and affine(c) for c in cells)

    def integration_cells(self, xs: np.ndarray, conn_s: np.ndarray, xm: np.ndarray,
                          conn_m: np.ndarray, normals: np.ndarray | None = None
                          ) -> IntegrationCells:
        """The registered segmentation's integration cells (``normals`` unused: the 2D
        segmentations make their own); ``data``: ``(segmentation, rows)``, a chunk of
        rows ``r`` is ``IntegrationCells(e_s[r], e_m[r], (segmentation, rows[r]))``."""
        sg = segmentation_for(self.cells)(xs, conn_s, xm, conn_m, self.cells, **self.options)
        return IntegrationCells(sg.e_s, sg.e_m, (sg, np.arange(sg.n)))

    def whole_cells(self, cells: IntegrationCells) -> np.ndarray | None:
        """Per integration cell: whether its slave cell is covered whole by its integration
        cells with both ends slave vertices (``elem_node`` -1, the cell's lengths in ``xi``
        summing to 2 to 1e-12: no gap, no overlap), on an affine slave cell: then its mass
        integrals ``int N_A``, ``int N_A N_B`` over the cell are the reference cell's times
        a constant Jacobian, so a dual basis ``A_e = D_e M_e^-1`` is the reference one,
        constant (no variable moves it); None: not an affine slave cell."""
        if not self.fast[0]:
            return None
        sg, rows = cells.data
        n_cells = sg.elem_node.shape[0]
        length = np.bincount(sg.e_s, weights=sg.xi[:, 1] - sg.xi[:, 0], minlength=n_cells)
        whole = (sg.elem_node < 0).all(axis=1) & (np.abs(length - 2.0) <= 1e-12)
        return whole[cells.e_s]

    def _ends(self, sg, local: LocalVariables) -> list:
        """``xi_a, xi_b`` as jets (module docstring): both ends of every cell in one
        projection (values ``(n, 2)``), each onto the master node its ``src`` names."""
        cm = self.cells[1]
        like = local.x_s[0][0]
        held = Jet.constant(sg.xi, like.g.shape[0], like.h is not None)
        on = sg.src >= 0
        if sg.frozen or not on.any():
            return [_column(held, 0), _column(held, 1)]
        if self.fast[0]:        # closed form: only the ends a master node makes
            return _placed(held, on, self._projected(sg, local, on))
        shape = sg.xi.shape
        xc = [_pick([local.x_m[c][i] for c in range(cm.n_nodes)], sg.src, shape)
              for i in range(2)]
        xs, ns = _spread(local.x_s, shape), _spread(local.n_s, shape)
        root = _solve(self._slave_residual(xs, ns, xc), sg.xi, like)
        xi = Jet.where(on, root, held)
        return [_column(xi, 0), _column(xi, 1)]

    def _projected(self, sg, local: LocalVariables, on: np.ndarray) -> Jet:
        """The closed-form projections (affine slave) of the ends ``on (n, 2)`` makes (a
        master node's), values ``(n_on,)`` in the order of ``on``'s entries; an entry's
        arithmetic is that of the whole ``(n, 2)`` projection (elementwise)."""
        rows = np.flatnonzero(on) // 2
        src = sg.src[on]
        xc = [_pick([local.x_m[c][i].take(rows) for c in range(self.cells[1].n_nodes)],
                    src, src.shape) for i in range(2)]
        xs = [[c.take(rows) for c in node] for node in local.x_s]
        ns = [[c.take(rows) for c in node] for node in local.n_s]
        return project_on_slave(slave_element(*xs, *ns), xc)[0]

    def _slave_residual(self, xs: list, ns: list, xc: list):
        """``f(xi) = (x_s(xi) - x_c) x n~(xi)`` and ``f'`` (jets of one shape, ``x_c`` the
        master node of each end)."""
        cs = self.cells[0]
        values = ([[c.v for c in node] for node in xs], [[c.v for c in node] for node in ns],
                  [c.v for c in xc])

        def residual(x, second=False):
            X, Nn, C = (xs, ns, xc) if isinstance(x, Jet) else values
            if second:             # values: f'' = x'' x n + 2 x' x n' + r x n''
                p, t, tt = _point(cs, x, X, 2)
                nn, dn, dd = _point(cs, x, Nn, 2)
                r = [p[0] - C[0], p[1] - C[1]]
                return (_cross(r, nn), _cross(t, nn) + _cross(r, dn),
                        _cross(tt, nn) + 2.0 * _cross(t, dn) + _cross(r, dd))
            p, t = _point(cs, x, X)
            nn, dn = _point(cs, x, Nn)
            r = [p[0] - C[0], p[1] - C[1]]
            return _cross(r, nn), _cross(t, nn) + _cross(r, dn)
        return residual

    def integration_points(self, cells: IntegrationCells, local: LocalVariables
                           ) -> IntegrationPoints:
        """Gauss points in jets of ``local`` (module docstring)."""
        sg = _Rows.of(*cells.data)
        cs, cm = self.cells
        lo, hi = self._ends(sg, local)
        eta, wk = line_quadrature(2 * self.n_gauss - 1)
        eta = eta[0]
        a, b = (1.0 - eta) * 0.5, (1.0 + eta) * 0.5
        xi_s = lo.expand() * a + hi.expand() * b
        w = (hi.expand() - lo.expand()) * (wk * 0.5)
        mass = None
        if self.n_mass is not None:
            e5, w5 = line_quadrature(2 * self.n_mass - 1)
            mass = ((lo.expand() * ((1.0 - e5[0]) * 0.5) + hi.expand() * ((1.0 + e5[0]) * 0.5),),
                    (hi.expand() - lo.expand()) * (w5 * 0.5))
        shape = xi_s.v.shape
        xs, ns, xm = (_spread(L, shape) for L in (local.x_s, local.n_s, local.x_m))
        N = shape_jets(cs, (xi_s,))          # once for x_s and n~ at the points
        p, n = _interpolate(N, xs), _interpolate(N, ns)
        if self.fast[1]:     # x_s + alpha n~ = x_m1 + s (x_m2 - x_m1), eta = 2 s - 1
            dm = [xm[1][i] - xm[0][i] for i in range(2)]
            r = [xm[0][i] - p[i] for i in range(2)]
            eta_m = _cross(r, n) * _cross(n, dm).inv() * 2.0 - 1.0
            return IntegrationPoints(cells.e_s, cells.e_m, (xi_s,), (eta_m,), w, mass, (p, n))
        guess = self._master_guess(sg, a, b)
        values = ([c.v for c in p], [c.v for c in n], _values(local.x_m, guess.shape))

        def residual(x, second=False):
            jets = isinstance(x, Jet)
            P, Nn, Xm = (p, n, xm) if jets else values
            if second:             # values: f'' = x_m'' x n
                q, t, tt = _point(cm, x, Xm, 2)
                return _cross([q[0] - P[0], q[1] - P[1]], Nn), _cross(t, Nn), _cross(tt, Nn)
            q, t = _point(cm, x, Xm)
            r = [q[0] - P[0], q[1] - P[1]]
            return _cross(r, Nn), _cross(t, Nn)
        eta_m = _solve(residual, guess, w)
        return IntegrationPoints(cells.e_s, cells.e_m, (xi_s,), (eta_m,), w, mass, (p, n))

    @staticmethod
    def _master_guess(sg, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        if sg.xi_m is None:
            return np.zeros((sg.n, a.size))
        return sg.xi_m[:, :1] * a + sg.xi_m[:, 1:] * b
