"""Time one Newton iteration of the neo-Hookean block: assembly against linear solve.

For unit squares of about 2k, 20k and 200k linear triangles (``tri1``) at a
finite homogeneous stretch (lx = 1.5 with a small perturbation so that the
state is not exactly the solution), the script times

* ``material``  P(F) and A(F) on all quadrature points,
* ``residual``  the skfem LinearForm ``Grad v : P``,
* ``tangent``   the skfem BilinearForm ``Grad v : A : Grad du``,
* ``model``     the whole ``Model.assemble`` (the three above + COO -> CSR),
* ``solve``     condensing the Dirichlet dofs and ``scipy.sparse.linalg.spsolve``
  (SuperLU, the solver the Newton method uses),

and prints a table (best of ``--repeat`` runs, seconds; wall time, or process
CPU time with ``--cpu``).

Usage: ``python benchmarks/bench_block.py [--sizes 32 100 316] [--repeat 3] [--cpu]``
(``N`` squares per side, ``2 N^2`` triangles).
"""
from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.sparse.linalg as spla
from skfem import MeshTri

from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.bodies.solid import Solid, internal_force, material_stiffness


CLOCK = time.perf_counter


def best_of(fun, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = CLOCK()
        fun()
        times.append(CLOCK() - t0)
    return min(times)


def bench(n: int, repeat: int) -> dict:
    mesh = MeshTri.init_tensor(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1)).with_defaults()
    solid = Solid(mesh, NeoHooke(E=1.0, nu=0.3), "tri1", name="block")
    model = Model([solid,
                   Dirichlet(solid, solid.dofs_on("left", "x")),
                   Dirichlet(solid, solid.dofs_on("bottom", "y")),
                   Dirichlet(solid, solid.dofs_on("right", "x"), 0.5)])
    rng = np.random.default_rng(0)
    z = solid.interpolate(lambda X: np.array([0.5 * X[0], -0.2 * X[1]]))
    z += 1e-3 / n * rng.standard_normal(z.shape)
    F = solid.deformation_gradient(z)
    P, A = solid.material.stress_and_tangent(F)
    At = np.transpose(A, (2, 3, 0, 1, 4, 5))
    out = {"triangles": mesh.nelements, "dofs": model.n}
    out["material"] = best_of(lambda: solid.material.stress_and_tangent(
        solid.deformation_gradient(z)), repeat)
    out["residual"] = best_of(lambda: internal_force.assemble(solid.basis, P=P), repeat)
    out["tangent"] = best_of(lambda: material_stiffness.assemble(solid.basis, At=At), repeat)
    out["model"] = best_of(lambda: model.assemble(z, 1.0), repeat)
    R, K, _ = model.assemble(z, 1.0)
    fixed, _ = model.prescribed(1.0)
    free = np.setdiff1d(np.arange(model.n), fixed)

    def linear_solve():
        Kff = K[free][:, free].tocsc()
        return spla.spsolve(Kff, -R[free])

    out["solve"] = best_of(linear_solve, repeat)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[32, 100, 316],
                    help="squares per side (2 N^2 triangles)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cpu", action="store_true",
                    help="process CPU time instead of wall time (steadier on a busy machine)")
    args = ap.parse_args()
    global CLOCK
    CLOCK = time.process_time if args.cpu else time.perf_counter
    print(f"clock: {'process CPU' if args.cpu else 'wall'} time, best of --repeat runs, seconds")
    cols = ["triangles", "dofs", "material", "residual", "tangent", "model", "solve"]
    print(" ".join(f"{c:>10}" for c in cols) + "  solve/model")
    for n in args.sizes:
        r = bench(n, args.repeat if n < 300 else 2)
        print(" ".join(f"{r[c]:>10d}" if isinstance(r[c], int) else f"{r[c]:>10.4f}"
                       for c in cols) + f"  {r['solve'] / r['model']:>10.2f}", flush=True)


if __name__ == "__main__":
    main()
