"""Time per Newton iteration by phase on a large scene, one core.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/solver/newton_phases.py \
        [--scene hertz] [--set refine=3] [--method mortar] [--steps 3] \
        [--solver pardiso|superlu] [--symmetric 0|1] [--json out.json] \
        [--linear direct|krylov|auto] [--krylov-max-iter 12] [--forcing-max 1e-2]

Per Newton iteration: ``wall_per_iteration_s`` (the whole ``solve``, its
one-time preflight and start included, over the iterations) and
``newton_loop_per_iteration_s`` (the Newton loops alone).
Phases (seconds per Newton iteration): ``bulk`` (the items' assembly: bodies
and loads), ``contact`` (the contact pairs' assembly, search and pattern hook
included; ``search`` alone), ``tangent_sum`` (the model's sum of the triplets
into its CSR pattern, pattern builds included; ``pattern_builds`` counts
them), ``free_gather`` (``K[free][:, free]``), ``solve`` (the linear solve),
within it for PARDISO ``analysis`` (phase 11, or the whole phase 13 of a
checkout that runs analysis and factorization together), ``factorization``
(phase 23: numerical factorization and solve) and ``refinement`` (phase 33
outside FGMRES).  With ``--linear krylov`` (inexact Newton,
:mod:`skfem_mortar.solver.krylov`): ``krylov`` (the FGMRES runs, their
preconditioner solves with the kept factors included, ``precond`` alone) and
the counts ``factorizations``, ``krylov_iterations``, ``krylov_solves``
(solves answered with kept factors) and ``fallbacks`` summed over the steps'
Newton reports (a checkout without them reports them absent).
Works on this checkout and on an older one (what it lacks is reported as
absent), so that before and after can be compared with the same script.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from collections import defaultdict

import numpy as np

T: dict[str, float] = defaultdict(float)
N: dict[str, int] = defaultdict(int)


def wrap(owner, name, key, count=None):
    """Time every call of ``owner.name`` into ``T[key]``."""
    real = getattr(owner, name, None)
    if real is None:
        return False

    def timed(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return real(*args, **kwargs)
        finally:
            T[key] += time.perf_counter() - t0
            N[key] += 1
    setattr(owner, name, timed)
    return True


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="hertz")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    p.add_argument("--method", default="mortar")
    p.add_argument("--steps", type=int, default=3)
    p.add_argument("--solver", default="pardiso", choices=("pardiso", "superlu"))
    p.add_argument("--symmetric", type=int, default=1, choices=(0, 1))
    p.add_argument("--json")
    p.add_argument("--linear", default="direct", choices=("direct", "krylov", "auto"))
    p.add_argument("--krylov-max-iter", type=int)
    p.add_argument("--forcing-max", type=float)
    a = p.parse_args(argv)
    os.environ["SKFEM_MORTAR_SOLVER"] = a.solver
    os.environ["SKFEM_MORTAR_SYMMETRIC"] = str(a.symmetric)

    from skfem_mortar.app.runner import build_scene
    from skfem_mortar.core import model as model_mod
    from skfem_mortar.core import timing
    from skfem_mortar.solver import linsolve, newton, stepping
    try:  # the PARDISO instance in its own module (before: in linsolve)
        from skfem_mortar.solver import pardiso as pardiso_mod
    except ImportError:
        pardiso_mod = linsolve
    from skfem_mortar.solver.stepping import solve

    params = {}
    for kv in a.set:
        k, v = kv.split("=", 1)
        params[k] = v
    t0 = time.perf_counter()
    setup, values, method = build_scene(a.scene, params, a.method)
    model = setup.model
    t_build = time.perf_counter() - t0

    wrap(model_mod.Model, "_tangent", "tangent_sum")
    has_gather = wrap(model_mod.Model, "free_block", "free_gather")
    wrap(newton, "solve_linear", "solve")
    reports = []
    inside = {"fgmres": 0}
    krylov_mod = None
    if a.linear != "direct" or a.krylov_max_iter or a.forcing_max:
        from dataclasses import replace

        from skfem_mortar.solver import krylov as krylov_mod
        extra = {k: v for k, v in (("linear", a.linear), ("krylov_max_iter", a.krylov_max_iter),
                                   ("forcing_max", a.forcing_max)) if v is not None}
        base = setup.solve_options.get("newton") or newton.NewtonOptions()
        setup.solve_options["newton"] = replace(base, **extra)
        wrap(krylov_mod.KrylovSolver, "solve", "solve")
        wrap(krylov_mod, "fgmres", "krylov")
        real_fgmres = krylov_mod.fgmres

        def fgmres(*args, **kwargs):  # the phase 33 runs inside are the preconditioner's
            inside["fgmres"] += 1
            try:
                return real_fgmres(*args, **kwargs)
            finally:
                inside["fgmres"] -= 1
        krylov_mod.fgmres = fgmres
    real_step = stepping.newton_step

    def step(*args, **kwargs):
        t = time.perf_counter()
        rep = real_step(*args, **kwargs)
        T["newton_loop"] += time.perf_counter() - t
        reports.append(rep)
        return rep
    stepping.newton_step = step
    pardiso_cls = getattr(pardiso_mod, "_Pardiso", None)
    if pardiso_cls is not None:
        real_run = pardiso_cls._run

        def run(self, A, b, phase):
            t = time.perf_counter()
            try:
                return real_run(self, A, b, phase)
            finally:
                key = {11: "analysis", 13: "analysis+factorization", 22: "factorization",
                       23: "factorization", 33: "refinement"}.get(phase, f"phase{phase}")
                if phase == 33 and inside["fgmres"]:
                    key = "precond"
                T[key] += time.perf_counter() - t
                N[key] += 1
        pardiso_cls._run = run
    search = {"t": 0.0}
    if hasattr(timing, "timed"):
        real_timed = timing.timed

        class _Timed:
            def __init__(self, name):
                self.name, self.inner = name, real_timed(name)

            def __enter__(self):
                self.t = time.perf_counter()
                return self.inner.__enter__()

            def __exit__(self, *exc):
                if self.name == "search":
                    search["t"] += time.perf_counter() - self.t
                return self.inner.__exit__(*exc)
        for mod in list(sys.modules.values()):
            if getattr(mod, "timed", None) is real_timed and mod is not timing:
                mod.timed = _Timed

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        res = solve(model, a.steps, **setup.solve_options)
        wall = time.perf_counter() - t0
    its = max(1, sum(s.newton_iterations for s in res.steps))
    # the K[free][:, free] of a checkout without free_block is inside newton: time it once
    if not has_gather:
        z = res.z
        R, K, _ = model.assemble(z, 1.0)
        fixed, _ = model.prescribed(1.0)
        free = np.setdiff1d(np.arange(model.n), fixed)
        t = time.perf_counter()
        K[free][:, free]
        T["free_gather"] = (time.perf_counter() - t) * N["solve"]
    tangent_calls = max(1, N["tangent_sum"])
    out = {"scene": a.scene, "params": params, "method": method, "solver": a.solver,
           "symmetric": bool(a.symmetric), "n_dofs": model.n, "steps": len(res.steps),
           "iterations": its, "converged": res.converged, "build_s": t_build,
           "wall_per_iteration_s": wall / its,
           # the Newton loops alone (the solve's one-time preflight and start left out)
           "newton_loop_per_iteration_s": T["newton_loop"] / its,
           "per_iteration_s": {
               "bulk": (model.timers["bulk"] - T["tangent_sum"]) / its,
               "contact": model.timers["contact"] / its,
               "search": search["t"] / its,
               "tangent_sum": T["tangent_sum"] / its,
               "free_gather": T["free_gather"] / its,
               "solve": T["solve"] / its,
               **{k: T[k] / its for k in ("analysis", "analysis+factorization",
                                          "factorization", "refinement", "krylov",
                                          "precond") if N[k]}},
           "counts": {"tangent_calls": tangent_calls, "solves": N["solve"],
                      "pattern_builds": getattr(model, "pattern_builds", None),
                      **{k: N[k] for k in ("analysis", "analysis+factorization",
                                           "factorization", "refinement", "precond") if N[k]}},
           "linear": a.linear,
           "newton": {k: sum(getattr(r, k, 0) for r in reports) if all(
               hasattr(r, k) for r in reports) else "absent"
               for k in ("factorizations", "krylov_iterations", "krylov_solves", "fallbacks")}}
    # nonzeros of the last factor (iparm(18)) and perturbed pivots (iparm(14))
    handles = dict(getattr(pardiso_mod, "_pardiso_solvers", {}))
    if getattr(linsolve, "_pardiso_solver", None) is not None:
        handles[11] = linsolve._pardiso_solver
    out["pardiso_factors"] = {str(m): {"factor_nnz": int(h.solver.get_iparm(18)),
                                       "perturbed_pivots": int(h.solver.get_iparm(14))}
                              for m, h in handles.items()}
    print(json.dumps(out, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)
    return out


if __name__ == "__main__":
    main()
