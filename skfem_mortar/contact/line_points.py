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

Each root is found by Newton in values from the segmentation's value, then two Newton
steps in jet arithmetic from it: the first gives the exact gradient, the second the
exact Hessian (the error of a Newton step is quadratic in the previous one).

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
from .mortar_segmentation import project_on_slave, slave_element
from .segmentation import segmentation_for

__all__ = ["LineSegmentation", "NEWTON_STEPS", "affine"]

NEWTON_STEPS = 12
"""Newton steps in values (quadratic convergence from the segmentation's value)."""


def affine(cell: CellType) -> bool:
    """Whether ``cell`` is an affine line (every node a corner, order 1: line2), the cells
    the closed forms take (a piecewise cell such as line2x2 is order 1 and not affine)."""
    return cell.dim == 1 and cell.order == 1 and len(cell.corners) == cell.n_nodes


def _point(cell: CellType, xi, nodes: list):
    """``x(xi)`` and ``dx/dxi`` on a line cell (``xi`` a jet or an array; ``nodes[a][i]``)."""
    if isinstance(xi, Jet):
        N, dN = shape_jets(cell, (xi,), derivatives=True)
        dN = [r[0] for r in dN]
        x = [sum((N[a] * nodes[a][i] for a in range(1, len(N))), N[0] * nodes[0][i])
             for i in range(2)]
        t = [sum((dN[a] * nodes[a][i] for a in range(1, len(N))), dN[0] * nodes[0][i])
             for i in range(2)]
        return x, t
    X = xi[None]
    N, dN = cell.shape(X), cell.dshape(X)[:, 0]
    x = [sum(N[a] * nodes[a][i] for a in range(len(N))) for i in range(2)]
    t = [sum(dN[a] * nodes[a][i] for a in range(len(N))) for i in range(2)]
    return x, t


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _solve(residual, x0: np.ndarray, like: Jet | None):
    """Root of ``residual(x) -> (f, f')``: Newton in values from ``x0``, then (with a
    jet ``like`` giving the variables) two Newton steps in jets from the value."""
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
    for _ in range(2):
        f, df = residual(xj)
        xj = xj - f * df.inv()
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


def _expand(nodes: list) -> list:
    return [[c.expand() for c in node] for node in nodes]


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

    def _ends(self, sg, local: LocalVariables) -> list:
        """``xi_a, xi_b`` as jets (module docstring)."""
        cs, cm = self.cells
        like = local.x_s[0][0]
        ends = []
        for e in range(2):
            xi = Jet.constant(sg.xi[:, e], like.g.shape[0], like.h is not None)
            for c in (() if sg.frozen else range(cm.n_nodes)):
                on = sg.src[:, e] == c
                if on.any() and self.fast[0]:
                    root, _ = project_on_slave(slave_element(*local.x_s, *local.n_s),
                                               local.x_m[c])
                    xi = Jet.where(on, root, xi)
                elif on.any():
                    root = _solve(self._slave_residual(local, c), sg.xi[:, e], like)
                    xi = Jet.where(on, root, xi)
            ends.append(xi)
        return ends

    def _slave_residual(self, local: LocalVariables, corner: int):
        """``f(xi) = (x_s(xi) - x_c) x n~(xi)`` and ``f'`` for the master node ``corner``."""
        cs = self.cells[0]
        n = local.x_s[0][0].v.shape
        values = (_values(local.x_s, n), _values(local.n_s, n), [j.v for j in local.x_m[corner]])

        def residual(x):
            jets = isinstance(x, Jet)
            xs, ns, xc = (local.x_s, local.n_s, local.x_m[corner]) if jets else values
            p, t = _point(cs, x, xs)
            nn, dn = _point(cs, x, ns)
            r = [p[0] - xc[0], p[1] - xc[1]]
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
        xs, ns, xm = _expand(local.x_s), _expand(local.n_s), _expand(local.x_m)
        p, _ = _point(cs, xi_s, xs)
        n, _ = _point(cs, xi_s, ns)
        if self.fast[1]:     # x_s + alpha n~ = x_m1 + s (x_m2 - x_m1), eta = 2 s - 1
            dm = [xm[1][i] - xm[0][i] for i in range(2)]
            r = [xm[0][i] - p[i] for i in range(2)]
            eta_m = _cross(r, n) * _cross(n, dm).inv() * 2.0 - 1.0
            return IntegrationPoints(cells.e_s, cells.e_m, (xi_s,), (eta_m,), w, mass)
        guess = self._master_guess(sg, a, b)
        values = ([c.v for c in p], [c.v for c in n], _values(local.x_m, guess.shape))

        def residual(x):
            jets = isinstance(x, Jet)
            P, Nn, Xm = (p, n, xm) if jets else values
            q, t = _point(cm, x, Xm)
            r = [q[0] - P[0], q[1] - P[1]]
            return _cross(r, Nn), _cross(t, Nn)
        eta_m = _solve(residual, guess, w)
        return IntegrationPoints(cells.e_s, cells.e_m, (xi_s,), (eta_m,), w, mass)

    @staticmethod
    def _master_guess(sg, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        if sg.xi_m is None:
            return np.zeros((sg.n, a.size))
        return sg.xi_m[:, :1] * a + sg.xi_m[:, 1:] * b
