"""Deprecated: ``skfem_mortar.discretization`` moved to :mod:`skfem_mortar.contact.discretization`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.discretization moved to skfem_mortar.contact.discretization; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.discretization")
