"""The bodies layer: internal forces and tangents. Hyperelastic materials (:mod:`.materials`),
plane-strain solids (:mod:`.solid`), MINI u-p triangles (:mod:`.mixed`), selectively reduced
quads (:mod:`.sri`), nonlinear cables and their axial laws (:mod:`.cable`, :mod:`.cable_laws`)
and mesh checks (:mod:`skfem_mortar.bodies.checks`). Imports only from the core layer.
The axisymmetric geometry's kernel terms (:mod:`.axisymmetric`) register on import.
"""
from . import axisymmetric  # noqa: F401  (registers the "axisymmetric" terms)
