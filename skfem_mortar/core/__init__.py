"""The core layer: the item protocols (:mod:`.item`), the unknown layout ``z = [u; lam]`` of a
model and the assembly of residual and tangent from COO triplets (:mod:`.model`, :mod:`.coo`)
into a fixed CSR pattern (:mod:`.pattern`), the model-wide checks (:mod:`skfem_mortar.core.checks`), the errors
the solver raises (:mod:`.errors`) and the timers (:mod:`.timing`). It imports nothing from the
other layers.
"""
