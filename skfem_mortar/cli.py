"""Deprecated: ``skfem_mortar.cli`` moved to :mod:`skfem_mortar.app.cli`."""
import sys
import warnings
from importlib import import_module

warnings.warn("skfem_mortar.cli moved to skfem_mortar.app.cli; the old path goes in the next release",
              DeprecationWarning, stacklevel=2)

if __name__ == "__main__":  # python -m skfem_mortar.cli
    sys.exit(import_module("skfem_mortar.app.cli").main())
else:
    sys.modules[__name__] = import_module("skfem_mortar.app.cli")
