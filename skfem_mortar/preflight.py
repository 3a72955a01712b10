"""Deprecated: ``skfem_mortar.preflight`` moved to :mod:`skfem_mortar.contact.preflight`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.preflight moved to skfem_mortar.contact.preflight; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.preflight")
