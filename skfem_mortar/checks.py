"""Deprecated: ``skfem_mortar.checks`` moved to :mod:`skfem_mortar.bodies.checks`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.checks moved to skfem_mortar.bodies.checks; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.bodies.checks")
