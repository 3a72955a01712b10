"""Deprecated: ``skfem_mortar.cable`` moved to :mod:`skfem_mortar.bodies.cable`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.cable moved to skfem_mortar.bodies.cable; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.bodies.cable")
