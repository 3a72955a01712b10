"""Deprecated: ``skfem_mortar.contact_output`` moved to :mod:`skfem_mortar.output.contact_output`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.contact_output moved to skfem_mortar.output.contact_output; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.output.contact_output")
