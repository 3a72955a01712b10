"""The finite-strain (hyperelastic) laws: :class:`NeoHooke` and
:class:`SaintVenantKirchhoff`, plane strain or plane stress.  Conventions of shapes in
:mod:`.materials`."""
from __future__ import annotations

import numpy as np
from skfem.helpers import inv

from ..core.errors import InversionError
from .deformation import _eye, checked_det
from .material import Material

__all__ = ["NeoHooke", "SaintVenantKirchhoff"]


class NeoHooke(Material):
    r"""Compressible neo-Hookean solid, plane strain or plane stress.

    Plane strain (``F_zz = 1``):

    .. math::

        W = \frac{\mu}{2}(\operatorname{tr} C - 2 - 2\ln J) + \frac{\lambda}{2}(\ln J)^2,
        \qquad P = \mu (F - F^{-T}) + \lambda \ln J \, F^{-T},

    .. math::

        A_{iJkL} = \mu \delta_{ik}\delta_{JL}
                   + (\mu - \lambda \ln J) F^{-1}_{Jk} F^{-1}_{Li}
                   + \lambda F^{-1}_{Ji} F^{-1}_{Lk},

    and ``sigma_zz = lambda ln J / J``.

    Plane stress (``S_zz = 0``): the 3D energy with ``tr C -> tr C + y^2`` and
    ``J -> J_3 = J y``, ``y = F_zz``; ``P_zz = 0`` is

    .. math::

        h(t) = \mu (e^{2t} - 1) + \lambda (\ln J + t) = 0, \qquad t = \ln y,

    solved at every quadrature point by a vectorized Newton iteration from the
    small-strain root ``t_0 = -lambda ln J / (lambda + 2 mu)`` (``h`` is convex
    and increasing for ``lambda >= 0``: it converges from any start).  Then
    ``P`` is the plane-strain formula with ``ln J -> ln J_3`` (envelope:
    ``dW/dy = 0``), and the consistent tangent condenses ``y`` out,

    .. math::

        A = A|_y - \frac{W_{Fy} \otimes W_{yF}}{W_{yy}}, \quad
        W_{Fy} = \frac{\lambda}{y} F^{-T}, \quad
        W_{yy} = \mu (1 + y^{-2}) + \lambda (1 - \ln J_3) y^{-2},

    i.e. the ``lambda F^-T (x) F^-T`` term gets the coefficient
    ``lambda - lambda^2 / (mu (y^2 + 1) + lambda (1 - ln J_3))`` (``lambda*``
    at ``F = I``); ``sigma_zz = 0``.  Parameters as :class:`Material`.
    """

    #: Newton iterations of the out-of-plane stretch (plane stress) at most
    MAX_ITERATIONS = 50

    def log_stretch_zz(self, F: np.ndarray, lnJ: np.ndarray | None = None) -> np.ndarray:
        """``t = ln F_zz`` of plane stress, the root of ``h(t)`` (class docstring);
        zeros in plane strain.

        Raises
        ------
        InversionError
            If the iteration does not converge (``h' <= 0``: a state beyond the
            material's stability limit, possible only for ``lambda < 0``).
        """
        if self.plane != "stress" or np.shape(F)[0] == 3:
            return np.zeros(np.shape(F)[2:])
        if lnJ is None:
            lnJ = np.log(checked_det(F))
        mu, lm = self.mu, self.lmbda
        t = -lm * lnJ / (lm + 2.0 * mu)
        for _ in range(self.MAX_ITERATIONS):
            e2 = np.exp(2.0 * t)
            dh = 2.0 * mu * e2 + lm
            if np.any(dh <= 0.0):
                raise InversionError("plane stress: no out-of-plane stretch (the state "
                                     "is beyond the stability limit of the material)")
            dt = (mu * (e2 - 1.0) + lm * (lnJ + t)) / dh
            t = t - dt
            if np.all(np.abs(dt) <= 4.0 * np.finfo(float).eps * (1.0 + np.abs(t))):
                return t
        raise InversionError("plane stress: the out-of-plane stretch did not converge "
                             f"in {self.MAX_ITERATIONS} Newton iterations")

    def stretch_zz(self, F: np.ndarray) -> np.ndarray:
        """``F_zz``: 1 (plane strain) or ``exp(t)`` from ``S_zz = 0`` (plane stress)."""
        return np.exp(self.log_stretch_zz(F))

    def stress_and_tangent(self, F: np.ndarray, tangent: bool = True
                           ) -> tuple[np.ndarray, np.ndarray | None]:
        F = np.asarray(F, dtype=float)
        J = checked_det(F)
        Fi = inv(F)                           # Fi[J, i] = F^-1_Ji
        FiT = np.swapaxes(Fi, 0, 1)           # F^-T
        lnJ = np.log(J)
        lam_vol = self.lmbda                  # coefficient of F^-T (x) F^-T in A
        if self.plane == "stress" and F.shape[0] == 2:
            t = self.log_stretch_zz(F, lnJ)
            lnJ = lnJ + t                     # ln J_3 = ln (J F_zz)
            y2 = np.exp(2.0 * t)
            lam_vol = self.lmbda - self.lmbda ** 2 / (self.mu * (y2 + 1.0)
                                                      + self.lmbda * (1.0 - lnJ))
        P = self.mu * (F - FiT) + self.lmbda * lnJ * FiT
        if not tangent:
            return P, None
        # outer products by broadcasting (faster than einsum on large arrays)
        A = ((self.mu - self.lmbda * lnJ) * Fi[None, :, :, None] * FiT[:, None, None, :]
             + lam_vol * FiT[:, :, None, None] * FiT[None, None, :, :])
        for i in range(F.shape[0]):
            for J in range(F.shape[0]):
                A[i, J, i, J] += self.mu          # mu delta_ik delta_JL
        return P, A

    def energy(self, F: np.ndarray) -> np.ndarray:
        """``W = mu/2 (tr C + F_zz^2 - 3 - 2 ln J_3) + lambda/2 (ln J_3)^2``,
        ``J_3 = J F_zz`` (``F_zz = 1`` in plane strain)."""
        F = np.asarray(F, dtype=float)
        lnJ = np.log(checked_det(F))
        trC = np.einsum("iJ...,iJ...->...", F, F)
        if self.plane == "stress" and F.shape[0] == 2:
            t = self.log_stretch_zz(F, lnJ)
            lnJ = lnJ + t
            trC = trC + np.exp(2.0 * t) - 1.0
        # the 2D plane-strain sum lacks F_zz^2 = 1: tr C - 2 there, tr C - 3 in 3D
        return (0.5 * self.mu * (trC - float(F.shape[0]) - 2.0 * lnJ)
                + 0.5 * self.lmbda * lnJ ** 2)

    def _plane_strain_stress_zz(self, F: np.ndarray) -> np.ndarray:
        """``sigma_zz = lambda ln J / J``."""
        J = checked_det(F)
        return self.lmbda * np.log(J) / J


