"""The ``mindlin`` scene under refinement: the Cattaneo-Mindlin errors per mesh level.

For each method and each ``n_a`` (elements per contact half-width): the nodes of
both bodies, the stick half-width's relative error, the shear traction's error
(max over the nodes / (mu p0), and relative L2), the pressure's (the half-space
floor on the same mesh), the drift of P over the shift, Q / (mu P) and the Newton
iterations per step (pressing, shifting), and the same errors in the stick core
(``|x| < 0.8 c`` for q, ``|x| < 0.8 a`` for p, away from the square-root cusps).
Prints a Markdown table; ``--json`` writes the rows too.  ``--pressing
frictional`` runs the scene with friction from the start (the default presses
frictionless, see the scene).

    PYTHONPATH=. python benchmarks/friction/mindlin_refinement.py [--levels 8 15 30]
        [--methods nts mortar mortar-dual] [--pressing frictionless|frictional]
        [--steps 16] [--json out.json]
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from skfem_mortar.app.runner import run_scene


def row(method: str, n_a: int, pressing: str = "frictionless", steps: int = 16) -> dict:
    t0 = time.perf_counter()
    summary, res, setup = run_scene("mindlin", {"n_a": n_a, "pressing": pressing,
                                                "n_steps": steps},
                                    method=method, return_result=True)
    m = summary["metrics"]
    nodes = sum(setup.model.item(b).mesh.p.shape[1] for b in ("cylinder", "block"))
    t = np.asarray(m["time"][1:])
    it = np.asarray(m["newton_iterations"])
    press = t <= 0.25 + 1e-12
    return {"method": method, "n_a": n_a, "nodes": nodes,
            "c_error": m["stick_half_width_error"], "q_max": m["shear_error"],
            "q_l2": m["shear_l2_error"], "p_max": m["pressure_error"],
            "p_l2": m["pressure_l2_error"], "q_core": m["shear_core_error"],
            "p_core": m["pressure_core_error"], "P_drift": m["P_drift"], "Q_ratio": m["Q_ratio"],
            "it_press": float(it[press].mean()), "it_shift": float(it[~press].mean()),
            "steps": int(it.size), "seconds": time.perf_counter() - t0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[6, 12, 24])
    ap.add_argument("--methods", nargs="+", default=["nts", "mortar", "mortar-dual"])
    ap.add_argument("--pressing", default="frictionless", choices=("frictionless", "frictional"))
    ap.add_argument("--steps", type=int, default=16)
    ap.add_argument("--json")
    args = ap.parse_args()
    rows = []
    print("| method | n_a | nodes | c error | q max/(mu p0) | q L2 | p max/p0 | p L2 | q core "
          "| p core | P drift | Q/(mu P) | it/step press | it/step shift | steps | s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for method in args.methods:
        for n_a in args.levels:
            r = row(method, n_a, args.pressing, args.steps)
            rows.append(r)
            print(f"| {method} | {n_a} | {r['nodes']} | {r['c_error']:.3f} | {r['q_max']:.3f} "
                  f"| {r['q_l2']:.3f} | {r['p_max']:.3f} | {r['p_l2']:.3f} | {r['q_core']:.3f} "
                  f"| {r['p_core']:.3f} | {r['P_drift']:.1e} "
                  f"| {r['Q_ratio']:.3f} | {r['it_press']:.1f} | {r['it_shift']:.1f} "
                  f"| {r['steps']} | {r['seconds']:.0f} |", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
