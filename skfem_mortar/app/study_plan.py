"""The speed-accuracy study's plan: the grids per scene (:data:`GRIDS`), the
checks of every option, and the list of runs (:func:`plan_study`: nothing runs,
nothing is written). The study itself: :mod:`skfem_mortar.app.study`.
"""
from __future__ import annotations

import itertools
import json
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

__all__ = ["StudyPlan", "plan_study", "parse_steps", "parse_solvers", "solver_path",
           "error_measures", "check_repeat", "check_tolerances", "run_key", "variant_key",
           "GRIDS", "SMALL_GRID_RUNS", "SMALL_REPEAT", "DEFAULT_TOLERANCES", "MORTAR_ONLY",
           "PHYSICS_AXES"]

#: per scene: its error measures (``metrics``: keys of the scene's metrics, the
#: first plotted by default), the full grid, the quick grid, and for scenes
#: without an analytic answer the quantities (``reference``) compared with a fine
#: mortar reference run (``reference_params``), each the measure ``<q>_error``.
GRIDS: dict[str, dict[str, Any]] = {
    "block": {"metrics": ["nominal_stress_error", "lateral_stretch_error", "max_stress_error"],
              "grid": {"refine": [1, 2, 3, 4], "element": ["tri1", "quad1", "tri2"]},
              "quick": {"refine": [1, 2]}},
    "ring": {"metrics": ["radius_error", "tension_error"],
             "grid": {"n_elements": [8, 16, 32, 64, 128, 256]},
             "quick": {"n_elements": [8, 16, 32]}},
    "cable_arc": {"metrics": ["apex_height_error", "tension_error"],
                  "grid": {"n_elements": [8, 16, 32, 64, 128]},
                  "quick": {"n_elements": [8, 16]}},
    "cable_flat": {"metrics": ["contact_force_error", "contact_half_width_error",
                               "tension_error"],
                   "grid": {"n_elements": [25, 50, 100, 200, 400]},
                   "quick": {"n_elements": [20, 40]}},
    "patch": {"metrics": ["pressure_error", "contact_force_error", "support_reaction_error"],
              "grid": {"n_top": [3, 7, 13], "n_bottom": [4, 10]},
              "quick": {"n_top": [3], "n_bottom": [4]}},
    # the *_ref_* measures read the pressure as linear theory does (reference
    # positions and lengths): with kinematics=small they hold the discretization error
    "hertz": {"metrics": ["peak_pressure_error", "half_width_error", "pressure_l2_error",
                          "peak_pressure_ref_error", "pressure_ref_l2_error"],
              "grid": {"refine": [-2, -1, 0, 1]},
              "quick": {"refine": [-2, -1]}},
    # seed refines both meshes together (a "levels" axis: zipped parameter sets)
    "seed": {"reference": ["contact_force", "max_indentation", "contact_length"],
             "reference_params": {"n_cable": 192, "refine_cushion": 4},
             "grid": {"levels": [{"n_cable": 24, "refine_cushion": 1},
                                 {"n_cable": 48, "refine_cushion": 2},
                                 {"n_cable": 96, "refine_cushion": 3}]},
             "quick": {"levels": [{"n_cable": 24, "refine_cushion": 1}]}},
    # max_penetration: the largest penetration of an active node over the die radius
    "ironing": {"reference": ["normal_force_mean"], "metrics": ["max_penetration"],
                "grid": {}, "quick": {}},
    # slide: the contact's tangential resultant against mu N (gross sliding at the end)
    "slide": {"metrics": ["tangential_ratio_error"], "grid": {"n": [10, 20, 40]},
              "quick": {"n": [10]}},
    # mindlin: the Cattaneo-Mindlin shear and stick zone (the pressure: the floor)
    "mindlin": {"metrics": ["shear_l2_error", "stick_half_width_error", "shear_core_error",
                            "pressure_l2_error"],
                "grid": {"n_a": [6, 12, 24]}, "quick": {"n_a": [6]}},
    # balloon: p(lambda) against the closed form, relative to p_max (volume control)
    "balloon": {"metrics": ["pressure_error"], "grid": {"n_elements": [16, 32, 64, 128]},
                "quick": {"n_elements": [16, 32]}},
    "tied": {"metrics": ["tip_deflection_error", "energy_error", "traction_max_error",
                         "traction_error"],
             "grid": {"refine": [1, 2, 3, 4]}, "quick": {"refine": [1, 2]}},
    # tied3d: the two parts against the one-piece beam at the master's h (tet1 or hex1,
    # standard or dual multipliers)
    "tied3d": {"metrics": ["tip_deflection_error", "traction_error"],
               "grid": {"refine": [1, 2, 3], "element": ["tet1", "hex1"],
                        "multipliers": ["standard", "dual"]},
               "quick": {"refine": [1, 2]}},
    # patch3d: the 3D contact patch test, exact with mortar on every pairing
    "patch3d": {"metrics": ["pressure_error", "displacement_error"],
                "grid": {"element": ["hex1", "tet1", "tet1/hex1", "hex1/tet1"],
                         "slave": ["upper", "lower"]},
                "quick": {"element": ["hex1"]}},
    # hertz3d: a quarter of hertz_axi's sphere against Hertz (the mesh series of refine,
    # hexahedra and Kuhn tetrahedra)
    "hertz3d": {"metrics": ["peak_pressure_error", "contact_radius_error", "contact_force_error"],
                "grid": {"refine": [-3, -2, -1], "element": ["hex1", "tet1"]},
                "quick": {"refine": [-3]}},
    # thick_sphere: the axisymmetric wall against Lame, linear and quadratic elements
    "thick_sphere": {"metrics": ["l2_error", "u_inner_error"],
                     "grid": {"element": ["tri1", "quad1", "tri2", "quad2"], "n": [2, 4, 8]},
                     "quick": {"element": ["quad1"], "n": [2, 4]}},
    # the 3D scenes: block3d exact on every element, thick_sphere3d against Lame,
    # cantilever3d against the beam and against its own refinement (hex2, n = 4)
    "block3d": {"metrics": ["max_displacement_error", "max_stress_error"],
                "grid": {"element": ["tet1", "tet2", "hex1", "hex2", "p2p1", "hex1-md"],
                         "mode": ["stretch", "combined"]},
                "quick": {"element": ["tet1", "hex1"], "n": [2]}},
    "thick_sphere3d": {"metrics": ["displacement_l2_error", "inner_radial_displacement_error"],
                       "grid": {"element": ["tet1", "hex1", "tet2", "hex2"], "n": [2, 4, 8]},
                       "quick": {"element": ["hex1"], "n": [2, 4]}},
    "cantilever3d": {"reference": ["tip_deflection"],
                     "reference_params": {"element": "hex2", "n": 4},
                     "metrics": ["tip_deflection_beam_error"],
                     "grid": {"element": ["tet2", "hex2", "p2p1", "hex1-md"], "n": [1, 2, 3]},
                     "quick": {"element": ["hex2"], "n": [1]}},
    # the axisymmetric contact scenes: hertz_axi against Hertz's sphere (the *_ref_*
    # readings as hertz's), oring and seed_axi against a fine mortar run (oring's
    # geometry a physics axis: each its own reference)
    "hertz_axi": {"metrics": ["peak_pressure_error", "contact_radius_error",
                              "peak_pressure_ref_error", "contact_radius_ref_error"],
                  "grid": {"refine": [-1, 0, 1, 2]}, "quick": {"refine": [-1, 0]}},
    "oring": {"reference": ["force_per_circumference", "contact_width", "peak_pressure"],
              "reference_params": {"refine": 1},
              "grid": {"refine": [-2, -1, 0], "geometry": ["axisymmetric", "plane"]},
              "quick": {"refine": [-2]}},
    "seed_axi": {"reference": ["pressure", "contact_force_radial"],
                 "reference_params": {"refine": 3},
                 "grid": {"refine": [-1, 0, 1, 2]}, "quick": {"refine": [-1, 0]}},
}
#: a study of at most this many grid points is *small*: each point is timed
#: ``SMALL_REPEAT`` times unless ``repeat`` says otherwise (larger grids once)
SMALL_GRID_RUNS = 12
SMALL_REPEAT = 3
#: the tolerances (relative errors) the report recommends a setting for
DEFAULT_TOLERANCES = (0.1, 0.03, 0.01, 0.003)
#: settings that only mortar methods have (an NTS run ignores them)
MORTAR_ONLY = ("n_gauss", "segmentation")
#: axes that change the problem, not its discretization (the friction
#: coefficient): each value of such an axis a grid sets gets its own reference
#: run (the reference parameters with that value), so that ``<q>_error`` of a
#: friction run is measured against a fine run with the same friction
PHYSICS_AXES = ("mu", "geometry")


