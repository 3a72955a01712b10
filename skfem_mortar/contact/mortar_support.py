"""The slave nodes' mortar supports and tributary weights, read from the cell table.

Values only (no derivatives), for any line cell type: the shape functions and their
derivatives come from the cell's row (:attr:`~skfem_mortar.contact.cells.CellType.shape`,
:attr:`~skfem_mortar.contact.cells.CellType.dshape`), the whole-cell rule from its
:attr:`~skfem_mortar.contact.cells.CellType.quadrature` (a piecewise cell brings its
composite rule), so the linear and the curved mortar kernels share them.

* the tributary weight of slave node ``A``, over the whole slave surface, ::

      w_A = sum_e int_{-1}^{1} N_A(xi) |dx/dxi| dxi,   x(xi) = sum_B N_B(xi) x_B;

* its mortar support, over the integration cells ``[xi_a, xi_b]`` of a segmentation
  (:class:`~skfem_mortar.contact.segmentation.Segmentation`), ::

      s_A = sum_c int_{xi_a}^{xi_b} N_A(xi) |dx/dxi| dxi,

  by the ``n_gauss``-point Gauss rule mapped onto each integration cell (an
  integration cell lies in one smooth piece of its slave cell).  The kernels mask a
  node whose ``s_A`` is at most ``MASK_TOL`` times ``w_A``
  (:func:`skfem_mortar.contact.mortar.evaluate`, Notes).
"""
from __future__ import annotations

import numpy as np

from .cells import CellType, line_quadrature
from .measures import PLANE, Measure
from .segmentation import Segmentation

__all__ = ["cell_jacobian", "tributary_weights", "multiplier_support"]


def cell_jacobian(cell: CellType, X: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """``|dx/dxi| = |sum_B dN_B/dxi x_B|`` at ``xi`` (n, nq) of line cells with node
    positions ``X`` (2, n, n_nodes), (n, nq); on surface cells ``xi`` (2, n, nq) and
    ``X`` (3, n, n_nodes): ``|T_1 x T_2|``, ``T_r = sum_B dN_B/dxi_r x_B``."""
    if cell.dim == 1:
        dN = np.asarray(cell.dshape(xi[None]))[:, 0]              # (n_nodes, n, nq)
        t = np.einsum("ink,knq->inq", X, dN)
        return np.sqrt(t[0] * t[0] + t[1] * t[1])
    dN = np.asarray(cell.dshape(xi))                              # (n_nodes, 2, n, nq)
    T = np.einsum("ink,krnq->irnq", X, dN)
    return np.sqrt((np.cross(T[:, 0], T[:, 1], axis=0) ** 2).sum(0))


def _weighted(dG: np.ndarray, cell: CellType, X: np.ndarray, N: np.ndarray,
              measure: Measure) -> np.ndarray:
    """``dGamma`` times the measure's weight ``w(x)`` at ``x = sum_B N_B x_B``
    (``X`` (2, n, n_nodes), ``N`` (n_nodes, n, nq)); unchanged for a unit measure."""
    if measure.unit:
        return dG
    x = np.einsum("ink,knq->inq", X, N)
    return dG * measure.weight(x)


def _scatter(n_s: int, nodes: np.ndarray, N: np.ndarray, dG: np.ndarray) -> np.ndarray:
    """``out_A = sum N_A dGamma`` summed into the nodes (n, n_nodes) of each cell."""
    out = np.zeros(n_s)
    for a in range(nodes.shape[1]):
        np.add.at(out, nodes[:, a], (N[a] * dG).sum(1))
    return out


def tributary_weights(xs: np.ndarray, seg: np.ndarray, cell: CellType, degree: int,
                      measure: Measure = PLANE, absolute: bool = False) -> np.ndarray:
    """``w_A = int N_A w(x) dGamma`` over the whole slave surface (module doc), (n_s,).

    ``degree``: the cell's rule is exact for polynomials of that degree in ``xi``
    (a straight cell's integrand ``N_A |dx/dxi|`` has the degree of ``N_A``).  On a
    straight line3 cell of length ``L`` with a centred mid node ``L/6, L/6, 2L/3``;
    ``L/2`` each for line2.  ``measure``: the weight ``w(x)`` of ``dGamma``
    (:mod:`~skfem_mortar.contact.measures`; linear in ``x``, so one degree more).
    ``absolute``: ``int |N_A| w dGamma`` instead, a positive scale even where
    ``int N_A w dGamma`` vanishes (a line3 vertex on the axis, ``w = 2 pi r``:
    ``int_0^h N_A r dr = 0`` on a straight cell).
    """
    xs = np.asarray(xs, dtype=float)
    seg = np.asarray(seg, dtype=np.int64)
    pts, w = cell.quadrature(degree + (0 if measure.unit else 1))
    xi = np.broadcast_to(pts[:, None, :], (pts.shape[0], seg.shape[0], pts.shape[1]))
    N = np.asarray(cell.shape(xi))
    xi = xi[0] if cell.dim == 1 else xi
    dG = _weighted(cell_jacobian(cell, xs[:, seg], xi) * w, cell, xs[:, seg], N, measure)
    return _scatter(xs.shape[1], seg, np.abs(N) if absolute else N, dG)


def multiplier_support(xs: np.ndarray, seg_s: np.ndarray, sg: Segmentation, cell: CellType,
                       n_gauss: int, measure: Measure = PLANE) -> np.ndarray:
    """``s_A = int N_A w(x) dGamma`` over the integration cells of ``sg`` (module doc),
    (n_s,); negative for a far vertex of a partly covered line3 cell.  ``measure`` as
    :func:`tributary_weights` (one degree more)."""
    xs = np.asarray(xs, dtype=float)
    e = sg.e_s
    eta, w = line_quadrature(2 * n_gauss - 1 + (0 if measure.unit else 1))
    lo, hi = sg.xi[:, :1], sg.xi[:, 1:]
    xi = lo * ((1.0 - eta[0]) * 0.5) + hi * ((1.0 + eta[0]) * 0.5)
    N = np.asarray(cell.shape(xi[None]))
    dG = _weighted(cell_jacobian(cell, xs[:, seg_s[e]], xi) * ((hi - lo) * 0.5) * w, cell,
                   xs[:, seg_s[e]], N, measure)
    return _scatter(xs.shape[1], seg_s[e], N, dG)
