"""Deprecated: ``skfem_mortar.jets`` moved to :mod:`skfem_mortar.contact.jets`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.jets moved to skfem_mortar.contact.jets; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.jets")