@dataclass
class StudyPlan:
    """The list of runs of a study and how to measure each.

    ``measures`` lists each scene's error measures (CSV columns), ``plotted``
    the one plotted and reported first, ``references`` the reference runs.
    """

    runs: list[dict] = field(default_factory=list)
    references: dict[str, dict] = field(default_factory=dict)
    measures: dict[str, list[str]] = field(default_factory=dict)
    plotted: dict[str, str | None] = field(default_factory=dict)


def _parse_values(text: str) -> list[str]:
    return [v.strip() for v in text.split(",") if v.strip()]


def parse_steps(steps: str | int | Sequence[int | str] | None) -> list[int] | None:
    """Load step counts from ``"5,10,20"``, an int or a sequence (None: the scenes').

    Raises
    ------
    ValueError
        Naming ``steps`` and the allowed range, for a value that is not an
        integer in ``[1, MAX_STEPS]`` or an empty list.
    """
    from ..scenes import MAX_STEPS, Param

    if steps is None:
        return None
    items = _parse_values(steps) if isinstance(steps, str) else (
        [steps] if isinstance(steps, int) else list(steps))
    if not items:
        raise ValueError(f"steps must list integers in [1, {MAX_STEPS}], got {steps!r}")
    param = Param("steps", 1, kind=int, low=1, high=MAX_STEPS)
    return [param.parse(v) for v in items]


