"""The loads layer: external forces. Follower pressure on cables and solid edges
(:mod:`.pressure`, :class:`~.pressure.FollowerPressure`) and on the boundary faces of 3D solids
(:mod:`.pressure3d`, :class:`~.pressure3d.FollowerPressure3D`), dead surface tractions and point
loads, 2D and 3D (:mod:`.traction`). Prescribed values (``Dirichlet``) live in
:mod:`skfem_mortar.core.dirichlet`.
"""
