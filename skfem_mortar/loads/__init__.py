"""The loads layer: external forces. Follower pressure on cables and solid edges
(:mod:`.pressure`, :class:`FollowerPressure`), dead surface tractions and point loads
(:mod:`.traction`). Prescribed values (``Dirichlet``) live in :mod:`skfem_mortar.core.model`.

This package also stands for the former module ``skfem_mortar.loads`` (now :mod:`.pressure`):
every name of that module resolves here, lazily, to the same object.
"""
from .._former import forward

__all__ = ["FollowerPressure", "facet_load_matrix"]

__getattr__ = forward(__name__, __path__, "pressure")
