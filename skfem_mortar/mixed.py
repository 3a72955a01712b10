"""Deprecated: ``skfem_mortar.mixed`` moved to :mod:`skfem_mortar.bodies.mixed`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.mixed moved to skfem_mortar.bodies.mixed; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.bodies.mixed")
