# %%
"""Speed of the NTS kernel and two NTS runs in two checkouts, side by side, interleaved.

    python benchmarks/nts_speed.py BEFORE_DIR AFTER_DIR [--repeat 5] [--json out.json]

Measures (a fresh process per measure with ``PYTHONPATH`` set to the checkout, the
checkouts alternating, their order flipped every round):

- ``nts_<cell>_ms``: ``nts.evaluate`` with ``G`` and ``H``, 25 slave segments (26
  nodes) on an arc against 33 master segments, line2 or line3 master; the median of
  40 calls in one process;
- ``patch_nts_s``, ``slide_nts_s``: ``skfem-mortar run patch|slide --method nts`` as a
  whole process (wall clock).

Prints the median of ``--repeat`` runs per checkout and their ratio.
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

CALL = r"""
import json, sys, time
import numpy as np
from skfem_mortar.contact import nts
k = int(sys.argv[1])

def chain(n, f, x0, x1, k):
    xv = np.linspace(x0, x1, n + 1)
    if k == 2:
        return np.vstack([xv, f(xv)]), np.c_[0:n, 1:n + 1]
    xm = 0.5 * (xv[:-1] + xv[1:])
    X = np.r_[xv, xm]
    return np.vstack([X, f(X)]), np.c_[0:n, 1:n + 1, n + 1:2 * n + 1]

xs, ss = chain(25, lambda x: 0.3 * x * x + 0.01, -0.8, 0.8, 2)
xm, sm = chain(33, lambda x: -0.2 * x * x, 1.0, -1.0, k)
lam = np.ones(xs.shape[1])
t = []
for _ in range(40):
    t0 = time.perf_counter()
    nts.evaluate(xs, ss, xm, sm, lam=lam)
    t.append(time.perf_counter() - t0)
print(json.dumps(1e3 * float(np.median(t))))
"""


def _env(root: str) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = root
    return env


def _call(root: str, k: int) -> float:
    out = subprocess.run([sys.executable, "-c", CALL, str(k)], env=_env(root), check=True,
                         capture_output=True, text=True).stdout
    return float(out.strip().splitlines()[-1])


def _run(root: str, scene: str) -> float:
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        subprocess.run(["skfem-mortar", "run", scene, "--method", "nts", "--out",
                        os.path.join(d, "out"), "--no-progress"], env=_env(root), check=True,
                       capture_output=True, cwd=d)
        return time.perf_counter() - t0


MEASURES = {"nts_line2_ms": lambda r: _call(r, 2), "nts_line3_ms": lambda r: _call(r, 3),
            "patch_nts_s": lambda r: _run(r, "patch"), "slide_nts_s": lambda r: _run(r, "slide")}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json")
    a = ap.parse_args()
    roots = {"before": os.path.abspath(a.before), "after": os.path.abspath(a.after)}
    got = {m: {"before": [], "after": []} for m in MEASURES}
    for r in range(a.repeat):
        order = ["before", "after"] if r % 2 == 0 else ["after", "before"]
        for m, f in MEASURES.items():
            for which in order:
                got[m][which].append(f(roots[which]))
    table = {}
    for m, v in got.items():
        b, c = statistics.median(v["before"]), statistics.median(v["after"])
        table[m] = {"before": b, "after": c, "ratio": c / b, "runs": v}
        print(f"{m:16s} before {b:9.4f}  after {c:9.4f}  ratio {c / b:6.3f}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(table, f, indent=1)


if __name__ == "__main__":
    main()
