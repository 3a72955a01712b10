"""Deprecated: ``skfem_mortar.mortar_segmentation`` moved to :mod:`skfem_mortar.contact.mortar_segmentation`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.mortar_segmentation moved to skfem_mortar.contact.mortar_segmentation; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

sys.modules[__name__] = import_module("skfem_mortar.contact.mortar_segmentation")
