"""The lookup of a package that stands for a former module of the same name."""
from __future__ import annotations

import pkgutil
from importlib import import_module
from typing import Any, Callable


def forward(package: str, path: list[str], module: str) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``package`` that resolves a name, lazily, to
    the object of the same name in its submodule ``module`` (the former module's
    new place). Names of submodules and dunder names are left to the import system."""
    submodules = frozenset(m.name for m in pkgutil.iter_modules(path))

    def __getattr__(name: str) -> Any:
        if not name.startswith("__") and name not in submodules:
            try:
                return getattr(import_module(f"{package}.{module}"), name)
            except AttributeError:
                pass
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
