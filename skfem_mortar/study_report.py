"""Deprecated: ``skfem_mortar.study_report`` moved to :mod:`skfem_mortar.app.study_report`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.study_report moved to skfem_mortar.app.study_report; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.app.study_report")
