"""Axisymmetric contact (issue 37): the scenes hertz_axi, oring and seed_axi over meshes.

Usage::

    python benchmarks/axi_contact.py [OUT_DIR] [--quick]

Prints markdown tables and writes ``OUT_DIR/axi_contact.json`` (default
``benchmarks/results_axi``) and the O-ring's force-squeeze figure
``docs/oring_force_squeeze.png`` (the three methods, axisymmetric, with
the plane-strain cross-section and Lindley's empirical band for reference):

* ``hertz_axi``, small strain on the rigid plane and dual mortar on the elastic
  cylinder, at h = a/15 ... a/120: the errors of Hertz's readings (``_ref``) and
  of the current ones, with observed orders ``log2(e_h / e_h/2)``;
* ``oring`` to 25 % squeeze (10 steps) at three meshes per method: the force
  per circumference, contact width and peak pressure, their changes between
  meshes, and the curve;
* ``seed_axi`` at four meshes per method: pressure and radial contact force;
* Newton iterations per step and the time per Newton iteration against the
  plane-strain run of the same mesh (``oring`` with ``geometry=plane``) and
  against ``hertz`` at the same ``refine``.
"""
from __future__ import annotations

import json
import math
import sys
import time
import warnings
from pathlib import Path

from skfem_mortar.app.runner import run_scene

METHODS = ("nts", "mortar", "mortar-dual")
ROOT = Path(__file__).resolve().parents[1]


def run(scene: str, method: str, steps: int | None = None, **params) -> dict:
    """One run: metrics, dofs, Newton iterations per step, seconds per iteration."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = time.perf_counter()
        out = run_scene(scene, params=params, method=method, steps=steps)
        wall = time.perf_counter() - t
    its = [s["newton_iterations"] for s in out["steps"]]
    return {"metrics": {k: v for k, v in out["metrics"].items() if k != "force_squeeze"},
            "curve": out["metrics"].get("force_squeeze"), "n_dofs": out["n_dofs"],
            "iterations": its, "wall_s": wall, "s_per_iteration": wall / max(sum(its), 1)}


def orders(errors: list[float]) -> list[float]:
    """``log2(e_k / e_k+1)`` between consecutive halvings of h."""
    return [math.log2(a / b) if a > 0 and b > 0 else math.nan
            for a, b in zip(errors, errors[1:])]


def hertz_series(levels: list[int]) -> dict:
    """hertz_axi errors over ``levels`` (refine), small strain."""
    out = {}
    for method, base in [(m, "rigid") for m in METHODS] + [("mortar-dual", "elastic")]:
        rows = [run("hertz_axi", method, kinematics="small", base=base, refine=r) for r in levels]
        keys = ("peak_pressure_ref_error", "contact_radius_ref_error", "peak_pressure_error",
                "contact_radius_error", "contact_force_error")
        table = {k: [r["metrics"][k] for r in rows] for k in keys}
        table["orders_peak_ref"] = orders(table["peak_pressure_ref_error"])
        table["orders_radius_ref"] = orders(table["contact_radius_ref_error"])
        table["trapz_over_F"] = [r["metrics"]["pressure_resultant_trapz"] / r["metrics"]["load"]
                                 for r in rows]
        table["n_dofs"] = [r["n_dofs"] for r in rows]
        table["iterations"] = [r["iterations"] for r in rows]
        table["s_per_iteration"] = [r["s_per_iteration"] for r in rows]
        out[f"{method}/{base}"] = table
    return out


def oring_series(levels: list[int]) -> dict:
    """oring to 25 % squeeze for each method and mesh; the plane run at the middle mesh."""
    out = {}
    for method in METHODS:
        rows = [run("oring", method, refine=r) for r in levels]
        out[method] = {
            "force_per_circumference": [r["metrics"]["force_per_circumference"] for r in rows],
            "contact_width": [r["metrics"]["contact_width"] for r in rows],
            "peak_pressure": [r["metrics"]["peak_pressure"] for r in rows],
            "lindley": rows[0]["metrics"]["lindley_force_per_circumference"],
            "curve": rows[-1]["curve"], "n_dofs": [r["n_dofs"] for r in rows],
            "iterations": [r["iterations"] for r in rows],
            "s_per_iteration": [r["s_per_iteration"] for r in rows]}
    plane = run("oring", "mortar-dual", refine=levels[-1], geometry="plane")
    out["plane/mortar-dual"] = {"force_per_circumference": plane["metrics"][
        "force_per_circumference"], "curve": plane["curve"], "n_dofs": plane["n_dofs"],
        "iterations": plane["iterations"], "s_per_iteration": plane["s_per_iteration"]}
    return out


def seed_series(levels: list[int]) -> dict:
    """seed_axi for each method and mesh."""
    out = {}
    for method in METHODS:
        rows = [run("seed_axi", method, refine=r) for r in levels]
        out[method] = {k: [r["metrics"][k] for r in rows]
                       for k in ("pressure_over_scale", "contact_force_radial",
                                 "axial_balance_error", "radial_balance_error",
                                 "tube_radial_error")}
        out[method].update(n_dofs=[r["n_dofs"] for r in rows],
                           iterations=[r["iterations"] for r in rows])
    return out


def plane_cost(levels: list[int]) -> dict:
    """Seconds per Newton iteration: hertz (plane) against hertz_axi, NTS, same refine."""
    out = {}
    for r in levels:
        a = run("hertz_axi", "nts", refine=r)
        p = run("hertz", "nts", refine=r)
        out[r] = {"axi": [a["n_dofs"], a["s_per_iteration"], a["iterations"]],
                  "plane": [p["n_dofs"], p["s_per_iteration"], p["iterations"]]}
    return out


def figure(oring: dict, path: Path) -> None:
    """The force-squeeze curves of the three methods (and the plane strain run,
    Lindley's band) in one small PNG."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(4.8, 3.4), dpi=110)
    styles = {"nts": "o-", "mortar": "s--", "mortar-dual": "^:"}
    for method in METHODS:
        s, f = zip(*oring[method]["curve"])
        ax.plot([100 * v for v in s], f, styles[method], ms=4, label=f"{method} (axisymmetric)")
    s, f = zip(*oring["plane/mortar-dual"]["curve"])
    ax.plot([100 * v for v in s], f, "k-", lw=0.8, label="mortar-dual (plane strain)")
    ss = [v / 200 for v in range(1, 51)]
    ax.plot([100 * v for v in ss], [1.25 * v ** 1.5 + 50 * v ** 6 for v in ss], color="0.6",
            lw=3, alpha=0.5, label="Lindley (empirical)")
    ax.set_xlabel("squeeze (% of d)")
    ax.set_ylabel("F / (2 pi R_m E d)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def main(argv: list[str]) -> None:
    quick = "--quick" in argv
    args = [a for a in argv if not a.startswith("--")]
    out_dir = Path(args[0]) if args else ROOT / "benchmarks" / "results_axi"
    out_dir.mkdir(parents=True, exist_ok=True)
    res = {"hertz_axi": hertz_series([-1, 0] if quick else [-1, 0, 1, 2]),
           "oring": oring_series([-2, -1] if quick else [-2, -1, 0]),
           "seed_axi": seed_series([-1, 0] if quick else [-1, 0, 1, 2]),
           "plane_cost": plane_cost([-1] if quick else [-1, 0, 1])}
    (out_dir / "axi_contact.json").write_text(json.dumps(res, indent=1))
    figure(res["oring"], ROOT / "docs" / "oring_force_squeeze.png")
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main(sys.argv[1:])
