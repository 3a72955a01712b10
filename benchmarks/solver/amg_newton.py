"""Newton's linear solves by algebraic multigrid instead of a factorization: the
experiment behind the decision not to ship one, reproducible.

    pip install pyamg   # not a dependency of the package
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/solver/amg_newton.py \
        [--refine 2] [--method mortar-dual] [--json out.json]

Solves hertz in one step twice, interleaved: with the package's direct path
and with inexact Newton whose solves are FGMRES preconditioned as below
(:class:`AmgSolver`, put in the place of the package's ``KrylovSolver``, so the
forcing term and the settled-active-set logic are the package's own).
Prints Newton iterations, load steps, seconds per Newton iteration, FGMRES
iterations, hierarchies built and direct fallbacks.

The preconditioner (:class:`AlPreconditioner`): the symmetrized Newton system
(``linsolve.symmetrize``: ``S = T K``) is ``[A, B; B^T, 0]`` on the
displacements and the active multipliers; ``P = [A + g B B^T, B; 0, -I/g]``
(the augmented-Lagrangian block triangle, ``g = GAMMA max|A| / max|B|^2``),
``A + g B B^T`` approximated by one V-cycle of smoothed aggregation (pyamg)
with the bodies' rigid modes as near-null space; FGMRES on ``K`` with
``P^-1 T``.  With an exact solve of ``A + g B B^T`` FGMRES needs 19 iterations
(g factor 1) or 7 (1e3) to 1e-10; with the V-cycle 20 to 40.

Measured (2026-12-04, one core; seconds per Newton iteration, hertz mortar-dual
one step):

=========  ==================  ===================================  =========
unknowns   direct              amg                                  peak RSS
=========  ==================  ===================================  =========
4.7e4      0.21 (7 its)        0.74 (7 its, 307 FGMRES, 5 setups)
1.7e5      0.89 (7 its)        3.07 (7 its, 1 direct fallback)
6.5e5      3.53 (11 its)       14.5 (24 its in 2 steps: a step cut,   2.8 / 3.8 GB
                               4 direct fallbacks)
=========  ==================  ===================================  =========

Slower at every size, larger in memory at the largest (the FGMRES basis:
2 x 81 vectors of 6.5e5), and the inexact early iterations cut a step the
direct path takes whole.
"""
from __future__ import annotations

import argparse
import json
import logging
import time
import warnings
from typing import Any

import numpy as np
import scipy.sparse as sp

log = logging.getLogger(__name__)

#: the augmentation factor (hertz refine=0..1: 1 gave the fewest FGMRES iterations
#: of 1, 10 and 100; with the V-cycle a larger g makes A + g B B^T harder)
GAMMA = 1.0
#: FGMRES iterations with one hierarchy before a fresh one, then the direct solve
MAX_ITER = 80
#: the solves' relative residual while the active set is unsettled (the direct
#: path's check): with the forcing term there, hertz refine=4 inverted elements
UNSETTLED_RTOL = 1e-8


def rigid_modes(model: Any, free: np.ndarray) -> np.ndarray:
    """The bodies' rigid modes (translations, rotation) on the free displacement
    unknowns, ``(n_free_u, 3 n_bodies)``, empty columns dropped."""
    from skfem_mortar.contact.preflight import _rigid_modes
    free_u = free[free < model.n_u]
    cols = []
    for body in model.bodies:
        if not (hasattr(body, "X") and hasattr(body, "node_dofs") and np.size(body.X)):
            continue
        local = _rigid_modes(body).modes
        glob = np.zeros((model.n_u, local.shape[1]))
        glob[body.offset:body.offset + local.shape[0]] = local
        cols.append(glob[free_u])
    B = np.hstack(cols) if cols else np.ones((free_u.size, 1))
    return np.ascontiguousarray(B[:, np.abs(B).sum(axis=0) > 0])


class AlPreconditioner:
    """``P^-1`` of the module docstring for the symmetrizable ``K`` it is built from."""

    def __init__(self, K: sp.csr_matrix, mult: np.ndarray, modes: np.ndarray,
                 gamma: float = GAMMA):
        import pyamg
        u, m = np.flatnonzero(~mult), np.flatnonzero(mult)
        Kc = K.tocsc()
        A = Kc[:, u].tocsr()[u]
        rows = K[m].tocoo()
        off = rows.col != m[rows.row]  # active: values off the diagonal (symmetrize's test)
        self.active = np.bincount(rows.row[off], np.abs(rows.data[off]), m.size) > 0
        B = Kc[:, m[self.active]].tocsr()[u]
        big = float(abs(B).max()) if B.nnz else 0.0
        self.g = gamma * float(abs(A).max()) / big ** 2 if big > 0 else 0.0
        Ag = (A + self.g * (B @ B.T)).tocsr() if B.nnz else A
        Ag = ((Ag + Ag.T) * 0.5).tocsr()
        # the rigid modes are the near-null space already: no candidate improvement
        self.ml = pyamg.smoothed_aggregation_solver(Ag, B=modes, BH=modes.copy(),
                                                    symmetry="symmetric",
                                                    improve_candidates=None)
        self.cycle = self.ml.aspreconditioner(cycle="V")
        self.u, self.m, self.B, self.n = u, m, B, K.shape[0]

    def apply(self, s: np.ndarray) -> np.ndarray:
        """``P^-1 s`` for a right-hand side of the symmetrized system."""
        y = s[self.m].copy()
        y[self.active] *= -self.g
        x = np.empty(self.n)
        x[self.u] = self.cycle @ (s[self.u] - self.B @ y[self.active])
        x[self.m] = y
        return x


