"""Deprecated: ``skfem_mortar.linsolve`` moved to :mod:`skfem_mortar.solver.linsolve`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.linsolve moved to skfem_mortar.solver.linsolve; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.solver.linsolve")