def error_measures(scene: str) -> list[str]:
    """The error measures (CSV columns) of a scene, the default plotted one first.

    The reference quantities ``q`` of :data:`GRIDS` give ``<q>_error`` (against
    the reference run), then come the scene's own metrics. Empty for a scene
    :data:`GRIDS` does not declare: its rows take every ``*_error`` metric.
    """
    conf = GRIDS.get(scene, {})
    return [f"{q}_error" for q in conf.get("reference", [])] + list(conf.get("metrics", []))


def solver_path(path: str) -> tuple[str, str | None]:
    """``(backend, linear)`` of a solver path ``"backend"`` or ``"backend+linear"``
    (``linear`` one of ``NewtonOptions.linear``'s; None for the bare backend)."""
    backend, _, linear = str(path).partition("+")
    return backend.strip(), (linear.strip() or None)


def parse_solvers(solvers: str | Sequence[str] | None) -> list[str]:
    """The solver paths of the ``solver`` axis (None: the default backend only).

    A path is a backend, optionally with the Newton systems' linear solves
    (``NewtonOptions.linear``): ``pardiso``, ``pardiso+krylov``, ``superlu+auto``;
    ``+direct`` is the bare backend.

    Raises
    ------
    ValueError
        Naming ``--solver`` and the backends available here (or the linear
        solves allowed), for any other name.
    """
    from ..solver.krylov import LINEAR
    from ..solver.linsolve import BACKENDS, available_backends, default_backend

    if solvers is None or (not isinstance(solvers, str) and not list(solvers)):
        return [default_backend()]
    items = _parse_values(solvers) if isinstance(solvers, str) else [
        str(s).strip() for s in solvers]
    available = available_backends()
    paths = []
    for name in items:
        backend, linear = solver_path(name)
        if backend not in available:
            why = (" (a backend of the package, but not installed here)"
                   if backend in BACKENDS else "")
            raise ValueError(f"solver {name!r} is not available{why}; allowed (--solver): "
                             f"{', '.join(available)}, each optionally +krylov or +auto")
        if linear is not None and linear not in LINEAR:
            raise ValueError(f"solver {name!r}: the linear solves after '+' must be one of "
                             f"{', '.join(LINEAR)} (--solver), got {linear!r}")
        paths.append(backend if linear in (None, "direct") else f"{backend}+{linear}")
    return list(dict.fromkeys(paths))


