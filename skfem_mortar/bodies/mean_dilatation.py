"""Nearly incompressible solids on linear hexahedra: the mean-dilatation rule, ``hex1-md``.

Trilinear hexahedra lock as ``nu -> 0.5``: the volumetric energy asks the volume
to stay put at each of the eight Gauss points.  The mean-dilatation rule asks it
once per element: with the split ``W = W_mu(F) + U(m)`` of
:mod:`.volumetric` (NeoHooke: ``m = J``, ``U = lambda / 2 (ln J)^2``; SVK and
linear: ``m = tr E`` or ``tr eps``, ``U = lambda / 2 m^2``) the element energy is

    Pi_e = int_e W_mu(F) dV + V_e U(m_bar) ,   m_bar = (1 / V_e) int_e m(F) dV ,

so for NeoHooke ``m_bar = J_bar = v_e / V_e`` (current over reference volume).
With ``g_l = int_e dm/dF : Grad N_l dV`` (at small strain ``g = int B dV``, the
volumetric row of ``B`` integrated: ``B_bar V_e``),

    r_e[l]    = int_e P_mu : Grad N_l dV + U'(m_bar) g_l ,
    K_e[l, m] = int_e Grad N_l : (A_mu + U'(m_bar) d2m/dF2) : Grad N_m dV
                + U''(m_bar) / V_e g_l g_m ,

one symmetric rank-one term per element over the solid's own kernel (the full
2 x 2 x 2 Gauss rule; no hourglass modes).  ``g`` is the exact integral, not the
centre-point value ``V_e B(centre)`` of the 2D one-point quads, which a
distorted hexahedron misses (:meth:`MeanDilatationSolid.volumetric_operator`;
the tests show the difference).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import Mesh

from ..core.item import Contribution
from .material import Material
from .solid import Solid, displacement_element
from .volumetric import VolumetricSplit

__all__ = ["MeanDilatationSolid"]


class MeanDilatationSolid(Solid):
    """A hex1 solid with the mean-dilatation volumetric rule (module docstring).

    Parameters as :class:`~skfem_mortar.bodies.solid.Solid` with ``element="hex1-md"``
    (``Solid(mesh, material, "hex1-md")`` builds this class): ``mesh`` a
    ``MeshHex1`` (or ``MeshHex2``), ``material`` NeoHooke, SaintVenantKirchhoff or
    LinearElastic, finite or small kinematics.

    Attributes
    ----------
    split : VolumetricSplit
        The law's shear part and volume measure.
    volume : ndarray
        ``V_e`` of every element.
    """

    def __init__(self, mesh: Mesh, material: Material, element: str = "hex1-md",
                 name: str = "solid", intorder: int | None = None, *,
                 kinematics: str | None = None, plane: str | None = None):
        base = displacement_element(mesh, element, "hex1-md", type(self).__name__)
        super().__init__(mesh, material, base, name, intorder, kinematics=kinematics,
                         plane=plane)
        self.element = "hex1-md"
        self.split = VolumetricSplit(self.material)
        self.volume = self._dx.sum(axis=1)

    def _volumetric(self, F: np.ndarray, tangent: bool):
        """``g`` ``(n_loc, n_el)``, ``U'``, ``U''`` per element and ``d2m/dF2``."""
        m, dm, d2m = self.split.mean_measure(F, tangent)
        mbar = np.sum(m * self._dx, axis=1) / self.volume
        dU, d2U = self.split.energy_derivatives(mbar)
        return self._residuals(dm), dU, d2U, d2m

    def volumetric_operator(self, z: np.ndarray | None = None) -> np.ndarray:
        """``g_l = int_e dm/dF : Grad N_l dV`` ``(n_loc, n_el)`` at ``z`` (default: the
        reference state, where it is ``int_e B dV = B_bar V_e``: ``int dN_l/dX_{c_l} dV``)."""
        if z is None:
            F = np.broadcast_to(np.eye(self.dim)[:, :, None, None],
                                (self.dim, self.dim) + self._dx.shape).copy()
        else:
            F = self.deformation_gradient(z)
        return self._volumetric(F, False)[0]

    def first_piola(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``F`` and ``P = P_mu + U'(m_bar) dm/dF`` on the quadrature points."""
        F = self.deformation_gradient(z)
        m, dm, _ = self.split.mean_measure(F, False)
        mbar = np.sum(m * self._dx, axis=1) / self.volume
        dU, _ = self.split.energy_derivatives(mbar)
        return F, self.split.shear.stress(F) + dU[:, None] * dm

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> Contribution:
        F = self.deformation_gradient(z)
        P, A = self.split.shear.stress_and_tangent(F, tangent=tangent)
        g, dU, d2U, d2m = self._volumetric(F, tangent)
        re = self._residuals(P) + dU * g
        r = np.bincount(self._edofs.ravel(), weights=re.ravel(), minlength=self.n_dofs)
        out = Contribution.from_local(self.offset, r)
        if not tangent:
            return out
        ke = self._tangents((A + dU[:, None] * d2m) * self._dx)
        ke += (d2U / self.volume) * g[:, None, :] * g[None, :, :]
        out.k_rows, out.k_cols = self._tangent_index()
        out.k_vals, out.k_elements = ke.ravel(), self._kidx[3]
        return out

    def internal_force(self, z: np.ndarray) -> np.ndarray:
        """The residual ``r`` of the module docstring on the body's dofs."""
        c = self.assemble(z, 1.0, tangent=False)
        return np.bincount(c.r_index - self.offset, weights=c.r_value, minlength=self.n_dofs)

    def assemble_forms(self, z: np.ndarray, tangent: bool = True
                       ) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Not offered: skfem's forms integrate point by point, the rule is per element."""
        raise NotImplementedError("the mean-dilatation rule has no pointwise skfem form")
