"""Deprecated: ``skfem_mortar.cable_laws`` moved to :mod:`skfem_mortar.bodies.cable_laws`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.cable_laws moved to skfem_mortar.bodies.cable_laws; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.bodies.cable_laws")
