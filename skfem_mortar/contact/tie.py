"""Mesh tying of two non-matching surfaces with mortar multipliers: :class:`TiePair`.

Two bodies meshed apart are glued along an interface ``Gamma`` by asking the
displacements of the two sides to agree in the weak mortar sense.  A slave
node ``A`` carries a vector multiplier ``lam_A`` (``d`` components, ``d`` = 2 or 3 the
coordinates of the surfaces) with the
multiplier shape function ``Phi_A`` (standard ``Phi_A = N_A`` or dual,
biorthogonal to ``N_A``), and the constraint of node ``A`` is

    c_A(u) = sum_B D_AB u_B - sum_C M_AC u_C = 0                 (every component)

    D_AB = int_Gamma Phi_A N_B dGamma,   M_AC = int_Gamma Phi_A N_C dGamma,

``B`` the slave nodes, ``C`` the master nodes, ``u = x - X`` the
displacements.  Written with positions this is the constraint of the issue,
``sum_B D_AB x_B - sum_C M_AC x_C = sum_B D_AB X_B - sum_C M_AC X_C``: the
reference offset ``g0_A = sum_B D_AB X_B - sum_C M_AC X_C`` (zero on a
straight interface where the two sides coincide) is kept.

Reference configuration
-----------------------
``D`` and ``M`` are the scalar mortar integrals of the one mortar kernel,
:func:`skfem_mortar.contact.mortar_kernel.evaluate` (segmentation, Gauss rule, dual
coefficients, masking of nodes without a master partner), for line and face cells
alike, computed **once, on the reference configuration** and frozen.
The constraint is then linear in ``u``, its rows are constant and the tangent
below is exact for any deformation (what most codes do for tying).  It holds
at finite strain: a rigid motion ``u = (Q - I) X + c`` of the glued pair
satisfies it up to ``(Q - I) g0_A`` (``sum_B D_AB = sum_C M_AC`` wherever
node ``A`` is tied), so on a straight coincident interface (``g0 = 0``) finite
rotations are exact; on a curved non-matching interface the two polygons differ by
``O(h^2 / R)`` and so does ``g0``.  Following the deformation instead (``D(x)``,
``M(x)`` re-integrated on the current surfaces) would need the derivatives of
``D`` and ``M`` and changes nothing where ``g0 = 0``.

Residual and tangent
--------------------
``lam_A`` is the traction the master side exerts on the slave side, per unit
reference length (and per unit reference thickness; per unit reference area on the
faces of a 3D model), ``t_h = sum_A Phi_A lam_A``.
With the tie potential ``-lam . c(u)`` (the sign of :class:`~skfem_mortar.contact.pair.ContactPair`):

    R_u   += -B^T lam          (slave rows: -sum_A D_AB lam_A; master rows: +sum_A M_AC lam_A)
    R_lam  = -B u              (the constraint rows)
    K_ulam = -B^T,   K_lamu = -B,   K_uu += 0,   K_lamlam = 0

with ``B = [D (x) I_d, -M (x) I_d]`` on the slave and master dofs: a symmetric
saddle point (:attr:`TiePair.symmetric` is True).  The multiplier rows are
``c_A`` itself (units: length^2), so the tangent stays symmetric; they are
linear, so one Newton iteration meets them to round-off.  Both sides'
tie forces, ``f_s = D^T lam`` on the slave and ``f_m = -M^T lam`` on the master,
sum to zero, and their moments to ``sum_A g0_A x lam_A`` at a state where
``c = 0`` (zero on a straight coincident interface, see :meth:`TiePair.forces`).

Nodes that are not tied
-----------------------
A slave node whose mortar support is (almost) empty (it faces no master
element, or only a sliver of it) and a slave node with a prescribed dof
(Dirichlet data on the slave side of the interface, e.g. where the interface
meets a clamped edge or face) are not tied: they are *merged*, not dropped, like
crosspoints (:func:`~skfem_mortar.contact.mortar_kernel.evaluate`, ``crosspoints``,
the kernel's merge rule of the cell table: on each of their cells their ``Phi``
goes to the nearest kept nodes along the cell's edges, in equal shares), so the
``Phi`` still sum to one and the patch test still passes; their multiplier rows
are ``lam_A = 0`` and :meth:`TiePair.tie_data` marks them ``tied = False``.
Tying them too would fix their dofs twice (measured on a 3D interface meeting a
clamped face: the free tangent's smallest singular value drops from 7e-9 of the
largest to round-off, ``tests/test_tie3d.py``).  The prescribed slave dofs are read in :meth:`TiePair.set_fixed`
(before each step): a slave with Dirichlet data on a tied dof over-constrains
the interface (the row of ``c_A`` would fix master dofs or be empty).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ..core.item import Contribution, Item
from ..core.validate import count
from . import mortar_kernel
from .measures import PLANE, Measure, measure_for
from .multiplier_spaces import MultiplierSpace, traction_space
from .normals import nodal_normals
from .points3d import FacePoints
from .segmentation import surface_cell
from .surface_kinds import CURVE, FACE, entry
from .surfaces import ContactSurface

__all__ = ["TiePair", "TieOutput"]


class _Integrals(NamedTuple):
    D: sp.csr_matrix
    M: sp.csr_matrix
    mask: np.ndarray


def _line_points(cells: tuple, n_gauss: int) -> None:
    """Lines: the kernel's own line segmentation (``points=None``: ``n_gauss`` points per
    integration cell, the dual mass rule of curved cells, mirror normals on an
    axisymmetric measure's axis)."""
    return None


