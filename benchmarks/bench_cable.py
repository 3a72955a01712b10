"""Time one Newton iteration of an inflated cable: assembly against linear solve.

For pinned cables (``cable_arc`` geometry, L0 = 2.5, span 2, svk law) of
1e3 and 1e5 elements, at the stress-free start arc plus a small perturbation,
the script times

* ``cable``     the Cable's residual and tangent (vectorized kernels, COO triplets),
* ``pressure``  the follower pressure's nodal loads and load stiffness,
* ``model``     the whole ``Model.assemble`` (both above + COO -> CSR),
* ``solve``     the free-dof block and ``solve_linear`` (SuperLU, as in Newton),
* ``newton``    a full one-step solve (from a fresh model) divided by its
  number of Newton iterations (``iterations``),

and prints a table (best of ``--repeat`` runs, seconds).

Usage: ``python benchmarks/bench_cable.py [--sizes 1000 100000] [--repeat 3]``
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from skfem_mortar.bodies.cable import Cable
from skfem_mortar.solver.linsolve import solve_linear
from skfem_mortar.loads.pressure import FollowerPressure
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve


#: Newton tolerance of the full solve (reachable at 1e5 elements since the
#: chords are computed from displacement differences, see Cable._geometry).
RTOL = 1e-10


def best_of(fun, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fun()
        times.append(time.perf_counter() - t0)
    return min(times)


def build(n: int):
    # tension floor 0.1 p a, as in the cable_arc scene (tangent only)
    cable = Cable.between((-1.0, 0.0), (1.0, 0.0), 2.5, n, EA=100.0, law="svk",
                          tension_floor=0.1)
    load = FollowerPressure(cable, 1.0, side="left")
    model = Model([cable, load, Dirichlet(cable, cable.support_dofs())])
    return cable, load, model


def bench(n: int, repeat: int) -> dict:
    cable, load, model = build(n)
    rng = np.random.default_rng(0)
    z = 1e-3 / n * rng.standard_normal(model.n)
    fixed, _ = model.prescribed(1.0)
    free = np.setdiff1d(np.arange(model.n), fixed)
    R, K, _ = model.assemble(z, 1.0)
    out = {"elements": n, "dofs": model.n}
    out["cable"] = best_of(lambda: cable.assemble(z, 1.0), repeat)
    out["pressure"] = best_of(lambda: load.assemble(z, 1.0), repeat)
    out["model"] = best_of(lambda: model.assemble(z, 1.0), repeat)
    out["solve"] = best_of(lambda: solve_linear(K[free][:, free], -R[free]), repeat)

    def full():
        _, _, m = build(n)
        res = solve(m, 1, newton=NewtonOptions(rtol=RTOL))
        return res

    t0 = time.perf_counter()
    res = full()
    wall = time.perf_counter() - t0
    its = sum(s.newton_iterations for s in res.steps)
    out["iterations"] = its
    out["newton"] = wall / max(its, 1)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 100000])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    cols = ["elements", "dofs", "cable", "pressure", "model", "solve", "iterations", "newton"]
    print(" ".join(f"{c:>10s}" for c in cols))
    for n in args.sizes:
        r = bench(n, args.repeat)
        print(" ".join(f"{r[c]:>10d}" if isinstance(r[c], (int, np.integer))
                       else f"{r[c]:>10.2e}" for c in cols))


if __name__ == "__main__":
    main()
