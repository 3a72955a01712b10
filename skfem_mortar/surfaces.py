"""Deprecated: ``skfem_mortar.surfaces`` moved to :mod:`skfem_mortar.contact.surfaces`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.surfaces moved to skfem_mortar.contact.surfaces; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.surfaces")
