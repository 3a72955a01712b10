"""The volumetric split of a law for the elements that treat the volume change apart
(:mod:`.mean_dilatation`, :mod:`.taylor_hood`).

Every law here is a shear part plus ``lambda / 2`` times the square of a volume
measure ``q``:

=====================  ==============================  ==========================
law                    ``q(F)``                        ``W_mu``
=====================  ==============================  ==========================
NeoHooke               ``ln J``                        the law at ``lambda = 0``
SaintVenantKirchhoff   ``tr E = (F : F - d) / 2``      the law at ``lambda = 0``
LinearElastic          ``tr eps = tr F - d``           the law at ``lambda = 0``
=====================  ==============================  ==========================

so ``W(F) = W_mu(F) + lambda / 2 q(F)^2`` exactly, and the shear part is the same
law with ``lambda = 0`` (its ``P_mu`` and ``A_mu``).  :meth:`VolumetricSplit.log_measure`
gives ``q`` and its first and second derivatives,

    dq/dF:    F^-T,                  F,              I ;
    d2q/dF2:  -F^-1_Jk F^-1_Li,      d_ik d_JL,      0 .

The mean-dilatation rule averages a measure ``m`` over each element and takes the
volumetric energy of its mean, ``V_e U(m_bar)``: for NeoHooke ``m = J`` and
``U(t) = lambda / 2 (ln t)^2`` (so ``m_bar = v_e / V_e``, the element's volume
ratio), for the others ``m = q`` and ``U(t) = lambda / 2 t^2``
(:meth:`VolumetricSplit.mean_measure`, :meth:`VolumetricSplit.energy_derivatives`);
with ``J``,

    dJ/dF = J F^-T ,   d2J/dF2 = J (F^-T_iJ F^-T_kL - F^-1_Jk F^-1_Li) .
"""
from __future__ import annotations

import copy

import numpy as np
from skfem.helpers import inv

from ..core.errors import InversionError
from .deformation import checked_det
from .hyperelastic import NeoHooke, SaintVenantKirchhoff
from .material import LinearElastic, Material

__all__ = ["VolumetricSplit"]


def _eye4(d: int, tail: tuple) -> np.ndarray:
    """``d_ik d_JL`` ``(d, d, d, d) + tail``."""
    I = np.eye(d)
    E = I[:, None, :, None] * I[None, :, None, :]
    return np.broadcast_to(E[(...,) + (None,) * len(tail)], E.shape + tail).copy()


class VolumetricSplit:
    """``W = W_mu + lambda / 2 q^2`` of a law (module docstring).

    Parameters
    ----------
    material : Material
        The law a solid evaluates (after :func:`~skfem_mortar.bodies.solid.constitutive_law`):
        NeoHooke or SaintVenantKirchhoff (finite strain) or LinearElastic.

    Attributes
    ----------
    shear : Material
        The same law with ``lambda = 0``.
    lmbda : float
        The law's ``lambda``.
    kind : {"log", "green", "linear"}
        ``q = ln J``, ``tr E`` or ``tr eps``.
    """

    def __init__(self, material: Material):
        kinds = ((LinearElastic, "linear"), (NeoHooke, "log"), (SaintVenantKirchhoff, "green"))
        kind = next((k for cls, k in kinds if isinstance(material, cls)), None)
        if kind is None:
            raise ValueError(f"material must be a NeoHooke, SaintVenantKirchhoff or "
                             f"LinearElastic law (a volumetric split is known for these), "
                             f"got {type(material).__name__}")
        self.kind = kind
        self.lmbda = float(material.lmbda)
        self.shear = copy.copy(material)
        self.shear.lmbda = 0.0

    def log_measure(self, F: np.ndarray, tangent: bool = True
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """``q``, ``dq/dF`` ``(d, d, ...)`` and ``d2q/dF2`` ``(d, d, d, d, ...)`` (None
        without ``tangent``; zeros for the linear law)."""
        F = np.asarray(F, dtype=float)
        d, tail = F.shape[0], F.shape[2:]
        if self.kind == "linear":
            I = np.eye(d)[(...,) + (None,) * len(tail)]
            q = np.trace(F) - d
            return q, np.broadcast_to(I, F.shape).copy(), \
                (np.zeros((d,) * 4 + tail) if tangent else None)
        if self.kind == "green":
            q = 0.5 * (np.einsum("iJ...,iJ...->...", F, F) - d)
            return q, F.copy(), (_eye4(d, tail) if tangent else None)
        J = checked_det(F)
        Fi = inv(F)
        FiT = np.swapaxes(Fi, 0, 1)
        d2 = -Fi[None, :, :, None] * FiT[:, None, None, :] if tangent else None
        return np.log(J), FiT, d2

    def mean_measure(self, F: np.ndarray, tangent: bool = True
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """The measure ``m`` the mean-dilatation rule averages (``J`` for NeoHooke, else
        ``q``), its first and second derivatives (module docstring)."""
        if self.kind != "log":
            return self.log_measure(F, tangent)
        F = np.asarray(F, dtype=float)
        J = checked_det(F)
        Fi = inv(F)
        FiT = np.swapaxes(Fi, 0, 1)
        d2 = None
        if tangent:
            d2 = J * (FiT[:, :, None, None] * FiT[None, None, :, :]
                      - Fi[None, :, :, None] * FiT[:, None, None, :])
        return J, J * FiT, d2

    def energy_derivatives(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``U'(t)`` and ``U''(t)`` of the mean-dilatation energy ``U`` (module docstring);
        ``t`` the element means ``m_bar`` (> 0 for NeoHooke)."""
        t = np.asarray(t, dtype=float)
        if self.kind != "log":
            return self.lmbda * t, np.full_like(t, self.lmbda)
        if np.any(t <= 0.0):
            raise InversionError(f"mean dilatation: an element's volume ratio v_e / V_e "
                                 f"<= 0 (min {t.min():.3e})")
        lt = np.log(t)
        return self.lmbda * lt / t, self.lmbda * (1.0 - lt) / t ** 2
