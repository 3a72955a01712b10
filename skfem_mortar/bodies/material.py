"""The material protocol (:class:`Material`: the Lame constants, the plane, the stress
post-processing) and its small-strain law :class:`LinearElastic` (every material's
:meth:`Material.linearized`).  Conventions of shapes in :mod:`.materials`."""
from __future__ import annotations

import copy

import numpy as np

from ..core.validate import real
from .deformation import _eye, _finite, checked_det
from .elastic_constants import PLANES, lame_from_young, plane_stress_lambda

__all__ = ["Material", "LinearElastic"]


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
            mu = real("mu", mu, 0.0, low_open=True)
            # > -2 mu / 3: a positive bulk modulus (the set -1 < nu < 0.5)
            lmbda = real("lmbda", lmbda, -2.0 * mu / 3.0, low_open=True)
        else:
            raise ValueError("give either (E, nu) or (mu, lmbda)")
        self.mu = mu
        self.lmbda = lmbda

    #: the 2D reduction: "strain" (``F_zz = 1``) or "stress" (``S_zz = 0``);
    #: set through :meth:`with_plane`
    plane: str = "strain"

    def with_plane(self, plane: str) -> "Material":
        """This material in plane ``"strain"`` or plane ``"stress"`` (a copy; ``self``
        when it already is).  ``Solid(..., plane=...)`` calls it.

        Raises
        ------
        ValueError
            If ``plane`` is not one of :data:`PLANES`.
        """
        if not isinstance(plane, str) or plane not in PLANES:
            raise ValueError(f"plane must be one of {', '.join(map(repr, PLANES))} "
                             f"(got {plane!r})")
        if plane == self.plane:
            return self
        out = copy.copy(self)
        out.plane = plane
        return out

    def linearized(self) -> "LinearElastic":
        """The small-strain law of this material: its linearization at ``F = I``,
        ``sigma = lambda tr(eps) I + 2 mu eps`` with the same ``mu``, ``lambda``
        and plane (the same for every hyperelastic law here)."""
        return LinearElastic(mu=self.mu, lmbda=self.lmbda).with_plane(self.plane)

    @property
    def lmbda_plane(self) -> float:
        """The in-plane ``lambda``: ``lambda`` (plane strain) or
        ``lambda* = 2 lambda mu / (lambda + 2 mu)`` (plane stress)."""
        if self.plane == "stress":
            return plane_stress_lambda(self.mu, self.lmbda)
        return self.lmbda

    @property
    def E(self) -> float:
        """Young's modulus ``mu (3 lambda + 2 mu) / (lambda + mu)``."""
        return self.mu * (3 * self.lmbda + 2 * self.mu) / (self.lmbda + self.mu)

    @property
    def nu(self) -> float:
        """Poisson's ratio ``lambda / (2 (lambda + mu))``."""
        return self.lmbda / (2.0 * (self.lmbda + self.mu))

    def __repr__(self) -> str:
        tail = "" if self.plane == "strain" else f", plane={self.plane!r}"
        return f"{type(self).__name__}(mu={self.mu:.6g}, lmbda={self.lmbda:.6g}{tail})"

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
        """Out-of-plane Cauchy stress ``sigma_zz``: ``sigma[2, 2]`` of a 3 x 3
        ``F``, 0 in plane stress, else the law's plane-strain value
        (:meth:`_plane_strain_stress_zz`)."""
        if np.shape(F)[0] == 3:
            return self.cauchy(F)[0][2, 2]
        if self.plane == "stress":
            return np.zeros(np.shape(F)[2:])
        return self._plane_strain_stress_zz(F)

    def _plane_strain_stress_zz(self, F: np.ndarray) -> np.ndarray:
        """``sigma_zz`` of a 2 x 2 ``F`` in plane strain (``F_zz = 1``)."""
        raise NotImplementedError

    def stretch_zz(self, F: np.ndarray) -> np.ndarray:
        """Out-of-plane stretch ``F_zz``: 1 in plane strain, from ``S_zz = 0`` in
        plane stress."""
        return np.ones(np.shape(F)[2:])

    # -- post-processing ---------------------------------------------------
    def cauchy(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cauchy stress ``sigma = P F^T / (J F_zz)`` (2, 2, ...) and ``sigma_zz`` (...);
        for a 3 x 3 ``F`` (3D, or a 2D body's ``F`` with its out-of-plane stretch)
        ``sigma = P F^T / J`` (3, 3, ...) and its ``sigma[2, 2]``."""
        J = checked_det(F)
        if np.shape(F)[0] == 3:
            sigma = np.einsum("iJ...,kJ...->ik...", self.stress(F), F) / J
            return sigma, sigma[2, 2]
        if self.plane == "stress":
            J = J * self.stretch_zz(F)
        P = self.stress(F)
        sigma = np.einsum("iJ...,kJ...->ik...", P, F) / J
        return sigma, self.stress_zz(F)

    def von_mises(self, F: np.ndarray) -> np.ndarray:
        """``sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2 + 3 s_xy^2)``."""
        s, szz = self.cauchy(F)
        shear = 3.0 * s[0, 1] ** 2
        if s.shape[0] == 3:   # + 3 (s_yz^2 + s_zx^2)
            shear = shear + 3.0 * (s[1, 2] ** 2 + s[2, 0] ** 2)
        return np.sqrt(0.5 * ((s[0, 0] - s[1, 1]) ** 2 + (s[1, 1] - szz) ** 2
                              + (szz - s[0, 0]) ** 2) + shear)


class LinearElastic(Material):
    r"""Small-strain linear elasticity, plane strain or plane stress.

    With the displacement gradient ``H = F - I`` and the linear strain
    ``eps = sym H``,

    .. math::

        \sigma = \lambda_p \operatorname{tr}(\varepsilon) I + 2\mu \varepsilon, \qquad
        A_{iJkL} = \lambda_p \delta_{iJ}\delta_{kL}
                   + \mu (\delta_{ik}\delta_{JL} + \delta_{iL}\delta_{Jk}),

    ``W = lambda_p/2 (tr eps)^2 + mu eps : eps``; ``stress`` returns
    ``sigma`` in the place of ``P`` (small strain does not tell them apart),
    so a :class:`~skfem_mortar.bodies.solid.Solid` assembles ``int Grad v :
    sigma dV`` over the reference domain.  ``lambda_p = lambda`` in plane
    strain (``sigma_zz = lambda tr eps``), ``lambda* = 2 lambda mu / (lambda + 2 mu)``
    in plane stress (``sigma_zz = 0``, ``eps_zz = -lambda tr eps / (lambda + 2 mu)``).
    No point is ever "inverted": only a non-finite ``F`` raises
    :class:`InversionError`.  Parameters as :class:`Material`.
    """

    @staticmethod
    def strain(F: np.ndarray) -> np.ndarray:
        """``eps = (H + H^T) / 2``, ``H = F - I``, shape ``(2, 2, ...)``."""
        F = _finite(F)
        H = F - _eye(F)
        return 0.5 * (H + np.swapaxes(H, 0, 1))

    def stress_and_tangent(self, F: np.ndarray, tangent: bool = True
                           ) -> tuple[np.ndarray, np.ndarray | None]:
        eps = self.strain(F)
        d = eps.shape[0]
        lm = self.lmbda_plane if d == 2 else self.lmbda
        sigma = 2.0 * self.mu * eps
        tr = eps[0, 0] + eps[1, 1] if d == 2 else np.trace(eps)
        for i in range(d):
            sigma[i, i] += lm * tr
        if not tangent:
            return sigma, None
        I = np.eye(d)
        A0 = (lm * I[:, :, None, None] * I[None, None, :, :]
              + self.mu * (I[:, None, :, None] * I[None, :, None, :]
                           + I[:, None, None, :] * I[None, :, :, None]))
        A = np.broadcast_to(A0[(...,) + (np.newaxis,) * (eps.ndim - 2)],
                            A0.shape + eps.shape[2:]).copy()
        return sigma, A

    def energy(self, F: np.ndarray) -> np.ndarray:
        """``W = lambda_p/2 (tr eps)^2 + mu eps : eps``."""
        eps = self.strain(F)
        if eps.shape[0] == 3:
            return (0.5 * self.lmbda * np.trace(eps) ** 2
                    + self.mu * np.einsum("IJ...,IJ...->...", eps, eps))
        tr = eps[0, 0] + eps[1, 1]
        return 0.5 * self.lmbda_plane * tr ** 2 + self.mu * np.einsum("IJ...,IJ...->...",
                                                                      eps, eps)

    def linearized(self) -> "LinearElastic":
        """Itself: it is the small-strain law."""
        return self

    def strain_zz(self, F: np.ndarray) -> np.ndarray:
        """``eps_zz``: 0 (plane strain) or ``-lambda tr eps / (lambda + 2 mu)``."""
        eps = self.strain(F)
        if eps.shape[0] == 3:
            return eps[2, 2]
        if self.plane != "stress":
            return np.zeros(eps.shape[2:])
        return -self.lmbda * (eps[0, 0] + eps[1, 1]) / (self.lmbda + 2.0 * self.mu)

    def stretch_zz(self, F: np.ndarray) -> np.ndarray:
        """``1 + eps_zz``."""
        return 1.0 + self.strain_zz(F)

    def _plane_strain_stress_zz(self, F: np.ndarray) -> np.ndarray:
        """``sigma_zz = lambda tr eps``."""
        eps = self.strain(F)
        return self.lmbda * (eps[0, 0] + eps[1, 1])

    def cauchy(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``sigma`` itself (no push-forward at small strain) and ``sigma_zz``
        (its ``[2, 2]`` entry for a 3 x 3 ``F``)."""
        sigma = self.stress(F)
        return sigma, (sigma[2, 2] if sigma.shape[0] == 3 else self.stress_zz(F))
