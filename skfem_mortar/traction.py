"""Deprecated: ``skfem_mortar.traction`` moved to :mod:`skfem_mortar.loads.traction`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.traction moved to skfem_mortar.loads.traction; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.loads.traction")
