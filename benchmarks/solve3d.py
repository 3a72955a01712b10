"""Where does the direct solver stop paying in 3D?  Time per Newton iteration, its
phases and the linear solvers side by side on the block3d scene (issue 36).

    pip install pyamg   # for the smoothed-aggregation column; not a dependency
    python benchmarks/solve3d.py [--elements tet1,hex1] [--dofs 1e4,1e5,3e5] \
        [--superlu-max 3e4] [--json solve3d.json]

For each element and target size (the cube of ``block3d`` at small strain, ``n``
cells a side with ``3 (n + 1)^3`` dofs closest to the target), two fresh
processes (so that each peak resident memory, ``ru_maxrss``, is its own):

1. **Newton**: ``run_scene("block3d", kinematics=small, one step)``, the package's
   own path (its default linear solver): build time, and per Newton iteration
   the bulk assembly and the linear solve (the summary's phase timers), the
   peak memory of the whole run.
2. **Solvers** on the same free system ``K_ff`` (the model's tangent without the
   prescribed dofs): PARDISO as symmetric positive definite (``mtype=2``, one
   thread per core): the factor's nonzeros (``iparm(18)``), its peak memory
   (``iparm(15..17)``), analysis + factorization and solve times; SciPy's
   SuperLU up to ``--superlu-max`` dofs (its fill ``nnz(L) + nnz(U)``); conjugate
   gradients preconditioned by one V-cycle of smoothed aggregation (pyamg) with
   the six rigid modes as near-null space, to a relative residual of 1e-8:
   setup, iterations, time.  The peak memory of this process is reported too.

Prints one row per size; ``--json`` writes the rows.

Measured 2026-12-06 on the 2-core, 24 GiB machine, shared: load average 5 to 10
during the tet1 rows, about 1 for hex1 at 2.9e5 (times of a loaded row are up to 3x
long).  Newton: one iteration of the package (bulk assembly / linear solve, s) and
its run's peak memory; PARDISO: SPD factorization (s), the factor's nonzeros and
memory; SA-CG: setup + iterations to 1e-8 (s, iterations)::

    element  dofs    Newton it.      peak    PARDISO factor        SA-CG
    tet1     1.0e4    1.0 /  0.40    0.3 GB    0.36 s 2.9e6  0.03 GB   0.36 + 0.37 (11)
    tet1     9.8e4   15.3 / 17.3     2.4 GB   29.8  s 7.8e7  0.70 GB  11.2  + 5.9  (16)
    tet1     2.9e5   23.9 / 80.9     7.0 GB  111    s 3.7e8  3.1  GB  10.4  + 5.6  (18)
    hex1     1.0e4    0.77 / 0.31    0.3 GB    0.30 s 3.3e6  0.04 GB   0.15 + 0.05 (9)
    hex1     9.8e4    9.7 /  7.7     2.5 GB   14.3  s 8.6e7  0.81 GB   4.7  + 2.3  (8)
    hex1     2.9e5   26.6 / 39.3     7.6 GB   34.9  s 4.0e8  3.5  GB   6.1  + 2.5  (9)

SuperLU at 1e4 dofs: 2.1 s (fill 7.7e6 tet1, 1.1e7 hex1), 6x PARDISO.  The factor
grows as dofs^1.3 (nnz(L) 3.3e6 -> 8.6e7 -> 4.0e8), the AMG iterations stay at 8 to
18: at 1e4 dofs both take 0.3 s; at 1e5 SA-CG is 2x faster (hex1 7 s against 14 s);
at 3e5 4x (hex1 8.6 s against 35 s; tet1 16 s against 111 s, loaded), and the
factor alone holds 3.5 GB, so near 1e6 dofs it would outgrow the 12 GB a run may
take.  A direct factorization stops paying from about 1e5 dofs for one solve;
kept factors (``linear="krylov"``) amortize it over Newton iterations, which
moves that point up but not the memory wall.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time

_NEWTON = r"""
import json, resource, sys, time
t0 = time.perf_counter()
from skfem_mortar.app.runner import run_scene
spec = json.loads(sys.argv[1])
s = run_scene("block3d", spec, steps=1)
its = sum(st["newton_iterations"] for st in s["steps"])
t = s["phase_times_s"]
print(json.dumps({"n_dofs": s["n_dofs"], "newton_iterations": its,
                  "wall_s": s["wall_time_s"], "bulk_per_it_s": t["bulk"] / its,
                  "solve_per_it_s": t["solve"] / its,
                  "error": s["metrics"]["max_displacement_error"],
                  "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""

_SOLVERS = r"""
import json, resource, sys, time
import numpy as np, scipy.sparse as sp, scipy.sparse.linalg as sla
from skfem_mortar.app.runner import build_scene
spec = json.loads(sys.argv[1])
setup, _, _ = build_scene("block3d", spec["params"], None)
model = setup.model
z = model.zeros()
t0 = time.perf_counter()
R, K, _ = model.assemble(z, 1.0)
t_asm = time.perf_counter() - t0
fixed, values = model.prescribed(1.0)
free = np.setdiff1d(np.arange(K.shape[0]), fixed)
z[fixed] = values
R, _, _ = model.assemble(z, 1.0, tangent=False)
A = K[free][:, free].tocsr()
b = -R[free]
out = {"n_free": int(free.size), "nnz_K": int(A.nnz), "assemble_s": t_asm}
import pypardiso
ps = pypardiso.PyPardisoSolver(mtype=2)
ps.set_iparm(18, -1)
t0 = time.perf_counter()
ps.factorize(sp.triu(A, format="csr"))
out["pardiso_factor_s"] = time.perf_counter() - t0
t0 = time.perf_counter()
x = ps.solve(sp.triu(A, format="csr"), b)
out["pardiso_solve_s"] = time.perf_counter() - t0
out["pardiso_residual"] = float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))
out["pardiso_nnz_L"] = int(ps.get_iparm(18))
out["pardiso_peak_mb"] = max(int(ps.get_iparm(15)), int(ps.get_iparm(16)) + int(ps.get_iparm(17))) / 1024
ps.free_memory(everything=True)
if free.size <= spec["superlu_max"]:
    t0 = time.perf_counter()
    lu = sla.splu(A.tocsc())
    out["superlu_factor_s"] = time.perf_counter() - t0
    out["superlu_fill"] = int(lu.L.nnz + lu.U.nnz)
    del lu
try:
    import pyamg
except ImportError:
    pyamg = None
if pyamg is not None:
    body = model.bodies[0]
    X = body.basis.doflocs
    c = body.dof_component
    B = np.zeros((body.basis.N, 6))
    for k in range(3):
        B[c == k, k] = 1.0                                # translations
    for k, (i, j) in enumerate(((0, 1), (1, 2), (2, 0))):  # rotations about z, x, y
        B[c == i, 3 + k] = -X[j, c == i]
        B[c == j, 3 + k] = X[i, c == j]
    t0 = time.perf_counter()
    ml = pyamg.smoothed_aggregation_solver(A, B=B[free], symmetry="symmetric")
    out["amg_setup_s"] = time.perf_counter() - t0
    res = []
    t0 = time.perf_counter()
    x2 = ml.solve(b, tol=1e-8, accel="cg", maxiter=500, residuals=res)
    out["amg_cg_s"] = time.perf_counter() - t0
    out["amg_iterations"] = len(res) - 1
    out["amg_residual"] = float(np.linalg.norm(A @ x2 - b) / np.linalg.norm(b))
out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps(out))
"""


def cells_for(dofs: float) -> int:
    """``n`` with ``3 (n + 1)^3`` closest to ``dofs``."""
    return max(1, round((dofs / 3.0) ** (1.0 / 3.0)) - 1)


def _child(code: str, spec: dict) -> dict:
    proc = subprocess.run([sys.executable, "-c", code, json.dumps(spec)], capture_output=True,
                          text=True)
    if proc.returncode:
        return {"status": "failed: " + (proc.stderr.strip().splitlines() or ["?"])[-1]}
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--elements", default="tet1,hex1")
    ap.add_argument("--dofs", default="1e4,1e5,3e5")
    ap.add_argument("--superlu-max", type=float, default=3e4)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    rows = []
    for element in args.elements.split(","):
        for target in (float(d) for d in args.dofs.split(",")):
            params = {"element": element, "n": cells_for(target), "kinematics": "small",
                      "law": "linear", "mode": "stretch", "distort": 0.0}
            t0 = time.perf_counter()
            newton = _child(_NEWTON, params)
            solvers = _child(_SOLVERS, {"params": params, "superlu_max": args.superlu_max})
            row = {"element": element, "n": params["n"], "newton": newton, "solvers": solvers,
                   "total_s": time.perf_counter() - t0}
            rows.append(row)
            print(json.dumps(row), flush=True)
            if args.json:
                with open(args.json, "w") as f:
                    json.dump(rows, f, indent=1)
    return rows


if __name__ == "__main__":
    main()