def _plotted(scenes: Sequence[str], metric: str | Sequence[str] | None) -> dict[str, str | None]:
    """Per scene, the plotted measure: the first of ``metric`` the scene has (default:
    its first measure). ValueError naming ``--metric`` and a scene's allowed names."""
    names = [metric] if isinstance(metric, str) else list(metric or [])
    allowed = {scene: error_measures(scene) for scene in scenes}
    for name in names:
        if not any(name in a for a in allowed.values()):
            listing = "; ".join(f"{s}: {', '.join(a) or '(none declared)'}"
                                for s, a in allowed.items())
            raise ValueError(f"metric {name!r} is not an error measure of the studied "
                             f"scenes; allowed (--metric): {listing}")
    out: dict[str, str | None] = {}
    for scene, names_here in allowed.items():
        pick = next((n for n in names if n in names_here), None)
        if names and pick is None:
            raise ValueError(f"metric {names} names no error measure of scene {scene!r}; "
                             f"allowed for {scene} (--metric): "
                             f"{', '.join(names_here) or '(none declared)'}")
        out[scene] = pick or (names_here[0] if names_here else None)
    return out


def plan_study(scenes: Sequence[str], *, methods: Sequence[str] | None = None,
               sets: dict[str, str] | None = None, steps: Sequence[int] | None = None,
               solvers: str | Sequence[str] | None = None,
               metric: str | Sequence[str] | None = None, quick: bool = False) -> StudyPlan:
    """Expand the grid and check every option (nothing runs, nothing is written).

    Parameters
    ----------
    scenes : names of scenes.
    methods : contact methods to compare (default: every method of the scene).
    sets : ``{name: "v1,v2,..."}`` axes that override or extend the scene's grid.
        A name that no scene knows is an error.
    steps : load step counts to compare (default: the scene's).
    solvers : solver paths to compare (:func:`parse_solvers`; default: the
        default backend only).
    metric : the plotted error measure, or several (each scene plots the first
        it has; default: the scene's first, :func:`error_measures`).
    quick : use the small grid (for CI).

    Raises
    ------
    ValueError
        For an unknown scene, method, axis, value, metric or solver.
    """
    from ..scenes import get_scene

    plan = StudyPlan()
    steps = parse_steps(steps)
    solvers = parse_solvers(solvers)
    sets = dict(sets or {})
    used = set()
    for name in scenes:
        get_scene(name)  # an unknown scene before an unknown metric
    plan.plotted = _plotted(scenes, metric)
    for name in scenes:
        scene = get_scene(name)
        conf = GRIDS.get(name, {})
        plan.measures[name] = error_measures(name)
        axes = dict(conf.get("quick" if quick else "grid", {}))
        levels = axes.pop("levels", [{}])
        known = {p.name for p in scene.params}
        for key, text in sets.items():
            if key in known:
                axes[key] = _parse_values(text)
                used.add(key)
                levels = [{k: v for k, v in lv.items() if k != key} for lv in levels]
        for key, vals in axes.items():  # validate now: a bad value is a clear error
            for v in vals:
                scene.param(key).parse(v)
        scene_methods = [m for m in scene.methods]
        if methods:
            bad = [m for m in methods if m not in scene.methods]
            scene_methods = [m for m in methods if m in scene.methods] or [None]
            if bad and scene.methods != (None,):
                raise ValueError(f"method(s) {bad} are not available for scene {name!r}; "
                                 f"allowed: {[m for m in scene.methods if m]}")
        keys = sorted(axes)
        for method, step, solver, level, combo in itertools.product(
                scene_methods, list(steps or [None]), solvers, levels,
                itertools.product(*(axes[k] for k in keys)) if keys else [()]):
            params = {**{k: scene.param(k).parse(v) for k, v in level.items()},
                      **{k: scene.param(k).parse(v) for k, v in zip(keys, combo)}}
            params = {k: v for k, v in params.items()
                      if not (method == "nts" and k in MORTAR_ONLY)}
            _check_point(scene, params)
            run = {"scene": name, "method": method, "steps": step, "solver": solver,
                   "params": params}
            if run not in plan.runs:  # NTS ignores the mortar axes: run it once
                plan.runs.append(run)
        if "reference" in conf:
            plan.references[name] = {"metrics": list(conf["reference"]),
                                     "params": conf.get("reference_params", {}),
                                     "variants": _variants(scene, plan.runs)}
    unknown = set(sets) - used
    if unknown:
        raise ValueError(f"--set names no parameter of the studied scenes: {sorted(unknown)}")
    return plan


