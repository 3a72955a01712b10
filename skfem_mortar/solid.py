"""Deprecated: ``skfem_mortar.solid`` moved to :mod:`skfem_mortar.bodies.solid`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.solid moved to skfem_mortar.bodies.solid; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.bodies.solid")
