"""Nearly incompressible solids on mixed u-p triangles: the MINI element.

Linear triangles lock when ``nu -> 0.5`` (Hertz on ``tri1`` at ``nu = 0.499``:
the peak contact pressure 63 % off).  :class:`MixedSolid` discretizes the
compressible neo-Hookean solid of :class:`~skfem_mortar.bodies.materials.NeoHooke`,

    W(F) = W_mu(F) + lambda/2 (ln J)^2,   W_mu = mu/2 (tr C - 2 - 2 ln J),

in its mixed (perturbed Lagrangian) form with an independent pressure ``p``:

    Pi(u, p) = int_Omega0 [ W_mu(F) + p ln J - p^2 / (2 lambda) ] dV .

Eliminating ``p`` (stationarity: ``p = lambda ln J``) gives back ``W``
exactly, so the continuum material is the same; only the discretization
differs.  Displacements are P1 plus a cubic bubble per element
(``ElementVector(ElementTriMini())``), the pressure is continuous P1
(``ElementTriP1``): an inf-sup stable pair, and the bubble vanishes on every
facet, so the boundary trace is linear and every contact method (nts, mortar,
mortar-dual) works unchanged.

Residuals (``v`` displacement, ``q`` pressure test functions)::

    r_u[a] = int Grad v_a : (P_mu + p F^-T) dV ,   P_mu = mu (F - F^-T) ,
    r_p[b] = int q_b (ln J - p / lambda) dV ,

tangent (symmetric)::

    K_uu = int Grad v : (A_mu - p F^-1_Jk F^-1_Li) : Grad du ,
           A_mu = mu delta_ik delta_JL + mu F^-1_Jk F^-1_Li ,
    K_up = int Grad v : F^-T q dV ,   K_pu = K_up^T ,
    K_pp = -(1 / lambda) int q q dV .

Scaling: the item's unknowns are ``[u; p~]`` with the scaled pressure
``p~ = p / s``, ``s = mu / ell``, ``ell = sqrt(mean element area)`` (a length,
like a displacement), and the pressure rows are multiplied by ``s`` (then every
row is a force per unit thickness).  Newton's relative test and the contact
complementarity parameter (the tangent diagonal at displacement dofs) then see
consistent units.  The scaled system is ``diag(1, s) K diag(1, s)``: still
symmetric.

Kernel: with the generalized strain ``e = [Grad u (4 entries, (i, J) -> 2 i + J);
p / s]`` every local dof ``l`` has a column ``B[:, l]`` (a displacement dof:
``dN_l`` in the rows of its component; a pressure dof: ``s N_b`` in row 4), and
with the stress vector ``sigma = [P_mu + p F^-T; ln J - p / lambda]`` and its
derivative ``D = d sigma / d e_unscaled`` (5 x 5, symmetric)

    r_e = sum_q B^T sigma dx ,   K_e = sum_q B^T D B dx ,

one batched product over all elements and quadrature points (``B`` is built
once: total Lagrangian, the reference gradients do not change).

Quadrature: ``intorder = 4`` (six points) by default.  On an affine triangle
the bubble gradient is quadratic, so the linearized integrands are of degree 4
(``Grad bubble . Grad bubble``), 3 (``Grad bubble  q``) and 2 (``q q``): the
order-4 rule integrates the small-strain system exactly; the pressure basis
uses the same points.  Lower orders (>= 2 allowed) under-integrate the bubble.
No static condensation: the bubble dofs are ordinary unknowns of the item.

Axisymmetric (:mod:`.axisymmetric`): ``F`` is the 3 x 3 ``[[F, 0], [0,
F_thth]]``, ``W_mu = mu/2 (tr C - 3 - 2 ln J)`` and ``J = det F`` include the
hoop stretch, ``dV = 2 pi R dA``.  The generalized strain gains the row
``F_thth`` (``B``: ``N_l / R`` on the radial dofs), so ``e`` has 6 entries,
``sigma[4] = P_thth = mu F_thth + (p - mu) / F_thth``, ``sigma[5] = ln J - p /
lambda``, and ``D`` adds ``D[4, 4] = mu + (mu - p) / F_thth^2``, ``D[4, 5] =
1 / F_thth`` (the in-plane and hoop entries do not couple but through ``p``:
``F^-1`` is block diagonal).  Quadrature: the plane order plus one (the
weight ``R`` raises the degree by one; 5 by default).

Every law, both kinematics (:func:`mixed_split`): with the split ``W = W_mu(F) +
lambda/2 q(F)^2`` of :mod:`.volumetric` (``q = ln J``, ``tr E`` or ``tr eps``; small
strain: that of the linearized law) the density is ``W_mu + p q - p^2 / (2 lambda)``,
``sigma = [P_mu + p dq/dF; q - p / lambda]`` and ``D = [[A_mu + p d2q/dF2, dq/dF];
[dq/dF, -1 / lambda]]`` over the same ``B``.  NeoHooke at finite strain keeps the
closed forms above, so its recorded results stay bit for bit (equal to the split's
to round-off: tests/test_volumetric_laws.py).

When to use: nearly incompressible bodies (``nu`` above about 0.45) in contact;
for compressible ones ``Solid(..., "tri1")`` is cheaper and as accurate.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementTriMini, ElementTriP1, ElementVector, MeshTri

from .checks import MAX_INTORDER, check_mesh, quadrature_order
from ..core.coo import element_coo
from skfem.helpers import inv

from .deformation import checked_det
from .geometry_terms import terms_of
from ..core.errors import InversionError
from ..core.item import Contribution
from .axisymmetric import output_names
from .material import Material
from .solid import Solid, constitutive_law, refuse_reduction
from .volumetric import VolumetricSplit

__all__ = ["MixedSolid", "mixed_stress_and_tangent", "mixed_axisymmetric", "mixed_split"]


def mixed_stress_and_tangent(F: np.ndarray, p: np.ndarray, mu: float, lmbda: float,
                             tangent: bool = True
                             ) -> tuple[np.ndarray, np.ndarray | None]:
    """Generalized stress ``sigma`` (5, ...) and its tangent ``D`` (5, 5, ...) of the
    mixed neo-Hookean density at quadrature arrays ``F (2, 2, ...)``, ``p (...)``.

    ``sigma[2 i + J] = (P_mu + p F^-T)[i, J]``, ``sigma[4] = ln J - p / lambda``;
    ``D`` its derivative with respect to ``[F (flattened), p]``.
    ``InversionError`` where ``det F <= 0`` (as in NeoHooke).
    """
    F = np.asarray(F, dtype=float)
    J = checked_det(F)
    Fi = inv(F)                           # Fi[J, i] = F^-1_Ji
    FiT = np.swapaxes(Fi, 0, 1)
    lnJ = np.log(J)
    tail = F.shape[2:]
    sig = np.empty((5,) + tail)
    sig[:4] = (mu * F + (p - mu) * FiT).reshape((4,) + tail)
    sig[4] = lnJ - p / lmbda
    if not tangent:
        return sig, None
    D = np.empty((5, 5) + tail)
    # A[i, J, k, L] = mu d_ik d_JL + (mu - p) F^-1_Jk F^-1_Li
    A = (mu - p) * Fi[None, :, :, None] * FiT[:, None, None, :]
    for i in range(2):
        for jj in range(2):
            A[i, jj, i, jj] += mu
    D[:4, :4] = A.reshape((4, 4) + tail)
    D[:4, 4] = FiT.reshape((4,) + tail)
    D[4, :4] = D[:4, 4]
    D[4, 4] = -1.0 / lmbda
    return sig, D


def mixed_axisymmetric(F: np.ndarray, p: np.ndarray, mu: float, lmbda: float,
                       tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`mixed_stress_and_tangent` with the hoop stretch: ``F`` ``(3, 3, ...)``
    block diagonal, ``sigma`` (6, ...) ``[P (4); P_thth; ln J - p / lambda]``, ``D``
    (6, 6, ...) its derivative with respect to ``[F (4); F_thth; p]`` (module
    docstring)."""
    sig2, D2 = mixed_stress_and_tangent(F[:2, :2], p, mu, lmbda, tangent)
    Ft = F[2, 2]
    if not np.all(Ft > 0.0):
        raise InversionError(f"inverted material point(s): hoop stretch <= 0, min "
                             f"{Ft.min():.3e}")
    sig = np.empty((6,) + sig2.shape[1:])
    sig[:4] = sig2[:4]
    sig[4] = mu * Ft + (p - mu) / Ft
    sig[5] = sig2[4] + np.log(Ft)
    if not tangent:
        return sig, None
    D = np.zeros((6, 6) + sig2.shape[1:])
    D[:4, :4] = D2[:4, :4]
    D[:4, 5] = D[5, :4] = D2[:4, 4]
    D[4, 4] = mu + (mu - p) / (Ft * Ft)
    D[4, 5] = D[5, 4] = 1.0 / Ft
    D[5, 5] = -1.0 / lmbda
    return sig, D


