"""Deprecated: ``skfem_mortar.mortar`` moved to :mod:`skfem_mortar.contact.mortar`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.mortar moved to skfem_mortar.contact.mortar; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.mortar")
