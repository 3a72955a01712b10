"""Deprecated: ``skfem_mortar.timing`` moved to :mod:`skfem_mortar.core.timing`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.timing moved to skfem_mortar.core.timing; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.core.timing")
