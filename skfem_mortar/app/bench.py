"""``skfem-mortar bench``: per-phase timings and peak memory at growing sizes.

Each size runs in its own Python process (so that its peak resident memory,
``ru_maxrss``, is its own) through :func:`~skfem_mortar.app.runner.run_scene`; the
phases are the model's item timers (bulk assembly, contact assembly), the
contact search inside it (:mod:`skfem_mortar.core.timing`), the linear solves and
the output. Times are divided by the number of Newton iterations. A log-log
fit of time per iteration against dofs gives the slope of each phase.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

__all__ = ["SIZES", "run_bench", "fit_slopes", "check_inputs", "size_of"]

#: the 3D block's runs: small strain (one Newton iteration per size, so the time per
#: iteration is that of one assembly and one factorization) on hex1 cells
_BLOCK3D = {"kinematics": "small", "element": "hex1"}

#: scene -> list of parameter sets of growing size: hertz 2e3 to 1.7e5 dofs,
#: seed 4e2 to 3e5 dofs (each cushion refinement is 4x), block3d 2e3 to 3.5e5 dofs
#: (its scene refuses a size whose estimated memory exceeds half the machine's)
SIZES: dict[str, list[dict]] = {
    "hertz": [{"refine": r} for r in (-2, -1, 0, 1, 2, 3)],
    "seed": [{"n_cable": 24 * 2**k, "refine_cushion": k + 1} for k in range(6)],
    "block3d": [{**_BLOCK3D, "n": n} for n in (8, 12, 16, 24, 32, 40, 48)],
}
QUICK: dict[str, list[dict]] = {
    "hertz": [{"refine": 0}],
    "seed": [{"n_cable": 24, "refine_cushion": 1}, {"n_cable": 48, "refine_cushion": 2}],
    "block3d": [{**_BLOCK3D, "n": 4}, {**_BLOCK3D, "n": 8}],
}
PHASES = ("bulk", "search", "contact_assembly", "solve", "output")

_WORKER = r"""
import json, os, resource, sys
from skfem_mortar.app.runner import run_scene
spec = json.loads(sys.argv[1])
if spec["backend"]:
    os.environ["SKFEM_MORTAR_SOLVER"] = spec["backend"]
s = run_scene(spec["scene"], spec["params"], method=spec["method"], steps=spec["steps"],
              linear=spec["linear"])
