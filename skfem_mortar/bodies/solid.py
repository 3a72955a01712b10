"""An elastic solid, finite or small strain, discretized with scikit-fem: 2D (plane
strain or plane stress; tri1, tri2, quad1, quad2) or 3D (tet1, tet2, hex1, hex2; the
nearly incompressible p2p1 and hex1-md in :mod:`.taylor_hood` and
:mod:`.mean_dilatation`).  The dimension ``d`` is the mesh's; the kernel below is the
same for both, over the components ``0 .. d - 1``.

The internal virtual work of a body with reference domain ``Omega_0``,

    r(u)_a = int_Omega0 Grad v_a : P(F) dV ,        F = I + Grad u ,

and its consistent tangent

    K(u)_ab = int_Omega0 Grad v_a : A(F) : Grad v_b dV ,   A = dP/dF ,

are the skfem forms ``internal_force``/``material_stiffness`` below over a vector
basis; the stress ``P`` and tangent ``A`` are evaluated once per assembly on all
quadrature points (vectorized, see :mod:`skfem_mortar.bodies.materials`).

Kinematics: ``kinematics="finite"`` (default for hyperelastic materials) uses
the material's ``P(F)``; ``kinematics="small"`` its linearization at ``F = I``
(:class:`~skfem_mortar.bodies.materials.LinearElastic`:
``sigma = lambda tr(eps) I + 2 mu eps``, ``eps = sym Grad u``, in the place
of ``P``: the residual ``int Grad v : sigma dV`` and the constant tangent).
Only the bulk is linearized: the body's current configuration is still
``x = X + u`` (:meth:`Solid.x`), and contact, follower pressures and the
preflight use it with their finite-deformation kernels, so rigid motions and
sliding stay exact.  What that leaves between this model and the fully
linearized contact of linear Hertz theory (gap along the reference normal,
pressures on the reference surface) is measured in ``scenes/hertz.py``.

Plane: ``plane="strain"`` (``F_zz = 1``, default) or ``"stress"``
(``S_zz = 0``, :meth:`~skfem_mortar.bodies.materials.Material.with_plane`).
Stresses and internal forces are per unit reference thickness; a model's
thickness ``H`` (``Model(items, thickness=H)``) multiplies them.

Speed: :meth:`Solid.assemble` evaluates the same integrals with kernels of its
own instead of the generic skfem form assembly (which contracts full
``(d, d)`` gradients of every vector basis function with ``A`` by ``einsum``
and sorts a fresh COO matrix each time): the scalar shape function gradients
``dN`` and the weights ``dx`` of the basis are cached once, each local vector
dof ``l`` has one component ``c_l``, and

    r_e[l]    = sum_q  P[c_l, J] dN[l, J] dx ,
    K_e[l, m] = sum_q  dN[l, J] A[c_l, J, c_m, L] dN[m, L] dx ,

with the global COO index arrays built once (the model sums them into a fixed
CSR pattern, see :meth:`skfem_mortar.core.model.Model.assemble`).  Linear triangles
and tetrahedra use the one-point (centroid) rule: ``Grad u`` is constant per
element, so it is exact.  The tests compare both paths.
"""
from __future__ import annotations

import importlib
from typing import Callable

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementVector, LinearForm, Mesh
from skfem.helpers import ddot, grad

from .checks import check_element, check_mesh, check_mesh_3d, quadrature_order
from .solid_setup import (ELEMENTS, ELEMENTS_3D, KINEMATICS, SPECIAL_ELEMENTS, _as_slice,
                          _component_index, boundary_facets, constitutive_law,
                          displacement_element, element_domains, refuse_reduction)
from .geometry_terms import TERMS, terms_of
from .hoop import hoop_gradient, hoop_residual, hoop_tangent
from .solid_output import nodal_output
from ..core.coo import element_coo
from .materials import Material
from ..core.item import Contribution, Item
from ..core.validate_arrays import index_array

__all__ = ["Solid", "ELEMENTS", "ELEMENTS_3D", "SPECIAL_ELEMENTS", "KINEMATICS",
           "element_domains", "displacement_element", "boundary_facets", "constitutive_law",
           "refuse_reduction"]

