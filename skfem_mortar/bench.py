"""Deprecated: ``skfem_mortar.bench`` moved to :mod:`skfem_mortar.app.bench`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.bench moved to skfem_mortar.app.bench; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.app.bench")
