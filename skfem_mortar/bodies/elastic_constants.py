"""The elastic constants: the 2D reductions a material offers (:data:`PLANES`), the Lame
constants by name and from Young's modulus, and the in-plane ``lambda`` of plane stress."""
from __future__ import annotations

from typing import NamedTuple

from ..core.validate import real

__all__ = ["Lame", "lame_from_young", "plane_stress_lambda", "PLANES"]

#: the 2D reductions of the 3D continuum a material offers
PLANES = ("strain", "stress")


class Lame(NamedTuple):
    """The Lame constants by name: ``mu`` (shear modulus) FIRST, then ``lmbda``."""

    mu: float
    lmbda: float


def lame_from_young(E: float, nu: float) -> Lame:
    """Lame constants ``mu = E / (2 (1 + nu))``, ``lambda = E nu / ((1 + nu)(1 - 2 nu))``.

    Returns ``Lame(mu, lmbda)``: ORDER (mu, lambda), the REVERSE of scikit-fem's
    ``skfem.models.elasticity.lame_parameters(E, nu) -> (lambda, mu)``.  Read
    the fields by name (``lame_from_young(E, nu).mu``) to need no order at all;
    unpacking ``mu, lmbda = lame_from_young(E, nu)`` stays valid.

    Raises
    ------
    ValueError
        If ``E`` is not a finite real number > 0 or ``nu`` not one in ``(-1, 0.5)``
        (a string such as ``"100"`` or a bool is refused, not converted).
    """
    E = real("E", E, 0.0, low_open=True)
    nu = real("nu", nu, -1.0, 0.5, low_open=True, high_open=True)
    return Lame(E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)))


def plane_stress_lambda(mu: float, lmbda: float) -> float:
    """``lambda* = 2 lambda mu / (lambda + 2 mu)``: the in-plane Lame constant of plane stress.

    ``S_zz = lambda (tr E + E_zz) + 2 mu E_zz = 0`` gives
    ``E_zz = -lambda tr E / (lambda + 2 mu)`` and the in-plane
    ``S = lambda* tr E I + 2 mu E`` (the same for the small strain ``eps``).
    """
    return 2.0 * lmbda * mu / (lmbda + 2.0 * mu)
