"""Nearly incompressible solids on linear quadrilaterals: selective reduced integration.

Linear elements lock when ``nu -> 0.5``: the volumetric energy
``lambda / 2 (ln J)^2`` of the compressible neo-Hookean solid
(:class:`~skfem_mortar.bodies.materials.NeoHooke`) asks ``J = 1`` at every
quadrature point, more constraints than a linear field can meet, and the
body turns far too stiff (Hertz on ``tri1`` at ``nu = 0.499``: the peak
pressure 60-90 % off).  :class:`SRISolid` splits the energy

    W = W_mu + W_lambda,   W_mu = mu/2 (tr C - 2 - 2 ln J),
                           W_lambda = lambda/2 (ln J)^2,

and integrates ``W_mu`` with the full 2 x 2 Gauss rule but ``W_lambda`` with
the one-point rule at the element centre (one volume constraint per element;
the full rule on ``W_mu`` leaves no hourglass modes).  Its pieces are

    P_lambda = lambda ln J F^-T,
    A_lambda = lambda F^-T (x) F^-T - lambda ln J F^-1_Jk F^-1_Li ,

(the neo-Hookean stress and tangent with ``mu = 0``).

Axisymmetric (:mod:`.axisymmetric`): the centre value is the element's mean
dilatation only in plane 2D (``det F`` of a bilinear map is linear in the
reference coordinates, so ``v_e / V_e`` is its centre value); with the weight
``2 pi R`` it is not (on a distorted ring element off by up to 4.5 %).  There
the volumetric energy is that of the mean dilatation,

    Pi_e = V_e lambda/2 (ln J_bar)^2,   J_bar = v_e / V_e,
    V_e = int_e 2 pi R dA,   v_e = int_e J 2 pi R dA   (J = det F, 3 x 3),

on the deviatoric part's quadrature points, with ``b_l = dv_e/du_l =
int J (F^-T : G_l) 2 pi R dA`` (``G_l = dF/du_l``, its hoop entry ``N_l / R``;
small strain: ``b_l / V_e`` is the B-bar row ``int B_vol 2 pi R dA / V_e``): ::

    r_l = lambda ln(J_bar) / J_bar b_l ,
    K_lm = lambda (1 - ln J_bar) / (J_bar^2 V_e) b_l b_m
           + lambda ln(J_bar) / J_bar int d^2 J / du_l du_m 2 pi R dA ,

``d^2 J / dF_iJ dF_kL = J (F^-1_Ji F^-1_Lk - F^-1_Jk F^-1_Li)``.

Every law, both kinematics (:meth:`SRISolid.assemble_split`): the split ``W = W_mu +
U(m)`` of :mod:`.volumetric` (SaintVenantKirchhoff: ``m = tr E``, LinearElastic and
every law at small strain: ``m = tr eps``, ``U = lambda/2 m^2``) with the mean
dilatation ``Pi_e = int_e W_mu dV + V_e U(m_bar)``, ``m_bar = int_e m dV / V_e`` on the
2 x 2 points (``dV`` with the ``2 pi R`` weight in an axisymmetric model), as
:mod:`.mean_dilatation` does for hex1: with ``g_l = int_e dm/dF : G_l dV``

    r_l = int_e P_mu : G_l dV + U'(m_bar) g_l ,
    K_lm = int_e G_l : (A_mu + U'(m_bar) d2m/dF2) : G_m dV + U''(m_bar) / V_e g_l g_m .

In plane 2D ``m_bar`` of ``tr eps`` is its centre value (``int_e div u dA`` is the
derivative of ``v_e``, the centre rule's exact volume), so small strain is the one-point
rule itself; of ``tr E`` it is the mean, which the centre misses by ``O(|Grad u|^2)`` on
a distorted element.  NeoHooke at finite strain keeps the two forms above (the
same discrete energy: its recorded results bit for bit, equal to this one to round-off).

Contact surfaces keep
their straight 2-node segments (quad1 facets), so every contact method applies.
:func:`split_to_quads` turns a triangle mesh (e.g. the graded Hertz meshes)
into a quadrilateral one.
"""
from __future__ import annotations

import numpy as np
from skfem import Basis, ElementQuad1, ElementVector, MeshQuad, MeshTri
from skfem.helpers import grad, inv

from .deformation import checked_det
from .hoop import hoop_residual, hoop_tangent
from ..core.item import Contribution
from .material import Material
from .solid import Solid, internal_force, material_stiffness, refuse_reduction
from .volumetric import VolumetricSplit

__all__ = ["SRISolid", "split_to_quads", "ONE_POINT"]

#: the one-point Gauss rule of the reference square [0, 1]^2: (points, weights)
ONE_POINT = (np.array([[0.5], [0.5]]), np.array([1.0]))


