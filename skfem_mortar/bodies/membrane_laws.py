"""Laws of membranes of revolution: the strain energy per unit reference area
and unit reference thickness ``W(l1, l2)`` of the meridional stretch ``l1`` and
the hoop stretch ``l2``, with its first and second derivatives.

* ``neo-hooke`` (incompressible, thickness stretch ``l3 = 1 / (l1 l2)``)::

      W = mu / 2 (l1^2 + l2^2 + l1^-2 l2^-2 - 3)

* ``svk`` (St Venant-Kirchhoff in plane stress, Green strains
  ``E_k = (l_k^2 - 1) / 2``, ``C = E / (1 - nu^2)``)::

      W = C / 2 (E1^2 + 2 nu E1 E2 + E2^2),   S1 = C (E1 + nu E2),  S2 = C (E2 + nu E1)

  and the thickness strain of plane stress ``E3 = -nu / (1 - nu) (E1 + E2)``,
  ``l3 = sqrt(1 + 2 E3)``.

The membrane (:class:`~skfem_mortar.bodies.membrane.Membrane`) integrates
``H W`` over the reference surface; its tensions per unit current length are
``T1 = H W_1 / l2`` (meridional) and ``T2 = H W_2 / l1`` (hoop).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import InversionError
from ..core.validate import real

__all__ = ["MembraneLaw", "NeoHookeMembrane", "SVKMembrane", "membrane_law", "MEMBRANE_LAWS"]

#: the law names a membrane takes
MEMBRANE_LAWS = ("neo-hooke", "svk")


class MembraneLaw:
    """A membrane law: :meth:`derivatives` of ``W(l1, l2)`` and the thickness stretch."""

    name = ""

    def energy(self, l1: np.ndarray, l2: np.ndarray) -> np.ndarray:
        """``W(l1, l2)`` per unit reference area and thickness."""
        return self.derivatives(l1, l2)[0]

    def derivatives(self, l1: np.ndarray, l2: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(W, W_1, W_2, W_11, W_12, W_22)``, the partial derivatives by the stretches."""
        raise NotImplementedError

    def thickness_stretch(self, l1: np.ndarray, l2: np.ndarray) -> np.ndarray:
        """``l3 = h / H``, the current over the reference thickness."""
        raise NotImplementedError


@dataclass(frozen=True)
class NeoHookeMembrane(MembraneLaw):
    """Incompressible neo-Hooke: ``W = mu / 2 (l1^2 + l2^2 + l1^-2 l2^-2 - 3)``."""

    mu: float
    name = "neo-hooke"

    def derivatives(self, l1, l2):
        if np.any(l1 <= 0.0) or np.any(l2 <= 0.0):
            raise InversionError("neo-Hooke membrane: a stretch is not positive")
        mu = self.mu
        i3 = 1.0 / (l1 * l1 * l2 * l2)
        W = 0.5 * mu * (l1 * l1 + l2 * l2 + i3 - 3.0)
        W1 = mu * (l1 - i3 / l1)
        W2 = mu * (l2 - i3 / l2)
        W11 = mu * (1.0 + 3.0 * i3 / (l1 * l1))
        W22 = mu * (1.0 + 3.0 * i3 / (l2 * l2))
        W12 = 2.0 * mu * i3 / (l1 * l2)
        return W, W1, W2, W11, W12, W22

    def thickness_stretch(self, l1, l2):
        return 1.0 / (l1 * l2)


@dataclass(frozen=True)
class SVKMembrane(MembraneLaw):
    """St Venant-Kirchhoff in plane stress (module docstring)."""

    E: float
    nu: float
    name = "svk"

    def derivatives(self, l1, l2):
        C = self.E / (1.0 - self.nu ** 2)
        E1, E2 = 0.5 * (l1 * l1 - 1.0), 0.5 * (l2 * l2 - 1.0)
        S1, S2 = C * (E1 + self.nu * E2), C * (E2 + self.nu * E1)
        W = 0.5 * C * (E1 * E1 + 2.0 * self.nu * E1 * E2 + E2 * E2)
        return (W, S1 * l1, S2 * l2, S1 + C * l1 * l1, C * self.nu * l1 * l2,
                S2 + C * l2 * l2)

    def thickness_stretch(self, l1, l2):
        E3 = -self.nu / (1.0 - self.nu) * 0.5 * (l1 * l1 + l2 * l2 - 2.0)
        return np.sqrt(np.maximum(1.0 + 2.0 * E3, 0.0))


def membrane_law(law: str | MembraneLaw, mu: float | None = None, E: float | None = None,
                 nu: float | None = None) -> MembraneLaw:
    """The law named ``law`` (``"neo-hooke"``: ``mu`` > 0; ``"svk"``: ``E`` > 0 and
    ``nu`` in ``[0, 0.5)``), or ``law`` itself when it is a :class:`MembraneLaw`.

    Raises
    ------
    ValueError
        An unknown name, or a missing or out-of-range modulus, naming it.
    """
    if isinstance(law, MembraneLaw):
        return law
    if law == "neo-hooke":
        if mu is None:
            raise ValueError("mu (the shear modulus, > 0) is required for law='neo-hooke'")
        return NeoHookeMembrane(real("mu", mu, 0.0, low_open=True))
    if law == "svk":
        if E is None or nu is None:
            raise ValueError("E (> 0) and nu (in [0, 0.5)) are required for law='svk'")
        return SVKMembrane(real("E", E, 0.0, low_open=True),
                           real("nu", nu, 0.0, 0.5, high_open=True))
    raise ValueError(f"law must be one of {MEMBRANE_LAWS} or a MembraneLaw, got {law!r}")
