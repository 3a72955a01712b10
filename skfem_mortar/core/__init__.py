"""The core layer: the items and the unknown layout ``z = [u; lam]`` of a model, the assembly of
residual and tangent from COO triplets into a fixed CSR pattern (:mod:`.model`, :mod:`.coo`),
the errors the solver raises (:mod:`.errors`) and the timers (:mod:`.timing`). It imports
nothing from the other layers.
"""