def _volumetric(F: np.ndarray, lmbda: float, tangent: bool = True):
    """``P`` and ``A = dP/dF`` of ``W = lambda/2 (ln J)^2`` on quadrature arrays
    ``F (2, 2, ...)``; ``InversionError`` where ``det F <= 0`` (as in NeoHooke)."""
    F = np.asarray(F, dtype=float)
    J = checked_det(F)
    Fi = inv(F)
    FiT = np.swapaxes(Fi, 0, 1)
    lnJ = np.log(J)
    P = lmbda * lnJ * FiT
    if not tangent:
        return P, None
    A = (-lmbda * lnJ * Fi[None, :, :, None] * FiT[:, None, None, :]
         + lmbda * FiT[:, :, None, None] * FiT[None, None, :, :])
    return P, A


class SRISolid(Solid):
    """A quad1 solid with the volumetric energy of one point (the mean dilatation) per
    element (module docstring).

    Parameters
    ----------
    mesh : skfem.MeshQuad
    material : Material
        NeoHooke, SaintVenantKirchhoff or LinearElastic: its ``mu`` goes to the fully
        integrated shear part, its ``lmbda`` to the volumetric one; any ``nu`` in
        ``(-1, 0.5)``.
    name : str
    kinematics : {"finite", "small"}, optional
        Finite strain (the law's split) or small strain (the split of its
        linearization); default as :class:`~skfem_mortar.bodies.solid.Solid`:
        ``"small"`` for a LinearElastic material, else ``"finite"``.
    plane : {"strain"}, optional
        Only plane strain: plane stress does not lock (its in-plane
        ``lambda* = 2 lambda mu / (lambda + 2 mu)`` stays below ``2 mu``), use
        :class:`~skfem_mortar.bodies.solid.Solid`.

    Attributes
    ----------
    material : Material
        The shear part the full 2 x 2 rule integrates (the law at ``lambda = 0``).
    full_material : Material
        The law (linearized for small kinematics): the stress output's.
    split : VolumetricSplit

    Notes
    -----
    Residual and tangent are the exact derivatives of the split discrete energy,
    so Newton converges quadratically.  Stress output (``output_data``) is the
    full law's Cauchy stress at the 2 x 2 points, smoothed per element.
    """

    geometries = ("plane", "axisymmetric")

    def __init__(self, mesh: MeshQuad, material: Material, name: str = "solid", *,
                 kinematics: str | None = None, plane: str | None = None):
        refuse_reduction(type(self).__name__, plane)
        super().__init__(mesh, material, element="quad1", name=name, kinematics=kinematics)
        self.full_material = self.material
        self.split = VolumetricSplit(self.full_material)
        self.material = self.split.shear
        self.lmbda = self.split.lmbda
        # one point at the centre of the reference square [0, 1]^2, weight 1:
        # scikit-fem gives quads 2 x 2 points for every intorder, so the rule
        # is passed explicitly (intorder=1 gave 4 points: plain quad1, locking)
        self.vbasis = Basis(mesh, ElementVector(ElementQuad1()), quadrature=ONE_POINT)

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> Contribution:
        if self.split.kind != "log":
            return self.assemble_split(z, tangent)
        dev = super().assemble(z, load_factor, tangent)
        if self._hoop is not None:
            return Contribution.concat([dev, self._mean_dilatation(z, tangent)])
        G = np.asarray(grad(self.vbasis.interpolate(self.u(z))))
        F = G.copy()
        F[0, 0] += 1.0
        F[1, 1] += 1.0
        P, A = _volumetric(F, self.lmbda, tangent)
        r = internal_force.assemble(self.vbasis, P=P)
        K = None
        if tangent:
            K = material_stiffness.assemble(self.vbasis, At=np.transpose(A, (2, 3, 0, 1, 4, 5)))
        return Contribution.concat([dev, Contribution.from_local(self.offset, r, K)])

    def assemble_split(self, z: np.ndarray, tangent: bool = True) -> Contribution:
        """The mean-dilatation residual and tangent of the law's split (module
        docstring), every law; :meth:`assemble` for all but NeoHooke at finite strain."""
        re, ke = self._split_local(z, tangent)
        out = Contribution.from_local(self.offset, np.bincount(
            self._edofs.ravel(), weights=re.ravel(), minlength=self.n_dofs))
        if tangent:
            out.k_rows, out.k_cols = self._tangent_index()
            out.k_vals, out.k_elements = ke.ravel(), self._kidx[3]
        return out

    def _split_local(self, z: np.ndarray, tangent: bool
                     ) -> tuple[np.ndarray, np.ndarray | None]:
        """Element residuals ``(n_loc, n_el)`` and tangents ``(n_loc, n_loc, n_el)`` of
        :meth:`assemble_split`."""
        F = self.deformation_gradient(z)
        split, dx, hoop = self.split, self._dx, self._hoop
        P, A = split.shear.stress_and_tangent(F, tangent=tangent)
        m, dm, d2m = split.mean_measure(F, tangent)
        V = dx.sum(axis=1)
        dU, d2U = split.energy_derivatives((m * dx).sum(axis=1) / V)
        P = P + dU[:, None] * dm
        g, re = self._residuals(dm), self._residuals(P)
        if hoop is not None:                    # the hoop rows: P_thth h_l, dm_thth h_l
            g += hoop_residual(dm, hoop, dx)
            re += hoop_residual(P, hoop, dx)
        if not tangent:
            return re, None
        A = A + dU[:, None] * d2m
        if hoop is None:
            ke = self._tangents(A * dx)
        else:
            ke = self._tangents(A[:2, :2, :2, :2] * dx) + hoop_tangent(A, self._dN, self._comp,
                                                                        hoop, dx)
        return re, ke + (d2U / V) * g[:, None] * g[None, :]

    def internal_force(self, z: np.ndarray) -> np.ndarray:
        """The whole residual (shear and volumetric parts) on the body's dofs."""
        c = self.assemble(z, 1.0, tangent=False)
        return np.bincount(c.r_index - self.offset, weights=c.r_value, minlength=self.n_dofs)

    def mean_dilatation(self, z: np.ndarray) -> np.ndarray:
        """``J_bar = v_e / V_e`` per element (the volume ratio of each element's ring;
        plane geometry: the centre value, equal to it for a bilinear map)."""
        if self._hoop is None:
            F = np.asarray(grad(self.vbasis.interpolate(self.u(z))))[..., 0]
            return (1.0 + F[0, 0]) * (1.0 + F[1, 1]) - F[0, 1] * F[1, 0]
        J = checked_det(self.deformation_gradient(z))
        return (J * self._dx).sum(axis=1) / self._dx.sum(axis=1)

    def _mean_dilatation(self, z: np.ndarray, tangent: bool) -> Contribution:
        """The mean-dilatation volumetric residual and tangent (module docstring)."""
        F = self.deformation_gradient(z)                       # (3, 3, n_el, n_qp)
        J = checked_det(F)
        Fi = inv(F)
        dN, comp, hoop, dx = self._dN, self._comp, self._hoop, self._dx
        w = np.einsum("lLeq,Lieq->lieq", dN, Fi[:2, :2])      # dN_l . F^-1[:, i]
        loc = np.arange(len(comp))
        a = w[loc, comp] + Fi[2, 2] * hoop                     # F^-T : G_l
        V = dx.sum(axis=1)
        Jb = (J * dx).sum(axis=1) / V
        b = np.einsum("leq,eq->le", a, J * dx)
        lnJb = np.log(Jb)
        c = self.lmbda * lnJb / Jb
        r = np.bincount(self._edofs.ravel(), weights=(c * b).ravel(), minlength=self.n_dofs)
        out = Contribution.from_local(self.offset, r)
        if not tangent:
            return out
        wc = w[:, comp]                                        # wc[m, l] = w[m, c_l]
        H = (a[:, None] * a[None, :] - np.swapaxes(wc, 0, 1) * wc
             - hoop[:, None] * hoop[None, :] * Fi[2, 2] ** 2)  # d2J/du_l du_m / J
        ke = (self.lmbda * (1.0 - lnJb) / (Jb * Jb * V) * b[:, None] * b[None, :]
              + c * np.einsum("lmeq,eq->lme", H, J * dx))
        rows, cols = self._tangent_index()
        out.k_rows, out.k_cols, out.k_vals = rows, cols, ke.ravel()
        return out

    def output_data(self, z: np.ndarray) -> tuple[dict, dict]:
        dev = self.material
        self.material = self.full_material
        try:
            return super().output_data(z)
        finally:
            self.material = dev


def split_to_quads(mesh: MeshTri) -> MeshQuad:
    """Each triangle into three quadrilaterals (corner, two edge midpoints, centroid).

    Edge midpoints are shared between neighbours; boundary tags are NOT carried
    over (set them again with ``with_boundaries``).  Quadrilaterals are
    oriented like their triangle (skfem accepts either orientation).
    """
    t = mesh.t
    p = mesh.p
    n_v, n_e = p.shape[1], mesh.facets.shape[1]
    mid = 0.5 * (p[:, mesh.facets[0]] + p[:, mesh.facets[1]])
    cen = p[:, t].mean(axis=1)
    P = np.hstack([p, mid, cen])
    t2f = mesh.t2f                      # facet k of element: opposite to ... (skfem order)
    # skfem's t2f[k] is the facet between local vertices (k, k+1 mod 3)
    e01, e12, e20 = (n_v + t2f[0], n_v + t2f[1], n_v + t2f[2])
    c = n_v + n_e + np.arange(t.shape[1])
    quads = np.hstack([np.vstack([t[0], e01, c, e20]),
                       np.vstack([t[1], e12, c, e01]),
                       np.vstack([t[2], e20, c, e12])])
    return MeshQuad(P, quads)