class SaintVenantKirchhoff(Material):
    r"""St Venant-Kirchhoff solid, plane strain or plane stress.

    .. math::

        E = \tfrac12 (F^T F - I), \quad S = \lambda_p \operatorname{tr}(E) I + 2\mu E,
        \quad P = F S,

    .. math::

        A_{iJkL} = \delta_{ik} S_{JL} + \lambda_p F_{iJ} F_{kL}
                   + \mu (F_{iL} F_{kJ} + (F F^T)_{ik} \delta_{JL}),

    with ``lambda_p = lambda`` in plane strain (``E_zz = 0``,
    ``sigma_zz = lambda tr(E) / J``) and ``lambda_p = lambda* = 2 lambda mu /
    (lambda + 2 mu)`` in plane stress (``S_zz = 0`` gives
    ``E_zz = -lambda tr E / (lambda + 2 mu)``, ``F_zz = sqrt(1 + 2 E_zz)``,
    ``sigma_zz = 0``), :func:`plane_stress_lambda`.  The energy is defined
    for any ``F``, but an inverted point (``det F <= 0``) still raises
    :class:`InversionError`: such a state is not physical.
    Parameters as :class:`Material`.
    """

    def _pk2(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        C = np.einsum("kI...,kJ...->IJ...", F, F)
        d = F.shape[0]
        trE = 0.5 * (C[0, 0] + C[1, 1] - 2.0) if d == 2 else 0.5 * (np.trace(C) - 3.0)
        lm = self.lmbda_plane if d == 2 else self.lmbda
        S = self.mu * (C - _eye(F))
        for i in range(d):
            S[i, i] += lm * trE
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
        lm = self.lmbda_plane if F.shape[0] == 2 else self.lmbda
        A = (lm * F[:, :, None, None] * F[None, None, :, :]
             + self.mu * F[:, None, None, :] * np.swapaxes(F, 0, 1)[None, :, :, None])
        for i in range(F.shape[0]):
            A[i, :, i, :] += S                           # delta_ik S_JL
            for J in range(F.shape[0]):
                A[i, J, :, J] += self.mu * B[i]          # mu B_ik delta_JL
        return P, A

    def energy(self, F: np.ndarray) -> np.ndarray:
        """``W = lambda_p/2 (tr E)^2 + mu E : E`` (plane stress: the 3D energy at its
        minimum over ``E_zz``)."""
        F = np.asarray(F, dtype=float)
        checked_det(F)
        C = np.einsum("kI...,kJ...->IJ...", F, F)
        E = 0.5 * (C - _eye(F))
        if F.shape[0] == 3:
            return (0.5 * self.lmbda * np.trace(E) ** 2
                    + self.mu * np.einsum("IJ...,IJ...->...", E, E))
        trE = E[0, 0] + E[1, 1]
        return 0.5 * self.lmbda_plane * trE ** 2 + self.mu * np.einsum("IJ...,IJ...->...", E, E)

    def stretch_zz(self, F: np.ndarray) -> np.ndarray:
        """``F_zz = sqrt(1 + 2 E_zz)`` (plane stress; InversionError where
        ``1 + 2 E_zz <= 0``), 1 in plane strain."""
        F = np.asarray(F, dtype=float)
        if self.plane != "stress" or F.shape[0] == 3:
            return np.ones(F.shape[2:])
        _, trE = self._pk2(F)
        c33 = 1.0 - 2.0 * self.lmbda * trE / (self.lmbda + 2.0 * self.mu)
        if np.any(c33 <= 0.0):
            raise InversionError("plane stress: the out-of-plane stretch is not real "
                                 "(1 + 2 E_zz <= 0)")
        return np.sqrt(c33)

    def _plane_strain_stress_zz(self, F: np.ndarray) -> np.ndarray:
        """``sigma_zz = lambda tr E / J``."""
        J = checked_det(F)
        _, trE = self._pk2(np.asarray(F, dtype=float))
        return self.lmbda * trE / J
