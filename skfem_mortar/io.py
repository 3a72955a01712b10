"""Deprecated: ``skfem_mortar.io`` moved to :mod:`skfem_mortar.output.io`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.io moved to skfem_mortar.output.io; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.output.io")
