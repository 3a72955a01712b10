"""Time per Newton iteration by phase on a 3D contact model (issue 38, "Measure and
report"): bulk assembly, contact search, contact evaluation, linear solve, the rest.

    python benchmarks/phases3d.py [--dofs 1e5 3e5] [--methods nts mortar mortar-dual]
        [--steps 2] [--json phases3d.json]

The model: two stacked hex1 blocks (``blocks3d.py``: patch3d's bodies, finite strain,
the upper block's bottom the slave on the lower block's covered top, non-matching
grids ``n_upper = 0.8 n_lower``) of about ``--dofs`` displacement dofs, pressed in
``--steps`` load steps, solved by the package's Newton with the direct solver on
PARDISO (``pypardiso``; ``SKFEM_MORTAR_SOLVER=pardiso``).  One fresh process per
size and method, so that the peak resident memory (``ru_maxrss``) is the run's own.

One thread (MKL, OpenMP, BLAS) and, by default (``--clock cpu``), every timer of the
package reading the process's CPU time (``time.perf_counter`` replaced by
``time.process_time`` in the run's process): on shared cores the wall clock of a run
grows with the other processes' load (measured: 101 s per iteration at 1e5 dofs at a
load average of 14 on 2 cores), its CPU time does not; ``--clock wall`` times the wall.

Phases (the model's item timers and the named timers of ``core.timing``, as the
runner's summary reports them), summed over the run and divided by its Newton
iterations (each iteration assembles once; every step assembles once more for its
last residual check, so the assembly phases per iteration include that share):

* bulk assembly: the bodies' and loads' triplets and the global sum into CSR;
* contact search: the candidate boxes (``search`` timer);
* contact evaluation: the pair's assembly without its search (gaps, G, H, the
  active set, the multiplier rows);
* linear solve: the free block's factorization and solve (``Result.solve_time``);
* the rest: the solve's wall clock minus the above (the free block's extraction,
  convergence tests, line search, the step controller, state copies).

Prints a Markdown table; ``--json`` writes the rows.

Measured 2026-12-06 on the 2 shared cores (load average 11 to 14; CPU clock), seconds
per Newton iteration (2 steps, 3 + 3 iterations in every run)::

    method       dofs     bulk   search  contact  solve   rest    total   peak RSS
    nts          9,456    0.118  0.006    0.025   0.192   0.040   0.38    0.4 GB
    mortar       9,456    0.124  0.009    4.17    0.298   0.078   4.68    1.0 GB
    mortar-dual  9,456    0.121  0.009    4.38    0.397   0.070   4.98    1.0 GB
    nts          106,518  1.95   0.019    0.12    17.6    0.38    20      3.9 GB

Mortar at 1.07e5 dofs (784 slave faces; 2026-12-06, main d0b2e08 with the n_gauss check,
mortar-dual also with the kernel's distinct-dofs scatter of issue 34; one thread, load
average 5 to 8; the same runs with the memory sampled by phase), seconds per Newton
iteration (3 + 3 iterations; contact includes its search, rest includes the build; the
contact is 34 and 65 ms per slave face and evaluation)::

    method       dofs     bulk   contact  solve   rest    total   peak RSS
    mortar       106,518  3.05   35.5     25.9    1.4     65.9    5.9 GB
    mortar-dual  106,518  3.14   67.9     28.0    1.4     100.5   5.8 GB

Where the resident memory rose (GB; each rise of the RSS, sampled every 20 ms, booked to
the phase running), and PARDISO's LU (the follower pressure makes the tangent
unsymmetric, ``mtype`` 11)::

    method       dofs     build  bulk  contact  global sum  solve  factor nonzeros  factor  analysis peak
    mortar       106,518  0.92   0.69  0.65     1.64        1.94   2.14e8           2.35    2.35
    mortar-dual  106,518  0.92   0.69  0.64     1.64        1.88   2.06e8           2.36    2.36

The peak (5.9 GB) is reached in a global sum while PARDISO still holds the last LU (2.35
GB, ``iparm(16) + iparm(17)``): the contact triplets are not where the memory goes (the
pair's Python-side peak is 69 MiB at 144 slave faces, tracemalloc).  Releasing the LU
after each direct solve (phase 0) left the peak where it was at 2.3e4 dofs (1.03 GB
either way; the freed memory is not handed back to the system), so it is not done.  With
``--load dead`` the tangent is symmetric but for the contact rows and PARDISO factors the
symmetrized system: at 23,223 dofs (mortar) 1.16e7 factor nonzeros against 2.68e7, 0.10
against 0.23 GB, 4.7 against 10.3 s of solve over 6 iterations; above ``SINGLE_ABOVE``
(5e4) unknowns in single precision, half again.

The solver's choices on NTS at 30,957 dofs (3 + 3 iterations; factor nonzeros, factor GB,
solve seconds per iteration, peak RSS): the LU (follower load) 3.08e7, 0.34 GB, 1.67 s,
1.1 GB; ``--load dead``, symmetrized in double 1.83e7, 0.20 GB, 1.24 s, 1.0 GB, and in
single precision (``SKFEM_MORTAR_SINGLE_ABOVE=0``) 1.83e7, 0.12 GB, 0.81 s, 0.9 GB.

At 3.1e5 dofs (``n_lower`` 50, 313,824 dofs, 1,600 slave faces; ``--load dead --steps
1``, 4 iterations; CPU clock; mortar-dual with the other core busy with the test suite,
so its times are upper bounds), seconds per Newton iteration::

    method       dofs     bulk   search  contact  solve   rest    total   peak RSS
    nts          313,824  6.02   0.038   0.236    37.3    1.62    45.3    8.5 GB
    mortar-dual  313,824  8.22   0.472   166      198     2.72    376     16.6 GB
    mortar       313,824  7.52   0.347    80.7    117     2.71    208     16.6 GB

(standard mortar run later, alone on one core, 14 min of wall clock.)  PARDISO's factor,
all three on the single-precision symmetric instance (the run's JSON names it,
``(-2, 'single')``): NTS 4.5e8 nonzeros, 2.23 GB; mortar-dual 5.1e8, 3.64 GB (analysis
peak 1.43 GB); mortar 5.1e8, 3.73 GB (1.47).  (An earlier reading of mortar-dual's 7
bytes a nonzero as a double-precision factor was wrong: ``iparm(16) + iparm(17)`` holds
more than the factor's values.)  The two mortar solves take 3 to 5 times NTS's for a
factor of nearly the same size; the JSON now counts each instance's analyses,
factorizations and solves.  At 4e4 dofs (``n_lower`` 24, dead load, 4 iterations, double
precision) NTS made 1 analysis (solve 3.65 s, factor 2.26e7 nonzeros), mortar and
mortar-dual 2 (6.91 and 7.76 s, 2.68e7 and 2.60e7): a mortar pair's pattern widens after
its first iteration, and the second symbolic analysis with the larger factor makes about
2x; at 3.1e5 the counts were not taken.  mortar-dual's
memory rose in the build 2.33 GB, bulk 2.03, contact 3.32, global sum 5.89, solve 2.92
(mortar's within 0.02 GB of these): the peak is again a global sum on top of the held
LU.  The contact is 104 ms (dual) and 50 ms (standard) per slave face and iteration (87
for dual at 1.07e5).  With the follower load (the LU) the factor would be about 13 GB
(the LU's growth ``n^1.56`` from 3.1e4 to 1.07e5 dofs), past the machine with the model.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

_RUN = r"""
import json, os, resource, sys, threading, time
sys.path.insert(0, sys.argv[2])
spec = json.loads(sys.argv[1])
if spec["clock"] == "cpu":       # every timer of the package reads the process's CPU time
    time.perf_counter = time.process_time
