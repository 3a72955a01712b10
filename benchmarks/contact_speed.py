# %%
"""Speed of two checkouts side by side, interleaved, for the contact layer's rewrite
(issue 34): did it leave the speed where it was?

    python benchmarks/contact_speed.py BEFORE_DIR AFTER_DIR [--repeat 5] [--json out.json]

The measures of :mod:`house_speed` (``hertz`` refine=3 one step: time per Newton
iteration; ``skfem-mortar demo`` as a whole process; ``ironing`` with mu = 0.3), run
the same way (a fresh process per measure with ``PYTHONPATH`` set to the checkout,
the checkouts alternating, their order flipped every round), plus a small mortar
call through the method, ``Mortar.evaluate`` with the tangent and ``H``:

- ``mortar_<order>_<kind>_ms``: 25 slave segments on an arc against 33 master
  segments, linear (2-node) or quadratic (3-node) on both sides, standard or dual
  multipliers; the median of 40 calls in one process, the kept evaluation dropped
  before each call (so every call runs the kernel).

Prints the median of ``--repeat`` runs per checkout and their ratio; a ratio above
1.05 is worth re-measuring with ``--repeat 11`` before it counts.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from house_speed import MEASURES as HOUSE, _env  # noqa: E402

CALL = r"""
import json, sys, time, types
import numpy as np
from skfem_mortar.contact.methods import make_method
k, dual = int(sys.argv[1]), sys.argv[2] == "dual"

def chain(n, f, x0, x1):
    xv = np.linspace(x0, x1, n + 1)
    X, seg = [list(xv), list(f(xv))], []
    for i in range(n):
        if k == 3:
            xm = 0.5 * (xv[i] + xv[i + 1])
            X[0].append(xm)
            X[1].append(f(xm))
            seg.append([i, i + 1, n + 1 + i])
        else:
            seg.append([i, i + 1])
    x, seg = np.array(X, float), np.array(seg)
    surf = types.SimpleNamespace(segments=seg, n_nodes=x.shape[1], order=k - 1,
                                 cell="line3" if k == 3 else "line2")
    return x, surf

xs, s = chain(25, lambda x: 0.999 - np.sqrt(1.0 - x * x), -0.3, 0.3)
xm, m = chain(33, lambda x: 0.0 * x, 0.45, -0.45)
meth = make_method("mortar-dual" if dual else "mortar", s, m)
lam = np.linspace(0.5, 1.5, xs.shape[1])
ts = []
for _ in range(41):
    meth._last = None
    t0 = time.perf_counter()
    ev = meth.evaluate(xs, xm, lam, True)
    ts.append(time.perf_counter() - t0)
assert ev.mask.sum() > 20 and ev.H is not None
print(json.dumps(sorted(ts[1:])[20]))
"""


def _mortar_call(k: int, kind: str):
    def measure(checkout: str) -> float:
        out = subprocess.run([sys.executable, "-c", CALL, str(k), kind], env=_env(checkout),
                             capture_output=True, text=True, check=True)
        return 1e3 * json.loads(out.stdout.strip().splitlines()[-1])
    return measure


MEASURES = {**{f"mortar_{name}_{kind}_ms": _mortar_call(k, kind)
               for name, k in (("linear", 2), ("quadratic", 3)) for kind in ("standard", "dual")},
            **HOUSE}


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
    for r in range(args.repeat):
        order = ("before", "after") if r % 2 == 0 else ("after", "before")
        for n in names:
            for side in order:
                times[n][side].append(MEASURES[n](getattr(args, side)))
        print(f"round {r + 1}/{args.repeat} done", file=sys.stderr, flush=True)
    out = {}
    for n in names:
        b, a = (statistics.median(times[n][s]) for s in ("before", "after"))
        out[n] = {"before": b, "after": a, "ratio": a / b, "runs": times[n]}
        print(f"{n:28s} before {b:9.3f}  after {a:9.3f}  after/before {a / b:6.3f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    return out


if __name__ == "__main__":
    main()
