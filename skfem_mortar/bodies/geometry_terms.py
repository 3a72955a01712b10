"""What a model's geometry adds to a solid's kernel: the hook between the solid
(:mod:`.solid`, dimension-generic) and the geometries (plane here; the
axisymmetric terms register themselves from their own module).

A geometry's terms answer three questions about a basis (``Basis`` of the
solid's vector element, its quadrature points ``(n_el, n_qp)``):

- :meth:`KernelTerms.quadrature`: the quadrature to build the basis with, given
  the element and the user's ``intorder`` (plane: the solid's own choice);
- :meth:`KernelTerms.weight`: a factor of ``dx`` at the quadrature points, or
  ``None`` (plane: the model's thickness multiplies later; axisymmetric:
  ``2 pi R``);
- :meth:`KernelTerms.hoop`: the derivative of an out-of-plane stretch with
  respect to each local dof, ``(n_loc, n_el, n_qp)``, or ``None`` (plane:
  ``F_zz = 1``; axisymmetric: ``F_thth = 1 + u_r / R``, so ``N_l / R`` on the
  radial dofs and 0 on the axial ones).

With a hoop term the solid evaluates its material on the 3 x 3 gradient
``[[F, 0], [0, F_thth]]`` and adds ``P_thth dF_thth/du_l`` to the residual and
the coupling and ``A_thth,thth`` terms to the tangent (:mod:`.solid`).
"""
from __future__ import annotations

from typing import Protocol

import numpy as np
from skfem import Basis

__all__ = ["KernelTerms", "PlaneTerms", "register_terms", "terms_of", "TERMS"]


class KernelTerms(Protocol):
    """The protocol (module docstring)."""

    def quadrature(self, element: str, intorder: int | None) -> dict: ...

    def weight(self, basis: Basis) -> np.ndarray | None: ...

    def hoop(self, basis: Basis, component: np.ndarray) -> np.ndarray | None: ...


class PlaneTerms:
    """The plane geometry: nothing added (``F_zz = 1`` or the plane-stress law)."""

    def quadrature(self, element: str, intorder: int | None) -> dict:
        """The solid's own rule: ``{}`` (its default) or ``{"intorder": intorder}``."""
        return {} if intorder is None else {"intorder": int(intorder)}

    def weight(self, basis: Basis) -> None:
        return None

    def hoop(self, basis: Basis, component: np.ndarray) -> None:
        return None


#: geometry name -> its kernel terms (a geometry a solid may be in)
TERMS: dict[str, KernelTerms] = {"plane": PlaneTerms()}


def register_terms(geometry: str, terms: KernelTerms) -> None:
    """Register the kernel terms of ``geometry`` (its module does, on import)."""
    TERMS[geometry] = terms


def terms_of(geometry: str) -> KernelTerms:
    """The kernel terms of ``geometry``; ValueError naming the geometries a solid
    may be in."""
    try:
        return TERMS[geometry]
    except KeyError:
        raise ValueError(f"a solid works in a {' or '.join(map(repr, TERMS))} geometry, "
                         f"got {geometry!r}") from None