class AmgSolver:
    """``KrylovSolver``'s interface: FGMRES with :class:`AlPreconditioner`, the
    hierarchy kept while the active set is settled, a fresh one when FGMRES
    fails with the kept one, the direct solve when a fresh one fails too or
    the system is not symmetrizable."""

    def __init__(self, modes_of, max_iter: int = MAX_ITER):
        from skfem_mortar.solver.krylov import KrylovCounts
        self.modes_of, self.max_iter = modes_of, max_iter
        self.pre: AlPreconditioner | None = None
        self.counts = KrylovCounts()
        self.setups = 0

    def solve(self, K, b, eta, multipliers=None, reuse=True, hint=None):
        from skfem_mortar.solver.krylov import fgmres
        from skfem_mortar.solver.linsolve import solve_linear, symmetrize
        K = K.tocsr()
        if not reuse:
            eta = min(eta, UNSETTLED_RTOL)
        sym = symmetrize(K, b, multipliers) if multipliers is not None else None
        if sym is not None:
            kept = reuse and self.pre is not None and self.pre.n == K.shape[0]
            for fresh in ((False, True) if kept else (True,)):
                if fresh:
                    self.pre = None
                    self.pre = AlPreconditioner(K, multipliers, self.modes_of())
                    self.setups += 1
                pre, transform = self.pre, sym.transform
                out = fgmres(K, b, lambda r: pre.apply(transform(r)), eta, self.max_iter)
                self.counts.krylov_iterations += out.iterations
                if out.converged:
                    self.counts.krylov_solves += 1
                    return out.x
        self.counts.fallbacks += 1
        self.counts.factorizations += 1
        return solve_linear(K, b, None, multipliers, hint)


def run(refine: int, method: str, linear: str) -> dict:
    """hertz in one step with the direct path or with :class:`AmgSolver`."""
    from dataclasses import replace

    from skfem_mortar.app.runner import build_scene
    from skfem_mortar.solver import newton, stepping
    from skfem_mortar.solver.newton import NewtonOptions

    setup = build_scene("hertz", {"refine": refine}, method)[0]
    model = setup.model
    seen: dict = {}
    real_block = model.free_block

    def block(K, free):
        seen["free"] = free
        return real_block(K, free)
    model.free_block = block
    opts = dict(setup.solve_options)
    base = opts.get("newton") or NewtonOptions()
    reports, solvers = [], []
    real_krylov, real_step = newton.KrylovSolver, stepping.newton_step
    if linear == "amg":
        def factory(max_iter=None):
            solvers.append(AmgSolver(lambda: rigid_modes(model, seen["free"])))
            return solvers[-1]
        newton.KrylovSolver = factory
        opts["newton"] = replace(base, linear="krylov")

    def step(*args, **kwargs):
        rep = real_step(*args, **kwargs)
        reports.append(rep)
        return rep
    stepping.newton_step = step
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = stepping.solve(model, 1, **opts)
    finally:
        newton.KrylovSolver, stepping.newton_step = real_krylov, real_step
    its = sum(r.iterations for r in reports)
    wall = time.perf_counter() - t0
    return {"linear": linear, "unknowns": int(model.n), "converged": bool(res.converged),
            "steps": len(res.steps), "newton_iterations": its,
            "seconds_per_iteration": wall / max(its, 1),
            "fgmres_iterations": sum(r.krylov_iterations for r in reports),
            "fallbacks": sum(r.fallbacks for r in reports),
            "setups": sum(s.setups for s in solvers)}


def main(argv=None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--refine", type=int, default=2)
    p.add_argument("--method", default="mortar-dual")
    p.add_argument("--json")
    a = p.parse_args(argv)
    rows = [run(a.refine, a.method, linear) for linear in ("direct", "amg")]
    for r in rows:
        print(json.dumps(r))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    return rows


if __name__ == "__main__":
    main()
