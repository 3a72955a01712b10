"""The solver layer: the block Newton method over displacements and multipliers
(:mod:`.newton`), load steps, cuts and restarts (:mod:`.stepping`), sparse linear solves
(:mod:`.linsolve`) and the observers a solve reports to (:mod:`.observers`). It calls the
items only through the protocol of :class:`skfem_mortar.core.model.Item`.
"""
