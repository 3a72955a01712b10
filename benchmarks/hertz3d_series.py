"""hertz3d against Hertz and against hertz_axi over three meshes (issue 38): the quarter
sphere on the rigid plane, small strain, one load step, at refine -3, -2 (the default)
and -1 (``h0 = (a / 30) 2^-refine`` in both scenes: the same ``refine`` is the same h).

    python benchmarks/hertz3d_series.py [--levels -3 -2 -1] [--methods nts mortar-dual]
        [--elements hex1 tet1] [--no-axi]

hex1 is the scene's default mesh (since 2026-12-07; tet1 before, for the reason below).

Columns: the errors against Hertz of the largest nodal pressure (``peak``), the fitted
``p0`` and the fitted radius (``hertz_metrics``), ``profile``: the largest
``|p_A - p_Hertz(r_A)| / p0`` over the nodes within 0.8 a (the nodal scatter), the
axis node's signed error, the sphere's dofs, Newton iterations, the CPU time of the
build and the solve (one process, shared cores).  Then hertz_axi at the same levels,
and the comparison: at each level but the finest, ``|q_3d - q_axi|`` against the sum of
the two scenes' discretization errors measured as ``2 |q(h) - q(h / 2)|`` (Richardson
for a first-order error: ``q(h) - q(0) = 2 (q(h) - q(h / 2))``), for the fitted ``p0``
and radius.  Both scenes discretize one continuum problem, so they must meet within
those errors; Hertz (a half space, ``a / R -> 0``) is not that problem's answer, and
the differences from it level off: hertz_axi (NTS, signed, against Hertz) at refine 0,
1, 2, 3 (5,230 to 151,762 dofs) reads the axis pressure +0.93, +0.96, +0.92, +0.88 %,
the fitted p0 +0.68, +0.79, +0.81, +0.81 % and the radius -0.35, -0.54, -0.57, -0.57 %.
Against that answer (hertz_axi at refine 2) hex1's largest nodal pressure (signed
+0.62, +0.75, +0.83 % against Hertz at -3, -2, -1) lies 0.30, 0.17, 0.09 % away and its
radius (-1.86, -0.67, -0.58 %) 1.29, 0.10, 0.017 % (``tests/test_hertz3d_series.py``);
tet1's largest nodal pressure (-0.79, +0.84, +1.11 %) overshoots it at -1 (the patch
bias below).

Measured 2026-12-06 (NTS; CPU seconds on two shared cores at load 10):

======  =====  ======  ======  ======  =======  =======  =======  ====  =====
refine  elem   peak    fit p0  radius  profile  axis     dofs     its   CPU s
======  =====  ======  ======  ======  =======  =======  =======  ====  =====
-3      tet1   0.79 %  1.87 %  3.07 %  6.39 %   -6.39 %  10,800   4     2.0
-2      tet1   0.84 %  0.93 %  1.13 %  5.67 %   -5.67 %  27,783   5     9.9
-1      tet1   1.11 %  0.77 %  0.14 %  2.94 %   -2.94 %  92,256   5     48
-3      hex1   0.62 %  0.88 %  1.86 %  1.39 %   +0.62 %  10,800   4     3.0
-2      hex1   0.75 %  0.72 %  0.67 %  0.75 %   +0.75 %  27,783   5     12
-1      hex1   0.83 %  0.79 %  0.58 %  0.83 %   +0.83 %  92,256   4     45
======  =====  ======  ======  ======  =======  =======  =======  ====  =====

Standard mortar (hex1) at -3 and -2: peak 1.53, 1.45 %; fit p0 4.08, 1.98 %; radius
69.7, 2.10 %; profile 22.8, 10.8 % (14 and 36 s); tet1 at -2: peak 6.7 %, radius 28 %,
profile 45 % (its consistent ``D`` inverted against the Kuhn patch bias).
mortar-dual on hex1 reads NTS's numbers to the digits shown (13 and 45 s at -3 and -2).
mortar-dual (tet1) reads NTS's numbers to the digits shown at -3, -2 and -1 (53 and 263 s
of CPU at -3 and -2; on 2026-12-07, with Hessians only where a multiplier is nonzero,
9 and 37 s, and 742 s at -1, where one step was cut on a ContactSizeError).  hertz_axi (tri1, NTS) at -3, -2, -1: peak 4.01, 0.74, 0.55 %; fit
p0 5.85, 1.78, 0.15 %; radius 19.65, 6.23, 0.56 % (966, 1,474, 2,526 dofs, 0.1 s).
3D against axi, at -3 and -2 (the errors 2 |q(h) - q(h/2)| of both summed):
fitted p0 7.72 % apart within 10.02 %, 2.71 % within 4.18 %; radius 16.58 % within
30.71 %, 5.10 % within 13.34 %.

Before (main 4c6eec0, tet1 graded by bisection): peak 8.2, 8.5, 5.5 %; fit p0 3.8,
3.0, 2.0 %; radius 4.7, 0.80, 0.063 % at 16,605 dofs (-2).  The cause was the mesh:
the NTS nodal pressure is the nodal reaction over the node's tributary area, and
linear tetrahedra give a reaction that depends on the node's patch; the bisection
patches under the contact came in several kinds (4, 8, 12 surface triangles) and the
nodal pressures scattered by +-10 % about Hertz at -2.  On the structured Kuhn grid
every node off the symmetry planes has one patch: they read alike (a bias of +2.6 %
at -2, +1.6 % at -1); the nodes on the planes (whose mirrored patch is another kind)
read low, the axis node most (``axis``), falling with h.  Hexahedra have no such
kinds (every patch mirror-symmetric).
"""
from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from skfem_mortar import solve
from skfem_mortar.solver.newton import NewtonOptions

