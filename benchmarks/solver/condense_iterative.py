"""What a condensed or an iterative linear solve would cost against the present
direct solve, on a Newton system of hertz (one step, its last tangent), one core.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/solver/condense_iterative.py \
        [--refine 3] [--method mortar-dual] [--repeat 3] [--json out.json]

Three solves of the same system (medians of ``--repeat`` where timed twice):

* ``direct``: the package's solve (``solve_linear`` with the multiplier rows:
  the symmetrized saddle point, PARDISO symmetric indefinite, in single
  precision refined in double above ``SINGLE_ABOVE`` unknowns), once with a
  fresh analysis and once reusing it (what a Newton iteration pays);
* ``condensed``: the null-space condensation of the active multipliers
  (:func:`condensed`): how far the pivot columns of the constraint rows are
  from diagonal (``condensed_offdiagonal_ratio``: the largest off-diagonal
  row sum over the diagonal), the time to form ``C = Z^T A Z`` with scipy,
  and PARDISO's Cholesky (mtype 2) of ``C`` in double and in single
  precision and its LDL^T (mtype -2, the present solve's settings) in single
  (analysis + factorization + solve, the factorization alone, and the
  relative residual of the answer before any refinement);
* ``amg``: the preconditioner of ``amg_newton.py`` (this folder), a fresh
  hierarchy, and FGMRES on the system to 1e-2 (a first inexact Newton
  solve) and to 1e-8, setup and solve apart.

pyamg is not a dependency of the package: ``pip install pyamg`` for this script.

Measured (2026-12-04, one core, mortar-dual, the last tangent of the step):

======================================  ============  =============
                                        refine=2      refine=3
======================================  ============  =============
unknowns (active multipliers)           4.7e4 (223)   1.7e5 (306)
direct, kept analysis                   0.08-0.14 s   0.30-0.33 s
condensed: off-diagonal of ``G_N``      7.9e-8        1.4e-7
condensed: forming ``Z^T A Z``          0.015-0.02 s  0.07 s
condensed: Cholesky, double             0.16-0.23 s   0.89 s
  (analysis + factorization + solve)
condensed: factorization alone          0.06-0.10 s   0.40 s
condensed: Cholesky, single             fails (-4)    fails (-4)
condensed: LDL^T single, factorization  0.05 s        0.27-0.29 s
  (its residual before refinement)      (2e-3)        (6e-3)
amg: setup                              0.18 s        0.52 s
amg: FGMRES to 1e-2 (iterations)        0.06 s (5)    0.20 s (7)
amg: FGMRES to 1e-8 (iterations)        0.42 s (38)   1.45 s (46)
======================================  ============  =============

The pivot columns are diagonal to 1e-7 (dual shape functions), so the
condensation would need no reformulated kernel; but its factorization alone
costs as much as the present solve with a kept analysis, the forming adds to
it, and the single-precision Cholesky that would halve it fails (the
condensed matrix is not positive definite to single precision); the
single-precision LDL^T factors it in as long as the present solve factors
and refines the whole saddle point (0.27-0.29 s against 0.30-0.33 s), and
its answer still needs refining from 6e-3.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # amg_newton


def capture(refine: int, method: str):
    """The last Newton system of hertz in one step and the bodies' rigid modes on
    its free displacement unknowns (``amg_newton.rigid_modes``)."""
    from amg_newton import rigid_modes  # (this folder)
    from skfem_mortar.app.runner import build_scene
    from skfem_mortar.solver import newton
    from skfem_mortar.solver.stepping import solve

    setup, _, _ = build_scene("hertz", {"refine": refine}, method)
    model = setup.model
    caps, frees = [], []
    real, real_block = newton.solve_linear, model.free_block

    def keep(K, b, **kw):
        caps.append((K.tocsr(), b.copy(), kw.get("multipliers")))
        return real(K, b, **kw)

    def block(K, free):
        frees.append(free.copy())
        return real_block(K, free)
    newton.solve_linear, model.free_block = keep, block
    try:
        solve(model, 1, **setup.solve_options)
    finally:
        newton.solve_linear = real
        del model.free_block
    K, b, mult = caps[-1]
    return K, b, mult, rigid_modes(model, frees[-1])


def condensed(K, b, mult, repeat: int) -> dict:
    """The null-space condensation of the active multipliers: per active row its
    pivot (the displacement unknown of its largest value), ``D`` the diagonal
    of the pivot columns (``G_N``; its off-diagonal part, relative, is
    reported), ``x_piv = -D^-1 G_R x_R`` and ``C = Z^T A Z``; PARDISO's Cholesky
    of ``C`` in double and in single precision, and its LDL^T in single."""
    from skfem_mortar.solver import linsolve, pardiso
    sym = linsolve.symmetrize(K, b, mult)
    U = sym.U
    S = (U + U.T - sp.diags(U.diagonal())).tocsr()
    u, m = np.flatnonzero(~mult), np.flatnonzero(mult)
    A = S[u][:, u].tocsr()
    G = S[m][:, u].tocsr()
    G = G[np.asarray(abs(G).sum(axis=1)).ravel() > 0].tocsr()
    piv = np.array([G.indices[G.indptr[i]:G.indptr[i + 1]][
        np.argmax(abs(G.data[G.indptr[i]:G.indptr[i + 1]]))] for i in range(G.shape[0])])
    GN = G[:, piv].toarray()
    d = np.diag(GN).copy()
    res = {"condensed_pivots_unique": bool(np.unique(piv).size == piv.size),
           "condensed_offdiagonal_ratio": float(
               (np.abs(GN - np.diag(d)).sum(axis=1) / np.abs(d)).max())}
    n = A.shape[0]
    R = np.setdiff1d(np.arange(n), piv)

    def form():
        Zp = -(sp.diags(1.0 / d) @ G[:, R])
        Z = sp.vstack([sp.identity(R.size, format="csr"), Zp]).tocsr()
        order = np.concatenate([R, piv])
        P = sp.csr_matrix((np.ones(n), (order, np.arange(n))), shape=(n, n))
        Zf = (P @ Z).tocsr()
        return (Zf.T @ A @ Zf).tocsr()
    C = form()
    res["condensed_form_s"] = median_time(form, repeat)
    upper = sp.triu(C, format="csr")
    upper.sort_indices()
    rhs = np.ones(C.shape[0])
    for mtype, single in ((2, False), (2, True), (-2, True)):
        chol = pardiso._Pardiso(mtype, single)
        key = ("condensed_cholesky_" if mtype == 2 else "condensed_ldlt_") + (
            "single" if single else "double")

        def run():
            chol.release()
            for phase in (11, 23):
                chol._run(upper, rhs, phase)
        try:
            res[key + "_s"] = median_time(run, repeat)
            chol.release()
            chol._run(upper, rhs, 11)
            t = time.perf_counter()
            x = chol._run(upper, rhs, 23)
            res[key + "_factorization_s"] = time.perf_counter() - t
            res[key + "_residual"] = float(np.linalg.norm(C @ x - rhs) / np.linalg.norm(rhs))
        except Exception as exc:  # noqa: BLE001 (PyPardisoError -4: not positive definite)
            res[key + "_s"] = f"failed: {exc}"
        chol.release()
    return res


def iterative(K, b, mult, modes) -> dict:
    """``amg_newton.py``'s preconditioned FGMRES on ``K`` (a fresh hierarchy) to
    1e-2 and 1e-8, setup apart; ``modes`` on the free displacement unknowns."""
    from amg_newton import AlPreconditioner  # (this folder)
    from skfem_mortar.solver import linsolve
    from skfem_mortar.solver.krylov import fgmres
    sym = linsolve.symmetrize(K, b, mult)
    res = {}
    t = time.perf_counter()
    pre = AlPreconditioner(K, mult, modes)
    res["amg_setup_s"] = time.perf_counter() - t
    for tol in (1e-2, 1e-8):
        t = time.perf_counter()
        got = fgmres(K, b, lambda r: pre.apply(sym.transform(r)), tol, 300)
        res[f"amg_fgmres_{tol:g}_s"] = time.perf_counter() - t
        res[f"amg_fgmres_{tol:g}_iterations"] = got.iterations
    return res


def median_time(f, repeat: int) -> float:
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--refine", type=int, default=3)
    p.add_argument("--method", default="mortar-dual")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--json")
    a = p.parse_args(argv)
    from skfem_mortar.solver import linsolve

    K, b, mult, modes = capture(a.refine, a.method)
    out: dict = {"refine": a.refine, "method": a.method, "unknowns": int(K.shape[0]),
                 "multipliers": int(mult.sum())}

    def fresh():
        linsolve.forget_analyses()
        linsolve.solve_linear(K, b, multipliers=mult)
    out["direct_fresh_s"] = median_time(fresh, a.repeat)
    out["direct_reused_s"] = median_time(lambda: linsolve.solve_linear(K, b, multipliers=mult),
                                         a.repeat)

    out.update(condensed(K, b, mult, a.repeat))
    out.update(iterative(K, b, mult, modes))
    print(json.dumps(out, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)
    return out


if __name__ == "__main__":
    main()
