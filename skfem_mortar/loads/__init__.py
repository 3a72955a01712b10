"""The loads layer: external forces. Follower pressure on cables and solid edges
(:mod:`.pressure`, :class:`~.pressure.FollowerPressure`), dead surface tractions and point loads
(:mod:`.traction`). Prescribed values (``Dirichlet``) live in :mod:`skfem_mortar.core.dirichlet`.
"""
