"""Scenes: small functions that build only the parts a problem needs.

Every module in this package that defines ``SCENE`` (a :class:`Scene`) is a
scene of the command line (``skfem-mortar scenes`` lists them). A scene's
``build(params, method)`` returns a :class:`Setup`: the model, how to compute
its metrics from a result, which items write output, and (for contact scenes)
the contact data for ``contact.csv``.  "Reference problem N" in a scene's
docstring and summary is section N of ``docs/reference_problems.rst``: the
problem, its analytic answer and what the scene checks.

Before anything is built, :meth:`Scene.resolve` refuses (ValueError, one line
naming the user's parameter and its allowed range):

* a value outside its :class:`Param` range, NaN, infinity, an empty string,
  or a subnormal number (``0 < |v| < 2.2e-308``);
* a size whose cheap dof estimate (``Scene.estimate_dofs``, from the
  parameters alone) exceeds :func:`max_dofs`;
* a value that drives a quantity the scene derives from its parameters
  (``Scene.derived``: Lamé parameters, loads, stiffness ratios, ...) out of
  the window ``[SAFE_LOW, SAFE_HIGH]`` or out of its own range.
"""
from __future__ import annotations

import importlib
import math
import os
import pkgutil
import sys
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from ..contact import BUILTIN_METHODS, DEFAULT_METHOD
from ._parse import to_bool, to_int, plain_number

__all__ = ["Param", "Derived", "Scene", "Setup", "get_scene", "list_scenes", "METHODS",
           "max_dofs", "MAX_STEPS", "SAFE_LOW", "SAFE_HIGH", "press_then_slide"]

METHODS = BUILTIN_METHODS  # the contact methods a scene with contact offers

#: the magnitude window of every quantity a scene derives from its parameters
#: (moduli, loads, tensions): products and squares of two such numbers (energy
#: norms, residual norms over up to 1e6 dofs) stay finite and normal
SAFE_LOW, SAFE_HIGH = 1e-100, 1e100

#: the largest load step count a scene parameter may ask for
MAX_STEPS = 100_000

#: default dof limit; the memory estimate below may lower it on a small machine
DEFAULT_MAX_DOFS = 2_000_000

#: estimated peak memory per displacement dof of a run (assembly, the sparse
#: direct factorization, the load step states): measured 5.8 kB on the seed
#: scene at 7.5e4 dofs (588 MB peak, 150 MB of it the interpreter); 8 kB leaves
#: room for the LU fill growing with size
BYTES_PER_DOF = 8_000

#: the share of the machine's memory a run may be estimated to use
MEMORY_SHARE = 0.5

#: environment variable that overrides the dof limit (a positive integer)
MAX_DOFS_ENV = "SKFEM_MORTAR_MAX_DOFS"

_TINY = sys.float_info.min  # smallest normal float, 2.2e-308


