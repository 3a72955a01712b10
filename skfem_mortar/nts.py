"""Deprecated: ``skfem_mortar.nts`` moved to :mod:`skfem_mortar.contact.nts`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.nts moved to skfem_mortar.contact.nts; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.nts")
