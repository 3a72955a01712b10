"""Per-phase times of a small hertz run, two checkouts interleaved (issue 16).

    python benchmarks/fixed_costs.py --before /path/to/old/checkout [--after .] \
        [--repeat 5] [--set refine=0]

Runs ``python -m skfem_mortar.app.cli run hertz --method mortar --out D
--replace --no-progress`` in fresh processes, alternating the two checkouts
(``PYTHONPATH`` set to each; one thread), and prints the medians of the whole
process (wall clock), the run's own wall time and phase timers
(``summary.json``: bulk, contact, search, solve, output) and the start-up
(whole process minus the run's wall time: interpreter, imports, CLI), with
the ratio after/before.  Only the ratios of one invocation compare: other
load on the machine inflates both sides alike.
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

HERE = os.path.dirname(os.path.abspath(__file__))


def one_run(checkout: str, out: str, extra: list[str]) -> dict[str, float]:
    env = dict(os.environ, OMP_NUM_THREADS="1", MKL_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1", PYTHONPATH=os.path.abspath(checkout))
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "skfem_mortar.app.cli", "run", "hertz", "--method",
                    "mortar", "--out", out, "--replace", "--no-progress", *extra],
                   env=env, check=True, stdout=subprocess.DEVNULL)
    whole = time.perf_counter() - t0
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    return {"whole process": whole, "in-run wall": s["wall_time_s"], **s["phase_times_s"],
            "start-up (whole - in-run)": whole - s["wall_time_s"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", required=True, help="the checkout to compare against")
    ap.add_argument("--after", default=os.path.dirname(HERE), help="default: this checkout")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    a = ap.parse_args(argv)
    extra = [x for s in a.set for x in ("--set", s)]
    res: dict[str, list[dict]] = {"before": [], "after": []}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(a.repeat):
            for side in ("before", "after"):
                res[side].append(one_run(getattr(a, side), os.path.join(tmp, side), extra))
    print(f"| phase [s] (median of {a.repeat}) | before | after | after/before |")
    print("|---|---|---|---|")
    for k in res["before"][0]:
        b = statistics.median(r[k] for r in res["before"])
        c = statistics.median(r[k] for r in res["after"])
        print(f"| {k} | {b:.3f} | {c:.3f} | {c / b if b else float('nan'):.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