def _total_memory() -> int | None:
    """Physical memory of the machine in bytes (None where it cannot be read)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


def max_dofs() -> int:
    """The largest dof estimate a scene may build.

    ``SKFEM_MORTAR_MAX_DOFS`` when set (a positive integer), else
    ``min(DEFAULT_MAX_DOFS, MEMORY_SHARE * RAM / BYTES_PER_DOF)``.

    Raises
    ------
    ValueError
        If the environment variable is set but not a positive integer.
    """
    text = os.environ.get(MAX_DOFS_ENV, "").strip()
    if text:
        try:
            value = int(text)
        except ValueError:
            value = 0
        if value < 1:
            raise ValueError(f"environment variable {MAX_DOFS_ENV} must be an integer >= 1, "
                             f"got {text!r}")
        return value
    ram = _total_memory()
    if ram is None:
        return DEFAULT_MAX_DOFS
    return int(min(DEFAULT_MAX_DOFS, MEMORY_SHARE * ram / BYTES_PER_DOF))


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
            return f"{self._article()} {self.kind.__name__}"
        lo = "(-inf" if self.low is None else ("[" if self.low_inclusive else "(") + f"{self.low:g}"
        hi = "inf)" if self.high is None else f"{self.high:g}" + ("]" if self.high_inclusive else ")")
        return f"{self._article()} {self.kind.__name__} in {lo}, {hi}"

    def _article(self) -> str:
        return "an" if self.kind.__name__[0] in "aeiou" else "a"

    def parse(self, value: Any) -> Any:
        """The typed, validated value of ``value`` (a command-line string or a Python value).

        Raises
        ------
        ValueError
            One line naming the parameter and its allowed range: for a value of
            the wrong type, NaN, infinity, a subnormal float, an empty string,
            a value outside the range or not among the choices.
        """
        err = ValueError(f"parameter {self.name!r} must be {self.range_text()}, got {value!r}")
        if self.kind in (int, float) and isinstance(value, str) and not plain_number(value):
            raise ValueError(f"parameter {self.name!r} must be {self.range_text()}, got "
                             f"{value!r} (not a plain number: digits with an optional sign, "
                             f"decimal point and exponent, e.g. 10, 0.5, 1e3)")
        try:
            v = self._convert(value)
        except (TypeError, ValueError, OverflowError):
            raise err from None
        if isinstance(v, float):
            if not math.isfinite(v):
                raise err
            if 0.0 < abs(v) < _TINY:
                raise ValueError(f"parameter {self.name!r} must be {self.range_text()}, got "
                                 f"{value!r} (a subnormal number: use 0 or a magnitude "
                                 f">= {_TINY:.3g})")
            v += 0.0  # -0.0 -> 0.0
        if (self.choices is not None and v not in self.choices) or not self.in_range(v):
            raise err
        return v

    def in_range(self, v: Any) -> bool:
        """Whether ``v`` lies within ``low`` and ``high`` (with their inclusiveness)."""
        if self.low is not None and (v < self.low or (v == self.low and not self.low_inclusive)):
            return False
        return self.high is None or v < self.high or (v == self.high and self.high_inclusive)

    def _convert(self, value: Any) -> Any:
        """``value`` as ``self.kind`` (TypeError/ValueError/OverflowError otherwise)."""
        if self.kind is bool:
            return to_bool(value)
        if self.kind is int:
            return to_int(value)
        if self.kind is float:
            if isinstance(value, bool):
                raise TypeError("a bool is not a number")
            return float(value)
        if isinstance(value, str) and not value.strip():
            raise ValueError("empty")
        return self.kind(value)


@dataclass(frozen=True)
class Derived:
    """A quantity a scene computes from its parameters, and its allowed range.

    Attributes
    ----------
    label : str
        What it is, e.g. ``"the Lame parameter lambda"`` (for the message only).
    value : float
        Its value for the parameters as given.
    params : tuple of str
        The parameters it is computed from (the message names these).
    low, high : float
        Its allowed closed range (default: the magnitude window
        ``[SAFE_LOW, SAFE_HIGH]`` of a positive quantity).
    """

    label: str
    value: float
    params: tuple[str, ...]
    low: float = SAFE_LOW
    high: float = SAFE_HIGH

    def ok(self) -> bool:
        """Finite and within ``[low, high]``."""
        v = float(self.value)
        return math.isfinite(v) and self.low <= v <= self.high


def positive(label: str, value: float, *params: str) -> Derived:
    """A positive scale quantity (modulus, load, length) in ``[SAFE_LOW, SAFE_HIGH]``."""
    return Derived(label, value, tuple(params))


def ratio(label: str, value: float, params: Sequence[str], low: float,
          high: float) -> Derived:
    """A dimensionless ratio of parameters with its range ``[low, high]``."""
    return Derived(label, value, tuple(params), low, high)


def lame_quantities(E: float, nu: float, E_name: str = "E", nu_name: str = "nu",
                    body: str = "") -> list[Derived]:
    """The Lame parameter ``mu`` in the scale window and ``lambda / mu = 2 nu / (1 - 2 nu)``
    at most ``1e8`` (nearly incompressible beyond: the tangent's condition number
    grows with it and the direct solve loses every digit)."""
    mu = E / (2.0 * (1.0 + nu))
    of = f" of {body}" if body else ""
    return [positive(f"the Lame parameter mu{of}", mu, E_name, nu_name),
            ratio(f"lambda / mu{of}", 2.0 * nu / (1.0 - 2.0 * nu), (nu_name,), -1.0, 1e8)]


def cable_quantities(EA: float, pressure: float, length: float,
                     length_name: str) -> list[Derived]:
    """A pressurized cable's scales: ``EA``, the tension scale ``p L`` and their ratio
    ``EA / (p L)`` at most ``1e9`` (beyond, round-off in the stretch forbids a
    Newton tolerance below ``1e3 eps EA / (p L)``, see ``newton_rtol``)."""
    names = ("EA", "pressure", length_name)
    return [positive("EA", EA, "EA"),
            positive(f"the tension scale pressure {length_name}", pressure * length,
                     "pressure", length_name),
            ratio(f"EA / (pressure {length_name})", EA / (pressure * length), names,
                  0.0, 1e9)]


def cable_dofs(n_elements: int) -> int:
    """Dofs of an open cable of ``n_elements`` (two per node)."""
    return 2 * (int(n_elements) + 1)


def grid_dofs(nx: int, ny: int, order: int = 1) -> int:
    """Dofs of a vector field on an ``nx x ny`` grid of elements of polynomial ``order``."""
    return 2 * (order * int(nx) + 1) * (order * int(ny) + 1)


def press_then_slide(t_press: float, press: float = 1.0, slide: float = 1.0
                     ) -> tuple[Callable[[float], float], Callable[[float], float]]:
    """The two phases of a press-and-slide load history over the load factor ``t``.

    Returns ``(pressed, slid)``: ``pressed(t) = press min(t / t_press, 1)`` (rises to
    ``press`` at ``t_press``, then held) and
    ``slid(t) = slide max(t - t_press, 0) / (1 - t_press)`` (0 while pressing, then
    rising to ``slide`` at ``t = 1``).

    Raises
    ------
    ValueError
        Unless ``0 < t_press < 1``.
    """
    if not 0.0 < t_press < 1.0:
        raise ValueError(f"t_press must lie in (0, 1), got {t_press!r}")

    def pressed(t: float) -> float:
        return press * min(t / t_press, 1.0)

    def slid(t: float) -> float:
        return slide * max(t - t_press, 0.0) / (1.0 - t_press)
    return pressed, slid


@dataclass
class Setup:
    """What a scene's ``build`` returns.

    Attributes
    ----------
    model : Model
    metrics : callable(Result) -> dict
        Scene-specific numbers (``q``, ``q_exact``, ``q_error``).
    outputs : list, optional
        Items with ``output_mesh()`` / ``output_data(z)`` written as series.
        Default: ``model.outputs()`` (every body, then every contact pair's
        slave surface, in the order of the model's items).
    contact : callable(z) -> dict or None, optional
        Arrays ``x, y, gap, pressure`` per slave node for ``contact.csv``.
        Default: the ``contact_data`` of the model's contact pair when it has
        exactly one (none without contact; a scene with several names one).
    n_steps : int or None
        Number of load steps this setup wants by default.
    solve_options : dict
        Extra keyword arguments of :func:`skfem_mortar.solver.stepping.solve`.
    plots : callable(metrics, out_dir) or None
        Scene-specific pictures written into ``--out`` (e.g. force histories).
    """

    model: Any
    metrics: Callable[[Any], dict] = field(default=lambda result: {})
    outputs: list | None = None
    contact: Callable[[Any], dict] | None = None
    n_steps: int | None = None
    solve_options: dict = field(default_factory=dict)
    plots: Callable[[dict, Any], None] | None = None

    def __post_init__(self):
        if self.outputs is None:
            self.outputs = self.model.outputs()
        if self.contact is None:
            tables = self.model.contact_tables()
            if len(tables) == 1:
                self.contact = tables[0].contact_data


@dataclass
class Scene:
    """A named problem with typed parameters.

    Attributes
    ----------
    estimate_dofs : callable(values) -> int, optional
        A cheap estimate (from the parameters alone, no mesh) of the
        displacement dofs the scene builds; above :func:`max_dofs` it is refused.
    sizes : tuple of str
        The parameters that set the size (named when the estimate is too large).
    derived : callable(values) -> list of Derived, optional
        The quantities the scene computes from its parameters, each with its
        allowed range; one out of range (or not finite) is refused, naming the
        parameters it comes from.
    one_step : callable(values, method) -> bool, optional
        Whether the answer at these parameters and method does not depend on the
        load path (a unique solution, and a method that keeps no state from one
        step to the next): then a run takes the whole load in one step and cuts
        only on failure, instead of ``default_steps`` (a suite test shows that
        one step gives the answer of several).  ``one_step_text`` says when, for
        the listing.
    """

    name: str
    summary: str
    params: tuple[Param, ...]
    build: Callable[[dict, str | None], Setup]
    methods: tuple = (None,)
    default_steps: int = 1
    estimate_dofs: Callable[[dict], int] | None = None
    sizes: tuple[str, ...] = ()
    derived: Callable[[dict], list[Derived]] | None = None
    one_step: Callable[[dict, str | None], bool] | None = None
    one_step_text: str = ""

    def steps(self, values: dict, method: str | None) -> int:
        """The load steps of a run at resolved ``values`` and ``method`` unless the
        user gives them: 1 where :attr:`one_step` holds, else ``default_steps``."""
        if self.one_step is not None and self.one_step(values, method):
            return 1
        return self.default_steps

    def param(self, name: str) -> Param:
        for p in self.params:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in self.params)
        raise ValueError(f"unknown parameter {name!r} for scene {self.name!r}; "
                         f"known parameters: {known}")

    def resolve(self, overrides: dict[str, Any] | None = None) -> dict[str, Any]:
        """Defaults updated by ``overrides`` (strings or values), all validated:
        each value in its range, the size within :func:`max_dofs`, the derived
        quantities within theirs (ValueError naming the parameter otherwise)."""
        values = {p.name: p.default for p in self.params}
        for key, val in (overrides or {}).items():
            values[key] = self.param(key).parse(val)
        given = tuple((overrides or {}).keys())
        self.check_size(values, given)
        self.check_derived(values, given)
        return values

    def check_size(self, values: dict[str, Any], given: Sequence[str] = ()) -> None:
        """Refuse a dof estimate above :func:`max_dofs`, naming the size parameters."""
        if self.estimate_dofs is None:
            return
        n, limit = int(self.estimate_dofs(values)), max_dofs()
        if n <= limit:
            return
        names = [k for k in self.sizes if k in given] or list(self.sizes)
        setting = ", ".join(f"{k} = {values[k]!r}" for k in names)
        raise ValueError(f"parameter {names[0]!r} is too large for scene {self.name!r}: "
                         f"{setting} gives about {n:.3g} dofs, above the limit {limit:.3g} "
                         f"(about {limit * BYTES_PER_DOF / 2**30:.0f} GB; "
                         f"{MAX_DOFS_ENV} overrides it)")

    def check_derived(self, values: dict[str, Any], given: Sequence[str] = ()) -> None:
        """Refuse parameters whose derived quantities leave their ranges, naming the
        parameter the user set and the range of it that would do (others as given)."""
        bad = _first_bad(self.derived, values)
        if bad is None:
            return
        names = [k for k in bad.params if k in given] or list(bad.params)
        name = names[0]
        where = (f"{bad.label} = {float(bad.value):.3g} must lie in "
                 f"[{bad.low:.3g}, {bad.high:.3g}]")
        span = self._allowed(values, name)
        others = ", ".join(f"{k} = {values[k]!r}" for k in bad.params if k != name)
        with_others = f" with {others}" if others else ""
        if span is None:
            raise ValueError(f"parameter {name!r} = {values[name]!r} is refused{with_others} "
                             f"({where}); change {', '.join(bad.params)}")
        raise ValueError(f"parameter {name!r} must lie in about [{span[0]}, {span[1]}]"
                         f"{with_others}, got {values[name]!r} ({where})")

    def _allowed(self, values: dict[str, Any], name: str) -> tuple[str, str] | None:
        """The smallest and largest of about 200 samples of the range of ``name`` for
        which every derived quantity is in range (the others as given)."""
        p = self.param(name)
        if p.kind is not float:
            return None
        samples = _samples(p)
        good = [_first_bad(self.derived, {**values, name: c}) is None for c in samples]
        if not any(good):
            return None
        i = good.index(True)
        j = len(good) - 1 - good[::-1].index(True)
        works = lambda c: _first_bad(self.derived, {**values, name: c}) is None  # noqa: E731
        below = samples[i - 1] if i > 0 else p.low
        above = samples[j + 1] if j + 1 < len(samples) else p.high
        lo = samples[i] if below is None else _bisect(works, below, samples[i])
        hi = samples[j] if above is None else _bisect(works, above, samples[j])
        return _short(lo, works), _short(hi, works)

    def check_method(self, method: str | None) -> str | None:
        if method is None:  # the package's default where the scene offers it
            return DEFAULT_METHOD if DEFAULT_METHOD in self.methods else self.methods[0]
        if method not in self.methods:
            allowed = ", ".join(str(m) for m in self.methods if m is not None) or "none"
            raise ValueError(f"method must be one of {allowed} for scene {self.name!r}, "
                             f"got {method!r}")
        return method


def _first_bad(derived: Callable[[dict], list[Derived]] | None,
               values: dict[str, Any]) -> Derived | None:
    """The first derived quantity out of its range (an exception computing them
    counts as an infinite first quantity), or None."""
    if derived is None:
        return None
    with np.errstate(all="ignore"):
        try:
            quantities = derived(values)
        except (ArithmeticError, ValueError) as exc:
            return Derived(f"a derived quantity ({exc})", math.inf, tuple(values))
    return next((d for d in quantities if not d.ok()), None)


def _bisect(works: Callable[[float], bool], bad: float, good: float) -> float:
    """The value near the edge between ``bad`` and ``good`` that still works (60
    bisections, geometric between two positive values)."""
    for _ in range(60):
        mid = math.sqrt(bad * good) if bad > 0 and good > 0 else 0.5 * (bad + good)
        if mid in (bad, good):
            break
        bad, good = (bad, mid) if works(mid) else (mid, good)
    return good


def _short(x: float, works: Callable[[float], bool]) -> str:
    """``x`` with the fewest significant digits (3, 6, 9, 12) that still work."""
    for digits in (3, 6, 9, 12):
        text = f"{x:.{digits}g}"
        if works(float(text)):
            return text
    return repr(x)


def _samples(p: Param) -> list[float]:
    """Candidate values over a float parameter's range: log-spaced for a positive
    range, linear for a bounded one (open ends excluded)."""
    lo = -SAFE_HIGH if p.low is None else p.low
    hi = SAFE_HIGH if p.high is None else p.high
    if lo >= 0.0:
        lo, hi = max(lo, 1e-300), min(hi, 1e300)
        c = np.logspace(math.log10(lo), math.log10(hi), 241)
    else:
        c = np.linspace(lo, min(hi, SAFE_HIGH), 241)
    return [float(x) for x in c if p.in_range(x)]


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
