"""Deprecated: ``skfem_mortar.stepping`` moved to :mod:`skfem_mortar.solver.stepping`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.stepping moved to skfem_mortar.solver.stepping; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.solver.stepping")
