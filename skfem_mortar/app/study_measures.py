"""The study's error measures of a row: the scene's own metrics, or the relative
deviation from a fine reference run with the default method, dual mortar
(computed once per scene and physics-axis variant, cached in ``references.json``).
"""
from __future__ import annotations

import json
from pathlib import Path

from .study_plan import PHYSICS_AXES, StudyPlan, error_measures, variant_key

def _measures(row: dict, refs: dict[str, dict]) -> dict[str, float | None]:
    """Every error measure of a row (None where the run failed or lacks it)."""
    names = error_measures(row["scene"])
    if row.get("status") != "ok":
        return {n: None for n in names}
    metrics = json.loads(row["metrics"])
    if not names:  # a scene GRIDS does not declare: its own *_error metrics
        names = [k for k in metrics if k.endswith("_error")]
    ref = refs.get(row["scene"], {}).get("values", {})
    variant = {k: row[f"param.{k}"] for k in PHYSICS_AXES
               if row.get(f"param.{k}") not in ("", None)}
    ref = refs.get(row["scene"], {}).get("variant_values", {}).get(variant_key(variant), ref) \
        if variant else ref
    out: dict[str, float | None] = {}
    for name in names:
        q = name.removesuffix("_error")
        if q in ref:  # against the reference run
            val, val_ref = metrics.get(q), ref[q]
            out[name] = (None if val is None or val_ref in (None, 0)
                         else abs(val - val_ref) / abs(val_ref))
        else:
            val = metrics.get(name)
            out[name] = None if val is None else float(val)
    return out


def _finish(row: dict, refs: dict[str, dict], plotted: dict[str, str | None]) -> None:
    """Add the measure columns, ``error_metric`` and ``error`` to a row."""
    measures = _measures(row, refs)
    row.update({k: ("" if v is None else v) for k, v in measures.items()})
    scene = row["scene"]
    name = plotted.get(scene) if scene in plotted else (error_measures(scene) or [None])[0]
    name = name or next(iter(measures), None)
    row["error_metric"] = name or ""
    val = measures.get(name) if name else None
    row["error"] = "" if val is None else val


def _references(plan: StudyPlan, out: Path) -> dict[str, dict]:
    """Fine mortar reference values, computed once and cached in ``references.json``:
    one per scene at its reference parameters, and one per variant of the
    :data:`PHYSICS_AXES` the grid sets (the reference parameters with it, cached
    as ``"<scene> <variant>"``, e.g. ``seed {"mu": 0.3}``)."""
    from ..output.io import write_json
    from ..scenes import get_scene
    from .runner import run_scene

    path = out / "references.json"
    cache = json.loads(path.read_text()) if path.exists() else {}
    for scene, ref in plan.references.items():
        variants = ref.get("variants", [])
        for variant in [{}] + list(variants):
            name = scene if not variant else f"{scene} {variant_key(variant)}"
            params = {**ref["params"], **variant}
            key = json.dumps({"metrics": ref["metrics"], "params": params}, sort_keys=True) \
                if variant else json.dumps({k: ref[k] for k in ("metrics", "params")},
                                           sort_keys=True)
            if cache.get(name, {}).get("key") != key:
                # the package's method where the scene has contact, none where not
                method = get_scene(scene).check_method(None)
                summary = run_scene(scene, params, method=method)
                values = {q: summary["metrics"].get(q) for q in ref["metrics"]}
                cache[name] = {"key": key, "values": values, "params": params}
                write_json(path, cache)
            if variant:
                ref.setdefault("variant_values", {})[variant_key(variant)] = cache[name]["values"]
            else:
                ref["values"] = cache[name]["values"]
    return plan.references