s["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
print(json.dumps(s))
"""


def _one(scene: str, params: dict, method: str | None, steps: int | None,
         path: str | None = None) -> dict:
    from .study_plan import solver_path

    backend, linear = solver_path(path) if path else (None, None)
    spec = json.dumps({"scene": scene, "params": params, "method": method, "steps": steps,
                       "backend": backend, "linear": linear})
    proc = subprocess.run([sys.executable, "-c", _WORKER, spec], capture_output=True,
                          text=True)
    if proc.returncode != 0:
        reason = (proc.stderr.strip().splitlines() or ["unknown"])[-1]
        return {"scene": scene, "params": params, "method": method, "solver": path,
                "status": f"failed: {reason}"}
    s = json.loads(proc.stdout.strip().splitlines()[-1])
    its = max(1, sum(st["newton_iterations"] for st in s["steps"]))
    t = s["phase_times_s"]
    per_it = {"bulk": t["bulk"], "search": t.get("search", 0.0),
              "contact_assembly": max(0.0, t["contact"] - t.get("search", 0.0)),
              "solve": t["solve"], "output": t["output"]}
    per_it = {k: v / its for k, v in per_it.items()}
    total = sum(per_it.values())
    return {"scene": scene, "params": params, "method": s["method"], "solver": path,
            "status": "ok", "n_dofs": s["n_dofs"], "n_multipliers": s["n_multipliers"],
            "newton_iterations": its,
            "factorizations": sum(st.get("factorizations", 0) for st in s["steps"]),
            "krylov_iterations": sum(st.get("krylov_iterations", 0) for st in s["steps"]), "max_iterations_per_step":
                max(st["newton_iterations"] for st in s["steps"]),
            "wall_time_s": s["wall_time_s"], "peak_rss_mb": s["peak_rss_mb"],
            "time_per_iteration_s": per_it,
            "contact_share": (per_it["search"] + per_it["contact_assembly"]) / total
            if total > 0 else 0.0}


def size_of(scene: str, params: dict, method: str | None) -> int:
    """The displacement dofs (``n_dofs`` of the run's summary) of one size: the
    scene built in this process, not solved (a second or two at the largest)."""
    from .runner import build_scene

    setup, _, _ = build_scene(scene, params, method)
    return int(setup.model.n_u)


def fit_slopes(rows: Sequence[dict], size: str = "n_dofs") -> dict[str, float]:
    """Least-squares slope of log(time per iteration) against log(size), per phase
    and for the contact work (``contact``: search + contact assembly).

    ``size`` is a row key: ``n_dofs``, or ``n_multipliers`` (the slave nodes:
    the contact work should grow linearly with them, slope 1).
    """
    # a scene without contact has no multipliers: no slope against them
    ok = [r for r in rows if r.get("status") == "ok" and r.get(size, 0) > 0]
    out = {}
    if len(ok) < 2:
        return out
    n = np.log([r[size] for r in ok])
    for ph in PHASES + ("contact",):
        if ph == "contact":
            t = np.array([r["time_per_iteration_s"]["search"]
                          + r["time_per_iteration_s"]["contact_assembly"] for r in ok])
        else:
            t = np.array([r["time_per_iteration_s"][ph] for r in ok])
        if np.all(t > 0):
            out[ph] = float(np.polyfit(n, np.log(t), 1)[0])
    return out


def check_inputs(scenes: Sequence[str], method: str, max_dofs: int | None,
                 steps: int | None, table: dict[str, list[dict]]) -> None:
    """Refuse bench inputs before any run: ValueError naming the input and its range.

    Every size of every scene is resolved as its run would be (ranges, the dof
    estimate, the derived quantities), so a bad size fails here, not in a child.
    """
    from ..scenes import MAX_STEPS, METHODS, get_scene

    if isinstance(scenes, str) or not list(scenes):
        raise ValueError(f"scenes must be a non-empty list of {sorted(table)}, got {scenes!r}")
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    for name, value, high in (("max_dofs", max_dofs, None), ("steps", steps, MAX_STEPS)):
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, int) or value < 1 or (
                high is not None and value > high):
            top = "inf)" if high is None else f"{high}]"
            raise ValueError(f"{name} must be an integer in [1, {top}, got {value!r}")
    for scene in scenes:
        sc = get_scene(scene)  # a clear error for an unknown scene
        if scene not in table:
            raise ValueError(f"scene must be one of {sorted(table)} for bench, got {scene!r}")
        sc.check_method(scene_method(scene, method))
        for params in table[scene]:
            sc.resolve(params)


def scene_method(scene: str, method: str | None) -> str | None:
    """``method`` for a scene with contact, None for one without (block3d): the
    contact method of a bench applies to the scenes that have contact."""
    from ..scenes import get_scene

    return None if get_scene(scene).methods == (None,) else method


def run_bench(out: str | Path, scenes: Sequence[str] = ("hertz", "seed"),
              method: str = "mortar-dual", quick: bool = False, max_dofs: int | None = None,
              steps: int | None = None, progress: bool = False,
              solvers: Sequence[str] | None = None) -> dict:
    """Run the sizes of each scene; write ``bench.json`` and ``bench.png`` into ``out``.

    ``solvers``: solver paths (:func:`~skfem_mortar.app.study_plan.parse_solvers`, e.g.
    ``["pardiso", "pardiso+krylov"]``; default: the default backend, direct).
    With several, every path runs every size and ``report["scenes"]`` has an
    entry ``"scene (path)"`` per path, each with its own slopes.

    Each scene's sizes run in growing order until one fails or, with
    ``max_dofs``, until the next size would have more than ``max_dofs``
    displacement dofs (counted on the built model before it runs): that size
    is not run, its row says ``skipped``.

    Raises
    ------
    ValueError
        Before any run, for an unknown scene or method, ``max_dofs`` or ``steps``
        not an integer >= 1 (``steps`` at most ``MAX_STEPS``), or a size the
        scene refuses.
    """
    from ..output.io import write_json

    from .study_plan import parse_solvers

    table = QUICK if quick else SIZES
    check_inputs(scenes, method, max_dofs, steps, table)
    paths = parse_solvers(list(solvers) if solvers else None)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    report: dict = {"method": method, "scenes": {}}
    for scene, path in [(sc, p) for sc in scenes for p in paths]:
        entry = scene if len(paths) == 1 else f"{scene} ({path})"
        rows, own = [], scene_method(scene, method)
        for params in table[scene]:
            n = size_of(scene, params, own) if max_dofs is not None else None
            if n is not None and n > max_dofs:  # never run a size above the bound
                rows.append({"scene": scene, "params": params, "method": own,
                             "n_dofs": n, "status": f"skipped: {n} dofs > max_dofs {max_dofs}"})
                break
            row = _one(scene, params, own, steps, path)
            rows.append(row)
            if progress:
                print(f"bench {entry} {params}: {row.get('n_dofs', '?')} dofs, "
                      f"{row.get('status')}", file=sys.stderr)
            if row.get("status") != "ok":
                break
        report["scenes"][entry] = {"rows": rows, "slopes": fit_slopes(rows),
                                   "slopes_vs_contact_nodes": fit_slopes(rows, "n_multipliers")}
        write_json(out / "bench.json", report)
    plot_bench(report, out / "bench.png")
    return report


#: the phases in words (legend of bench.png)
PHASE_WORDS = {"bulk": "bulk assembly", "search": "contact search",
               "contact_assembly": "contact assembly (without search)",
               "solve": "linear solve", "output": "output (files)"}


def plot_bench(report: dict, path: str | Path) -> Path:
    """Time per Newton iteration against dofs (log-log), one line per phase (the
    same colour in every panel), its fitted slope in the legend under the panel;
    a scene's failed sizes are counted in its title."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..output.plot_common import _save

    scenes = list(report["scenes"])
    fig, axes = plt.subplots(1, max(1, len(scenes)), figsize=(5.5 * max(1, len(scenes)), 5.0),
                             squeeze=False, layout="constrained")
    colours = dict(zip(PHASES, plt.get_cmap("tab10").colors))
    for ax, scene in zip(axes[0], scenes):
        rows = report["scenes"][scene]["rows"]
        ok = [r for r in rows if r.get("status") == "ok"]
        failed = len(rows) - len(ok)
        slopes = report["scenes"][scene]["slopes"]
        n = [r["n_dofs"] for r in ok]
        for ph in PHASES:
            t = [r["time_per_iteration_s"][ph] for r in ok]
            if t and max(t) > 1e-6:  # a phase that did not run (e.g. no output) is left out
                words = PHASE_WORDS.get(ph, ph)
                label = f"{words} (slope {slopes[ph]:.2f})" if ph in slopes else words
                ax.loglog(n, np.maximum(t, 1e-7), "o-", color=colours[ph], label=label)
        method = next((r.get("method") for r in rows), report["method"])
        title = scene if method is None else f"{scene} ({method})"
        if failed:
            title += f"\n{failed} of {len(rows)} sizes failed (not drawn)"
        ax.set_title(title, fontsize=11)
        ax.set_xlabel("displacement dofs")
        ax.set_ylabel("time per Newton iteration (s)")
        ax.grid(alpha=0.3, which="both")
        if ok:
            ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.15), ncol=2,
                      frameon=False)
        else:
            ax.text(0.5, 0.5, "no size ran", transform=ax.transAxes, ha="center")
    return _save(fig, path)
