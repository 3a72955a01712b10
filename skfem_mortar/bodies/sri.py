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
small strain: ``b_l / V_e`` is the B-bar row ``int B_vol 2 pi R dA / V_e``):

    r_l = lambda ln(J_bar) / J_bar b_l ,
    K_lm = lambda (1 - ln J_bar) / (J_bar^2 V_e) b_l b_m
           + lambda ln(J_bar) / J_bar int d^2 J / du_l du_m 2 pi R dA ,

``d^2 J / dF_iJ dF_kL = J (F^-1_Ji F^-1_Lk - F^-1_Jk F^-1_Li)``.  Contact surfaces keep
their straight 2-node segments (quad1 facets), so every contact method applies.
:func:`split_to_quads` turns a triangle mesh (e.g. the graded Hertz meshes)
into a quadrilateral one.
"""
from __future__ import annotations

import numpy as np
from skfem import Basis, ElementQuad1, ElementVector, MeshQuad, MeshTri
from skfem.helpers import grad, inv

from .deformation import checked_det
from .hyperelastic import NeoHooke
from ..core.item import Contribution
from .solid import Solid, internal_force, material_stiffness, refuse_reduction

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
    """A quad1 neo-Hookean solid with the volumetric energy integrated at one point.

    Parameters
    ----------
    mesh : skfem.MeshQuad
    material : NeoHooke
        Its ``mu`` goes to the fully integrated part, its ``lmbda`` to the
        reduced one; any ``nu`` in ``(-1, 0.5)``.
    name : str
    kinematics : {"finite"}
        Only finite strain (the split is of the neo-Hookean energy).
    plane : {"strain"}
        Only plane strain: plane stress does not lock (its in-plane
        ``lambda* = 2 lambda mu / (lambda + 2 mu)`` stays below ``2 mu``), use
        :class:`~skfem_mortar.bodies.solid.Solid`.

    Notes
    -----
    Residual and tangent are the exact derivatives of the split discrete energy,
    so Newton converges quadratically.  Stress output (``output_data``) is the
    full neo-Hookean Cauchy stress at the 2 x 2 points, smoothed per element.
    """

    geometries = ("plane", "axisymmetric")

    def __init__(self, mesh: MeshQuad, material: NeoHooke, name: str = "solid", *,
                 kinematics: str = "finite", plane: str = "strain"):
        refuse_reduction(type(self).__name__, kinematics, plane)
        if not isinstance(material, NeoHooke):
            raise ValueError("material must be a NeoHooke (the split is of its energy)")
        super().__init__(mesh, NeoHooke(mu=material.mu, lmbda=0.0), element="quad1",
                         name=name)
        self.full_material = material
        self.lmbda = float(material.lmbda)
        # one point at the centre of the reference square [0, 1]^2, weight 1:
        # scikit-fem gives quads 2 x 2 points for every intorder, so the rule
        # is passed explicitly (intorder=1 gave 4 points: plain quad1, locking)
        self.vbasis = Basis(mesh, ElementVector(ElementQuad1()), quadrature=ONE_POINT)

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> Contribution:
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