#: the generalized strain's ``F`` entries ``(i, J)``: in-plane, then the hoop ``(2, 2)``
_ROWS = (np.array([0, 0, 1, 1, 2]), np.array([0, 1, 0, 1, 2]))


def mixed_split(F: np.ndarray, p: np.ndarray, split: VolumetricSplit, tangent: bool = True
                ) -> tuple[np.ndarray, np.ndarray | None]:
    """Generalized stress and tangent of the mixed density ``W_mu(F) + p q(F) - p^2 /
    (2 lambda)`` of any law's :class:`~skfem_mortar.bodies.volumetric.VolumetricSplit`.

    ``F`` ``(2, 2, ...)`` (plane strain) or the block-diagonal ``(3, 3, ...)`` with the
    hoop stretch; with ``k = 4`` or ``5`` entries of ``F`` (:data:`_ROWS`),

        sigma[:k] = (P_mu + p dq/dF)[i, J],      sigma[k] = q - p / lambda ,
        D[:k, :k] = (A_mu + p d2q/dF2)[i, J, k, L] ,
        D[:k, k] = D[k, :k] = dq/dF[i, J],       D[k, k] = -1 / lambda ,

    the layout of :func:`mixed_stress_and_tangent` and :func:`mixed_axisymmetric` (equal
    to them for NeoHooke up to round-off).  Small strain: the split of the linearized law
    (``q = tr eps``, ``P_mu = 2 mu eps``).  InversionError where ``det F <= 0`` or the hoop
    stretch ``<= 0`` (finite strain).
    """
    F = np.asarray(F, dtype=float)
    k = 4 if F.shape[0] == 2 else 5
    I, J = _ROWS[0][:k], _ROWS[1][:k]
    if k == 5 and split.kind != "linear" and not np.all(F[2, 2] > 0.0):
        raise InversionError(f"inverted material point(s): hoop stretch <= 0, min "
                             f"{F[2, 2].min():.3e}")
    P, A = split.shear.stress_and_tangent(F, tangent=tangent)
    q, dq, d2q = split.log_measure(F, tangent)
    sig = np.empty((k + 1,) + F.shape[2:])
    sig[:k] = (P + p * dq)[I, J]
    sig[k] = q - p / split.lmbda
    if not tangent:
        return sig, None
    D = np.empty((k + 1,) + sig.shape)
    D[:k, :k] = (A + p * d2q)[I[:, None], J[:, None], I[None, :], J[None, :]]
    D[:k, k] = D[k, :k] = dq[I, J]
    D[k, k] = -1.0 / split.lmbda
    return sig, D