COLUMNS = ("peak_pressure_error", "fit_p0_error", "contact_radius_error",
           "pressure_profile_error")


def run(scene: str, refine: int, method: str = "nts", element: str | None = None) -> dict:
    """One small-strain solve of ``scene`` (hertz3d or hertz_axi) on the rigid plane at
    ``refine``: its metrics, the fitted p0's error, dofs, iterations and CPU time."""
    from importlib import import_module

    mod = import_module(f"skfem_mortar.scenes.{scene}")
    params = {**{p.name: p.default for p in mod.SCENE.params}, "base": "rigid",
              "kinematics": "small", "refine": refine}
    if element is not None:
        params["element"] = element
    t0 = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        setup = mod.build(params, method)
        res = solve(setup.model, n_steps=1, newton=NewtonOptions(rtol=1e-12))
    out = setup.metrics(res)
    out["cpu"] = time.process_time() - t0
    out["fit_p0_error"] = abs(out["peak_pressure_fit"] / out["peak_pressure_exact"] - 1.0)
    out["iterations"] = sum(s.newton_iterations for s in res.steps)
    out["dofs"] = int(setup.model.n_u)                   # displacement dofs
    return out


def richardson_check(m3: dict, m3_fine: dict, ma: dict, ma_fine: dict, key: str
                     ) -> tuple[float, float]:
    """``|q_3d - q_axi| / q_exact`` and the bound ``2 |q(h) - q(h/2)| / q_exact``
    summed over the two scenes (the module docstring), for ``key``."""
    exact = m3[key.replace("_fit", "") + "_exact"]
    gap = abs(m3[key] - ma[key]) / exact
    bound = 2.0 * (abs(m3[key] - m3_fine[key]) + abs(ma[key] - ma_fine[key])) / exact
    return gap, bound


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[-3, -2, -1])
    ap.add_argument("--methods", nargs="+", default=["nts"])
    ap.add_argument("--elements", nargs="+", default=["hex1", "tet1"])
    ap.add_argument("--no-axi", action="store_true")
    args = ap.parse_args()
    print("scene     method       elem  refine   peak  fit p0  radius  profile    dofs its"
          "   CPU s")
    rows = {}
    for method in args.methods:
        for element in args.elements:
            for r in args.levels:
                m = rows[("hertz3d", method, element, r)] = run("hertz3d", r, method, element)
                _print("hertz3d", method, element, r, m)
    if args.no_axi:
        return
    for r in args.levels:
        m = rows[("hertz_axi", "nts", "tri1", r)] = run("hertz_axi", r)
        _print("hertz_axi", "nts", "tri1", r, m)
    levels = sorted(args.levels)
    for method in args.methods:
        for element in args.elements:
            for r, fine in zip(levels[:-1], levels[1:]):
                for key in ("peak_pressure_fit", "contact_radius"):
                    gap, bound = richardson_check(
                        rows[("hertz3d", method, element, r)],
                        rows[("hertz3d", method, element, fine)],
                        rows[("hertz_axi", "nts", "tri1", r)],
                        rows[("hertz_axi", "nts", "tri1", fine)], key)
                    print(f"{method} {element} refine {r}: {key} 3D - axi {100 * gap:.2f} % "
                          f"within the discretization errors {100 * bound:.2f} %: "
                          f"{gap <= bound}")


def _print(scene: str, method: str, element: str, r: int, m: dict) -> None:
    cells = "  ".join(f"{100 * m.get(k, np.nan):5.2f}%" for k in COLUMNS[:3])
    prof = 100 * m.get("pressure_profile_error", np.nan)
    print(f"{scene:9s} {method:12s} {element:5s} {r:5d}  {cells}  {prof:5.2f}%  "
          f"{m['dofs']:7d} {m['iterations']:3d} {m['cpu']:7.1f}", flush=True)


if __name__ == "__main__":
    main()
