"""Deprecated: ``skfem_mortar.model`` moved to :mod:`skfem_mortar.core.model`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.model moved to skfem_mortar.core.model; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.core.model")