class MixedSolid(Solid):
    """A plane-strain or axisymmetric body on MINI triangles (P1 + bubble / P1 pressure).

    Parameters
    ----------
    mesh : skfem.MeshTri
        Reference configuration; named boundaries can be used by :meth:`dofs_on`.
    material : Material
        NeoHooke, SaintVenantKirchhoff or LinearElastic with ``lmbda > 0`` (``nu > 0``:
        the pressure equation divides by ``lmbda``).
    name : str
        Item name.
    intorder : int
        Quadrature order (>= 2) of the displacement and pressure bases, default 4
        (exact for the linearized integrands, see the module docstring); in an
        axisymmetric model one more (the weight ``R`` raises the degree by one).
    kinematics : {"finite", "small"}, optional
        Finite strain (the law's split) or small strain (the split of its
        linearization, ``q = tr eps``); default as
        :class:`~skfem_mortar.bodies.solid.Solid`: ``"small"`` for a LinearElastic
        material, else ``"finite"``.
    plane : {"strain"}, optional
        Only plane strain: the pressure constrains the volume of the in-plane
        motion, and plane stress does not lock (use
        :class:`~skfem_mortar.bodies.solid.Solid` with ``plane="stress"``).

    Attributes
    ----------
    material : Material
        The law evaluated (linearized for small kinematics).
    split : VolumetricSplit
        Its shear part and volume measure ``q``.

    Notes
    -----
    Local unknowns ``[u (N_u); p~ (N_p)]``: the MINI vector basis dofs (vertex
    dofs, then one bubble per element and component, skfem's numbering) and the
    scaled nodal pressures ``p~ = p / s``, ``s = mu / ell`` (:attr:`pressure_scale`).
    """

    element = "mini"
    dof_kind = "u"
    phase = "bulk"
    geometries = ("plane", "axisymmetric")
    _geometry = "plane"

    def __init__(self, mesh: MeshTri, material: Material, name: str = "solid",
                 intorder: int = 4, *, kinematics: str | None = None,
                 plane: str | None = None):
        refuse_reduction(type(self).__name__, plane)
        if not isinstance(mesh, MeshTri):
            raise ValueError(f"mesh must be a skfem.MeshTri (linear triangles), "
                             f"got {type(mesh).__name__}")
        law, kinematics = constitutive_law(material, kinematics)
        self.split = VolumetricSplit(law)
        if not law.lmbda > 0.0:
            raise ValueError(f"material must have lmbda > 0 (nu > 0): the pressure equation "
                             f"divides by lmbda (got lmbda = {law.lmbda})")
        self._intorder = quadrature_order(intorder, 2)
        check_mesh(mesh, f"mesh of {name!r}")
        self.mesh = mesh
        self.material = law
        self.kinematics, self.plane = kinematics, "strain"
        self.name = name
        self._cell_type = "triangle"
        self._n_nodes = int(mesh.nvertices)
        self._make_basis()

    def _make_basis(self) -> None:
        """The bases (their quadrature from the geometry's terms), scales and kernel data."""
        terms = terms_of(self._geometry)
        extra = 0 if self._geometry == "plane" else 1
        self.intorder = min(self._intorder + extra, MAX_INTORDER)
        kw = terms.quadrature("mini", self.intorder)
        self.basis = Basis(self.mesh, ElementVector(ElementTriMini()), **kw)
        self.pbasis = Basis(self.mesh, ElementTriP1(), quadrature=self.basis.quadrature)
        self._kernel_data()                      # u-part: _edofs, _comp, _dN, _dx, _hoop
        self.n_u = int(self.basis.N)
        self.n_p = int(self.pbasis.N)
        self.n_dofs = self.n_u + self.n_p
        self.dof_component = np.zeros(self.n_u, dtype=np.int64)
        self.dof_component[self._edofs.ravel()] = np.repeat(self._comp, self._edofs.shape[1])
        #: ``ell = sqrt(mean element area)`` and ``s = mu / ell`` (p = s p~)
        self.length_scale = float(np.sqrt(np.mean(np.sum(np.asarray(self.basis.dx), axis=1))))
        self.pressure_scale = float(self.material.mu) / self.length_scale
        self._mixed_kernel_data()

    def _mixed_kernel_data(self) -> None:
        """The generalized strain operator ``B`` (n_el, n_qp * 5, n_loc) and the local dofs."""
        pe = np.asarray(self.pbasis.element_dofs, dtype=np.int64)        # (3, n_el)
        self._pdofs = pe
        self._alldofs = np.vstack([self._edofs, self.n_u + pe])          # (n_loc, n_el)
        self._N = np.stack([np.asarray(self.pbasis.basis[b][0])
                            for b in range(self.pbasis.Nbfun)])           # (3, n_el, n_qp)
        n_u_loc, n_p_loc = self._edofs.shape[0], pe.shape[0]
        n_el, n_qp = self._dx.shape
        ng = self._n_gen = 5 if self._hoop is None else 6    # generalized strain entries
        B = np.zeros((n_el, n_qp, ng, n_u_loc + n_p_loc))
        for l, c in enumerate(self._comp):
            B[:, :, 2 * c, l] = self._dN[l, 0]
            B[:, :, 2 * c + 1, l] = self._dN[l, 1]
            if self._hoop is not None:
                B[:, :, 4, l] = self._hoop[l]
        for b in range(n_p_loc):
            B[:, :, ng - 1, n_u_loc + b] = self.pressure_scale * self._N[b]
        self._B = B.reshape(n_el, n_qp * ng, -1)
        self._mixed_idx: tuple[int, np.ndarray, np.ndarray] | None = None

    def _mixed_index(self) -> tuple[np.ndarray, np.ndarray]:
        """Global COO rows and columns of the element tangents ``(n_el, n_loc, n_loc)``."""
        if self._mixed_idx is None or self._mixed_idx[0] != self.offset:
            self._mixed_idx = (self.offset, *element_coo(self.offset + self._alldofs.T))
        return self._mixed_idx[1], self._mixed_idx[2]

    # -- fields at quadrature points ------------------------------------------
    def pressure_dofs(self) -> np.ndarray:
        """Local indices of the scaled pressure unknowns (``n_u .. n_dofs - 1``)."""
        return self.n_u + np.arange(self.n_p, dtype=np.int64)

    def pressure(self, z: np.ndarray) -> np.ndarray:
        """Nodal pressures ``p = s p~`` (stress units), length ``n_p`` (= vertices)."""
        return self.pressure_scale * np.asarray(self.u(z), dtype=float)[self.n_u:]

    def pressure_at_points(self, z: np.ndarray) -> np.ndarray:
        """``p`` on all quadrature points, ``(n_el, n_qp)``."""
        pe = self.pressure(z)[self._pdofs]                               # (3, n_el)
        return np.einsum("be,beq->eq", pe, self._N)

    def interpolate(self, fun: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """Local dof vector (length ``n_dofs``) of the interpolant of ``u = fun(X)``:
        vertex values, bubble coefficients so that ``u`` matches ``fun`` at the
        centroids, zero pressure."""
        # skfem gives no location for the bubble dofs (nan): use the centroids
        ib = np.asarray(self.basis.interior_dofs, dtype=np.int64)        # (2, n_el)
        t = self.mesh.t
        pts = np.array(self.basis.doflocs, dtype=float)
        cen = self.mesh.p[:, t].mean(axis=1)
        pts[:, ib[0]] = cen
        pts[:, ib[1]] = cen
        vals = np.asarray(fun(pts), dtype=float)
        if vals.shape != pts.shape:
            raise ValueError(f"fun must return an array of shape {pts.shape}")
        out = np.zeros(self.n_dofs)
        out[:self.n_u] = vals[self.dof_component, np.arange(self.n_u)]
        # the bubble is 27 l1 l2 l3 (1 at the centroid): its coefficient is the
        # centroid value minus the mean of the vertex values
        for c in (0, 1):
            out[ib[c]] -= out[self.node_dofs[c][t]].mean(axis=0)
        return out

    # -- assembly ----------------------------------------------------------------
    def _state(self, z: np.ndarray, tangent: bool):
        F = self.deformation_gradient(z)
        p = self.pressure_at_points(z)
        if self.split.kind != "log":          # the split of any other law
            return mixed_split(F, p, self.split, tangent)
        # NeoHooke at finite strain: its closed form (the same numbers to round-off)
        law = mixed_stress_and_tangent if self._hoop is None else mixed_axisymmetric
        return law(F, p, self.material.mu, self.material.lmbda, tangent)

    def _local(self, z: np.ndarray, tangent: bool
               ) -> tuple[np.ndarray, np.ndarray | None]:
        """Element residuals ``(n_el, n_loc)`` and tangents ``(n_el, n_loc, n_loc)``."""
        sig, D = self._state(z, tangent)
        n_el, n_qp = self._dx.shape
        ng = self._n_gen
        sdx = np.moveaxis(sig * self._dx, 0, -1).reshape(n_el, n_qp * ng)  # (n_el, Q*ng)
        re = np.einsum("ea,eal->el", sdx, self._B)
        if not tangent:
            return re, None
        Ddx = np.moveaxis(D * self._dx, (0, 1), (-2, -1))                   # (n_el, Q, 5, 5)
        B4 = self._B.reshape(n_el, n_qp, ng, -1)
        T = np.matmul(Ddx, B4).reshape(n_el, n_qp * ng, -1)
        ke = np.matmul(np.swapaxes(self._B, 1, 2), T)
        return re, ke

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> Contribution:
        re, ke = self._local(z, tangent)
        r = np.bincount(self._alldofs.T.ravel(), weights=re.ravel(), minlength=self.n_dofs)
        out = Contribution.from_local(self.offset, r)
        if tangent:
            out.k_rows, out.k_cols = self._mixed_index()
            out.k_vals = ke.ravel()
        return out

    def internal_force(self, z: np.ndarray) -> np.ndarray:
        """The item's residual on its local dofs (length ``n_dofs``): the internal
        force ``int Grad v : (P_mu + p F^-T) dV`` on the displacement dofs and the
        scaled constraint ``s int q (ln J - p / lambda) dV`` on the pressure dofs."""
        re, _ = self._local(z, False)
        return np.bincount(self._alldofs.T.ravel(), weights=re.ravel(), minlength=self.n_dofs)

    def assemble_forms(self, z: np.ndarray, tangent: bool = True
                       ) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Residual and tangent through skfem's form assembly (a reference for
        :meth:`assemble`; local numbering, length ``n_dofs``; plane geometry only)."""
        if self._hoop is not None:
            raise ValueError(f"assemble_forms is the plane reference; {self.name!r} is in "
                             f"an {self._geometry!r} model: use assemble")
        from skfem import BilinearForm, LinearForm
        from skfem.helpers import ddot, grad

        sig, D = self._state(z, tangent)
        tail = sig.shape[1:]
        s, lm = self.pressure_scale, self.material.lmbda
        P = sig[:4].reshape((2, 2) + tail)
        ru = LinearForm(lambda v, w: ddot(w.P, grad(v))).assemble(self.basis, P=P)
        rp = LinearForm(lambda q, w: s * w.g * q).assemble(self.pbasis, g=sig[4])
        r = np.concatenate([ru, rp])
        if not tangent:
            return r, None
        At = np.transpose(D[:4, :4].reshape((2, 2, 2, 2) + tail), (2, 3, 0, 1, 4, 5))
        Kuu = BilinearForm(lambda du, v, w: ddot(ddot(w.At, grad(du)), grad(v))
                           ).assemble(self.basis, At=At)
        FiT = D[:4, 4].reshape((2, 2) + tail)
        Kpu = BilinearForm(lambda du, q, w: s * q * ddot(w.FiT, grad(du))
                           ).assemble(self.basis, self.pbasis, FiT=FiT)
        Kpp = BilinearForm(lambda dp, q, w: -(s * s / lm) * dp * q).assemble(self.pbasis)
        return r, sp.bmat([[Kuu, Kpu.T], [Kpu, Kpp]], format="csr")

    # -- output ------------------------------------------------------------------
    def cauchy(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mixed Cauchy stress on the quadrature points: ``sigma = J^-1 (P_mu + p dq/dF)
        F^T`` (2, 2, n_el, n_qp) and ``sigma_zz = p / J`` (plane strain, ``F_zz = 1``: the
        shear part has no ``P_zz`` and ``dq/dF_zz = 1`` for every law), equal to the law's
        own when ``p = lambda q``; axisymmetric: the hoop ``sigma_thth = P_thth F_thth / J``
        in its place.  Small strain: ``sigma = P_mu + p I`` itself, ``sigma_zz = p``."""
        F = self.deformation_gradient(z)
        sig, _ = self._state(z, False)
        P = sig[:4].reshape((2, 2) + F.shape[2:])
        if self.kinematics == "small":
            return P, (sig[4] if self._hoop is not None else self.pressure_at_points(z))
        J = checked_det(F)
        sigma = np.einsum("iJ...,kJ...->ik...", P, F[:2, :2]) / J
        if self._hoop is not None:
            return sigma, sig[4] * F[2, 2] / J
        return sigma, self.pressure_at_points(z) / J

    def output_data(self, z: np.ndarray) -> tuple[dict, dict]:
        """Point data ``displacement`` (N, 2) and ``pressure`` (N,) (stress units);
        cell data: element-averaged mixed Cauchy stress ``sigma_xx, sigma_yy,
        sigma_xy, sigma_zz`` and ``von_mises``."""
        u = self.u(z)[self.node_dofs].T.copy()
        pn = self.pressure(z)[np.asarray(self.pbasis.nodal_dofs[0], dtype=np.int64)]
        s, szz = self.cauchy(z)
        vm = np.sqrt(0.5 * ((s[0, 0] - s[1, 1]) ** 2 + (s[1, 1] - szz) ** 2
                            + (szz - s[0, 0]) ** 2) + 3.0 * s[0, 1] ** 2)
        avg = self.element_average
        cells = {"sigma_xx": [avg(s[0, 0])], "sigma_yy": [avg(s[1, 1])],
                 "sigma_xy": [avg(s[0, 1])], "sigma_zz": [avg(szz)],
                 "von_mises": [avg(vm)]}
        return {"displacement": u, "pressure": pn}, output_names(cells, self._geometry)
