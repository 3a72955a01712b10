"""Deprecated: ``skfem_mortar.observers`` moved to :mod:`skfem_mortar.solver.observers`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.observers moved to skfem_mortar.solver.observers; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.solver.observers")
