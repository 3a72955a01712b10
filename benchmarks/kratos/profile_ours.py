"""Where the time of ``skfem-mortar run hertz --method mortar`` goes (one thread).

    python benchmarks/kratos/profile_ours.py --out DIR [--set refine=0] [--steps 4] [--top 25]

Three measurements, each in a fresh process:

1. ``python -c pass`` and ``python -c "import skfem_mortar.app.cli"`` timed by
   the wall clock (interpreter start-up; the command line imports its heavy
   dependencies lazily), and the run under ``python -X importtime``: the
   cumulative import time of the top-level packages and of the slowest single
   modules;
2. the whole run (``python -m skfem_mortar.app.cli run hertz ...``) timed by the
   wall clock;
3. the same run under ``cProfile`` (in-process, ``skfem_mortar.app.cli.main``):
   the time of building the scene (``build_scene``), of the solve
   (``stepping.solve``), of the Newton iterations (``newton.newton``, per
   iteration), of writing the outputs, the run's own phase timers
   (``summary.json``) and the functions with the largest own and cumulative
   time.  cProfile inflates Python-heavy code; the phase shares, not the
   absolute numbers, are the point.

Prints a markdown report and writes it to ``DIR/profile.md``
(``DIR/run.prof`` holds the profile for ``python -m pstats``).
"""
from __future__ import annotations

import argparse
import cProfile
import io
import json
import os
import pstats
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from side_by_side import ONE_THREAD  # noqa: E402


def wall(cmd: list[str], env: dict, repeat: int = 3) -> float:
    """Median wall-clock seconds of ``cmd`` over ``repeat`` fresh processes."""
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(cmd, env=env, cwd=REPO, check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        ts.append(time.perf_counter() - t0)
    return sorted(ts)[len(ts) // 2]


def import_times(run: list[str], env: dict, top: int
                 ) -> tuple[list[tuple[str, float]], list[tuple[str, float]]]:
    """``-X importtime`` of the whole run (the package imports numpy, scipy and
    scikit-fem lazily, so importing the command line alone says little):
    cumulative seconds per top-level package (its root imports) and the
    ``top`` slowest modules by their own time."""
    p = subprocess.run([sys.executable, "-X", "importtime", "-m", "skfem_mortar.app.cli"] + run,
                       env=env, cwd=REPO, capture_output=True, text=True, check=True)
    pkgs, own = {}, []
    for ln in p.stderr.splitlines():
        m = re.match(r"import time:\s+(\d+) \|\s+(\d+) \|( *)(\S+)", ln)
        if not m:
            continue
        self_us, cum_us, indent, name = int(m[1]), int(m[2]), len(m[3]), m[4]
        own.append((name, self_us / 1e6))
        if indent == 1:  # a root import of the statement
            root = name.split(".")[0]
            pkgs[root] = pkgs.get(root, 0.0) + cum_us / 1e6
    return (sorted(pkgs.items(), key=lambda kv: -kv[1]),
            sorted(own, key=lambda kv: -kv[1])[:top])


def cum(stats: pstats.Stats, file_part: str, func: str) -> tuple[float, int]:
    """Cumulative seconds and calls of the function ``func`` in a file whose path
    contains ``file_part``."""
    t, n = 0.0, 0
    for (fname, _, name), (cc, nc, tt, ct, _) in stats.stats.items():
        if name == func and file_part in fname.replace(os.sep, "/"):
            t, n = t + ct, n + cc
    return t, n


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--steps", type=int, default=None)
    ap.add_argument("--top", type=int, default=25)
    a = ap.parse_args(argv)
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    os.environ.update(ONE_THREAD)
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    run = ["run", "hertz", "--method", "mortar", "--out", os.path.join(out, "run"),
           "--replace", "--no-progress"]
    run += [x for s in a.set for x in ("--set", s)]
    run += ["--steps", str(a.steps)] if a.steps else []

    t_python = wall([sys.executable, "-c", "pass"], env)
    t_import = wall([sys.executable, "-c", "import skfem_mortar.app.cli"], env)
    t_whole = wall([sys.executable, "-m", "skfem_mortar.app.cli"] + run, env)
    pkgs, mods = import_times(run, env, a.top)

    from skfem_mortar.app import cli
    prof = cProfile.Profile()
    t0 = time.perf_counter()
    prof.runcall(cli.main, run)
    t_prof = time.perf_counter() - t0
    prof.dump_stats(os.path.join(out, "run.prof"))
    st = pstats.Stats(prof)
    with open(os.path.join(out, "run", "summary.json")) as f:
        summary = json.load(f)
    t_build, _ = cum(st, "skfem_mortar/app/runner", "build_scene")
    t_solve, _ = cum(st, "skfem_mortar/solver/stepping", "solve")
    t_newton, n_newton_calls = cum(st, "skfem_mortar/solver/newton", "newton")
    its = sum(s["newton_iterations"] for s in summary["steps"])

    lines = [f"# Profile of `skfem-mortar {' '.join(run)}`", "",
             f"{summary['n_dofs'] // 2} nodes, {summary['n_multipliers']} multipliers, "
             f"{len(summary['steps'])} load steps, {its} Newton iterations; one thread.", "",
             "| what | seconds |", "|---|---|",
             f"| `python -c pass` (interpreter start) | {t_python:.3f} |",
             f"| `python -c 'import skfem_mortar.app.cli'` (start + imports) | {t_import:.3f} |",
             f"| whole run, wall clock (median of 3) | {t_whole:.3f} |",
             f"| under cProfile: the run without imports | {t_prof:.3f} |",
             f"| ... building the scene (`build_scene`) | {t_build:.3f} |",
             f"| ... the solve (`stepping.solve`) | {t_solve:.3f} |",
             f"| ... Newton (`newton.newton`, {n_newton_calls} calls) | {t_newton:.3f} |",
             f"| ... per Newton iteration | {t_newton / max(its, 1):.4f} |"]
    for k, v in summary["phase_times_s"].items():
        lines.append(f"| phase timer `{k}` (summary.json) | {v:.3f} |")
    lines += ["", f"Imports during the run (`-X importtime`, cumulative per root package; "
              f"all: {sum(v for _, v in pkgs):.3f} s):", "",
              "| package | seconds |", "|---|---|"]
    lines += [f"| {k} | {v:.3f} |" for k, v in pkgs[:12]]
    lines += ["", f"Slowest single modules (own time, top {a.top}):", "",
              "| module | seconds |", "|---|---|"]
    lines += [f"| {k} | {v:.4f} |" for k, v in mods]
    for key in ("tottime", "cumulative"):
        buf = io.StringIO()
        pstats.Stats(prof, stream=buf).sort_stats(key).print_stats(a.top)
        body = buf.getvalue()
        body = body[body.find("   ncalls"):]
        lines += ["", f"cProfile, top {a.top} by {key}:", "", "```", body.rstrip(), "```"]
    md = "\n".join(lines) + "\n"
    print(md)
    with open(os.path.join(out, "profile.md"), "w") as f:
        f.write(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
