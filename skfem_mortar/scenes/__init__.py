"""Scenes: small functions that build only the parts a problem needs.

Every module in this package that defines ``SCENE`` (a :class:`Scene`) is a
scene of the command line (``skfem-mortar scenes`` lists them). A scene's
``build(params, method)`` returns a :class:`Setup`: the model, how to compute
its metrics from a result, which items write output, and (for contact scenes)
the contact data for ``contact.csv``.
"""
from __future__ import annotations

import importlib
import math
import pkgutil
from dataclasses import dataclass, field
from typing import Any, Callable

__all__ = ["Param", "Scene", "Setup", "get_scene", "list_scenes", "METHODS"]

METHODS = ("nts", "mortar", "mortar-dual")


@dataclass(frozen=True)
class Param:
    """A scene parameter with its default and its allowed range.

    ``parse`` turns a command-line string (or a Python value) into the typed
    value and raises ValueError naming the parameter and the allowed range.
    """

    name: str
    default: Any
    doc: str = ""
    kind: type = float
    choices: tuple | None = None
    low: float | None = None
    high: float | None = None
    low_inclusive: bool = True
    high_inclusive: bool = True

    def range_text(self) -> str:
        if self.choices is not None:
            return "one of " + ", ".join(map(str, self.choices))
        if self.low is None and self.high is None:
            return f"a {self.kind.__name__}"
        lo = "(-inf" if self.low is None else ("[" if self.low_inclusive else "(") + f"{self.low:g}"
        hi = "inf)" if self.high is None else f"{self.high:g}" + ("]" if self.high_inclusive else ")")
        return f"a {self.kind.__name__} in {lo}, {hi}"

    def parse(self, value: Any) -> Any:
        err = ValueError(f"parameter {self.name!r} must be {self.range_text()}, got {value!r}")
        try:
            if self.kind is bool:
                if isinstance(value, str):
                    low = value.strip().lower()
                    if low not in ("1", "0", "true", "false", "yes", "no", "on", "off"):
                        raise err
                    v = low in ("1", "true", "yes", "on")
                else:
                    v = bool(value)
            elif self.kind is int:
                if isinstance(value, float) and not value.is_integer():
                    raise err
                v = int(value) if not isinstance(value, str) else int(value.strip())
            elif self.kind is float:
                v = float(value)
            else:
                v = self.kind(value)
        except (TypeError, ValueError):
            raise err from None
        if isinstance(v, float) and not math.isfinite(v):
            raise err
        if self.choices is not None and v not in self.choices:
            raise err
        if self.low is not None and (v < self.low or (v == self.low and not self.low_inclusive)):
            raise err
        if self.high is not None and (v > self.high or (v == self.high and not self.high_inclusive)):
            raise err
        return v


@dataclass
class Setup:
    """What a scene's ``build`` returns.

    Attributes
    ----------
    model : Model
    metrics : callable(Result) -> dict
        Scene-specific numbers (``q``, ``q_exact``, ``q_error``).
    outputs : list
        Items with ``output_mesh()`` / ``output_data(z)`` written as series.
    contact : callable(z) -> dict or None
        Arrays ``x, y, gap, pressure`` per slave node for ``contact.csv``.
    n_steps : int or None
        Number of load steps this setup wants by default.
    solve_options : dict
        Extra keyword arguments of :func:`skfem_mortar.stepping.solve`.
    plots : callable(metrics, out_dir) or None
        Scene-specific pictures written into ``--out`` (e.g. force histories).
    """

    model: Any
    metrics: Callable[[Any], dict] = field(default=lambda result: {})
    outputs: list = field(default_factory=list)
    contact: Callable[[Any], dict] | None = None
    n_steps: int | None = None
    solve_options: dict = field(default_factory=dict)
    plots: Callable[[dict, Any], None] | None = None


@dataclass
class Scene:
    """A named problem with typed parameters."""

    name: str
    summary: str
    params: tuple[Param, ...]
    build: Callable[[dict, str | None], Setup]
    methods: tuple = (None,)
    default_steps: int = 1

    def param(self, name: str) -> Param:
        for p in self.params:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in self.params)
        raise ValueError(f"unknown parameter {name!r} for scene {self.name!r}; "
                         f"known parameters: {known}")

    def resolve(self, overrides: dict[str, Any] | None = None) -> dict[str, Any]:
        """Defaults updated by ``overrides`` (strings or values), all validated."""
        values = {p.name: p.default for p in self.params}
        for key, val in (overrides or {}).items():
            values[key] = self.param(key).parse(val)
        return values

    def check_method(self, method: str | None) -> str | None:
        if method is None:
            return self.methods[0]
        if method not in self.methods:
            allowed = ", ".join(str(m) for m in self.methods if m is not None) or "none"
            raise ValueError(f"method must be one of {allowed} for scene {self.name!r}, "
                             f"got {method!r}")
        return method


def _discover() -> dict[str, str]:
    return {m.name: f"{__name__}.{m.name}" for m in pkgutil.iter_modules(__path__)
            if not m.name.startswith("_")}


def get_scene(name: str) -> Scene:
    """The scene called ``name`` (ValueError listing the known scenes otherwise)."""
    modules = _discover()
    if name not in modules:
        raise ValueError(f"unknown scene {name!r}; known scenes: {', '.join(sorted(modules))}")
    return importlib.import_module(modules[name]).SCENE


def list_scenes() -> list[Scene]:
    return [get_scene(n) for n in sorted(_discover())]
