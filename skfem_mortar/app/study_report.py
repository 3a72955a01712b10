"""What a study shows: the Pareto plot (an error measure against wall time), the
cheapest setting per error measure and tolerance (``report.md`` and
``recommendations.csv``)."""
from __future__ import annotations

import csv
import io as _io
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

__all__ = ["pareto_front", "pareto_figure", "pareto_plot", "recommend", "write_report",
           "friction_cost"]

_MARKERS = {"nts": "s", "mortar": "o", "mortar-dual": "^", "": "D"}


def _num(v) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return float("nan")
    return f


def _flag(v) -> bool:
    """A boolean column, as written (True) or read back from the CSV ("True")."""
    return v is True or str(v).strip().lower() in ("true", "1")


def pareto_front(times: np.ndarray, errors: np.ndarray) -> np.ndarray:
    """Indices of the non-dominated points (no other point is both faster and
    more accurate), sorted by time."""
    times, errors = np.asarray(times, float), np.asarray(errors, float)
    ok = np.flatnonzero(np.isfinite(times) & np.isfinite(errors))
    order = ok[np.lexsort((errors[ok], times[ok]))]
    best = np.minimum.accumulate(errors[order]) if order.size else order
    keep = np.r_[True, best[1:] < best[:-1]] if order.size else np.zeros(0, bool)
    return order[keep]


def _params(row: Mapping) -> str:
    return ", ".join(f"{k[6:]}={v}" for k, v in row.items()
                     if k.startswith("param.") and v not in ("", None))


def _point_label(row: Mapping) -> str:
    """A grid point's setting in short, as written beside its marker: the
    parameters and, where the study set them, the load steps and the solver."""
    parts = [f"{k[6:]}={v}" for k, v in row.items()
             if k.startswith("param.") and v not in ("", None)]
    if row.get("steps") not in ("", None):
        parts.append(f"steps={row['steps']}")
    if row.get("solver"):
        parts.append(str(row["solver"]))
    return " ".join(parts) or "defaults"


def _steps(row: Mapping) -> str:
    """The load steps of a row: the requested count, or the steps the scene's
    default took (a one-step scene: 1, more if a step was cut)."""
    if row.get("steps") not in ("", None):
        return str(row["steps"])
    n = row.get("n_steps")
    return f"{int(_num(n))} (scene default)" if np.isfinite(_num(n)) else "scene default"


def _settings(row: Mapping) -> str:
    """Parameters, load steps and solver of a row, as one line."""
    parts = [p for p in (_params(row),) if p] + [f"load steps {_steps(row)}"]
    if row.get("solver"):
        parts.append(f"solver {row['solver']}")
    return ", ".join(parts)


def _plotted_metric(rows: Sequence[Mapping], scene: str,
                    plotted: Mapping[str, str | None] | None) -> str:
    if plotted and plotted.get(scene):
        return str(plotted[scene])
    names = [r.get("error_metric") for r in rows if r["scene"] == scene and r.get("error_metric")]
    return names[0] if names else "error"


def _measures_of(rows: Sequence[Mapping], scene: str, first: str,
                 measures: Mapping[str, Sequence[str]] | None) -> list[str]:
    """The error measure columns of a scene, the plotted one first: the declared
    ones, else every ``*_error`` column its rows fill."""
    names = list(measures.get(scene, ())) if measures else []
    if not names:
        names = list(dict.fromkeys(k for r in rows if r["scene"] == scene for k, v in r.items()
                                   if k.endswith("_error") and v not in ("", None)))
    return list(dict.fromkeys(([first] if first != "error" else []) + names)) or ["error"]


