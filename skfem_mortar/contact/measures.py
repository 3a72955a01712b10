"""The measure of a contact surface: what ``dGamma`` weighs in each geometry.

Every contact integral (the mortar matrices D and M, the weighted gap, the
slip, the tributary areas, the dual basis) is an integral over the current
slave surface with the weight ``w(x) dGamma``:

* plane: ``w = 1`` (per unit thickness; the pair multiplies its forces by the
  model's thickness);
* axisymmetric: ``w = 2 pi r`` with ``r = x[0]`` the current radius of the
  point, so every integral is a total over the revolution.

A measure is data the kernels multiply in; they never branch on the
geometry.  :attr:`Measure.unit` says the weight is 1 (the kernels then skip
the product, bit for bit the plane result).  A contact method learns its
measure from the pair at bind
(:meth:`~skfem_mortar.contact.discretization.ContactDiscretization.set_measure`).
"""
from __future__ import annotations

import math
from typing import Any

__all__ = ["Measure", "PLANE", "AXISYMMETRIC", "measure_for"]


class Measure:
    """The weight ``w(x)`` of ``dGamma`` at a current point ``x``.

    Parameters
    ----------
    name : str
        The model geometry it belongs to.
    factor : float
        ``w = factor * x[axis]``; with ``axis=None``, ``w = factor``.
    axis : int or None
        The coordinate the weight is proportional to (0: the radius ``r``).
    """

    def __init__(self, name: str, factor: float = 1.0, axis: int | None = None):
        self.name, self.factor, self.axis = name, float(factor), axis

    @property
    def unit(self) -> bool:
        """True when ``w = 1`` everywhere (the kernels skip the product)."""
        return self.axis is None and self.factor == 1.0

    def weight(self, x: Any) -> Any:
        """``w(x)``; ``x`` is a sequence of coordinates (arrays or jets), so
        the result carries the derivatives of ``x``: ``dw/dx[axis] = factor``."""
        if self.axis is None:
            return self.factor
        return self.factor * x[self.axis]

    def __repr__(self) -> str:
        return f"Measure({self.name!r})"


#: plane models: ``dGamma`` per unit thickness
PLANE = Measure("plane")
#: axisymmetric models: ``2 pi r dGamma``, a total over the revolution
AXISYMMETRIC = Measure("axisymmetric", 2.0 * math.pi, axis=0)

_MEASURES = {"plane": PLANE, "axisymmetric": AXISYMMETRIC, "3d": PLANE}


def measure_for(geometry: str) -> Measure:
    """The measure of a model geometry (``"plane"``, ``"axisymmetric"``, ``"3d"``)."""
    try:
        return _MEASURES[geometry]
    except KeyError:
        raise ValueError(f"geometry must be one of {sorted(_MEASURES)}, got {geometry!r}") from None
