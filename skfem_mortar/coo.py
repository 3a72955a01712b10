"""Deprecated: ``skfem_mortar.coo`` moved to :mod:`skfem_mortar.core.coo`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.coo moved to skfem_mortar.core.coo; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.core.coo")
