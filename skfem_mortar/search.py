"""Deprecated: ``skfem_mortar.search`` moved to :mod:`skfem_mortar.contact.search`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.search moved to skfem_mortar.contact.search; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.search")
