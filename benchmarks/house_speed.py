# %%
"""Speed of two checkouts side by side, interleaved: did a change that only moves
code (issue 33, one job per module) leave the speed where it was?

    python benchmarks/house_speed.py BEFORE_DIR AFTER_DIR [--repeat 5] [--json out.json]

Each measure runs in a fresh process with ``PYTHONPATH`` set to the checkout, the
two checkouts alternating and their order flipped every round, so that a drift
of the machine falls on both:

- ``hertz_per_iteration_s``: ``hertz`` at ``refine=3``, one load step,
  ``mortar-dual``: the solve's wall time (from the run's summary) over its
  Newton iterations;
- ``demo_process_s``: ``skfem-mortar demo`` as a whole process (start-up, both
  runs, the pictures);
- ``ironing_mu03_s``: ``ironing --set mu=0.3`` (``mortar-dual``), the run's wall
  time.

Prints the median of ``--repeat`` runs per checkout and their ratio; a ratio
above 1.05 is worth re-measuring with ``--repeat 11`` before it counts.
It uses only the public ``run_scene`` and the command line, so it runs on any
checkout of the package since the summary had ``wall_time_s``.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

RUN = ("import json, sys, warnings; warnings.simplefilter('ignore');"
       "from skfem_mortar.app.runner import run_scene;"
       "s = run_scene(sys.argv[1], json.loads(sys.argv[2]), method='mortar-dual',"
       " steps=(int(sys.argv[3]) or None));"
       "print(json.dumps({'wall': s['wall_time_s'],"
       " 'its': sum(st['newton_iterations'] for st in s['steps'])}))")


def _env(checkout: str) -> dict:
    return {**os.environ, "PYTHONPATH": os.path.abspath(checkout)}


def _scene(checkout: str, scene: str, params: dict, steps: int) -> dict:
    out = subprocess.run([sys.executable, "-c", RUN, scene, json.dumps(params), str(steps)],
                         env=_env(checkout), capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def hertz_per_iteration(checkout: str) -> float:
    r = _scene(checkout, "hertz", {"refine": 3}, 1)
    return r["wall"] / r["its"]


def demo_process(checkout: str) -> float:
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "skfem_mortar.app.cli", "demo", "--out",
                        os.path.join(tmp, "demo")], env=_env(checkout), capture_output=True,
                       check=True, cwd=tmp)
        return time.perf_counter() - t0


def ironing(checkout: str) -> float:
    return _scene(checkout, "ironing", {"mu": 0.3}, 0)["wall"]


MEASURES = {"hertz_per_iteration_s": hertz_per_iteration, "demo_process_s": demo_process,
            "ironing_mu03_s": ironing}


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("before")
    p.add_argument("after")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--measure", action="append", choices=list(MEASURES))
    p.add_argument("--json")
    args = p.parse_args(argv)
    names = args.measure or list(MEASURES)
    times = {n: {"before": [], "after": []} for n in names}
    for k in range(args.repeat):
        order = ("before", "after") if k % 2 == 0 else ("after", "before")
        for n in names:
            for side in order:
                times[n][side].append(MEASURES[n](getattr(args, side)))
        print(f"round {k + 1}/{args.repeat} done", file=sys.stderr, flush=True)
    out = {}
    for n in names:
        b, a = (statistics.median(times[n][s]) for s in ("before", "after"))
        out[n] = {"before": b, "after": a, "ratio": a / b, "runs": times[n]}
        print(f"{n:24s} before {b:8.3f}  after {a:8.3f}  after/before {a / b:6.3f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    return out


if __name__ == "__main__":
    main()
