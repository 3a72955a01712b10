"""The axisymmetric geometry's kernel terms: a 2D solid in the meridian plane
``(r, z) = (x, y)`` of a body of revolution, the axis at ``r = 0``.

A solid of revolution whose displacement has no hoop component and does not
depend on the angle has the deformation gradient

    F = [[F_rr, F_rz, 0], [F_zr, F_zz, 0], [0, 0, F_thth]],   F_thth = r / R = 1 + u_r / R

(small strain: ``eps_thth = u_r / R``), and every integral over the body is one
over the meridian section with the weight ``2 pi R``:

    r(u)_a = int_A ( Grad v_a : P ) 2 pi R dA + int_A P_thth (v_a,r / R) 2 pi R dA .

The hook (:mod:`.geometry_terms`) carries it: :meth:`AxisymmetricTerms.weight`
is ``2 pi R`` at the quadrature points, :meth:`AxisymmetricTerms.hoop` is
``dF_thth/du_l = N_l / R`` on the radial dofs (0 on the axial ones), and the
solid evaluates its 3D law on the 3 x 3 ``F`` (:mod:`.hoop`).  Forces and
reactions are therefore totals over the full revolution.

Quadrature (:meth:`AxisymmetricTerms.quadrature`): the rule of degree ``2 p``
for elements of order ``p`` (tri1: skfem's degree-2 triangle rule, 3 points;
quad1: 2 x 2 Gauss; tri2: degree 4, 6 points; quad2: 3 x 3 Gauss).  The plane
integrand ``dN . dN`` has degree ``2 (p - 1)`` on an affine element; the
weight ``R`` raises that to ``2 p - 1``, and the residual of a homogeneous
state, ``(R N_l),R`` times a constant stress, has degree ``p``: the rule
integrates both exactly on affine triangles (and, mapped, on parallelogram
quads), so homogeneous states are reproduced to round-off.  The hoop-hoop
part ``N_l N_m / R`` is rational, integrated to the rule's order: on the
``thick_sphere`` scene the rule of degree ``2 p + 1`` changes the L2 error by
less than 0.1 % (tri1) and 5 % (tri2, where it is the larger one).  Linear
triangles no longer have a constant integrand (``R`` and ``N_l / R`` vary
across the element), so the centroid rule of the plane solid is not used.
MINI (:mod:`.mixed`) takes its plane order plus one.

The axis (:meth:`AxisymmetricTerms.reference_mesh`,
:meth:`AxisymmetricTerms.held_dofs`): nodes with ``|r| <= AXIS_RTOL`` times
the body's size (the largest extent of its mesh) are on the axis: snapped to
``r = 0``, and their radial dofs held at ``u_r = 0`` by the body itself (its
``prescribed``); a node with ``r`` below ``-AXIS_RTOL`` times the size is
refused, naming the body and the smallest ``r``.  No quadrature point lies
on the axis, so ``N_l / R`` stays finite.

Outputs (:data:`CYLINDRICAL`): the stress fields in cylindrical components,
``sigma_rr``, ``sigma_zz`` (axial), ``sigma_rz``, ``sigma_tt`` (hoop).
"""
from __future__ import annotations

import dataclasses

import numpy as np
from skfem import Basis, Mesh

from .geometry_terms import register_terms, terms_of

__all__ = ["AxisymmetricTerms", "AXIS_RTOL", "CYLINDRICAL", "output_names", "radius_at_points"]

#: nodes with ``|r| <= AXIS_RTOL * size`` are on the axis (module docstring)
AXIS_RTOL = 1e-10

#: plane output name -> axisymmetric output name (the plane ``sigma_zz`` is the hoop)
CYLINDRICAL = {"sigma_xx": "sigma_rr", "sigma_yy": "sigma_zz", "sigma_xy": "sigma_rz",
               "sigma_zz": "sigma_tt"}

#: element name -> its polynomial order
_ORDER = {"tri1": 1, "quad1": 1, "tri2": 2, "quad2": 2}


def output_names(cells: dict, geometry: str) -> dict:
    """``cells`` (a solid's output fields) with the names of ``geometry``'s terms
    (``output_names``, axisymmetric: :data:`CYLINDRICAL`), in the same order."""
    names = getattr(terms_of(geometry), "output_names", None) or {}
    return {names.get(k, k): v for k, v in cells.items()}


def radius_at_points(basis: Basis) -> np.ndarray:
    """The reference radius ``R`` at the quadrature points of ``basis``, ``(n_el, n_qp)``."""
    return np.asarray(basis.mapping.F(basis.quadrature[0])[0])


class AxisymmetricTerms:
    """The axisymmetric geometry's :class:`~.geometry_terms.KernelTerms` (module docstring)."""

    #: renamed output fields (read by the solids' ``output_data``)
    output_names = CYLINDRICAL

    def quadrature(self, element: str, intorder: int | None) -> dict:
        """The user's ``intorder``, else the rule of degree ``2 p`` (module docstring)."""
        if intorder is not None:
            return {"intorder": int(intorder)}
        return {"intorder": 2 * _ORDER.get(element, 2)}

    def weight(self, basis: Basis) -> np.ndarray:
        """``2 pi R`` at the quadrature points."""
        return 2.0 * np.pi * radius_at_points(basis)

    def hoop(self, basis: Basis, component: np.ndarray) -> np.ndarray:
        """``dF_thth/du_l = N_l / R`` for the radial dofs (``component == 0``), 0 for the
        axial ones, ``(n_loc, n_el, n_qp)``."""
        R = radius_at_points(basis)
        N = np.stack([np.asarray(basis.basis[l][0])[0] for l in range(basis.Nbfun)])
        return np.where((np.asarray(component) == 0)[:, None, None], N / R, 0.0)

    def reference_mesh(self, mesh: Mesh, name: str) -> Mesh:
        """``mesh`` with its nodes within ``AXIS_RTOL`` of the body's size from the axis
        moved onto it (the same mesh when none needs to move).

        Raises
        ------
        ValueError
            A node at ``r < -AXIS_RTOL * size``, naming the body and the smallest ``r``.
        """
        p = np.asarray(mesh.doflocs, dtype=float)
        size = float(np.max(np.ptp(p, axis=1)))
        tol = AXIS_RTOL * size
        r_min = float(p[0].min())
        if r_min < -tol:
            raise ValueError(f"body {name!r}: an axisymmetric body lies in r >= 0 (the axis "
                             f"at r = x = 0), and its smallest r is {r_min:.6g} (nodes within "
                             f"{AXIS_RTOL:g} of its size {size:.6g} from the axis are put on it)")
        near = np.abs(p[0]) <= tol
        if not np.any(p[0, near] != 0.0):
            return mesh
        q = p.copy()
        q[0, near] = 0.0
        return dataclasses.replace(mesh, doflocs=q)

    def held_dofs(self, basis: Basis, component: np.ndarray) -> np.ndarray:
        """The local radial dofs at ``r = 0`` (``u_r = 0`` there), sorted."""
        locs = np.asarray(basis.doflocs)
        on_axis = np.isfinite(locs[0]) & (locs[0] == 0.0)     # MINI's bubbles: nan
        return np.flatnonzero(on_axis & (np.asarray(component) == 0)).astype(np.int64)


register_terms("axisymmetric", AxisymmetricTerms())
