"""Nearly incompressible solids on Taylor-Hood tetrahedra: ``p2p1``, quadratic
displacements and continuous linear pressures (scikit-fem's own Stokes pair).

Tetrahedra of either order lock as ``nu -> 0.5`` when the volume is constrained
at every quadrature point.  :class:`TaylorHoodSolid` writes the law in its mixed
(perturbed Lagrangian) form with the split ``W = W_mu(F) + lambda / 2 q(F)^2``
of :mod:`.volumetric` (``q = ln J``, ``tr E`` or ``tr eps``) and an independent
pressure ``p``:

    Pi(u, p) = int_Omega0 [ W_mu(F) + p q(F) - p^2 / (2 lambda) ] dV .

Stationarity in ``p`` gives ``p = lambda q`` and back ``W``: the same continuum,
another discretization.  P2 displacements (``ElementVector(ElementTetP2())``) with
P1 pressures (``ElementTetP1()``) are inf-sup stable: no locking, displacement
errors of order 3 in ``L2``.

Residuals and tangent (``v`` displacement, ``N_b`` pressure shape functions)::

    r_u[l] = int Grad v_l : (P_mu + p dq/dF) dV ,
    r_p[b] = s int N_b (q - p / lambda) dV ,
    K_uu   = int Grad v : (A_mu + p d2q/dF2) : Grad dv dV ,
    K_up   = s int (dq/dF : Grad v_l) N_b dV ,   K_pu = K_up^T ,
    K_pp   = -(s^2 / lambda) int N_b N_c dV ,

over the element as one local matrix ``(30 + 4) x (30 + 4)``.  The item's
unknowns are ``[u; p~]`` with the scaled pressure ``p = s p~``, ``s = mu / ell``,
``ell`` the cube root of the mean element volume (every row a force, as
:mod:`.mixed` does in 2D).  Quadrature: order 2 (four points) by default, exact
for the small-strain system on straight-sided tetrahedra.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
from skfem import Basis, ElementTetP1, Mesh

from ..core.coo import element_coo
from ..core.item import Contribution
from .material import Material
from .solid import Solid, displacement_element
from .volumetric import VolumetricSplit

__all__ = ["TaylorHoodSolid"]


class TaylorHoodSolid(Solid):
    """A 3D solid on P2-P1 (Taylor-Hood) tetrahedra (module docstring).

    Parameters as :class:`~skfem_mortar.bodies.solid.Solid` with ``element="p2p1"``
    (``Solid(mesh, material, "p2p1")`` builds this class): ``mesh`` a ``MeshTet2``
    (or ``MeshTet1``: straight edges), ``material`` NeoHooke, SaintVenantKirchhoff or
    LinearElastic with ``lambda > 0``, finite or small kinematics.

    Notes
    -----
    Local unknowns ``[u (n_u); p~ (n_p)]``: the P2 vector dofs, then the scaled
    vertex pressures ``p~ = p / s`` (:attr:`pressure_scale`).
    """

    def __init__(self, mesh: Mesh, material: Material, element: str = "p2p1",
                 name: str = "solid", intorder: int | None = None, *,
                 kinematics: str | None = None, plane: str | None = None):
        base = displacement_element(mesh, element, "p2p1", type(self).__name__)
        super().__init__(mesh, material, base, name, intorder, kinematics=kinematics,
                         plane=plane)
        if not self.material.lmbda > 0.0:
            raise ValueError(f"material must have lmbda > 0 (nu > 0): the pressure equation "
                             f"divides by lmbda (got lmbda = {self.material.lmbda})")
        self.element = "p2p1"
        self.split = VolumetricSplit(self.material)
        self.pbasis = Basis(mesh, ElementTetP1(), quadrature=self.basis.quadrature)
        self.n_u, self.n_p = int(self.basis.N), int(self.pbasis.N)
        self.n_dofs = self.n_u + self.n_p
        #: ``ell`` (cube root of the mean element volume) and ``s = mu / ell``
        self.length_scale = float(np.cbrt(np.mean(np.sum(self._dx, axis=1))))
        self.pressure_scale = float(self.material.mu) / self.length_scale
        self._pdofs = np.asarray(self.pbasis.element_dofs, dtype=np.int64)   # (4, n_el)
        self._N = np.stack([np.asarray(self.pbasis.basis[b][0])
                            for b in range(self.pbasis.Nbfun)])             # (4, n_el, n_qp)
        self._alldofs = np.vstack([self._edofs, self.n_u + self._pdofs])
        self._mixed_idx: tuple[int, np.ndarray, np.ndarray] | None = None

    # -- the pressure ------------------------------------------------------------
    def pressure_dofs(self) -> np.ndarray:
        """Local indices of the scaled pressure unknowns (``n_u .. n_dofs - 1``)."""
        return self.n_u + np.arange(self.n_p, dtype=np.int64)

    def pressure(self, z: np.ndarray) -> np.ndarray:
        """Vertex pressures ``p = s p~`` (stress units), length ``n_p``."""
        return self.pressure_scale * np.asarray(self.u(z), dtype=float)[self.n_u:]

    def pressure_at_points(self, z: np.ndarray) -> np.ndarray:
        """``p`` on all quadrature points, ``(n_el, n_qp)``."""
        return np.einsum("be,beq->eq", self.pressure(z)[self._pdofs], self._N)

    def interpolate(self, fun: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """Local dof vector (length ``n_dofs``) of the P2 interpolant of ``u = fun(X)``
        and zero pressure."""
        pts = self.basis.doflocs
        vals = np.asarray(fun(pts), dtype=float)
        if vals.shape != pts.shape:
            raise ValueError(f"fun must return an array of shape {pts.shape}")
        out = np.zeros(self.n_dofs)
        out[:self.n_u] = vals[self.dof_component, np.arange(self.n_u)]
        return out

    # -- assembly ----------------------------------------------------------------
    def first_piola(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``F`` and ``P = P_mu + p dq/dF`` on the quadrature points."""
        F = self.deformation_gradient(z)
        _, dq, _ = self.split.log_measure(F, False)
        return F, self.split.shear.stress(F) + self.pressure_at_points(z) * dq

    def _local(self, z: np.ndarray, tangent: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """Element residuals ``(n_loc, n_el)`` and tangents ``(n_loc, n_loc, n_el)`` over
        ``[u; p~]`` (module docstring)."""
        F = self.deformation_gradient(z)
        p = self.pressure_at_points(z)
        P, A = self.split.shear.stress_and_tangent(F, tangent=tangent)
        q, dq, d2q = self.split.log_measure(F, tangent)
        s, lm, dx, N = self.pressure_scale, self.split.lmbda, self._dx, self._N
        ru = self._residuals(P + p * dq)
        rp = s * np.einsum("beq,eq->be", N, (q - p / lm) * dx)
        re = np.concatenate([ru, rp])
        if not tangent:
            return re, None
        n_u = ru.shape[0]
        ke = np.empty((re.shape[0], re.shape[0], dx.shape[0]))
        ke[:n_u, :n_u] = self._tangents((A + p * d2q) * dx)
        G = np.einsum("lJeq,lJeq->leq", dq[self._comp], self._dN)   # dq : Grad v_l
        ke[:n_u, n_u:] = s * np.einsum("leq,beq->lbe", G * dx, N)
        ke[n_u:, :n_u] = np.swapaxes(ke[:n_u, n_u:], 0, 1)
        ke[n_u:, n_u:] = -(s * s / lm) * np.einsum("beq,ceq->bce", N * dx, N)
        return re, ke

    def _mixed_index(self) -> tuple[np.ndarray, np.ndarray]:
        """Global COO rows and columns of the element tangents ``(n_loc, n_loc, n_el)``."""
        if self._mixed_idx is None or self._mixed_idx[0] != self.offset:
            self._mixed_idx = (self.offset, *element_coo(self.offset + self._alldofs,
                                                         elements_last=True))
        return self._mixed_idx[1], self._mixed_idx[2]

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> Contribution:
        re, ke = self._local(z, tangent)
        r = np.bincount(self._alldofs.ravel(), weights=re.ravel(), minlength=self.n_dofs)
        out = Contribution.from_local(self.offset, r)
        if tangent:
            out.k_rows, out.k_cols = self._mixed_index()
            out.k_vals, out.k_elements = ke.ravel(), self.offset + self._alldofs
        return out

    def internal_force(self, z: np.ndarray) -> np.ndarray:
        """The item's residual on its local dofs (length ``n_dofs``), module docstring."""
        re, _ = self._local(z, False)
        return np.bincount(self._alldofs.ravel(), weights=re.ravel(), minlength=self.n_dofs)

    def assemble_forms(self, z: np.ndarray, tangent: bool = True):
        """Not offered: the u-p system is assembled by :meth:`assemble` only."""
        raise NotImplementedError("TaylorHoodSolid: use assemble")

    def output_data(self, z: np.ndarray) -> tuple[dict, dict]:
        """As :meth:`Solid.output_data <skfem_mortar.bodies.solid.Solid.output_data>`
        (the stress from ``P_mu + p dq/dF``) and ``pressure`` on every output node: the
        linear pressure field evaluated there (at a mid-edge node the mean of its
        edge's vertices), so that the series has no NaN."""
        point, cells = super().output_data(z)
        pv = self.pressure(z)[np.asarray(self.pbasis.nodal_dofs[0], dtype=np.int64)]
        edges = np.asarray(self.mesh.edges, dtype=np.int64)     # the output's mid-edge nodes,
        pn = np.concatenate([pv, 0.5 * (pv[edges[0]] + pv[edges[1]])])  # in edge order
        if pn.size != point["displacement"].shape[0]:
            raise RuntimeError(f"p2p1 output: {pn.size} pressures for "
                               f"{point['displacement'].shape[0]} nodes")
        point["pressure"] = pn
        return point, cells
