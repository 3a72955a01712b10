"""What a study shows: the Pareto plot (error against wall time) and report.md."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

__all__ = ["pareto_front", "pareto_plot", "write_report"]

_MARKERS = {"nts": "s", "mortar": "o", "mortar-dual": "^", "": "D"}


def _num(v) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return float("nan")
    return f


def pareto_front(times: np.ndarray, errors: np.ndarray) -> np.ndarray:
    """Indices of the non-dominated points (no other point is both faster and
    more accurate), sorted by time."""
    times, errors = np.asarray(times, float), np.asarray(errors, float)
    ok = np.flatnonzero(np.isfinite(times) & np.isfinite(errors))
    order = ok[np.lexsort((errors[ok], times[ok]))]
    best = np.minimum.accumulate(errors[order]) if order.size else order
    keep = np.r_[True, best[1:] < best[:-1]] if order.size else np.zeros(0, bool)
    return order[keep]


def _settings(row: dict) -> str:
    parts = [f"{k[6:]}={v}" for k, v in row.items() if k.startswith("param.") and v != ""]
    if row.get("steps") not in ("", None):
        parts.append(f"steps={row['steps']}")
    return ", ".join(parts)


def pareto_plot(rows: Sequence[dict], path: str | Path) -> Path:
    """Error against wall time on log axes, one panel per scene, a marker per method."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..output.plot import _save

    scenes = list(dict.fromkeys(r["scene"] for r in rows)) or ["(no runs)"]
    fig, axes = plt.subplots(1, len(scenes), figsize=(5 * len(scenes), 4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        sub = [r for r in rows if r["scene"] == scene and r.get("status") == "ok"]
        t = np.array([_num(r.get("wall_time_s")) for r in sub])
        e = np.array([_num(r.get("error")) for r in sub])
        e = np.where(e > 0, e, 1e-16)  # an exact answer is drawn at round-off
        for method in dict.fromkeys(r["method"] for r in sub):
            sel = np.array([r["method"] == method for r in sub])
            ax.loglog(t[sel], e[sel], _MARKERS.get(method, "x"), label=method or "-",
                      alpha=0.8)
        front = pareto_front(t, e)
        if front.size:
            ax.loglog(t[front], e[front], "k--", lw=1, label="Pareto front")
        ax.set_title(scene)
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel("relative error")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, path)


def write_report(rows: Sequence[dict], path: str | Path, tolerance: float) -> Path:
    """A Markdown table of all runs and, per scene, the cheapest setting within tolerance."""
    from ..output.io import atomic_path

    lines = ["# Speed-accuracy study", "",
             f"Tolerance: relative error <= {tolerance:g}.", ""]
    for scene in dict.fromkeys(r["scene"] for r in rows):
        sub = [r for r in rows if r["scene"] == scene]
        lines += [f"## {scene}", "",
                  "| method | settings | dofs | Newton its | wall time (s) | error | status |",
                  "|---|---|---|---|---|---|---|"]
        for r in sub:
            lines.append(f"| {r['method'] or '-'} | {_settings(r)} | {r.get('n_dofs', '')} | "
                         f"{r.get('newton_iterations', '')} | {_num(r.get('wall_time_s')):.3g} | "
                         f"{_num(r.get('error')):.3g} | {r.get('status', '')} |")
        ok = [r for r in sub if r.get("status") == "ok" and _num(r.get("error")) <= tolerance]
        lines.append("")
        if ok:
            best = min(ok, key=lambda r: _num(r.get("wall_time_s")))
            lines.append(f"Cheapest within tolerance: **{best['method'] or '-'}**, "
                         f"{_settings(best)}: error {_num(best['error']):.3g} in "
                         f"{_num(best['wall_time_s']):.3g} s.")
        else:
            lines.append("No setting reached the tolerance.")
        lines.append("")
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    return Path(path)