def _face_points(cells: tuple, n_gauss: int) -> FacePoints:
    """Faces: the triangle rule of degree ``2 n_gauss`` on each integration cell (4 by
    default: ``N_A N_B`` of flat tri3 faces has degree 2, of parallelogram quad4 faces 4)."""
    return FacePoints(cells, 2 * n_gauss)


#: the one kernel's integration points by the slave cell's kind (:mod:`.surface_kinds`)
POINTS = {CURVE: _line_points, FACE: _face_points}


def _shear_along(lam: np.ndarray, n: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Along a curve: the signed scalar ``lam . t``, ``t = (-n_y, n_x)``."""
    return lam[1] * n[0] - lam[0] * n[1]


def _shear_vector(lam: np.ndarray, n: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """On faces: the tangential vector ``lam - (lam . n) n``."""
    return lam - normal * n


#: :meth:`TiePair.tie_data`'s shear by the slave cell's kind
SHEAR = {CURVE: _shear_along, FACE: _shear_vector}


def _integrals(s: ContactSurface, m: ContactSurface, space: MultiplierSpace, n_gauss: int,
               crosspoints: np.ndarray | None, measure: Measure = PLANE) -> _Integrals:
    """``D``, ``M`` and the mask on the reference configuration: the one mortar kernel's
    :func:`~skfem_mortar.contact.mortar_kernel.evaluate` (values only) for any cells,
    its points from :data:`POINTS`; in ``measure``'s ``w dGamma``."""
    cells = (surface_cell(s), surface_cell(m))
    order = max(c.order for c in cells)      # quadratic lines: at least 3 points
    n_gauss = max(n_gauss, 2 * order - 1)
    ev = mortar_kernel.evaluate(s.X, s.segments, m.X, m.segments, tangent=False,
                                **space.kernel_options(), n_gauss=n_gauss,
                                crosspoints=crosspoints, measure=measure, cells=cells,
                                points=entry(POINTS, cells[0], "TiePair")(cells, n_gauss))
    return _Integrals(ev.info["D"], ev.info["M"], ev.mask)


class TiePair(Item):
    """Glue a slave surface to a master surface: vector mortar constraints on the
    displacement jump, ``d`` multipliers (the interface traction) per slave node: two on
    the lines of a plane or axisymmetric model, three on the faces (tri3, quad4) of a
    3D one.

    Parameters
    ----------
    slave : ContactSurface
        A deformable surface (its nodes carry the multipliers).  Take the side
        with the finer mesh (standard mortar rule: a coarse slave over a fine
        master over-constrains it).
    master : ContactSurface
        A deformable surface, or a rigid one (then the slave is glued to the
        ground, a weak clamp).
    name : str
        Item name (unique among the bodies and multiplier items).
    n_gauss : int
        Gauss points per mortar segment (>= 1; at least 3 on line3 cells); the
        default 2 integrates ``D`` and ``M`` exactly on straight segments.  On faces
        the triangle rule of degree ``2 n_gauss`` on each integration cell (default 4:
        exact on flat tri3 and parallelogram quad4 faces).
    dual : bool, keyword only
        Dual (biorthogonal) multiplier shape functions: ``D`` is diagonal
        (exactly: off-diagonal entries below 1e-12 of the diagonal, the kernel's
        round-off, are dropped; a node merged into its neighbour, module doc,
        keeps its coupling to it), so each multiplier couples to its own slave
        node only.  Default False:
        standard ``Phi_A = N_A``.  Read into :attr:`space`, a
        :class:`~skfem_mortar.contact.multiplier_spaces.MultiplierSpace`
        (:func:`~skfem_mortar.contact.multiplier_spaces.traction_space`).

    Raises
    ------
    ValueError
        When a surface is not a :class:`ContactSurface`, the slave is rigid,
        slave and master are the same surface, ``dual`` is not a bool,
        ``n_gauss`` is not an integer in [1, 10], or the surfaces do not overlap
        (no slave element faces a master element in the reference configuration).

    Attributes
    ----------
    D, M : csr_matrix (n_s, n_s), (n_s, n_m)
        The reference mortar matrices (rows of the tied nodes only).
    reference_gap : ndarray (d, n_s)
        ``g0_A / sum_B D_AB``: the reference offset of each tied node's
        constraint as a length (zero on a straight coincident interface).
    """

    dof_kind = "lam"
    #: plane, axisymmetric (``D``, ``M`` in ``2 pi r dGamma``: :meth:`set_measure`) and 3D
    #: (faces); the bodies tell which
    geometries = ("plane", "axisymmetric", "3d")
    loaded = False  # its residual does not depend on the load factor
    symmetric = True  # K_ulam = -B^T, K_lamu = -B
    has_history = False  # D and M depend only on the reference configuration
    phase = "contact"

    def __init__(self, slave: ContactSurface, master: ContactSurface, name: str = "tie",
                 n_gauss: int = 2, **basis: bool):
        for what, s in (("slave", slave), ("master", master)):
            if not isinstance(s, ContactSurface):
                raise ValueError(f"{what} must be a ContactSurface (e.g. "
                                 f"ContactSurface.from_solid(body, tag)), got {type(s).__name__}")
        if slave.dofs() is None:
            raise ValueError(f"slave must be a deformable surface (a rigid surface "
                             f"{slave.name!r} can only be the master)")
        if slave is master or (master.body is slave.body and
                               np.array_equal(np.sort(slave.nodes), np.sort(master.nodes))):
            raise ValueError(f"slave and master must be two different surfaces, got "
                             f"{slave.name!r} twice")
        self.slave, self.master, self.name = slave, master, name
        #: the multipliers' space (``dual=True``: biorthogonal, else standard)
        self.space = traction_space(**basis)
        self.n_gauss = count("n_gauss", n_gauss, 1, 10)
        #: components per node: the surfaces' coordinates (2, or 3 for faces)
        self.dim = int(slave.X.shape[0])
        self.n_dofs = self.dim * slave.n_nodes
        self._merged = np.zeros(slave.n_nodes, dtype=bool)  # prescribed slave nodes
        self._geometry = "plane"
        #: the weight of ``dGamma`` (:meth:`set_measure`; the model's geometry's)
        self.measure: Measure = PLANE
        self._integrate()
        if not self.tied.any():
            raise ValueError(
                f"tie {name!r}: the slave {slave.name!r} and the master {master.name!r} do "
                f"not overlap (no slave element faces a master element in the reference "
                f"configuration): give the two boundaries that lie on the same interface, "
                f"facing each other (outward normals opposite, as "
                f"ContactSurface.from_solid(body, tag) builds them for two touching bodies)")

    @property
    def geometry(self) -> str:  # type: ignore[override]
        """The model's geometry (set by the model at bind); setting it sets the
        measure of that geometry (:meth:`set_measure`)."""
        return self._geometry

    @geometry.setter
    def geometry(self, value: str) -> None:
        self._geometry = value
        self.set_measure(measure_for(value))

    def set_measure(self, measure: Measure) -> None:
        """The weight ``w(x)`` of ``dGamma`` (:mod:`~skfem_mortar.contact.measures`;
        ``2 pi r`` in an axisymmetric model): ``D`` and ``M`` are integrated again in
        ``w dGamma`` on the reference configuration when it changes, so the
        multipliers are tractions per unit reference area of the revolution surface."""
        if not isinstance(measure, Measure):
            raise ValueError(f"measure must be a Measure of contact.measures, got {measure!r}")
        if measure is not self.measure:
            self.measure = measure
            self._integrate()

    # -- the mortar matrices -------------------------------------------------------
    def _integrate(self) -> None:
        """``D``, ``M``, the tied mask and the constant triplets of ``B`` (reference)."""
        s, m = self.slave, self.master
        cp = np.flatnonzero(self._merged)
        ints = _integrals(s, m, self.space, self.n_gauss, cp if cp.size else None,
                          self.measure)
        tied = np.asarray(ints.mask, dtype=bool)
        keep = sp.diags(tied.astype(float))
        D = (keep @ ints.D).tocoo()
        if self.space.diagonal:  # D_AB = delta_AB int N_A; drop the kernel's round-off
            d = np.abs(D.diagonal())
            on = (D.row == D.col) | (np.abs(D.data) > 1e-12 * d[D.row])
            D = sp.coo_matrix((D.data[on], (D.row[on], D.col[on])), shape=D.shape)
        self.D = D.tocsr()
        self.M = (keep @ ints.M).tocsr()
        self.D.eliminate_zeros()
        self.M.eliminate_zeros()
        self.tied = tied
        weight = np.asarray(self.D.sum(axis=1)).ravel()
        self._weight = weight  # sum_B D_AB = int Phi_A (the node's mortar support)
        g0 = (self.D @ s.X.T - self.M @ m.X.T).T
        self.reference_gap = np.where(tied, g0 / np.where(weight != 0, weight, 1.0), 0.0)
        # untied rows lam_A = 0, scaled like a tied row (a length: the mean support)
        self._untied_scale = float(np.mean(weight[tied])) if tied.any() else 1.0
        self._triplets = None

    def _b_triplets(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``B`` as COO triplets: local multiplier rows ``2 A + i``, global columns."""
        rows, cols, vals = [], [], []
        for mat, surf, sign in ((self.D, self.slave, 1.0), (self.M, self.master, -1.0)):
            dofs = surf.dofs()
            if dofs is None:  # a rigid master: no unknowns
                continue
            c = mat.tocoo()
            for i in range(self.dim):
                rows.append(self.dim * c.row.astype(np.int64) + i)
                cols.append(dofs[i, c.col].astype(np.int64))
                vals.append(sign * c.data)
        return np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)

    def _constant(self) -> tuple:
        """The constant arrays of :meth:`assemble` (the same objects every call, so the
        model sums the tangent into its fixed pattern): ``B``'s triplets, the untied
        multiplier rows, and the tangent's triplets."""
        key = (self.offset, self.slave.body.offset,
               None if self.master.body is None else self.master.body.offset)
        if self._triplets is None or self._triplets[0] != key:
            rows, cols, vals = self._b_triplets()
            untied = np.repeat(~self.tied, self.dim)
            diag = self.offset + np.flatnonzero(untied)
            k_rows = np.concatenate([cols, self.offset + rows, diag])
            k_cols = np.concatenate([self.offset + rows, cols, diag])
            k_vals = np.concatenate([-vals, -vals, np.full(diag.size, self._untied_scale)])
            self._triplets = (key, rows, cols, vals, untied, k_rows, k_cols, k_vals)
        return self._triplets[1:]

    def constraint(self, z: np.ndarray) -> np.ndarray:
        """``c = D u_s - M u_m`` per slave node, shape (d, n_s) (zero at untied nodes)."""
        us = self.slave.x(z) - self.slave.X
        um = self.master.x(z) - self.master.X
        return (self.D @ us.T - self.M @ um.T).T

    # -- the item protocol -----------------------------------------------------------
    def referenced_bodies(self) -> list:
        """The bodies of the slave and (unless rigid) the master surface."""
        return [b for b in (self.slave.body, self.master.body) if b is not None]

    def set_fixed(self, fixed: np.ndarray) -> None:
        """Slave nodes with a prescribed dof are not tied (merged like crosspoints,
        module doc); ``D`` and ``M`` are integrated again when that set changes.

        Raises
        ------
        ValueError
            When no slave node is left tied (every one carries Dirichlet data).
        """
        merged = np.any(np.isin(self.slave.dofs(), np.asarray(fixed)), axis=0)
        if np.array_equal(merged, self._merged):
            return
        self._merged = merged
        self._integrate()
        if not self.tied.any():
            raise ValueError(
                f"tie {self.name!r}: every slave node of {self.slave.name!r} carries "
                f"Dirichlet data, so nothing is left to tie: swap slave and master, or drop "
                f"the Dirichlet data on the slave side of the interface")

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True) -> Contribution:
        """``R_u = -B^T lam``, ``R_lam = -B u`` (tied rows) or ``s lam`` (untied rows,
        ``s`` the mean support), and the constant tangent (module doc)."""
        z = np.asarray(z)
        lam = z[self.dofs]
        rows, cols, vals, untied, k_rows, k_cols, k_vals = self._constant()
        c = -self.constraint(z).T.ravel()            # -B u, index 2 A + i
        c[untied] = self._untied_scale * lam[untied]
        out = Contribution(np.concatenate([cols, self.offset + np.arange(self.n_dofs)]),
                           np.concatenate([-vals * lam[rows], c]))
        if tangent:
            out.k_rows, out.k_cols, out.k_vals = k_rows, k_cols, k_vals
        return out

    def end_step(self, z: np.ndarray, load_factor: float) -> None:
        """The untied multipliers of a converged state are exact zeros."""
        lam = z[self.dofs]
        lam[np.repeat(~self.tied, self.dim)] = 0.0

    def outputs(self) -> list:
        """The slave surface with the interface traction (:class:`TieOutput`)."""
        return [TieOutput(self)]

    def __repr__(self) -> str:
        """One line: name, multipliers, the two surfaces, the tied slave nodes."""
        kind = self.space.name
        return (f"TiePair({self.name!r}, {kind}: slave {self.slave.name!r} "
                f"({self.slave.n_nodes} nodes) on master {self.master.name!r} "
                f"({self.master.n_nodes} nodes), {int(np.sum(self.tied))} tied)")

    # -- results -------------------------------------------------------------------
    def traction(self, z: np.ndarray) -> np.ndarray:
        """The multipliers ``lam_A`` as (d, n_s): the traction the master exerts on the
        slave, per unit reference length (area in 3D; 0 at untied nodes)."""
        return np.asarray(z)[self.dofs].reshape(-1, self.dim).T.copy()

    def forces(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The tie forces ``(d, n_s)`` on the slave nodes, ``f_B = sum_A D_AB lam_A``,
        and ``(d, n_m)`` on the master nodes, ``f_C = -sum_A M_AC lam_A`` (the force the
        other side exerts; the residual term is its negative).

        Their resultants cancel exactly (``sum_B D_AB = sum_C M_AC`` for every tied
        ``A``); their moments about any point cancel up to ``sum_A g0_A x lam_A`` where
        the constraint holds (module doc).  Totals over the model's thickness
        ``H`` (:attr:`~skfem_mortar.core.item.Item.thickness`): both times ``H``.
        """
        lam = self.thickness * self.traction(z)
        return (self.D.T @ lam.T).T, -(self.M.T @ lam.T).T

    def tie_data(self, z: np.ndarray) -> dict[str, np.ndarray]:
        """Per slave node: ``x, y`` (``x, y, z`` in 3D; current), ``traction`` (d, n_s),
        its ``normal`` component ``lam . n`` (> 0 tension, on the current outward
        slave nodal normal ``n``) and its ``shear``: ``lam . t`` with ``t = (-n_y, n_x)``
        along a 2D surface, the tangential vector ``lam - (lam . n) n`` (3, n_s) on
        faces; ``jump`` (the constraint ``c_A`` over the support ``sum_B D_AB``: the
        weak displacement jump, a length) and ``tied``."""
        x = self.slave.x(z)
        lam = self.traction(z)
        cell = surface_cell(self.slave)
        n = nodal_normals(x, self.slave.segments, cell, order=0).n
        normal = np.sum(lam * n, axis=0)
        shear = entry(SHEAR, cell, "tie_data")(lam, n, normal)
        w = np.where(self._weight != 0, self._weight, 1.0)
        return {**{c: x[i].copy() for i, c in enumerate("xyz"[:self.dim])},
                "traction": lam, "normal": normal, "shear": shear,
                "jump": self.constraint(z) / w, "tied": self.tied.copy()}


class TieOutput:  # an Output (skfem_mortar.core.model) for the output layer
    """The slave surface of a :class:`TiePair` as an output series (its lines or faces) with
    point data ``displacement``, ``traction`` (the multiplier vector), its
    ``normal`` and ``shear`` components and ``tied`` (1 or 0)."""

    def __init__(self, tie: TiePair, name: str | None = None):
        self.tie = tie
        self.name = name or tie.name

    def output_mesh(self) -> tuple[np.ndarray, list[tuple[str, np.ndarray]]]:
        s = self.tie.slave
        return s.X.T.copy(), s.output_cells()

    def output_data(self, z: np.ndarray) -> tuple[dict, dict]:
        s = self.tie.slave
        d = self.tie.tie_data(z)
        return ({"displacement": (s.x(z) - s.X).T.copy(), "traction": d["traction"].T.copy(),
                 "normal": d["normal"], "shear": np.asarray(d["shear"]).T.copy(),
                 "tied": d["tied"].astype(float)}, {})
