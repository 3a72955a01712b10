"""skfem-mortar: large-deformation contact for scikit-fem, in 2D.

Node-to-segment and mortar contact (dual mortar by default) with Lagrange
multipliers, frictionless or with Coulomb or Tresca friction, mortar tying,
nonlinear cables under follower pressure and hyperelastic solids (plane strain
or plane stress), solved by one block Newton method over displacements and
multipliers. Axisymmetric and 3D models are not supported yet.
"""
from __future__ import annotations

from importlib import import_module
from typing import Any

__version__ = "0.1.0"  # the one source of the version (pyproject.toml reads it)

# public name -> module; resolved lazily so that `import skfem_mortar` and the
# command line start fast and a module that has not landed yet breaks nothing else
_EXPORTS = {
    "Model": "core.model", "Item": "core.item", "Dirichlet": "core.dirichlet", "Contribution": "core.item",
    "solve": "solver.stepping", "Result": "solver.stepping", "StepRecord": "solver.stepping",
    "NewtonOptions": "solver.newton",
    "ConvergenceError": "core.errors", "InversionError": "core.errors",
    "ContactSizeError": "core.errors",
    "NeoHooke": "bodies.hyperelastic", "SaintVenantKirchhoff": "bodies.hyperelastic",
    "LinearElastic": "bodies.material",
    "Solid": "bodies.solid", "MixedSolid": "bodies.mixed",
    "TaylorHoodSolid": "bodies.taylor_hood", "MeanDilatationSolid": "bodies.mean_dilatation", "Traction": "loads.traction", "PointLoad": "loads.traction",
    "Cable": "bodies.cable", "Membrane": "bodies.membrane", "VolumeControl": "loads.volume",
    "LimitPointError": "solver.limit_point",
    "FollowerPressure": "loads.pressure", "FollowerPressure3D": "loads.pressure3d",
    "read_mesh": "output.mesh_io", "render3d": "output.render3d",
    "ContactPair": "contact.pair", "TiePair": "contact.tie",
    "Coulomb": "contact.friction", "Tresca": "contact.friction",
    "ContactSurface": "contact.surfaces", "RigidPlane": "contact.surfaces", "RigidCircle": "contact.surfaces",
    "RigidPlane3D": "contact.rigid3d", "RigidSphere": "contact.rigid3d",
    "RigidCylinder": "contact.rigid3d",
    "pressure_profile": "output.contact_output",
    "run_scene": "app.runner", "build_scene": "app.runner",
}

__all__ = sorted(_EXPORTS) + ["__version__"]


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
