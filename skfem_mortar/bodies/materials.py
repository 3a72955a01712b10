"""Hyperelastic plane-strain materials evaluated on quadrature arrays.

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

Plane strain throughout: the third direction has ``F_zz = 1``, ``F_iz = 0``.
``InversionError`` is raised wherever ``det F <= 0`` or ``F`` is not finite.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from skfem.helpers import det, inv

from ..core.errors import InversionError

__all__ = ["Material", "NeoHooke", "SaintVenantKirchhoff", "Lame", "lame_from_young",
           "checked_det"]


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
        If ``E <= 0`` or ``nu`` is outside ``(-1, 0.5)``.
    """
    E = float(E)
    nu = float(nu)
    if not np.isfinite(E) or E <= 0.0:
        raise ValueError(f"E must be > 0 (got {E})")
    if not np.isfinite(nu) or not -1.0 < nu < 0.5:
        raise ValueError(f"nu must lie in the open interval (-1, 0.5) (got {nu})")
    return Lame(E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)))


def checked_det(F: np.ndarray) -> np.ndarray:
    """``J = det F``; raise :class:`InversionError` if any ``J <= 0`` or non-finite."""
    F = np.asarray(F, dtype=float)
    if F.shape[:2] != (2, 2):
        raise ValueError(f"F must have shape (2, 2, ...), got {F.shape}")
    J = det(F)   # skfem.helpers: the same products as our own 2 x 2 formula, bit for bit
    if not np.all(np.isfinite(J)):
        raise InversionError("non-finite deformation gradient")
    if np.any(J <= 0.0):
        n = int(np.count_nonzero(J <= 0.0))
        raise InversionError(f"inverted material point(s): det F <= 0 at {n} point(s), "
                             f"min det F = {J.min():.3e}")
    return J