def pareto_figure(rows: Sequence[Mapping], plotted: Mapping[str, str | None] | None = None):
    """The figure of :func:`pareto_plot` (not saved): one panel per scene, its
    plotted measure against the median wall time, a marker per method (open:
    ``timing_unsteady``), the Pareto front dashed. The y label and the title name
    the measure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = list(dict.fromkeys(r["scene"] for r in rows)) or ["(no runs)"]
    fig, axes = plt.subplots(1, len(scenes), figsize=(5 * len(scenes), 4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        metric = _plotted_metric(rows, scene, plotted)
        sub = [r for r in rows if r["scene"] == scene and r.get("status") == "ok"]
        t = np.array([_num(r.get("wall_time_s")) for r in sub])
        e = np.array([_num(r.get(metric)) for r in sub])
        e = np.where(e > 0, e, 1e-16)  # an exact answer is drawn at round-off
        unsteady = np.array([_flag(r.get("timing_unsteady")) for r in sub], dtype=bool)
        groups = list(dict.fromkeys((r["method"], r.get("solver", "")) for r in sub))
        several = len({g[1] for g in groups}) > 1
        for method, solver in groups:
            sel = np.array([(r["method"], r.get("solver", "")) == (method, solver)
                            for r in sub], dtype=bool)
            label = (method or "-") + (f" ({solver})" if several else "")
            line, = ax.loglog(t[sel & ~unsteady], e[sel & ~unsteady],
                              _MARKERS.get(method, "x"), label=label, alpha=0.8)
            if (sel & unsteady).any():
                ax.loglog(t[sel & unsteady], e[sel & unsteady], _MARKERS.get(method, "x"),
                          mfc="none", color=line.get_color(), alpha=0.8)
        if unsteady.any():  # one legend entry for the open markers
            ax.plot([], [], "o", mfc="none", color="grey",
                    label="timing spread > 20 %")
        for r, ti, ei in zip(sub, t, e):  # each point names its setting
            if np.isfinite(ti) and np.isfinite(ei):
                ax.annotate(_point_label(r), (ti, ei), xytext=(3, 3),
                            textcoords="offset points", fontsize=6, alpha=0.8)
        front = pareto_front(t, e)
        if front.size:
            ax.loglog(t[front], e[front], "k--", lw=1, label="Pareto front")
        ax.set_title(f"{scene}: {metric}")
        ax.set_xlabel("wall time (s), median of the runs")
        ax.set_ylabel(f"{metric} (relative)")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def pareto_plot(rows: Sequence[Mapping], path: str | Path,
                plotted: Mapping[str, str | None] | None = None) -> Path:
    """Write :func:`pareto_figure` to ``path`` (PNG)."""
    from ..output.plot_common import _save

    return _save(pareto_figure(rows, plotted), path)


def recommend(rows: Sequence[Mapping], metric: str, tolerances: Sequence[float]
              ) -> list[tuple[float, Mapping | None]]:
    """Per tolerance, the cheapest row that meets it on ``metric``.

    The cheapest is the ok row of least median wall time ``wall_time_s`` whose
    ``metric`` is at most the tolerance (the first such row on a tie); None when
    no row meets it.
    """
    out: list[tuple[float, Mapping | None]] = []
    for tol in tolerances:
        ok = [r for r in rows if r.get("status") == "ok" and _num(r.get(metric)) <= tol
              and np.isfinite(_num(r.get("wall_time_s")))]
        out.append((tol, min(ok, key=lambda r: _num(r["wall_time_s"])) if ok else None))
    return out


def _setting_key(row: Mapping, without: str) -> tuple:
    """A row's setting (scene, method, load steps, solver, parameters) without the
    parameter ``without``; numbers compared as floats (a row read back from the
    CSV holds strings)."""
    def norm(v):
        f = _num(v)
        return repr(f) if np.isfinite(f) else str(v)
    params = tuple(sorted((k, norm(v)) for k, v in row.items()
                          if k.startswith("param.") and k != without and v not in ("", None)))
    return (row["scene"], row.get("method") or "", norm(row.get("steps") or ""),
            row.get("solver") or "", params)


def friction_cost(rows: Sequence[Mapping], param: str = "mu") -> list[dict]:
    """What friction costs: each ok row with ``param`` (the friction coefficient)
    ``> 0`` against the ok row of the same setting with ``param = 0``.

    Per such row: ``mu``, ``newton_iterations`` and ``wall_time_s`` of both runs
    (``*_frictionless``), the ratios ``iterations_ratio = its / its_0``,
    ``time_ratio = t / t_0`` and ``time_per_iteration_ratio = (t / its) / (t_0 /
    its_0)``.  A friction row without such a partner is listed with the ratios
    None (``partner`` False).
    """
    col = f"param.{param}"
    ok = [r for r in rows if r.get("status") == "ok" and np.isfinite(_num(r.get(col)))]
    dry = {_setting_key(r, col): r for r in ok if _num(r[col]) == 0.0}
    out = []
    for r in ok:
        mu = _num(r[col])
        if mu <= 0.0:
            continue
        d = dry.get(_setting_key(r, col))
        its, t = _num(r.get("newton_iterations")), _num(r.get("wall_time_s"))
        entry = {"row": r, "mu": mu, "newton_iterations": its, "wall_time_s": t,
                 "partner": d is not None, "newton_iterations_frictionless": None,
                 "wall_time_s_frictionless": None, "iterations_ratio": None,
                 "time_ratio": None, "time_per_iteration_ratio": None}
        if d is not None:
            its0, t0 = _num(d.get("newton_iterations")), _num(d.get("wall_time_s"))
            entry.update(newton_iterations_frictionless=its0, wall_time_s_frictionless=t0,
                         iterations_ratio=its / its0 if its0 > 0 else None,
                         time_ratio=t / t0 if t0 > 0 else None,
                         time_per_iteration_ratio=(t / its) / (t0 / its0)
                         if its > 0 and its0 > 0 and t0 > 0 else None)
        out.append(entry)
    return out


def _friction_lines(rows: Sequence[Mapping]) -> list[str]:
    """The report's ``friction_cost`` section of one scene's rows (none without
    a friction row)."""
    cost = friction_cost(rows)
    if not cost:
        return []

    def g(v):
        return "-" if v is None else f"{v:.3g}"
    lines = ["### friction_cost", "",
             "Each run with friction (`mu > 0`) against the run of the same setting with "
             "`mu = 0` (no friction built): Newton iterations (summed over the load steps) "
             "and wall time, their ratios, and the ratio of the time per Newton iteration.",
             "", "| method | setting | mu | Newton its | its at mu = 0 | its ratio | "
             "wall time (s) | at mu = 0 | time ratio | time per iteration ratio |",
             "|---" * 10 + "|"]
    for c in cost:
        r = c["row"]
        setting = _settings({k: v for k, v in r.items() if k != "param.mu"})
        if not c["partner"]:
            lines.append(f"| {r['method'] or '-'} | {setting} | {c['mu']:g} | "
                         f"{g(c['newton_iterations'])} | no mu = 0 run of this setting in the "
                         f"grid | | {g(c['wall_time_s'])}{_timing_mark(r)} | | | |")
            continue
        lines.append(f"| {r['method'] or '-'} | {setting} | {c['mu']:g} | "
                     f"{g(c['newton_iterations'])} | {g(c['newton_iterations_frictionless'])} | "
                     f"{g(c['iterations_ratio'])} | {g(c['wall_time_s'])}{_timing_mark(r)} | "
                     f"{g(c['wall_time_s_frictionless'])} | {g(c['time_ratio'])} | "
                     f"{g(c['time_per_iteration_ratio'])} |")
    return lines + [""]


def _pct(tol: float) -> str:
    return f"{100 * tol:g} %"


def _timing_mark(row: Mapping) -> str:
    return " ⚠" if _flag(row.get("timing_unsteady")) else ""


def write_report(rows: Sequence[Mapping], path: str | Path,
                 tolerance: float | Sequence[float],
                 plotted: Mapping[str, str | None] | None = None,
                 measures: Mapping[str, Sequence[str]] | None = None,
                 repeat: int | None = None, csv_path: str | Path | None = None) -> Path:
    """``report.md``: per scene, the cheapest setting (method, parameters, load
    steps, solver) per error measure and tolerance, then every run, then (for a
    grid with a friction axis ``mu``) the ``friction_cost`` section
    (:func:`friction_cost`); and, with
    ``csv_path``, the same recommendations as CSV (one row per scene, measure
    and tolerance; empty settings where no run meets it)."""
    from ..output.io import atomic_path

    tolerances = [tolerance] if isinstance(tolerance, (int, float)) else list(tolerance)
    timed = (f"the median of {repeat} runs per setting, interleaved across settings"
             if repeat and repeat > 1 else "one run per setting")
    lines = ["# Speed-accuracy study", "",
             f"Tolerances (relative error): {', '.join(_pct(t) for t in tolerances)}. "
             f"Wall time: {timed}; its spread is (max - min) / median, and ⚠ marks a "
             "spread above 20 % (`timing_unsteady`): such a time is not reliable to "
             "that level.", ""]
    recs: list[dict] = []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        sub = [r for r in rows if r["scene"] == scene]
        first = _plotted_metric(rows, scene, plotted)
        names = _measures_of(rows, scene, first, measures)
        lines += [f"## {scene}", "", f"Plotted error measure: `{first}`.", ""]
        for tol, best in recommend(sub, first, tolerances):
            if best is None:
                lines.append(f"No setting reached tolerance {_pct(tol)} on `{first}`.")
            else:
                lines.append(f"Cheapest within tolerance {_pct(tol)} on `{first}`: "
                             f"**{best['method'] or '-'}**, {_settings(best)}: error "
                             f"{_num(best[first]):.3g} in {_num(best['wall_time_s']):.3g} s"
                             f"{_timing_mark(best)}.")
        lines += ["", "### Cheapest setting per error measure and tolerance", "",
                  "| error measure | tolerance | method | parameters | load steps | solver | "
                  "wall time (s) | error |", "|---|---|---|---|---|---|---|---|"]
        for metric in names:
            for tol, best in recommend(sub, metric, tolerances):
                rec = {"scene": scene, "error_metric": metric, "tolerance": tol}
                if best is None:
                    lines.append(f"| {metric} | {_pct(tol)} | none of the runs | | | | | |")
                    recs.append({**rec, "status": "not reached"})
                    continue
                lines.append(f"| {metric} | {_pct(tol)} | {best['method'] or '-'} | "
                             f"{_params(best) or '-'} | {_steps(best)} | "
                             f"{best.get('solver', '') or '-'} | "
                             f"{_num(best['wall_time_s']):.3g}{_timing_mark(best)} | "
                             f"{_num(best[metric]):.3g} |")
                recs.append({**rec, "status": "ok", "method": best["method"],
                             "parameters": _params(best), "steps": _steps(best),
                             "solver": best.get("solver", ""),
                             "wall_time_s": best["wall_time_s"],
                             "timing_unsteady": _flag(best.get("timing_unsteady")),
                             "error": best[metric], "key": best["key"]})
        lines += ["", "### Runs", "",
                  "| method | parameters | load steps | solver | dofs | Newton its | "
                  "wall time (s) | spread | " + " | ".join(names) + " | status |",
                  "|---" * (9 + len(names)) + "|"]
        for r in sub:
            spread = _num(r.get("wall_time_spread"))
            lines.append(
                f"| {r['method'] or '-'} | {_params(r) or '-'} | "
                f"{_steps(r) if r.get('status') == 'ok' else r.get('steps', '')} | "
                f"{r.get('solver', '') or '-'} | {r.get('n_dofs', '')} | "
                f"{r.get('newton_iterations', '')} | {_num(r.get('wall_time_s')):.3g} | "
                + (f"{100 * spread:.0f} %{_timing_mark(r)}" if np.isfinite(spread) else "-")
                + " | " + " | ".join(f"{_num(r.get(m)):.3g}" for m in names)
                + f" | {r.get('status', '')} |")
        lines.append("")
        lines += _friction_lines(sub)
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    if csv_path is not None:
        _write_recommendations(Path(csv_path), recs)
    return Path(path)


_REC_COLUMNS = ("scene", "error_metric", "tolerance", "status", "method", "parameters",
                "steps", "solver", "wall_time_s", "timing_unsteady", "error", "key")


def _write_recommendations(path: Path, recs: list[dict]) -> None:
    from ..output.io import atomic_path

    buf = _io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(_REC_COLUMNS))
    w.writeheader()
    for r in recs:
        w.writerow({k: ("" if r.get(k) is None else r.get(k, "")) for k in _REC_COLUMNS})
    with atomic_path(path) as tmp:
        tmp.write_text(buf.getvalue())
