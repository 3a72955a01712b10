"""The contract between a segmentation and the mortar kernel: integration points as jets.

A segmentation of any dimension ``d`` (2: lines, 3: surfaces) hands the one mortar
kernel (:mod:`~skfem_mortar.contact.mortar_cells`) the Gauss points of its
integration cells; the kernel computes everything else (``D``, ``M``, the weighted
gap, the slip, the supports, the dual basis) from the cell rows
(:class:`~skfem_mortar.contact.cells.CellType`) and these points, written once for
every ``d``.

Local variables
---------------
An integration cell lies on one slave cell ``e_s`` (``k_s`` nodes) and one master
cell ``e_m`` (``k_m`` nodes).  Its local variables have a fixed size for a cell-type
pair, in any dimension::

    [x of the slave cell's k_s nodes (k_s d), x of the master cell's k_m nodes (k_m d),
     the slave cell's nodal normals (k_s d)],      n_loc = d (2 k_s + k_m),

node by node, components inside (:class:`LocalLayout`).  The nodal normals enter as
local variables; their first and second derivatives over the neighbouring nodes
(:func:`~skfem_mortar.contact.normals.nodal_normals`, mirror included) are chained in
at assembly: ``G = G_loc J``, ``H = J^T H_loc J + sum_k (df/dn_k) d2n_k/dx2``.

The two calls
-------------
1. ``integration_cells(xs, conn_s, xm, conn_m, normals) -> IntegrationCells``, in
   values: which slave/master cell pairs overlap (``e_s``, ``e_m``, one row per
   integration cell, a pair may give several rows) and whatever the segmentation
   keeps to make the points (``data``, opaque to the kernel; e.g. the origin of each
   vertex).
2. ``integration_points(cells, local) -> IntegrationPoints``, in jets of the local
   variables of those rows (:meth:`LocalVariables.of`): for each integration cell and
   Gauss point the slave and master parametric coordinates ``xi_s``, ``xi_m``
   (``d - 1`` jets each, values ``(n, n_gp)``) and the weight ``w`` (a jet
   ``(n, n_gp)``): the Gauss weight times the integration cell's Jacobian in the
   SLAVE PARAMETER space.  The kernel multiplies in the slave surface Jacobian
   ``J_s(xi_s)`` and the measure ``w(x_s(xi_s))`` itself, so that::

       int_cell f dGamma = sum_k w_k J_s(xi_s,k) measure(x_s(xi_s,k)) f(xi_s,k, xi_m,k).

For lines the cell is ``[xi_a, xi_b]`` (end points from the projections, as jets),
its Gauss points ``xi_s = (1 - eta)/2 xi_a + (1 + eta)/2 xi_b`` with
``w = w_eta (xi_b - xi_a)/2``, and ``xi_m`` the projection along the normal field.  In
3D the cells are triangles on the slave face's auxiliary plane (the clipped polygon
triangulated there), each Gauss point back-projected to the slave ``(xi, eta)`` along
the plane's normal, and ``w`` the Jacobian of that chain at the point: the rule's weight
times the plane triangle's area vector over the face's ``T_1 x T_2`` at ``xi_s`` (normal
components), so that ``w J_s`` is the plane area element (straight triangles in
``(xi, eta)`` would be wrong on a quad4 that is no parallelogram); ``xi_m`` by
projection.  An integration cell lies in one smooth piece of its slave and master
cells (what makes piecewise cells such as ``line2x2`` integrate exactly).
"""
from __future__ import annotations

from typing import Any, NamedTuple, Protocol

import numpy as np

from .cells import CellType
from .jets import Jet

__all__ = ["LocalLayout", "LocalVariables", "IntegrationCells", "IntegrationPoints",
           "PointSegmentation", "check_points"]


class LocalLayout(NamedTuple):
    """Where each local variable of an integration cell sits (module docstring).

    ``x_s(a, i) = a d + i``, ``x_m(b, i) = (k_s + b) d + i``,
    ``n_s(a, i) = (k_s + k_m + a) d + i``; ``n_loc = d (2 k_s + k_m)``.
    """

    d: int
    k_s: int
    k_m: int

    @property
    def n_loc(self) -> int:
        """Number of local variables, ``d (2 k_s + k_m)``."""
        return self.d * (2 * self.k_s + self.k_m)

    def x_s(self, a: int, i: int) -> int:
        """Index of component ``i`` of slave node ``a``."""
        return a * self.d + i

    def x_m(self, b: int, i: int) -> int:
        """Index of component ``i`` of master node ``b``."""
        return (self.k_s + b) * self.d + i

    def n_s(self, a: int, i: int) -> int:
        """Index of component ``i`` of slave node ``a``'s nodal normal."""
        return (self.k_s + self.k_m + a) * self.d + i

    @staticmethod
    def of(cells: tuple[CellType, CellType]) -> "LocalLayout":
        """The layout of a slave/master cell-type pair (``d = slave dim + 1``)."""
        cs, cm = cells
        if cs.dim != cm.dim:
            raise ValueError(f"cells must have one reference dimension, got {cs.name} "
                             f"(dim {cs.dim}) and {cm.name} (dim {cm.dim})")
        return LocalLayout(cs.dim + 1, cs.n_nodes, cm.n_nodes)


