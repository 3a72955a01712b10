"""Deprecated: ``skfem_mortar.materials`` moved to :mod:`skfem_mortar.bodies.materials`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.materials moved to skfem_mortar.bodies.materials; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.bodies.materials")