class Material:
    """Base class: Lame constants, validation and the stress post-processing.

    Either ``E`` and ``nu`` or ``mu`` and ``lmbda`` are given (not both pairs).

    Parameters
    ----------
    E : float, optional
        Young's modulus, ``E > 0``.
    nu : float, optional
        Poisson's ratio, ``-1 < nu < 0.5``.
    mu : float, optional
        Shear modulus, ``mu > 0``.
    lmbda : float, optional
        First Lame constant, ``lmbda > -2 mu / 3`` (positive bulk modulus;
        the same set as ``-1 < nu < 0.5``).
    """

    def __init__(self, E: float | None = None, nu: float | None = None,
                 mu: float | None = None, lmbda: float | None = None):
        if E is not None or nu is not None:
            if mu is not None or lmbda is not None:
                raise ValueError("give either (E, nu) or (mu, lmbda), not both")
            if E is None or nu is None:
                raise ValueError("E and nu must be given together")
            mu, lmbda = lame_from_young(E, nu)
        elif mu is not None and lmbda is not None:
            mu, lmbda = float(mu), float(lmbda)
            if not np.isfinite(mu) or mu <= 0.0:
                raise ValueError(f"mu must be > 0 (got {mu})")
            if not np.isfinite(lmbda) or lmbda <= -2.0 * mu / 3.0:
                raise ValueError(f"lmbda must be > -2 mu / 3 = {-2.0 * mu / 3.0} (got {lmbda})")
        else:
            raise ValueError("give either (E, nu) or (mu, lmbda)")
        self.mu = mu
        self.lmbda = lmbda

    @property
    def E(self) -> float:
        """Young's modulus ``mu (3 lambda + 2 mu) / (lambda + mu)``."""
        return self.mu * (3 * self.lmbda + 2 * self.mu) / (self.lmbda + self.mu)

    @property
    def nu(self) -> float:
        """Poisson's ratio ``lambda / (2 (lambda + mu))``."""
        return self.lmbda / (2.0 * (self.lmbda + self.mu))

    def __repr__(self) -> str:
        return f"{type(self).__name__}(mu={self.mu:.6g}, lmbda={self.lmbda:.6g})"

    # -- to be provided by subclasses ------------------------------------
    def stress(self, F: np.ndarray) -> np.ndarray:
        """First Piola-Kirchhoff stress ``P(F)``."""
        return self.stress_and_tangent(F, tangent=False)[0]

    def tangent(self, F: np.ndarray) -> np.ndarray:
        """Material tangent ``A = dP/dF``."""
        return self.stress_and_tangent(F, tangent=True)[1]

    def stress_and_tangent(self, F: np.ndarray, tangent: bool = True
                           ) -> tuple[np.ndarray, np.ndarray | None]:
        raise NotImplementedError

    def energy(self, F: np.ndarray) -> np.ndarray:
        """Strain energy density ``W(F)`` per unit reference volume."""
        raise NotImplementedError

    def stress_zz(self, F: np.ndarray) -> np.ndarray:
        """Out-of-plane Cauchy stress ``sigma_zz`` (plane strain)."""
        raise NotImplementedError

    # -- post-processing ---------------------------------------------------
    def cauchy(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cauchy stress ``sigma = P F^T / J`` (2, 2, ...) and ``sigma_zz`` (...)."""
        J = checked_det(F)
        P = self.stress(F)
        sigma = np.einsum("iJ...,kJ...->ik...", P, F) / J
        return sigma, self.stress_zz(F)

    def von_mises(self, F: np.ndarray) -> np.ndarray:
        """``sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2 + 3 s_xy^2)``."""
        s, szz = self.cauchy(F)
        return np.sqrt(0.5 * ((s[0, 0] - s[1, 1]) ** 2 + (s[1, 1] - szz) ** 2
                              + (szz - s[0, 0]) ** 2) + 3.0 * s[0, 1] ** 2)


class NeoHooke(Material):
    r"""Compressible neo-Hookean solid in plane strain.

    .. math::

        W = \frac{\mu}{2}(\operatorname{tr} C - 2 - 2\ln J) + \frac{\lambda}{2}(\ln J)^2,
        \qquad P = \mu (F - F^{-T}) + \lambda \ln J \, F^{-T},

    .. math::

        A_{iJkL} = \mu \delta_{ik}\delta_{JL}
                   + (\mu - \lambda \ln J) F^{-1}_{Jk} F^{-1}_{Li}
                   + \lambda F^{-1}_{Ji} F^{-1}_{Lk},

    and ``sigma_zz = lambda ln J / J``. Parameters as :class:`Material`.
    """

    def stress_and_tangent(self, F: np.ndarray, tangent: bool = True
                           ) -> tuple[np.ndarray, np.ndarray | None]:
        F = np.asarray(F, dtype=float)
        J = checked_det(F)
        Fi = inv(F)                           # Fi[J, i] = F^-1_Ji
        FiT = np.swapaxes(Fi, 0, 1)           # F^-T
        lnJ = np.log(J)
        P = self.mu * (F - FiT) + self.lmbda * lnJ * FiT
        if not tangent:
            return P, None
        # outer products by broadcasting (faster than einsum on large arrays)
        A = ((self.mu - self.lmbda * lnJ) * Fi[None, :, :, None] * FiT[:, None, None, :]
             + self.lmbda * FiT[:, :, None, None] * FiT[None, None, :, :])
        for i in range(2):
            for J in range(2):
                A[i, J, i, J] += self.mu          # mu delta_ik delta_JL
        return P, A

    def energy(self, F: np.ndarray) -> np.ndarray:
        """``W = mu/2 (tr C - 2 - 2 ln J) + lambda/2 (ln J)^2``."""
        F = np.asarray(F, dtype=float)
        lnJ = np.log(checked_det(F))
        trC = np.einsum("iJ...,iJ...->...", F, F)
        return 0.5 * self.mu * (trC - 2.0 - 2.0 * lnJ) + 0.5 * self.lmbda * lnJ ** 2

    def stress_zz(self, F: np.ndarray) -> np.ndarray:
        J = checked_det(F)
        return self.lmbda * np.log(J) / J


class SaintVenantKirchhoff(Material):
    r"""St Venant-Kirchhoff solid in plane strain.

    .. math::

        E = \tfrac12 (F^T F - I), \quad S = \lambda \operatorname{tr}(E) I + 2\mu E,
        \quad P = F S,

    .. math::

        A_{iJkL} = \delta_{ik} S_{JL} + \lambda F_{iJ} F_{kL}
                   + \mu (F_{iL} F_{kJ} + (F F^T)_{ik} \delta_{JL}),

    and ``sigma_zz = lambda tr(E) / J`` (``E_zz = 0``). The energy is defined
    for any ``F``, but an inverted point (``det F <= 0``) still raises
    :class:`InversionError`: such a state is not physical.
    Parameters as :class:`Material`.
    """

    def _pk2(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        C = np.einsum("kI...,kJ...->IJ...", F, F)
        trE = 0.5 * (C[0, 0] + C[1, 1] - 2.0)
        S = self.mu * (C - np.eye(2)[(...,) + (np.newaxis,) * (F.ndim - 2)])
        S[0, 0] += self.lmbda * trE
        S[1, 1] += self.lmbda * trE
        return S, trE

    def stress_and_tangent(self, F: np.ndarray, tangent: bool = True
                           ) -> tuple[np.ndarray, np.ndarray | None]:
        F = np.asarray(F, dtype=float)
        checked_det(F)
        S, _ = self._pk2(F)
        P = np.einsum("iM...,MJ...->iJ...", F, S)
        if not tangent:
            return P, None
        B = np.einsum("iM...,kM...->ik...", F, F)
        # outer products by broadcasting (faster than einsum on large arrays)
        A = (self.lmbda * F[:, :, None, None] * F[None, None, :, :]
             + self.mu * F[:, None, None, :] * np.swapaxes(F, 0, 1)[None, :, :, None])
        for i in range(2):
            A[i, :, i, :] += S                           # delta_ik S_JL
            for J in range(2):
                A[i, J, :, J] += self.mu * B[i]          # mu B_ik delta_JL
        return P, A

    def energy(self, F: np.ndarray) -> np.ndarray:
        """``W = lambda/2 (tr E)^2 + mu E : E``."""
        F = np.asarray(F, dtype=float)
        checked_det(F)
        C = np.einsum("kI...,kJ...->IJ...", F, F)
        E = 0.5 * (C - np.eye(2)[(...,) + (np.newaxis,) * (F.ndim - 2)])
        trE = E[0, 0] + E[1, 1]
        return 0.5 * self.lmbda * trE ** 2 + self.mu * np.einsum("IJ...,IJ...->...", E, E)

    def stress_zz(self, F: np.ndarray) -> np.ndarray:
        J = checked_det(F)
        _, trE = self._pk2(np.asarray(F, dtype=float))
        return self.lmbda * trE / J
