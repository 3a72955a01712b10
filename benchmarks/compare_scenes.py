"""Record every scene's summary (metrics, iterations per step, active nodes) at
its defaults for every method, or compare a recording with this checkout's.

    python benchmarks/compare_scenes.py record before.json
    python benchmarks/compare_scenes.py compare before.json [--rtol 1e-12]

``compare`` runs the scenes again and reports, per scene and method, whether
the Newton iterations and active nodes per step are identical and the largest
difference of a metric relative to its scale (the larger of its two values;
metrics that are themselves round-off, i.e. both values below 1e-9 of their
scene's largest metric, are compared to 1e-12 of that largest metric). It exits
1 when anything differs beyond ``--rtol``. Timings and paths are not compared.
"""
from __future__ import annotations

import argparse
import json
import sys
import warnings

from skfem_mortar.app.runner import run_scene
from skfem_mortar.scenes import list_scenes

#: the step fields that must be identical
STEP_KEYS = ("newton_iterations", "n_active", "cuts")


def record(only: set | None = None) -> dict:
    """Every scene/method run at its defaults (``only``: just these ``scene/method`` keys)."""
    out = {}
    for scene in list_scenes():
        for method in scene.methods:
            if only is not None and f"{scene.name}/{method}" not in only:
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                s = run_scene(scene.name, {}, method)
            out[f"{scene.name}/{method}"] = {
                "steps": [{k: st[k] for k in STEP_KEYS} for st in s["steps"]],
                "metrics": {k: v for k, v in s["metrics"].items()
                            if isinstance(v, (int, float)) and not isinstance(v, bool)}}
            print(scene.name, method, flush=True)
    return out


def compare(before: dict, after: dict, rtol: float) -> list[str]:
    bad = []
    for key, b in before.items():
        a = after.get(key)
        if a is None:
            bad.append(f"{key}: missing")
            continue
        if a["steps"] != b["steps"]:
            bad.append(f"{key}: steps differ: {b['steps']} -> {a['steps']}")
        top = max([abs(v) for v in b["metrics"].values()] + [1e-300])
        for m, vb in b["metrics"].items():
            va = a["metrics"].get(m)
            if va is None:
                bad.append(f"{key}: metric {m} missing")
                continue
            scale = max(abs(va), abs(vb))
            if scale < 1e-9 * top:
                scale = top
            if abs(va - vb) > rtol * scale:
                bad.append(f"{key}: {m} {vb!r} -> {va!r} (rel {abs(va - vb) / scale:.2e})")
    return bad


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("mode", choices=["record", "compare"])
    p.add_argument("path")
    p.add_argument("--rtol", type=float, default=1e-12)
    a = p.parse_args(argv)
    if a.mode == "record":
        with open(a.path, "w") as f:
            json.dump(record(), f, indent=1)
        return 0
    with open(a.path) as f:
        before = json.load(f)
    # the recording's runs only: scenes added since are recorded anew, not compared
    bad = compare(before, record(set(before)), a.rtol)
    print("\n".join(bad) if bad else f"identical: {len(before)} scene/method runs")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
