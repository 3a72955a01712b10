"""Side by side: Kratos' ``hertz_simple`` contact test against ``skfem-mortar run hertz``.

    python benchmarks/kratos/side_by_side.py --out DIR [--repeat 3] [--levels 1 2 4]
        [--refine -2 -1 0 1 2] [--steps 1 2 4] [--methods mortar mortar-dual]
        [--kratos-python /work/kratos-venv/bin/python]

Every run is a fresh process, timed by the wall clock around it (imports, mesh
reading, solve and output included; both codes' Python modules byte-compiled
first, as an install leaves them: :func:`compile_bytecode`), with one thread (``OMP_NUM_THREADS`` and
the BLAS variables set to 1).  The runs are interleaved: each round runs every
configuration once, ``--repeat`` rounds, and the time reported is the median
over the rounds (a configuration whose first run took longer than ``--slow``
seconds is run once only; its ``n`` says so).

Kratos (its venv's python, ``run_kratos.py``): the test's mesh (1x) and its
uniform refinements (``make_meshes.py``: 2x, 4x), two load steps to the line
load ``P = 3.2032``, each with the test's linear solver (skyline LU) and with
Eigen's sparse LU (``--kratos-solvers``; the test's solver is the slower one
from 2x on).  Ours: ``python -m skfem_mortar.app.cli run hertz --method
M --set refine=R --steps S --out TMP --replace`` for every ``M`` (``--methods``,
default ``mortar``: standard multipliers, as Kratos' test), ``R`` and ``S``
asked for.  The scene's defaults are the data of ``hertz_simple``: R = 8, E =
200, nu = 0.3, line load 3.2032 on a rigid base (Kratos: a plate with E = 2e12,
every node fixed).  Kratos models the whole half cylinder; ours the quarter
disk ``x >= 0`` with the symmetry condition ``u_x = 0`` on ``x = 0``.

The errors are computed the same way for both from the nodal contact pressure
of the slave surface (the cylinder's arc in both; ``x`` its current
coordinate, nodes with ``x >= 0``):

* peak pressure: the largest nodal pressure against ``p0 = 2 P / (pi a)``;
* half-width: midway between the last node in compression and the next one
  (the scene's metric) against ``a = sqrt(4 P R / (pi E*))``.

Kratos' pressure is ``-AUGMENTED_NORMAL_CONTACT_PRESSURE`` on the nodes it
flags ``ACTIVE`` (0 elsewhere): the augmented multiplier ``k lambda + eps
g~`` of its mortar ALM, a traction (the nodal value of the multiplier field,
not a nodal force: it is not divided by a tributary length); on active nodes
the weighted gap is ~0 and it equals ``SCALE_FACTOR * lambda``.  Ours: the
``pressure`` column of ``contact.csv`` (standard mortar: the multiplier, a
traction).  Our bodies are finite-strain neo-Hookean, Kratos' small-strain
linear elastic; the finite-strain model lies ``FINITE_STRAIN_OFFSET`` = 0.79 %
above linear Hertz theory in the pressure at this a/R = 0.048
(``skfem_mortar/scenes/hertz.py``, measured at the interior nodes 0.2 a < x <
0.5 a), so our peak error is taken against ``p0 (1 + offset)`` and, as the
same load spread elliptically under a peak that much higher is that much
narrower, our half-width error against ``a / (1 + offset)`` (``peak_error``,
``half_width_error``; ``*_raw`` against ``p0`` and ``a``).  "Ours meets a
Kratos run" means both of our offset-free errors are at most Kratos' in
absolute value.  ``interior_offset``
reports, for every run, the mean of ``p / p_Hertz - 1`` over those interior
nodes: the offset as each run sees it (Kratos ~0, ours ~ +0.8 %).

Written to ``DIR``: ``side_by_side.json`` (every run, every repetition) and
``side_by_side.md`` (the table, also printed), the meshes under
``DIR/meshes`` and the runs' outputs under ``DIR/runs``.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from make_meshes import make  # noqa: E402

#: the data of hertz_simple (and the defaults of our scene)
RADIUS, LOAD, E, NU = 8.0, 3.2032, 200.0, 0.3
#: the finite-strain deviation of our neo-Hookean model from linear Hertz
#: theory in the peak pressure at a/R = 0.048, as scenes/hertz.py documents it
FINITE_STRAIN_OFFSET = 0.0079
#: a node is in compression when its pressure exceeds this fraction of the peak
#: (inactive nodes carry exact zeros in both codes; round-off is far below)
COMPRESSION = 1e-8
#: one thread for every library of both codes
ONE_THREAD = {k: "1" for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                               "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")}
TARGETS = {1: 0.7, 2: 0.3, 4: 0.3}
#: the linear solver of Kratos' test (SkylineLUFactorizationSolver, renamed in 10.4)
TEST_SOLVER = "skyline_lu_factorization"


def hertz() -> dict:
    """Half-width ``a`` and peak pressure ``p0`` on a rigid base (plane strain)."""
    Es = E / (1.0 - NU * NU)
    a = math.sqrt(4.0 * LOAD * RADIUS / (math.pi * Es))
    return {"half_width": a, "peak_pressure": 2.0 * LOAD / (math.pi * a), "E_star": Es}


def errors(x: np.ndarray, p: np.ndarray, offset: float = 0.0) -> dict:
    """Peak-pressure and half-width errors of nodal pressures ``p`` at ``x`` (nodes
    with ``x >= 0`` are used), relative to Hertz theory, signed (``value / exact
    - 1``).  ``offset`` removes a relative deviation of the model from linear
    theory: the peak is compared with ``p0 (1 + offset)`` and the half-width
    with ``a / (1 + offset)`` (an elliptic profile carrying the same load ``P =
    pi a p0 / 2`` with a peak ``1 + offset`` times higher is that much
    narrower); ``*_raw`` are against ``p0`` and ``a``."""
    ex = hertz()
    a, p0 = ex["half_width"], ex["peak_pressure"]
    keep = x >= -1e-9 * a
    order = np.argsort(x[keep])
    x, p = x[keep][order], p[keep][order]
    peak = float(p.max())
    comp = np.flatnonzero(p > COMPRESSION * max(peak, 0.0))
    k = int(comp.max()) if comp.size else 0
    half = float(0.5 * (x[k] + x[min(k + 1, len(x) - 1)])) if comp.size else 0.0
    inner = (x > 0.2 * a) & (x < 0.5 * a)
    pe = p0 * np.sqrt(1.0 - (x[inner] / a) ** 2)
    return {"peak_pressure": peak, "half_width": half,
            "peak_error": peak / (p0 * (1.0 + offset)) - 1.0,
            "peak_error_raw": peak / p0 - 1.0,
            "half_width_error": half * (1.0 + offset) / a - 1.0,
            "half_width_error_raw": half / a - 1.0,
            "interior_offset": float(np.mean(p[inner] / pe) - 1.0) if inner.any() else None,
            "n_contact_nodes": int(comp.size)}


def kratos_metrics(path: str) -> dict:
    """Nodes, iterations, steps and errors of a ``run_kratos.py`` output."""
    with open(path) as f:
        d = json.load(f)
    slave = [n for n in d["contact_nodes"] if n["slave"]]
    x = np.array([n["X"] + n["ux"] for n in slave])
    p = np.array([-n["augmented_pressure"] if n["active"] else 0.0 for n in slave])
    return {"nodes": d["n_nodes"], "newton_iterations": int(sum(d["iterations"])),
            "iterations_per_step": d["iterations"], "load_steps": len(d["iterations"]),
            "linear_solver": d.get("linear_solver"), **errors(x, p)}


def ours_metrics(out: str) -> dict:
    """Nodes, iterations, steps and errors of a ``skfem-mortar run hertz`` output
    directory (errors recomputed from ``contact.csv`` by :func:`errors`)."""
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    with open(os.path.join(out, "contact.csv")) as f:
        rows = list(csv.DictReader(f))
    x = np.array([float(r["x"]) for r in rows])
    p = np.array([float(r["pressure"]) for r in rows])
    its = [st["newton_iterations"] for st in s["steps"]]
    return {"nodes": s["n_dofs"] // 2,  # rigid base, linear triangles: 2 dofs a node
            "newton_iterations": int(sum(its)), "iterations_per_step": its,
            "load_steps": len(its), "converged": s["converged"],
            "scene_peak_error": s["metrics"].get("peak_pressure_error"),
            "scene_half_width_error": s["metrics"].get("half_width_error"),
            **errors(x, p, FINITE_STRAIN_OFFSET)}


def compile_bytecode(kratos_python: str) -> None:
    """Byte-compile this checkout and the Kratos scripts before any timed run.

    An installed package has its bytecode (pip compiles a wheel's modules at
    install; Kratos' wheels ship theirs), but a checkout run with
    ``PYTHONDONTWRITEBYTECODE`` set (as on the development machines) would
    compile every module from source in every run: about 0.2 s of a 1 s run.
    Compiling once here (``compileall``, into the usual ``__pycache__``) makes
    both codes start like an installed one.
    """
    subprocess.run([sys.executable, "-m", "compileall", "-q", os.path.join(REPO, "skfem_mortar")],
                   check=True)
    subprocess.run([kratos_python, "-m", "compileall", "-q", HERE], check=True)


def timed(cmd: list[str], env: dict, cwd: str, log: str) -> tuple[float, int]:
    """Wall-clock seconds and exit code of ``cmd`` as a fresh process."""
    with open(log, "w") as f:
        t0 = time.perf_counter()
        rc = subprocess.run(cmd, env=env, cwd=cwd, stdout=f, stderr=subprocess.STDOUT).returncode
        return time.perf_counter() - t0, rc


def configurations(a) -> list[dict]:
    runs = [{"code": "kratos", "name": f"kratos {k}x" + ("" if sol == TEST_SOLVER else f" {sol}"),
             "level": k, "solver": sol} for sol in a.kratos_solvers for k in a.levels]
    runs += [{"code": "ours", "name": f"ours {m} refine={r} steps={s}", "method": m,
              "refine": r, "steps": s}
             for m in a.methods for r in a.refine for s in a.steps]
    return runs


def command(run: dict, a, paths: dict, rundir: str) -> list[str]:
    if run["code"] == "kratos":
        cmd = [a.kratos_python, os.path.join(HERE, "run_kratos.py"), paths[run["level"]],
               os.path.join(rundir, "kratos.json")]
        return cmd + ["--linear-solver", run["solver"]]
    return [sys.executable, "-m", "skfem_mortar.app.cli", "run", "hertz",
            "--method", run["method"],
            "--set", f"refine={run['refine']}", "--steps", str(run["steps"]),
            "--out", rundir, "--replace", "--no-progress"]


def table(results: list[dict]) -> str:
    """The markdown table of the runs, then the cheapest of ours per Kratos run."""
    def pct(v):
        return "" if v is None else f"{100 * v:+.2f} %"
    lines = ["| run | nodes | load steps | Newton its | whole process [s] (n) | peak error "
             "| half-width error | interior offset |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results:
        m = r.get("metrics")
        if not m:
            lines.append(f"| {r['name']} | failed (exit {r['rc']}) | | | | | | |")
            continue
        peak, half = pct(m["peak_error"]), pct(m["half_width_error"])
        if r["code"] != "kratos":
            peak += f" (raw {pct(m['peak_error_raw'])})"
            half += f" (raw {pct(m['half_width_error_raw'])})"
        lines.append(f"| {r['name']} | {m['nodes']} | {m['load_steps']} | "
                     f"{m['newton_iterations']} | {r['time']:.2f} ({len(r['times'])}) | {peak} | "
                     f"{half} | {pct(m['interior_offset'])} |")
    lines += ["", "| Kratos run | its time [s] | peak / half-width error to meet | cheapest of "
              "ours meeting both | its time [s] | ratio | target |", "|---|---|---|---|---|---|---|"]
    for k in results:
        if k["code"] != "kratos" or not k.get("metrics"):
            continue
        km = k["metrics"]
        ok = [r for r in results if r["code"] == "ours" and r.get("metrics")
              and r["metrics"]["converged"]
              and abs(r["metrics"]["peak_error"]) <= abs(km["peak_error"])
              and abs(r["metrics"]["half_width_error"]) <= abs(km["half_width_error"])]
        target = TARGETS.get(k["level"])
        need = f"{100 * abs(km['peak_error']):.2f} % / {100 * abs(km['half_width_error']):.2f} %"
        if not ok:
            lines.append(f"| {k['name']} | {k['time']:.2f} | {need} | none | | | {target} |")
            continue
        best = min(ok, key=lambda r: r["time"])
        ratio = best["time"] / k["time"]
        verdict = "" if target is None else (f"<= {target}: met" if ratio <= target
                                             else f"<= {target}: not met")
        lines.append(f"| {k['name']} | {k['time']:.2f} | {need} | {best['name']} | "
                     f"{best['time']:.2f} | {ratio:.2f} | {verdict} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="directory for the results (not committed)")
    ap.add_argument("--repeat", type=int, default=3, help="rounds; the median is reported")
    ap.add_argument("--slow", type=float, default=120.0,
                    help="a configuration whose first run takes longer is not repeated [s]")
    ap.add_argument("--levels", type=int, nargs="*", default=[1, 2, 4],
                    help="Kratos meshes: refinement factors of the test mesh")
    ap.add_argument("--refine", type=int, nargs="*", default=[-2, -1, 0, 1, 2],
                    help="our scene's refine values to sweep")
    ap.add_argument("--steps", type=int, nargs="*", default=[1, 2, 4],
                    help="our load step counts to sweep")
    ap.add_argument("--methods", nargs="*", default=["mortar"],
                    help="our contact methods to sweep (mortar: standard multipliers like "
                         "Kratos' test; mortar-dual, nts)")
    ap.add_argument("--kratos-python", default="/work/kratos-venv/bin/python")
    ap.add_argument("--kratos-solvers", nargs="*", default=[TEST_SOLVER, "sparse_lu"],
                    help="Kratos linear solvers to run each mesh with: the test's skyline LU "
                         "and Eigen's sparse LU (LinearSolversApplication) by default")
    ap.add_argument("--retable", action="store_true",
                    help="run nothing: recompute the metrics from the outputs kept in --out "
                         "and rewrite the table (times from side_by_side.json)")
    a = ap.parse_args(argv)
    if a.retable:
        return retable(os.path.abspath(a.out))
    if a.repeat < 1:
        raise ValueError(f"--repeat must be >= 1, got {a.repeat}")
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    paths = make(os.path.join(out, "meshes"), tuple(a.levels)) if a.levels else {}
    env = dict(os.environ, **ONE_THREAD)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    compile_bytecode(a.kratos_python)
    runs = configurations(a)
    for run in runs:
        run["times"], run["rc"] = [], 0
    for rnd in range(a.repeat):
        for i, run in enumerate(runs):
            if rnd and (run["rc"] or run["times"][0] > a.slow):
                continue
            rundir = os.path.join(out, "runs", f"{i:02d}")
            os.makedirs(rundir, exist_ok=True)
            t, rc = timed(command(run, a, paths, rundir), env, REPO,
                          os.path.join(out, "runs", f"{i:02d}.log"))
            run["rc"] = rc
            if rc == 0:
                run["times"].append(t)
                if rnd == 0:
                    run["metrics"] = metrics_of(out, i, run)
            print(f"round {rnd + 1}/{a.repeat} {run['name']}: {t:.2f} s (exit {rc})",
                  flush=True)
    for run in runs:
        run["time"] = statistics.median(run["times"]) if run["times"] else float("nan")
    write(out, runs, a.repeat, os.getloadavg())
    return 0


def metrics_of(out: str, i: int, run: dict) -> dict:
    rundir = os.path.join(out, "runs", f"{i:02d}")
    return (kratos_metrics(os.path.join(rundir, "kratos.json")) if run["code"] == "kratos"
            else ours_metrics(rundir))


def write(out: str, runs: list[dict], repeat: int, load) -> None:
    """Print the table and write ``side_by_side.md`` and ``side_by_side.json``."""
    md = table(runs)
    head = (f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
            f"load average at the end {load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f}; "
            f"one thread per run; median of {repeat} interleaved rounds.\n"
            f"Hertz: a = {hertz()['half_width']:.5f}, p0 = {hertz()['peak_pressure']:.4f}; "
            f"our errors are against p0 (1 + {FINITE_STRAIN_OFFSET}) and a / (1 + "
            f"{FINITE_STRAIN_OFFSET}) (finite-strain offset removed; raw: against p0, a).\n")
    print(head + "\n" + md)
    with open(os.path.join(out, "side_by_side.md"), "w") as f:
        f.write(head + "\n" + md + "\n")
    with open(os.path.join(out, "side_by_side.json"), "w") as f:
        json.dump({"hertz": hertz(), "finite_strain_offset": FINITE_STRAIN_OFFSET,
                   "repeat": repeat, "loadavg": list(load), "runs": runs}, f, indent=1)


def retable(out: str) -> int:
    """Recompute every run's metrics from its kept output and rewrite the table."""
    with open(os.path.join(out, "side_by_side.json")) as f:
        d = json.load(f)
    for i, run in enumerate(d["runs"]):
        if run.get("metrics"):
            run["metrics"] = metrics_of(out, i, run)
    write(out, d["runs"], d["repeat"], d["loadavg"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
