"""Deprecated: ``skfem_mortar.study`` moved to :mod:`skfem_mortar.app.study`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.study moved to skfem_mortar.app.study; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.app.study")