#: elements per block of the one-point tangent kernel (its temporaries then stay
#: in the cache; measured at hertz ``refine=3``: 4096 to 16384 alike, 2x faster
#: than all elements at once)
CHUNK = 8192
#: elements per block of the 3D multi-point tangent kernel (measured on hex1: 1024
#: and 4096 alike, 256 slower by a third)
CHUNK_3D = 1024

@LinearForm
def internal_force(v, w):
    """``Grad v : P`` with ``P`` given on the quadrature points as ``w.P``."""
    return ddot(w.P, grad(v))


@BilinearForm
def material_stiffness(du, v, w):
    """``Grad v : A : Grad du``; ``w.At[k, L, i, J] = A[i, J, k, L]``.

    ``ddot(w.At, grad(du))`` contracts the first two indices of ``At`` (those
    of ``du``), leaving the ``(i, J)`` pair that is contracted with ``Grad v``.
    """
    return ddot(ddot(w.At, grad(du)), grad(v))


class Solid(Item):
    """An elastic body, 2D (plane strain or stress) or 3D: an
    :class:`~skfem_mortar.core.item.Item` with ``dof_kind="u"``.

    Parameters
    ----------
    mesh : skfem.Mesh
        Reference configuration: ``MeshTri`` for ``tri*``, ``MeshQuad`` for
        ``quad*``, ``MeshTet1``/``MeshTet2`` for ``tet*`` and ``p2p1``,
        ``MeshHex1``/``MeshHex2`` for ``hex*`` and ``hex1-md``.  Named boundaries
        (``mesh.boundaries``) can be used by :meth:`dofs_on`.
    material : Material
        :class:`~skfem_mortar.bodies.materials.NeoHooke`,
        :class:`~skfem_mortar.bodies.materials.SaintVenantKirchhoff` or
        :class:`~skfem_mortar.bodies.materials.LinearElastic`.
    element : {"tri1", "tri2", "quad1", "quad2", "tet1", "tet2", "hex1", "hex2", "p2p1", "hex1-md"}
        Lagrange element of the displacement field; ``"p2p1"`` (Taylor-Hood u-p
        tetrahedra, :mod:`.taylor_hood`) and ``"hex1-md"`` (mean dilatation,
        :mod:`.mean_dilatation`) build their own classes.
    name : str
        Item name.
    intorder : int, optional
        Quadrature order. Default: the centroid for ``tri1`` and ``tet1``
        (``Grad u`` and hence the integrand are constant per element, so one
        point is exact); 3 (five points) for ``tet2``, 3 (2 x 2 x 2 Gauss) for
        ``hex1``, 5 (3 x 3 x 3) for ``hex2``: the lowest orders that integrate
        ``int Grad N dV`` exactly on curved (isoparametric) elements, so that a
        homogeneous deformation is exact (tet2 at order 2, four points: 2e-5
        off with mid-edge nodes moved by 5 % of a cell); 2D: skfem's default
        (twice the element order).
    kinematics : {"finite", "small"}, optional
        Finite strain (the material's ``P(F)``) or small strain (its
        linearization, ``sigma = lambda tr(eps) I + 2 mu eps``; module
        docstring: contact still sees ``x = X + u``).  Default: ``"small"``
        for a LinearElastic material, else ``"finite"``.
    plane : {"strain", "stress"}, optional
        2D only: plane strain (``F_zz = 1``, the default) or plane stress
        (``S_zz = 0``).  Refused for a 3D mesh.

    Attributes
    ----------
    material : Material
        The law evaluated: the given material in ``plane``, linearized for
        small kinematics (:func:`constitutive_law`).
    dim : int
        2 or 3, from the mesh.
    """

    dof_kind = "u"
    loaded = False  # its residual does not depend on the load factor
    phase = "bulk"
    dim = 2         # the subclasses of 2D meshes only keep it

    def __new__(cls, *args, **kwargs):
        """``Solid(..., element=name)`` with a name of :data:`SPECIAL_ELEMENTS` builds
        that element's class (the same arguments)."""
        element = kwargs.get("element", args[2] if len(args) > 2 else None)
        if cls is Solid and isinstance(element, str) and element in SPECIAL_ELEMENTS:
            _, _, module, name = SPECIAL_ELEMENTS[element]
            return super().__new__(getattr(importlib.import_module(module), name))
        return super().__new__(cls)

    def __init__(self, mesh: Mesh, material: Material, element: str = "tri1",
                 name: str = "solid", intorder: int | None = None, *,
                 kinematics: str | None = None, plane: str | None = None):
        check_element(mesh, element, element_domains())
        self.dim = int(mesh.dim())
        if self.dim == 3 and plane is not None:
            raise ValueError(f"plane applies to a 2D body only; a 3D mesh has no plane "
                             f"reduction (got plane={plane!r}): leave it out")
        plane = "strain" if plane is None else plane     # 3D: None, the check above
        material, kinematics = constitutive_law(material, kinematics, plane)
        if intorder is not None:
            intorder = quadrature_order(intorder, 1)
        if self.dim == 2:
            elem_cls, _, cell_type = ELEMENTS[element]
            check_mesh(mesh, f"mesh of {name!r}")  # folded, zero-area, non-convex elements
        else:
            elem_cls, _, cell_type, _ = ELEMENTS_3D[element]
            check_mesh_3d(mesh, f"mesh of {name!r}")  # inverted, flat, unreferenced nodes
        self.mesh = mesh
        self.material = material
        self.kinematics = kinematics
        self.plane = plane if self.dim == 2 else None
        self.element = element
        self.name = name
        self._cell_type = cell_type
        self._elem_cls, self._intorder = elem_cls, intorder
        self._geometry = "plane" if self.dim == 2 else "3d"
        self._make_basis()
        self.n_dofs = int(self.basis.N)
        self._n_nodes = int(mesh.nvertices)
        every = self.basis.get_dofs(elements=np.arange(mesh.nelements))
        self.dof_component = np.zeros(self.n_dofs, dtype=np.int64)
        for c in range(1, self.dim):
            self.dof_component[np.asarray(every.all([f"u^{c + 1}"]), dtype=np.int64)] = c

    # -- the geometry (the model's, :mod:`.geometry_terms`) -------------------
    @property
    def geometries(self) -> tuple[str, ...]:
        """The geometries this solid works in: those with kernel terms (2D), ``("3d",)``
        (a 3D mesh)."""
        return tuple(TERMS) if self.dim == 2 else ("3d",)

    @property
    def geometry(self) -> str:
        """The model's geometry; setting another rebuilds the basis and kernel data."""
        return self._geometry

    @geometry.setter
    def geometry(self, value: str) -> None:
        if value != self._geometry:
            if self.dim == 3:
                raise ValueError(f"geometry must be '3d' for a body on a 3D mesh "
                                 f"({self.name!r}), got {value!r}")
            terms_of(value)
            self._geometry = value
            self._make_basis()

    def _make_basis(self) -> None:
        """The vector basis (its quadrature from the geometry's terms) and the kernel data."""
        if self.dim == 3:
            order = self._intorder or ELEMENTS_3D[self.element][3]
            kw = {"intorder": order} if order else \
                {"quadrature": (np.full((3, 1), 0.25), np.array([1.0 / 6.0]))}
        else:
            kw = terms_of(self._geometry).quadrature(self.element, self._intorder)
        if not kw and self.element == "tri1" and self._geometry == "plane":
            # the centroid: exact for piecewise constant integrands (skfem's
            # lowest triangle rule has three points)
            kw = {"quadrature": (np.array([[1.0 / 3.0], [1.0 / 3.0]]), np.array([0.5]))}
        self.basis = Basis(self.mesh, ElementVector(self._elem_cls()), **kw)
        self._kernel_data()

    def _kernel_data(self) -> None:
        """Cache what every assembly needs: local dofs, components, ``dN``, ``dx``
        (times the geometry's weight) and the hoop term (:mod:`.geometry_terms`)."""
        b, d = self.basis, self.dim
        self._edofs = np.asarray(b.element_dofs, dtype=np.int64)       # (n_loc, n_el)
        grads = [np.asarray(b.basis[l][0].grad) for l in range(b.Nbfun)]  # (d, d, n_el, n_qp)
        self._comp = np.array([int(np.argmax(np.abs(g).sum(axis=(1, 2, 3)))) for g in grads])
        self._dN = np.stack([g[c] for g, c in zip(grads, self._comp)])  # (n_loc, d, n_el, n_qp)
        if d == 3:
            self._dx, self._hoop = np.asarray(b.dx), None
        else:
            terms = terms_of(self._geometry)
            weight = terms.weight(b)
            self._dx = np.asarray(b.dx) if weight is None else np.asarray(b.dx) * weight
            self._hoop = terms.hoop(b, self._comp)          # None or (n_loc, n_el, n_qp)
        self._dNdx = self._dN * self._dx                                 # the residual's
        # each component's local dofs and dN (copies: Grad u reads them every call)
        self._by_component = [(self._edofs[self._comp == c], self._dN[self._comp == c])
                              for c in range(d)]
        # the local dofs of each component as slices (None unless evenly spaced)
        on = [_as_slice(np.flatnonzero(self._comp == c)) for c in range(d)]
        self._comp_slices = list(enumerate(on)) if all(isinstance(o, slice) for o in on) else None
        self._kidx: tuple[int, np.ndarray, np.ndarray, np.ndarray] | None = None

    def _tangent_index(self) -> tuple[np.ndarray, np.ndarray]:
        """Global COO rows and columns of the element tangents ``(n_loc, n_loc, n_el)``,
        built once per offset (the same arrays every call)."""
        if self._kidx is None or self._kidx[0] != self.offset:
            dofs = self.offset + self._edofs
            self._kidx = (self.offset, *element_coo(dofs, elements_last=True), dofs)
        return self._kidx[1], self._kidx[2]

    def _grad_u(self, u: np.ndarray) -> np.ndarray:
        """``Grad u`` on all quadrature points, ``(d, d, n_el, n_qp)``, from the cached ``dN``."""
        G = np.zeros((self.dim,) + self._dN.shape[1:])
        for c, (edofs, dN) in enumerate(self._by_component):
            G[c] = np.einsum("le,lJeq->Jeq", u[edofs], dN)
        return G

    # -- geometry ----------------------------------------------------------
    @property
    def X(self) -> np.ndarray:
        """Reference coordinates of the mesh vertices, shape ``(d, n_nodes)``."""
        return self.mesh.p[:, :self.n_nodes]

    @property
    def n_nodes(self) -> int:
        """Number of mesh vertices (quadratic meshes list their vertices first)."""
        return self._n_nodes

    @property
    def node_dofs(self) -> np.ndarray:
        """Local dofs of the vertices, ``(d, n_nodes)``: row 0 x-, row 1 y-, (3D) row 2 z-dofs."""
        return self.basis.nodal_dofs

    def u(self, z: np.ndarray) -> np.ndarray:
        """The body's block of ``z`` (all its displacement dofs)."""
        return np.asarray(z)[self.dofs]

    def x(self, z: np.ndarray) -> np.ndarray:
        """Current vertex coordinates ``X + u``, shape ``(d, n_nodes)``."""
        return self.X + self.u(z)[self.node_dofs]

    def interpolate(self, fun: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """Local dof vector of the nodal interpolant of ``u = fun(X)``.

        ``fun`` maps reference points ``(d, n)`` to displacements ``(d, n)``.
        """
        pts = self.basis.doflocs
        vals = np.asarray(fun(pts), dtype=float)
        if vals.shape != pts.shape:
            raise ValueError(f"fun must return an array of shape {pts.shape}")
        return vals[self.dof_component, np.arange(self.n_dofs)]

    def dofs_on(self, boundary: str | np.ndarray | Callable, component: int | str | None = None
                ) -> np.ndarray:
        """Local dofs on a boundary (vertex and, for quadratic elements, facet dofs).

        Parameters
        ----------
        boundary : str, array of int or callable
            A tag of ``mesh.boundaries``, an array of facet indices, or a
            function ``f(x) -> bool array`` of facet midpoints ``x (d, n)``
            (skfem's convention: interior facets are tested too).
        component : {None, 0, 1, 2, "x", "y", "z"}
            All components (None) or only one (2 and "z" in 3D).
        """
        if isinstance(boundary, str):
            boundary_facets(self.mesh, boundary)        # an unknown tag raises
        elif not callable(boundary):                    # indices or a mask, checked
            boundary = boundary_facets(self.mesh, boundary)
        view = self.basis.get_dofs(boundary)
        c = _component_index(component, self.dim)
        out = view.all() if c is None else view.all([f"u^{c + 1}"])
        return np.unique(np.asarray(out, dtype=np.int64))

    def dofs_at_nodes(self, nodes: np.ndarray, component: int | str | None = None
                      ) -> np.ndarray:
        """Local dofs of a set of vertices (indices into ``X``)."""
        nodes = index_array("nodes", nodes, self.n_nodes).ravel()
        c = _component_index(component, self.dim)
        nd = self.node_dofs if c is None else self.node_dofs[[c]]
        return np.unique(nd[:, nodes].ravel().astype(np.int64))

    # -- kinematics and stress at quadrature points ---------------------------
    def deformation_gradient(self, z: np.ndarray) -> np.ndarray:
        """``F = I + Grad u`` on all quadrature points, shape ``(d, d, n_el, n_qp)``,
        for the global unknowns ``z`` (every method taking ``z`` expects the global vector)."""
        u = np.asarray(self.u(z), dtype=float)
        F = self._grad_u(u)
        for i in range(self.dim):
            F[i, i] += 1.0
        return F if self._hoop is None else hoop_gradient(F, u, self._edofs, self._hoop)

    def first_piola(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``F`` and the stress ``P`` (``sigma`` at small strain) on all quadrature
        points, ``(d, d, n_el, n_qp)`` each (what the output pushes forward)."""
        F = self.deformation_gradient(z)
        return F, self.material.stress(F)

    def internal_force(self, z: np.ndarray) -> np.ndarray:
        """Internal force ``int Grad v : P dV`` on the body's dofs (length ``n_dofs``)
        at the global unknowns ``z``."""
        P = self.material.stress(self.deformation_gradient(z))
        return internal_force.assemble(self.basis, P=P)

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> Contribution:
        F = self.deformation_gradient(z)
        P, A = self.material.stress_and_tangent(F, tangent=tangent)
        re = self._residuals(P)
        if self._hoop is not None:
            re += hoop_residual(P, self._hoop, self._dx)
        r = np.bincount(self._edofs.ravel(), weights=re.ravel(), minlength=self.n_dofs)
        if not tangent:
            return Contribution.from_local(self.offset, r)
        if self._hoop is not None:
            ke = self._tangents(A[:2, :2, :2, :2] * self._dx)
            ke += hoop_tangent(A, self._dN, self._comp, self._hoop, self._dx)
        elif self._dx.shape[1] == 1 and self._comp_slices:
            ke = self._tangents_one_point(A)
        else:
            ke = self._tangents(A * self._dx)
        rows, cols = self._tangent_index()
        out = Contribution.from_local(self.offset, r)
        out.k_rows, out.k_cols, out.k_vals = rows, cols, ke.ravel()
        out.k_elements = self._kidx[3]
        return out

    def _residuals(self, P: np.ndarray) -> np.ndarray:
        """Element residuals ``r_e[l] = sum_q P[c_l, J] dN[l, J] dx``, ``(n_loc, n_el)``;
        with one quadrature point the two-term sums of ``einsum`` written by
        component (no copy ``P[comp]``, as :meth:`_tangents_one_point`)."""
        d = self.dim
        if self._dx.shape[1] != 1 or not self._comp_slices or self._hoop is not None:
            return np.einsum("lJeq,lJeq->le", P[:d, :d][self._comp], self._dNdx)
        dNdx = self._dNdx[..., 0]
        re = np.empty(dNdx[:, 0].shape)
        for k, on in self._comp_slices:
            np.multiply(P[k, 0, :, 0], dNdx[on, 0], out=re[on])
            for J in range(1, d):
                re[on] += P[k, J, :, 0] * dNdx[on, J]
        return re

    def _tangents(self, Adx: np.ndarray) -> np.ndarray:
        """Element tangents ``K_e[l, m]`` ``(n_loc, n_loc, n_el)`` from ``A dx``
        ``(d, d, d, d, n_el, n_qp)``: ``W[k, L] = sum_J dN[l, J] A[c_l, J, k, L] dx``,
        then ``K_e[l, m] = sum_q W[c_m, L] dN[m, L]``."""
        if self.dim == 3 and self._comp_slices:
            return self._tangents_3d(Adx)
        dN, comp = self._dN, self._comp
        ke = np.empty((len(comp), len(comp), dN.shape[2]))
        for l in range(len(comp)):
            W = dN[l, 0] * Adx[comp[l], 0] + dN[l, 1] * Adx[comp[l], 1]   # (2, 2, n_el, n_qp)
            ke[l] = np.einsum("mLeq,mLeq->me", W[comp], dN)
        return ke

    def _tangents_3d(self, Adx: np.ndarray) -> np.ndarray:
        """:meth:`_tangents` in 3D: the same products, over :data:`CHUNK_3D` elements
        at a time and by component (``einsum`` on ``W[k]`` and the component's
        ``dN``, no copy ``W[comp]``): 1.8x faster on hex1 (142 -> 78 us per element),
        the same numbers to the last bit."""
        dN, comp = self._dN, self._comp
        ke = np.empty((len(comp), len(comp), dN.shape[2]))
        for start in range(0, dN.shape[2], CHUNK_3D):
            e = slice(start, start + CHUNK_3D)
            Ae, dNe = Adx[..., e, :], dN[:, :, e]
            for l in range(len(comp)):
                W = dNe[l, 0] * Ae[comp[l], 0] + dNe[l, 1] * Ae[comp[l], 1]
                W += dNe[l, 2] * Ae[comp[l], 2]                           # (3, 3, n, n_qp)
                for k, on in self._comp_slices:
                    ke[l, on, e] = np.einsum("Leq,mLeq->me", W[k], dNe[on])
        return ke

    def _tangents_one_point(self, A: np.ndarray) -> np.ndarray:
        """:meth:`_tangents` for one quadrature point, from ``A``, the same
        products and sums.

        Our own two-term sums instead of ``einsum``: with one point its sum
        over ``L`` is ``W[c_m, 0] dN[m, 0] + W[c_m, 1] dN[m, 1]`` as well,
        written into the result by component (no copy ``W[comp]``; the
        components' local dofs evenly spaced, as ``ElementVector`` has them), over
        :data:`CHUNK` elements at a time, so that the temporaries stay in
        the cache: 3x faster at hertz ``refine=3``."""
        dN, dx, comp, d = self._dN[..., 0], self._dx[:, 0], self._comp, self.dim
        n_el = dN.shape[2]
        ke = np.empty((len(comp), len(comp), n_el))
        for start in range(0, n_el, CHUNK):
            e = slice(start, start + CHUNK)
            Adx, dNe, kee = A[..., e, 0] * dx[e], dN[:, :, e], ke[:, :, e]
            for l in range(len(comp)):
                W = dNe[l, 0] * Adx[comp[l], 0] + dNe[l, 1] * Adx[comp[l], 1]   # (d, d, n)
                for J in range(2, d):
                    W += dNe[l, J] * Adx[comp[l], J]
                for k, on in self._comp_slices:  # on: a slice, kee[l, on] a view
                    np.multiply(W[k, 0], dNe[on, 0], out=kee[l, on])
                    for L in range(1, d):
                        kee[l, on] += W[k, L] * dNe[on, L]
        return ke

    def assemble_forms(self, z: np.ndarray, tangent: bool = True
                       ) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Residual and tangent on the body's dofs through the skfem forms
        ``internal_force`` and ``material_stiffness`` (a reference for :meth:`assemble`)."""
        F = self.deformation_gradient(z)
        P, A = self.material.stress_and_tangent(F, tangent=tangent)
        r = internal_force.assemble(self.basis, P=P)
        if not tangent:
            return r, None
        return r, material_stiffness.assemble(self.basis, At=np.transpose(A, (2, 3, 0, 1, 4, 5)))

    def reaction(self, R: np.ndarray, dofs: np.ndarray) -> float:
        """Sum of the global residual ``R`` over the body's local ``dofs``.

        At a prescribed dof ``R = f_int - f_ext`` is the force the support
        exerts on the body.
        """
        return float(np.sum(np.asarray(R)[self.offset + np.asarray(dofs, dtype=np.int64)]))

    # -- output ------------------------------------------------------------
    def output_mesh(self) -> tuple[np.ndarray, list[tuple[str, np.ndarray]]]:
        """2D: vertices ``(N, 2)`` and linear cells (corner nodes only).  3D: every node
        of the field ``(N, 3)`` (vertices first, in mesh order) and one cell block
        (``tetra``, ``tetra10``, ``hexahedron`` or ``hexahedron27``) whose columns are
        the element's nodes in scikit-fem's local order (vertices, edges, faces,
        interior: a writer reorders them to VTK's)."""
        if self.dim == 3:
            points, conn = self._output_nodes()
            return points.T.copy(), [(self._cell_type, conn.T.copy())]
        # not skfem.io.meshio.to_meshio: identical on linear meshes, but on quadratic
        # ones it gives triangle6/quad9 cells on all nodes; the fields are per vertex
        nv = 3 if self._cell_type == "triangle" else 4
        return self.X.T.copy(), [(self._cell_type, self.mesh.t[:nv].T.copy())]

    def _output_nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """3D: the field's nodes ``(3, N)`` and the cells ``(n_sloc, n_el)`` over them
        (a node is numbered by its x-dof: vertices first); cached."""
        if getattr(self, "_nodes", None) is None:
            d, n_loc = self.dim, self._edofs.shape[0]
            # ElementVector interleaves the components of each scalar dof
            assert np.array_equal(self._comp, np.arange(n_loc) % d)
            first = self._edofs[::d]                                     # (n_sloc, n_el)
            xdofs, conn = np.unique(first, return_inverse=True)
            conn = conn.reshape(first.shape)
            ndofs = np.empty((d, xdofs.size), dtype=np.int64)          # each node's dofs
            for c in range(d):
                ndofs[c, conn] = self._edofs[c::d]
            points = np.asarray(self.basis.doflocs)[:, xdofs]
            self._nodes = (points, conn, ndofs)
        return self._nodes[0], self._nodes[1]

    def element_average(self, q: np.ndarray) -> np.ndarray:
        """Volume average over each element of a quadrature array ``(..., n_el, n_qp)``."""
        dx = self.basis.dx
        return np.sum(q * dx, axis=-1) / np.sum(dx, axis=-1)

    def output_data(self, z: np.ndarray) -> tuple[dict, dict]:
        """2D: point data ``displacement`` (N, 2); cell data: element-averaged Cauchy
        stress ``sigma_xx, sigma_yy, sigma_xy, sigma_zz`` and ``von_mises`` (small
        strain: ``sigma`` itself), and in plane stress the out-of-plane stretch
        ``stretch_zz``.  3D: point data on every node of :meth:`output_mesh`:
        ``displacement`` (N, 3), the Cauchy stress ``sigma_xx, sigma_yy, sigma_zz,
        sigma_xy, sigma_yz, sigma_xz`` and ``von_mises``, each the mean over the
        elements at the node of the stress there (:func:`.solid_output.nodal_stress`);
        no cell data."""
        if self.dim == 3:
            return nodal_output(self, z), {}
        u = self.u(z)[self.node_dofs].T.copy()
        F = self.deformation_gradient(z)
        s, szz = self.material.cauchy(F)
        vm = self.material.von_mises(F)
        avg = self.element_average
        cells = {"sigma_xx": [avg(s[0, 0])], "sigma_yy": [avg(s[1, 1])],
                 "sigma_xy": [avg(s[0, 1])], "sigma_zz": [avg(szz)],
                 "von_mises": [avg(vm)]}
        if self.plane == "stress":  # the thickness change (the loaded area keeps H)
            cells["stretch_zz"] = [avg(self.material.stretch_zz(F))]
        return {"displacement": u}, cells

    def __repr__(self) -> str:
        """One line: class, name, material, element, kinematics, plane and sizes."""
        kin = "" if self.kinematics == "finite" else f", {self.kinematics} strain"
        where = "3D" if self.dim == 3 else f"plane {self.plane}"
        return (f"{type(self).__name__}({self.name!r}, {self.material!r}, {self.element}"
                f"{kin}, {where}: {self.n_nodes} nodes, "
                f"{self.mesh.nelements} elements, {self.n_dofs} dofs)")
