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

(the neo-Hookean stress and tangent with ``mu = 0``).  Contact surfaces keep
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

    geometries = ("plane",)

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