from blocks3d import blocks_model, blocks_params
import skfem_mortar.core.model as core_model
import skfem_mortar.solver.newton as newton
from skfem_mortar.core.timing import TIMERS, reset
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve
PAGE, now, grew, top = os.sysconf("SC_PAGE_SIZE"), ["build"], {}, [0.0]
def sample():                    # RSS every 20 ms; each rise is the running phase's
    while True:
        with open("/proc/self/statm") as f:
            r = int(f.read().split()[1]) * PAGE / 2**30
        if r > top[0]:
            grew[now[0]] = grew.get(now[0], 0.0) + r - top[0]
            top[0] = r
        time.sleep(0.02)
threading.Thread(target=sample, daemon=True).start()
def phase(obj, name, label):
    f = getattr(obj, name)
    def g(*a, **k):
        last, now[0] = now[0], label
        try:
            return f(*a, **k)
        finally:
            now[0] = last
    setattr(obj, name, g)
t0 = time.perf_counter()
params = blocks_params(n_lower=spec["n_lower"], n_upper=spec["n_upper"])
model, pair, parts = blocks_model(params, spec["method"], spec["load"])
model.timers.clear(); reset()
t_build = time.perf_counter() - t0
now[0] = "rest"
for it in model.items:
    phase(it, "assemble", "contact" if it is pair else "bulk")
phase(core_model.Model, "_tangent", "global sum")
phase(core_model.Model, "free_block", "free block")
phase(newton, "solve_linear", "solve")
t0 = time.perf_counter()
res = solve(model, spec["steps"], newton=NewtonOptions(linear="direct"))
wall = time.perf_counter() - t0
its = [s.newton_iterations for s in res.steps]
tm = dict(model.timers)
search = TIMERS.get("search", 0.0)
phases = {"bulk": tm.get("bulk", 0.0) + tm.get("loads", 0.0),
          "search": search, "contact": tm.get("contact", 0.0) - search,
          "solve": res.solve_time}
phases["rest"] = wall - sum(phases.values())
n = sum(its)
from skfem_mortar.solver.pardiso import _pardiso_solvers
fill = {str(k): {"factor_nonzeros": int(h.solver.get_iparm(18)),
                 "factor_gb": (h.solver.get_iparm(16) + h.solver.get_iparm(17)) / 2**20,
                 "analysis_peak_gb": h.solver.get_iparm(15) / 2**20,
                 "analyses": h.analyses, "factorizations": h.factorizations,
                 "solves": h.solves}
        for k, h in _pardiso_solvers.items()}
