"""Deprecated: ``skfem_mortar.newton`` moved to :mod:`skfem_mortar.solver.newton`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.newton moved to skfem_mortar.solver.newton; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.solver.newton")
