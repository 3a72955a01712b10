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

import copy
from typing import NamedTuple

import numpy as np
from skfem.helpers import det, inv

from ..core.errors import InversionError
from ..core.validate import real

__all__ = ["Material", "NeoHooke", "SaintVenantKirchhoff", "LinearElastic", "Lame",
           "lame_from_young", "checked_det", "plane_stress_lambda", "PLANES"]

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


def _finite(F: np.ndarray) -> np.ndarray:
    """``F`` as floats of shape ``(2, 2, ...)``; InversionError if not finite."""
    F = np.asarray(F, dtype=float)
    if F.shape[:2] != (2, 2):
        raise ValueError(f"F must have shape (2, 2, ...), got {F.shape}")
    if not np.all(np.isfinite(F)):
        raise InversionError("non-finite deformation gradient")
    return F


def _eye(F: np.ndarray) -> np.ndarray:
    """The 2 x 2 identity broadcast against the trailing axes of ``F``."""
    return np.eye(2)[(...,) + (np.newaxis,) * (F.ndim - 2)]


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
        """Out-of-plane Cauchy stress ``sigma_zz`` (0 in plane stress)."""
        raise NotImplementedError

    def stretch_zz(self, F: np.ndarray) -> np.ndarray:
        """Out-of-plane stretch ``F_zz``: 1 in plane strain, from ``S_zz = 0`` in
        plane stress."""
        return np.ones(np.shape(F)[2:])

    # -- post-processing ---------------------------------------------------
    def cauchy(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cauchy stress ``sigma = P F^T / (J F_zz)`` (2, 2, ...) and ``sigma_zz`` (...)."""
        J = checked_det(F)
        if self.plane == "stress":
            J = J * self.stretch_zz(F)
        P = self.stress(F)
        sigma = np.einsum("iJ...,kJ...->ik...", P, F) / J
        return sigma, self.stress_zz(F)

    def von_mises(self, F: np.ndarray) -> np.ndarray:
        """``sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2 + 3 s_xy^2)``."""
        s, szz = self.cauchy(F)
        return np.sqrt(0.5 * ((s[0, 0] - s[1, 1]) ** 2 + (s[1, 1] - szz) ** 2
                              + (szz - s[0, 0]) ** 2) + 3.0 * s[0, 1] ** 2)


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
        if self.plane != "stress":
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
        if self.plane == "stress":
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
        for i in range(2):
            for J in range(2):
                A[i, J, i, J] += self.mu          # mu delta_ik delta_JL
        return P, A

    def energy(self, F: np.ndarray) -> np.ndarray:
        """``W = mu/2 (tr C + F_zz^2 - 3 - 2 ln J_3) + lambda/2 (ln J_3)^2``,
        ``J_3 = J F_zz`` (``F_zz = 1`` in plane strain)."""
        F = np.asarray(F, dtype=float)
        lnJ = np.log(checked_det(F))
        trC = np.einsum("iJ...,iJ...->...", F, F)
        if self.plane == "stress":
            t = self.log_stretch_zz(F, lnJ)
            lnJ = lnJ + t
            trC = trC + np.exp(2.0 * t) - 1.0
        return 0.5 * self.mu * (trC - 2.0 - 2.0 * lnJ) + 0.5 * self.lmbda * lnJ ** 2

    def stress_zz(self, F: np.ndarray) -> np.ndarray:
        J = checked_det(F)
        if self.plane == "stress":
            return np.zeros_like(J)
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
        trE = 0.5 * (C[0, 0] + C[1, 1] - 2.0)
        lm = self.lmbda_plane
        S = self.mu * (C - _eye(F))
        S[0, 0] += lm * trE
        S[1, 1] += lm * trE
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
        A = (self.lmbda_plane * F[:, :, None, None] * F[None, None, :, :]
             + self.mu * F[:, None, None, :] * np.swapaxes(F, 0, 1)[None, :, :, None])
        for i in range(2):
            A[i, :, i, :] += S                           # delta_ik S_JL
            for J in range(2):
                A[i, J, :, J] += self.mu * B[i]          # mu B_ik delta_JL
        return P, A

    def energy(self, F: np.ndarray) -> np.ndarray:
        """``W = lambda_p/2 (tr E)^2 + mu E : E`` (plane stress: the 3D energy at its
        minimum over ``E_zz``)."""
        F = np.asarray(F, dtype=float)
        checked_det(F)
        C = np.einsum("kI...,kJ...->IJ...", F, F)
        E = 0.5 * (C - _eye(F))
        trE = E[0, 0] + E[1, 1]
        return 0.5 * self.lmbda_plane * trE ** 2 + self.mu * np.einsum("IJ...,IJ...->...", E, E)

    def stretch_zz(self, F: np.ndarray) -> np.ndarray:
        """``F_zz = sqrt(1 + 2 E_zz)`` (plane stress; InversionError where
        ``1 + 2 E_zz <= 0``), 1 in plane strain."""
        F = np.asarray(F, dtype=float)
        if self.plane != "stress":
            return np.ones(F.shape[2:])
        _, trE = self._pk2(F)
        c33 = 1.0 - 2.0 * self.lmbda * trE / (self.lmbda + 2.0 * self.mu)
        if np.any(c33 <= 0.0):
            raise InversionError("plane stress: the out-of-plane stretch is not real "
                                 "(1 + 2 E_zz <= 0)")
        return np.sqrt(c33)

    def stress_zz(self, F: np.ndarray) -> np.ndarray:
        J = checked_det(F)
        if self.plane == "stress":
            return np.zeros_like(J)
        _, trE = self._pk2(np.asarray(F, dtype=float))
        return self.lmbda * trE / J


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
        lm = self.lmbda_plane
        sigma = 2.0 * self.mu * eps
        tr = eps[0, 0] + eps[1, 1]
        sigma[0, 0] += lm * tr
        sigma[1, 1] += lm * tr
        if not tangent:
            return sigma, None
        I = np.eye(2)
        A0 = (lm * I[:, :, None, None] * I[None, None, :, :]
              + self.mu * (I[:, None, :, None] * I[None, :, None, :]
                           + I[:, None, None, :] * I[None, :, :, None]))
        A = np.broadcast_to(A0[(...,) + (np.newaxis,) * (eps.ndim - 2)],
                            A0.shape + eps.shape[2:]).copy()
        return sigma, A

    def energy(self, F: np.ndarray) -> np.ndarray:
        """``W = lambda_p/2 (tr eps)^2 + mu eps : eps``."""
        eps = self.strain(F)
        tr = eps[0, 0] + eps[1, 1]
        return 0.5 * self.lmbda_plane * tr ** 2 + self.mu * np.einsum("IJ...,IJ...->...",
                                                                      eps, eps)

    def linearized(self) -> "LinearElastic":
        """Itself: it is the small-strain law."""
        return self

    def strain_zz(self, F: np.ndarray) -> np.ndarray:
        """``eps_zz``: 0 (plane strain) or ``-lambda tr eps / (lambda + 2 mu)``."""
        eps = self.strain(F)
        if self.plane != "stress":
            return np.zeros(eps.shape[2:])
        return -self.lmbda * (eps[0, 0] + eps[1, 1]) / (self.lmbda + 2.0 * self.mu)

    def stretch_zz(self, F: np.ndarray) -> np.ndarray:
        """``1 + eps_zz``."""
        return 1.0 + self.strain_zz(F)

    def stress_zz(self, F: np.ndarray) -> np.ndarray:
        """``sigma_zz = lambda tr eps`` (plane strain) or 0 (plane stress)."""
        eps = self.strain(F)
        if self.plane == "stress":
            return np.zeros(eps.shape[2:])
        return self.lmbda * (eps[0, 0] + eps[1, 1])

    def cauchy(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``sigma`` itself (no push-forward at small strain) and ``sigma_zz``."""
        return self.stress(F), self.stress_zz(F)
