"""Deprecated: ``skfem_mortar.contact_eval`` moved to :mod:`skfem_mortar.contact.contact_eval`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.contact_eval moved to skfem_mortar.contact.contact_eval; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.contact_eval")