print(json.dumps({"method": spec["method"], "load": spec["load"], "n_lower": spec["n_lower"],
                  "n_upper": spec["n_upper"], "n_dofs": int(model.n_u),
                  "n_multipliers": int(model.n_lam), "converged": bool(res.converged),
                  "iterations": its, "build_s": t_build, "wall_s": wall,
                  "per_iteration_s": {k: v / n for k, v in phases.items()},
                  "timers": tm, "slave_faces": int(len(pair.slave.segments)),
                  "rss_growth_gb": grew, "pardiso": fill,
                  "peak_rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20}))
"""

PHASES = ("bulk", "search", "contact", "solve", "rest")

#: one thread for MKL (PARDISO), OpenMP and BLAS: the CPU clock is then the time of
#: the one core a run gets
ONE_THREAD = {k: "1" for k in ("MKL_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS")}


def run(n_lower: int, n_upper: int, method: str, steps: int, clock: str = "cpu",
        load: str = "follower") -> dict:
    """One fresh process: the model of ``n_lower``/``n_upper`` cells solved by ``method``
    (``clock``: ``cpu`` or ``wall``; ``load``: :func:`blocks3d.blocks_model`'s)."""
    spec = json.dumps({"n_lower": n_lower, "n_upper": n_upper, "method": method,
                       "steps": steps, "clock": clock, "load": load})
    env = {**os.environ, "SKFEM_MORTAR_SOLVER": "pardiso", **ONE_THREAD}
    out = subprocess.run([sys.executable, "-c", _RUN, spec, HERE], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def table(rows: list[dict]) -> str:
    """The Markdown table of ``rows``: seconds per Newton iteration by phase."""
    head = ("| method | dofs | multipliers | slave faces | iterations per step | "
            + " | ".join(PHASES) + " | total per it. [s] | peak RSS [GB] |\n|"
            + "---|" * (len(PHASES) + 7) + "\n")
    lines = []
    for r in rows:
        p = r["per_iteration_s"]
        tot = sum(p.values())
        cells = " | ".join(f"{p[k]:.3g} ({100 * p[k] / tot:.0f} %)" for k in PHASES)
        lines.append(f"| {r['method']} | {r['n_dofs']:,} | {r['n_multipliers']:,} | "
                     f"{r['slave_faces']:,} | {'+'.join(map(str, r['iterations']))} | "
                     f"{cells} | {tot:.3g} | {r['peak_rss_gb']:.1f} |")
    return head + "\n".join(lines) + "\n"


MEMORY = ("build", "bulk", "contact", "global sum", "free block", "solve", "rest")


def memory_table(rows: list[dict]) -> str:
    """The Markdown table of where the resident memory rose (GB, module docstring) and
    PARDISO's factor: its nonzeros and memory (``iparm(16) + iparm(17)``) and the
    analysis' peak (``iparm(15)``)."""
    head = ("| method | dofs | " + " | ".join(MEMORY) + " | factor nonzeros | factor [GB] | "
            "analysis peak [GB] | peak RSS [GB] |\n|" + "---|" * (len(MEMORY) + 6) + "\n")
    lines = []
    for r in rows:
        g = r["rss_growth_gb"]
        f = max(r["pardiso"].values(), key=lambda v: v["factor_nonzeros"], default=None)
        pf = (f"{f['factor_nonzeros']:,} | {f['factor_gb']:.2f} | {f['analysis_peak_gb']:.2f}"
              if f else "- | - | -")
        lines.append(f"| {r['method']} | {r['n_dofs']:,} | "
                     + " | ".join(f"{g.get(k, 0.0):.2f}" for k in MEMORY)
                     + f" | {pf} | {r['peak_rss_gb']:.1f} |")
    return head + "\n".join(lines) + "\n"


def main(argv=None) -> int:
    sys.path.insert(0, HERE)
    from blocks3d import sizes_for
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dofs", type=float, nargs="+", default=[1e5, 3e5])
    ap.add_argument("--methods", nargs="+", default=["nts", "mortar", "mortar-dual"])
    ap.add_argument("--steps", type=int, default=2)
    ap.add_argument("--clock", choices=("cpu", "wall"), default="cpu")
    ap.add_argument("--load", choices=("follower", "dead"), default="follower")
    ap.add_argument("--json")
    a = ap.parse_args(argv)
    if a.steps < 1:
        raise ValueError(f"--steps must be >= 1, got {a.steps}")
    rows = []
    for dofs in a.dofs:
        n_lower, n_upper = sizes_for(dofs)
        for method in a.methods:
            rows.append(run(n_lower, n_upper, method, a.steps, a.clock, a.load))
            print(table(rows[-1:]) + memory_table(rows[-1:]), flush=True)
            if a.json:
                with open(a.json, "w") as f:
                    json.dump(rows, f, indent=1)
    print(table(rows))
    print(memory_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