class LocalVariables(NamedTuple):
    """The local variables of ``n`` integration cells as jets of shape ``(n,)``.

    Attributes
    ----------
    layout : LocalLayout
    x_s : list of list of Jet
        ``x_s[a][i]``: component ``i`` of slave node ``a``.
    x_m : list of list of Jet
        ``x_m[b][i]``: component ``i`` of master node ``b``.
    n_s : list of list of Jet
        ``n_s[a][i]``: component ``i`` of slave node ``a``'s nodal normal.
    """

    layout: LocalLayout
    x_s: list
    x_m: list
    n_s: list

    @staticmethod
    def of(xs: np.ndarray, xm: np.ndarray, ns: np.ndarray, second: bool = True
           ) -> "LocalVariables":
        """Independent variables from values ``xs (n, k_s, d)``, ``xm (n, k_m, d)``,
        ``ns (n, k_s, d)`` (``second``: track Hessians)."""
        xs, xm, ns = (np.asarray(a, dtype=float) for a in (xs, xm, ns))
        n, k_s, d = xs.shape
        if xm.ndim != 3 or xm.shape[0] != n or xm.shape[2] != d:
            raise ValueError(f"xm must have shape ({n}, k_m, {d}), got {xm.shape}")
        if ns.shape != xs.shape:
            raise ValueError(f"ns must have the shape of xs {xs.shape}, got {ns.shape}")
        lay = LocalLayout(d, k_s, xm.shape[1])
        nv = lay.n_loc

        def var(a, idx):
            return [[Jet.variable(a[:, b, i], idx(b, i), nv, second) for i in range(d)]
                    for b in range(a.shape[1])]
        return LocalVariables(lay, var(xs, lay.x_s), var(xm, lay.x_m), var(ns, lay.n_s))


class IntegrationCells(NamedTuple):
    """Integration cells in values: the first call of the contract.

    Attributes
    ----------
    e_s, e_m : int ndarray (n,)
        Slave and master parent cell of each integration cell.
    data : Any
        What the segmentation needs to make the points of these rows, as
        ``(whole, rows)``: the segmentation's own object (opaque to the kernel) and the
        row indices into it, in the order of ``e_s``, so that the kernel takes a chunk
        ``r`` as ``IntegrationCells(e_s[r], e_m[r], (whole, rows[r]))``; None: nothing.
    """

    e_s: np.ndarray
    e_m: np.ndarray
    data: Any = None


class IntegrationPoints(NamedTuple):
    """Gauss points of integration cells in jets: the second call of the contract.

    Attributes
    ----------
    e_s, e_m : int ndarray (n,)
    xi_s : tuple of Jet
        ``d - 1`` slave parametric coordinates, values ``(n, n_gp)``.
    xi_m : tuple of Jet
        ``d - 1`` master parametric coordinates, values ``(n, n_gp)``.
    w : Jet
        ``(n, n_gp)``: Gauss weight times the cell's Jacobian in the slave parameter
        space (not ``J_s``, not the measure: the kernel multiplies those).
    mass : (tuple of Jet, Jet) or None
        ``(xi_s, w)`` of a second rule on the same cells for the slave-only integrals of
        a dual space (``int N_A``, ``int N_A N_B``), where they need more points than the
        gap (curved cells); None: these points.
    geometry : (list of Jet, list of Jet) or None
        ``(x_s, n~)`` at the points (``d`` jets each, ``sum_a N_a x_a`` and
        ``sum_a N_a n_a``) if the segmentation made them on its way (the lines' does), so
        the kernel does not make them again; None: the kernel makes them.
    """

    e_s: np.ndarray
    e_m: np.ndarray
    xi_s: tuple
    xi_m: tuple
    w: Jet
    mass: tuple | None = None
    geometry: tuple | None = None


class PointSegmentation(Protocol):
    """A segmentation that feeds the one mortar kernel (module docstring)."""

    cells: tuple[CellType, CellType]

    def integration_cells(self, xs: np.ndarray, conn_s: np.ndarray, xm: np.ndarray,
                          conn_m: np.ndarray, normals: np.ndarray) -> IntegrationCells:
        """Integration cells in values; ``normals (d, n_s_nodes)`` the slave nodal normals."""
        ...

    def integration_points(self, cells: IntegrationCells, local: LocalVariables
                           ) -> IntegrationPoints:
        """Gauss points of ``cells`` in jets of ``local`` (rows of ``cells``)."""
        ...


def check_points(points: IntegrationPoints, local: LocalVariables) -> None:
    """ValueError unless ``points`` fits ``local``: ``d - 1`` coordinates on each side,
    every jet of at most ``n_loc`` variables (the leading ones: a jet of fewer does not
    depend on the others, :meth:`~skfem_mortar.contact.jets.Jet.widen`) with values
    ``(n, n_gp)``."""
    lay = local.layout
    n = points.e_s.shape[0]
    shape = points.w.v.shape
    if len(shape) != 2 or shape[0] != n:
        raise ValueError(f"points.w must have values of shape ({n}, n_gp), got {shape}")
    for name in ("xi_s", "xi_m"):
        xi = getattr(points, name)
        if len(xi) != lay.d - 1:
            raise ValueError(f"points.{name} must hold d - 1 = {lay.d - 1} jets, got {len(xi)}")
        for j in xi:
            if j.v.shape != shape or not 1 <= j.g.shape[0] <= lay.n_loc:
                raise ValueError(f"points.{name} must be jets of at most {lay.n_loc} "
                                 f"variables with values {shape}")
    if not 1 <= points.w.g.shape[0] <= lay.n_loc:
        raise ValueError(f"points.w must be a jet of at most {lay.n_loc} variables")
