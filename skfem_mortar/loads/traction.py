"""Dead loads on a :class:`~skfem_mortar.bodies.solid.Solid`: surface tractions and point loads.

Both are fixed in the reference configuration (they do not follow the
deformation), so their residual contribution ``-load_factor * f`` does not
depend on ``u`` and their tangent is zero.
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np
from skfem import FacetBasis, LinearForm
from skfem.element.discrete_field import DiscreteField
from skfem.helpers import dot

from ..core.item import Contribution, Item
from ..core.validate_arrays import index_array, real_array
from ..bodies.checks import check_boundary_facets
from ..bodies.solid import boundary_facets

__all__ = ["Traction", "PointLoad"]


@LinearForm
def _traction_work(v, w):
    """``v . t`` with the reference traction ``t`` on the facet quadrature points."""
    return dot(w.t, v)


def _facet_basis(body, facets: np.ndarray) -> tuple[FacetBasis, np.ndarray]:
    """The facets' basis on the body's mesh moved by ``-c`` (``c`` the facets' node
    centroid) and ``c``: the load's integrals do not depend on where the mesh lies, but
    scikit-fem finds its facet points by inverting the isoparametric map to an absolute
    1e-12, which coordinates of 1e7 (a quad mesh of cell size 0.1) cannot reach."""
    nodes = np.unique(body.mesh.facets[:, facets])
    centre = body.mesh.p[:, nodes].mean(axis=1)
    return FacetBasis(body.mesh.translated(-centre), body.basis.elem, facets=facets), centre


class Traction(Item):
    """A reference (dead) traction ``T`` on a boundary, ramped with the load factor.

    Residual: ``R_a -= load_factor * int_Gamma0 v_a . T dA``; in an axisymmetric
    model ``dA = 2 pi R dS`` on the surface of revolution (``R`` the reference
    radius, ``x``), so the force is the total over the full revolution.

    Parameters
    ----------
    body : Solid
        The loaded body.
    boundary : str or array of int
        A tag of ``body.mesh.boundaries`` or an array of boundary facet indices.
    traction : sequence of d floats, or callable
        The traction vector: in 2D per unit reference length and unit
        reference thickness (a model's thickness multiplies its force), in an
        axisymmetric model and in 3D per unit reference area; or a function ``T(x) -> array (d, ...)`` of
        the reference facet quadrature points ``x (d, n_facets, n_qp)``
        (``d`` = 2 or 3, the mesh's dimension).
    name : str
        Item name (default ``traction_<body>_<boundary>``).
    """

    phase = "loads"
    geometries = ("plane", "axisymmetric", "3d")

    def __init__(self, body, boundary: str | np.ndarray,
                 traction: Sequence[float] | Callable[[np.ndarray], np.ndarray],
                 name: str = ""):
        if not (hasattr(body, "mesh") and hasattr(body, "basis")):
            raise ValueError(f"body must be a Solid (a body with an skfem mesh and basis), "
                             f"got {type(body).__name__}")
        facets = boundary_facets(body.mesh, boundary)
        check_boundary_facets(body.mesh, facets, boundary)
        dim = int(body.mesh.p.shape[0])
        if not callable(traction):
            t0 = real_array("traction", traction)
            if t0.shape != (dim,):
                raise ValueError(f"traction must be a {dim}-vector (the mesh is {dim}D) or "
                                 f"a callable, got shape {t0.shape}")
        fb, centre = _facet_basis(body, facets)
        if callable(traction):
            x = fb.global_coordinates()
            x = DiscreteField(x.value + centre[:, None, None])     # the true coordinates
            t = real_array("traction", traction(x))
            if t.shape != x.shape:
                raise ValueError(f"traction(x) must return an array of the shape of x "
                                 f"{x.shape} (one {dim}-vector per point), got {t.shape}")
        else:
            t = t0[:, None, None] * np.ones((1,) + fb.global_coordinates().shape[1:])
        self.body = body
        tag = boundary if isinstance(boundary, str) else "facets"
        self.name = name or f"traction_{body.name}_{tag}"
        self._fb, self._t, self._centre = fb, t, centre
        self._loads: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._load()                     # the plane (or 3D) load, checked now

    def _load(self) -> tuple[np.ndarray, np.ndarray]:
        """The loaded local dofs and their full-load forces in the model's geometry
        (computed once per geometry: the weight ``2 pi R`` of a revolved surface)."""
        g = self.geometry if self.geometry == "axisymmetric" else "plane"
        if g not in self._loads:
            t = self._t
            if g == "axisymmetric":
                t = t * (2.0 * np.pi * (self._fb.global_coordinates()[0] + self._centre[0]))
            f = _traction_work.assemble(self._fb, t=t)
            idx = np.flatnonzero(f)
            self._loads[g] = (idx, f[idx])
        return self._loads[g]

    @property
    def force(self) -> np.ndarray:
        """The full-load nodal force vector (local to the body)."""
        idx, f = self._load()
        out = np.zeros(self.body.n_dofs)
        out[idx] = f
        return out

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> Contribution:
        idx, f = self._load()
        return Contribution(self.body.offset + idx, -load_factor * f)


class PointLoad(Item):
    """Nodal forces on given local dofs of a body, ramped with the load factor.

    Residual: ``R[dofs] -= load_factor * values``.  The values are total forces
    (not per unit thickness): ``Model(..., thickness=H)`` leaves them as they are.

    Parameters
    ----------
    body : Item
        The body (``dof_kind == "u"``).
    local_dofs : array of int
        Dofs local to the body's block.
    values : float or array
        Force per dof (a scalar applies to all).
    """

    phase = "loads"
    #: its values are total forces: a model's thickness does not multiply them
    per_thickness = False

    def __init__(self, body, local_dofs: np.ndarray, values: float | np.ndarray,
                 name: str = ""):
        if not (isinstance(body, Item) and body.dof_kind == "u"):
            raise ValueError(f"body must be a body of the model (a Solid, a Cable: an Item "
                             f"with displacement dofs), got {type(body).__name__}")
        dofs = index_array("local_dofs", local_dofs, body.n_dofs).ravel()
        if dofs.size == 0:
            raise ValueError("local_dofs must hold at least one dof (a load on no dof "
                             "does nothing)")
        twice = np.flatnonzero(np.bincount(dofs, minlength=body.n_dofs) > 1)
        if twice.size:
            raise ValueError(f"local_dofs must list each dof once, with its total force "
                             f"(a repeated dof's load counts twice): dof {int(twice[0])} "
                             f"is listed more than once ({twice.size} such)")
        vals = real_array("values", values)
        try:
            vals = np.broadcast_to(vals, dofs.shape).copy()
        except ValueError:
            raise ValueError(f"values must be a scalar or one value per local dof "
                             f"({dofs.size}), got shape {vals.shape}") from None
        self.body = body
        self.local_dofs = dofs
        self.values = vals
        self.name = name or f"point_load_{body.name}"

    def assemble(self, z: np.ndarray, load_factor: float, tangent: bool = True
                 ) -> Contribution:
        return Contribution(self.body.offset + self.local_dofs, -load_factor * self.values)
