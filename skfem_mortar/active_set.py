"""Deprecated: ``skfem_mortar.active_set`` moved to :mod:`skfem_mortar.contact.active_set`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.active_set moved to skfem_mortar.contact.active_set; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.active_set")
