"""Axial laws of cables: ``N(lambda)`` and ``dN/dlambda`` by name, and the Newton
tolerance a cable's residual can reach (linear, svk, hencky:
``docs/reference_problems.rst``, cable laws)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..core.errors import InversionError
from ..core.validate import real

__all__ = ["CableLaw", "LAWS", "get_law", "newton_rtol"]


@dataclass(frozen=True)
class CableLaw:
    """An axial law ``N(lambda)`` of a cable and its derivative.

    Attributes
    ----------
    name : str
        Name used in scenes and on the command line.
    force : callable
        ``force(stretch, EA) -> N``.
    stiffness : callable
        ``stiffness(stretch, EA) -> dN/dlambda``.

    All three laws have ``N(1) = 0`` and ``N'(1) = EA``.
    """

    name: str
    force: Callable[[np.ndarray, np.ndarray], np.ndarray]
    stiffness: Callable[[np.ndarray, np.ndarray], np.ndarray]

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"name must be a non-empty string, got {self.name!r}")
        for what in ("force", "stiffness"):
            if not callable(getattr(self, what)):
                raise ValueError(f"{what} must be a function of (stretch, EA), got "
                                 f"{getattr(self, what)!r}")


def _log_positive(stretch: np.ndarray) -> np.ndarray:
    if np.any(stretch <= 0.0):
        raise InversionError("hencky law: stretch must be positive")
    return np.log(stretch)


#: The laws by name: ``linear`` N = EA (lambda - 1), ``svk``
#: N = EA lambda (lambda^2 - 1) / 2 (Green strain) and ``hencky`` N = EA ln(lambda).
LAWS: dict[str, CableLaw] = {
    "linear": CableLaw("linear", lambda stretch, EA: EA * (stretch - 1.0),
                       lambda stretch, EA: EA * np.ones_like(stretch)),
    "svk": CableLaw("svk", lambda stretch, EA: 0.5 * EA * stretch * (stretch * stretch - 1.0),
                    lambda stretch, EA: 0.5 * EA * (3.0 * stretch * stretch - 1.0)),
    "hencky": CableLaw("hencky", lambda stretch, EA: EA * _log_positive(stretch),
                       lambda stretch, EA: EA / stretch),
}


def get_law(law: str | CableLaw) -> CableLaw:
    """Return the :class:`CableLaw` named ``law`` (one of :data:`LAWS`)."""
    if isinstance(law, CableLaw):
        return law
    if not isinstance(law, str) or law not in LAWS:
        raise ValueError(f"law must be one of {sorted(LAWS)}, got {law!r}")
    return LAWS[law]


def newton_rtol(EA: float, tension: float, rtol: float = 1e-10) -> float:
    """A relative Newton tolerance that a cable's residual can reach.

    The stretch of an element carries a relative round-off of about ``eps``,
    so its axial force one of about ``eps EA``; the solver measures the
    residual against forces of the order of the tension ``T``.  Below
    ``eps EA / T`` the residual is noise (a steel-like cable, ``EA / T ~ 1e6``,
    cannot reach ``rtol = 1e-10``).  Returns

        max(rtol, 1e3 eps EA / T) ,

    the factor 1e3 leaving room for load steps down to a few percent of the
    final tension.

    Parameters
    ----------
    EA : float
        Axial stiffness.
    tension : float
        Tension scale of the final state (e.g. ``p a`` for a pressure ``p`` on
        a cable of half-span or radius ``a``), > 0.
    rtol : float
        The tolerance wanted where round-off allows it.
    """
    EA = real("EA", EA, 0.0, low_open=True)
    tension = real("tension", tension, 0.0, low_open=True)
    rtol = real("rtol", rtol, 0.0, 1.0, low_open=True, high_open=True)
    return max(rtol, 1e3 * np.finfo(float).eps * EA / tension)
