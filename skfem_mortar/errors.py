"""Deprecated: ``skfem_mortar.errors`` moved to :mod:`skfem_mortar.core.errors`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.errors moved to skfem_mortar.core.errors; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.core.errors")
