"""Deprecated: ``skfem_mortar.outdir`` moved to :mod:`skfem_mortar.output.outdir`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.outdir moved to skfem_mortar.output.outdir; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.output.outdir")
