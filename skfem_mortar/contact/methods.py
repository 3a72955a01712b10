"""The built-in contact methods, registered: importing this module imports :mod:`.nts`
(``"nts"``) and :mod:`.mortar_method` (``"mortar"``, ``"mortar-dual"``), which register
themselves with :func:`~.discretization.register_method` in the order of
``BUILTIN_METHODS``; :func:`make_method` and :data:`METHODS` from here know them.
The pair imports it (:mod:`.discretization`, the protocol and the registry, imports no
method)."""
from __future__ import annotations

from . import mortar_method, nts  # noqa: F401 (register the built-ins)
from .discretization import METHODS, make_method

__all__ = ["METHODS", "make_method"]
