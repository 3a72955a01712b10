"""The solver layer: the block Newton method over displacements and multipliers
(:mod:`.newton`), load steps, cuts and restarts (:mod:`.stepping`), the items' states a
checkpoint keeps (:mod:`.states`), sparse linear solves (:mod:`.linsolve`, with the PARDISO
instance in :mod:`.pardiso` and the symmetrization of the saddle-point system in
:mod:`.symmetrization`) and the observers a solve reports to (:mod:`.observers`). It calls the
items only through the protocol of :class:`skfem_mortar.core.item.Item`.
"""