def _variants(scene, runs: list[dict]) -> list[dict]:
    """The settings of :data:`PHYSICS_AXES` the scene's runs use other than the
    scene's defaults (each wants its own reference run), in order of appearance."""
    out: list[dict] = []
    for run in runs:
        if run["scene"] != scene.name:
            continue
        variant = {k: run["params"][k] for k in PHYSICS_AXES
                   if k in run["params"] and run["params"][k] != scene.param(k).default}
        if variant and variant not in out:
            out.append(variant)
    return out


def variant_key(values: dict) -> str:
    """The key of a reference variant (its physics-axis values, as floats where they
    read as numbers, a CSV's strings included; a choice such as ``geometry`` as text)."""
    return json.dumps({k: _number_or_text(v) for k, v in values.items()}, sort_keys=True)


def _number_or_text(value: Any) -> float | str:
    """``float(value)``, or ``value`` as text when it is not a number."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return str(value)


def _check_point(scene, params: dict) -> None:
    """Validate one grid point as a run would (sizes, derived quantities), naming
    the grid point in the message."""
    try:
        scene.resolve(params)
    except ValueError as exc:
        point = ", ".join(f"{k}={v}" for k, v in params.items())
        raise ValueError(f"{exc} [scene {scene.name}, grid point {point}]") from None


def check_repeat(repeat: int | None, n_points: int) -> int:
    """The number of timed runs per point: ``repeat``, or by default
    :data:`SMALL_REPEAT` for at most :data:`SMALL_GRID_RUNS` points, else 1.

    Raises
    ------
    ValueError
        Naming ``--repeat`` for anything but an integer >= 1.
    """
    if repeat is None:
        return SMALL_REPEAT if n_points <= SMALL_GRID_RUNS else 1
    if isinstance(repeat, bool) or not isinstance(repeat, (int, np.integer)) or repeat < 1:
        raise ValueError(f"repeat (--repeat) must be an integer >= 1, got {repeat!r}")
    return int(repeat)


def check_tolerances(tolerance: float | Sequence[float] | None) -> list[float]:
    """The report's tolerances, largest first (None: :data:`DEFAULT_TOLERANCES`).

    Raises
    ------
    ValueError
        Naming ``tolerance`` for a value outside (0, 1).
    """
    if tolerance is None:
        return list(DEFAULT_TOLERANCES)
    values = [tolerance] if isinstance(tolerance, (int, float)) else list(tolerance)
    if not values:
        return list(DEFAULT_TOLERANCES)
    for t in values:
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not (0.0 < t < 1.0):
            raise ValueError(f"tolerance must lie in (0, 1), got {t!r}")
    return sorted({float(t) for t in values}, reverse=True)


def run_key(run: dict) -> str:
    """A stable identity of a run (to resume without redoing rows)."""
    return json.dumps({"scene": run["scene"], "method": run["method"], "steps": run["steps"],
                       "solver": run.get("solver"), "params": run["params"]}, sort_keys=True)
