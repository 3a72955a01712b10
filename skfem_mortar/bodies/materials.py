"""Plane-strain and plane-stress materials evaluated on quadrature arrays.

Every function takes the deformation gradient ``F`` with skfem's layout,
shape ``(2, 2, ...)`` (the two tensor indices first, then any number of
trailing axes such as ``(n_elements, n_points)``), and returns arrays of the
same trailing shape:

* ``stress(F)``   first Piola-Kirchhoff stress ``P``, shape ``(2, 2, ...)``
* ``tangent(F)``  ``A = dP/dF``, ``A[i, J, k, L] = dP_iJ / dF_kL``,
  shape ``(2, 2, 2, 2, ...)``
* ``cauchy(F)``   in-plane Cauchy stress ``sigma = P F^T / J`` and the
  out-of-plane component ``sigma_zz`` (plane strain: ``F_zz = 1``)
* ``von_mises(F)`` the equivalent stress including ``sigma_zz``.

Plane strain by default: the third direction has ``F_zz = 1``, ``F_iz = 0``.
Plane stress (:meth:`Material.with_plane`, what ``Solid(..., plane="stress")``
calls): ``S_zz = 0`` and the out-of-plane stretch ``F_zz`` follows from it at
every point (:meth:`Material.stretch_zz`); ``P`` and ``A`` are those of the
2D problem with ``F_zz`` condensed out.  Stresses are per unit *reference*
thickness: the out-of-plane stretch changes no loaded area.

Finite strain (:class:`NeoHooke`, :class:`SaintVenantKirchhoff`) or small
strain (:class:`LinearElastic`, also every material's :meth:`Material.linearized`).
``InversionError`` is raised wherever ``det F <= 0`` (finite strain) or ``F``
is not finite.
"""
from __future__ import annotations

from .deformation import checked_det
from .elastic_constants import PLANES, Lame, lame_from_young, plane_stress_lambda
from .hyperelastic import NeoHooke, SaintVenantKirchhoff
from .material import LinearElastic, Material

__all__ = ["Material", "NeoHooke", "SaintVenantKirchhoff", "LinearElastic", "Lame",
           "lame_from_young", "checked_det", "plane_stress_lambda", "PLANES"]
