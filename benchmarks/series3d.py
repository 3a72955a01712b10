"""Refinement series on tet/tet meshes for ``tied3d`` and ``hertz3d`` (issue 38, "Tests
that must exist"): the multipliers' L2 error against the reference traction and their
nodal oscillation, standard and dual multipliers, three levels.

    python benchmarks/series3d.py tied3d [--levels 1 2 3] [--spaces standard dual]
        [--fine 5] [--json out.json]
    python benchmarks/series3d.py hertz3d [--levels -3 -2 -1] [--methods nts mortar
        mortar-dual] [--base elastic] [--base-h 1.5] [--slave cap] [--json out.json]

``tied3d``: tet1, cut across, ``L = 2``, small strain, one step; the slave part ``b``
has ``3 2^(level - 1)`` cells per unit length, the master ``2 2^(level - 1)``.  The
reference traction is the one-piece beam's interface traction
(:func:`~skfem_mortar.scenes._tied3d.cut_traction`) at the master's ``h`` of the same
level (``err same``, the scene's ``traction_error``: the error of the pair, tie and
reference, as a user would see it) and at level ``--fine`` (``err fine``: a one-piece
beam 4 to 16 times finer than the slave, so that the reference's own discretization
error is small beside the tie's and the rate is the multiplier's own).
``oscillation``: :func:`~skfem_mortar.scenes._tied3d.oscillation`, the largest
departure of a nodal multiplier from the mean of its neighbours over the largest
multiplier (``O(h)`` on unstructured faces, ``O(h^2)`` on a uniform grid for a
smooth traction, ``O(1)`` for a checkerboard), beside the same reading of the
reference traction (``osc ref``: the one-piece beam's own roughness at that level).

``hertz3d``: tet1 both bodies (``base=elastic``: the sphere on the elastic quarter
cylinder, both tetrahedral; ``rigid``: the rigid plane's quad4 faces), small strain,
one load step, NTS, mortar, mortar-dual.  ``L2 err``: the nodal pressure's lumped L2
error against Hertz's ``p(r) = p0 sqrt(1 - r^2 / a^2)`` over the slave nodes with
``r < a``, ``sqrt(sum w_A (p_A - p(r_A))^2 / sum w_A p(r_A)^2)``, ``w_A = int N_A dA``
(:func:`hertz_readings`); ``oscillation`` the same reading as ``tied3d``'s over the
nodes with ``r < 0.8 a`` (Hertz's fit window) and all their neighbours there, beside
Hertz's own at the same nodes (``osc ref``); ``L2 win`` the L2 error over that window
only (the error over ``r < a`` is dominated by the ring of nodes within a cell of the
contact edge, where Hertz's square root falls with an infinite slope: it depends on
how far those nodes sit from ``a``); ``err force``, ``osc force`` the L2 error and the
oscillation of the nodal forces over the tributary areas (``pair.forces(z)[0][2] /
w_A``: the dual multipliers, or the standard ones times ``D`` over its row sums).
``--base-h`` is the scene's ``base_h`` (1: the two graded grids coincide under the
contact, 1.5: non-matching), ``--slave cap`` (the default here) the sphere's faces
within ``a + 2 h0`` (the same answer as the whole sphere, 3 to 10 times cheaper).

Times are the process's CPU time of build, solve and readings (the cores are shared:
the wall clock grows with the others' load).

Measured 2026-12-06 (2 shared cores at a load average of 10 to 17, CPU seconds).

tied3d (tet1, across, L = 2; h the slave's cell size; ``err fine`` against the one-piece
beam at level 5, 32 cells per unit length, 2.1e5 dofs, 107 s; ``err force`` and ``osc
force`` the tie's nodal forces ``D^T lam`` over the tributary areas, which for the dual
space are its multipliers)::

    space     level  h       dofs    err same  err fine  osc    osc ref  err force  osc force  it  cpu
    standard  1      0.333     321   1.29      0.903     0.395  0.039    0.356      0.149      1   0.5
    standard  2      0.167    1551   0.516     0.488     0.259  0.085    0.143      0.108      1   0.1
    standard  3      0.0833   9285   0.181     0.189     0.183  0.052    0.049      0.066      1   0.7
    standard  4      0.0417  63489   0.0614    0.0628    0.111  0.028    0.017      0.037      1   13
    dual      1      0.333     321   0.361     0.383     0.147  0.039    0.361      0.147      1   0.1
    dual      2      0.167    1551   0.154     0.199     0.117  0.085    0.154      0.117      1   0.1
    dual      3      0.0833   9285   0.0561    0.0755    0.072  0.052    0.056      0.072      1   0.7
    dual      4      0.0417  63489   0.0206    0.0232    0.041  0.028    0.021      0.041      1   14

Both spaces converge (against the fine beam by 1.9, 2.6, 3.0 a level standard and 1.9,
2.6, 3.3 dual) and their oscillation falls; neither locks.  The standard multipliers
read 2.4 to 3.6 times the dual ones' error while their nodal forces are as good as the
dual multipliers (err force): ``lam = D^-1 f`` amplifies the forces' roughness, ``D``
the consistent mass of the slave faces (eigenvalues over the lumped areas in
``[1/4, 1]`` on tri3).

hertz3d on the structured graded meshes (tet1, small strain, one step, the cap;
``level`` the refine, a float for the levels between; ``n`` the sphere's cells across
the fine zone 1.2 a, the base's in brackets; PARDISO; dofs with the multipliers; cpu
in seconds; peak RSS at -1 3.3 GB at base_h 1.5, 6.1 GB at 1)::

    base_h  method       level   n       dofs    L2 err  L2 win  osc    osc ref  err f   osc f   it  cpu
    1.5     nts          -3      5 (3)    15368  0.240   0.193   0.202  0.046    0.239   0.202    7  3.3
    1.5     nts          -2      9 (6)    40092  0.180   0.139   0.219  0.021    0.179   0.219    9  19
    1.5     mortar       -3      5 (3)    15368  0.516   0.438   0.287  0.046    0.214   0.186    7  9.1
    1.5     mortar       -2.585  6 (4)    21338  0.383   0.296   0.250  0.036    0.160   0.055    8  11
    1.5     mortar       -2      9 (6)    40092  0.341   0.262   0.196  0.021    0.146   0.068   13  60
    1.5     mortar       -1      18 (12) 133993  0.161   0.036   0.102  0.0067   0.069   0.034    9  134
    1.5     mortar-dual  -3      5 (3)    15368  0.223   0.171   0.223  0.046    0.221   0.223    7  11
    1.5     mortar-dual  -2.585  6 (4)    21338  0.109   0.088   0.102  0.036    0.108   0.102    8  13
    1.5     mortar-dual  -2.5    7 (5)        -  0.106   -       0.068  0.031    0.105   0.068    8  19
    1.5     mortar-dual  -2      9 (6)    40092  0.116   0.049   0.073  0.021    0.116   0.073    9  51
    1.5     mortar-dual  -1      18 (12) 133993  0.056   0.019   0.037  0.0067   0.055   0.037    7  125
    1       nts          -3      5 (5)    20294  0.065   0.042   0.088  0.047    0.064   0.087    7  4.1
    1       mortar       -3      5 (5)    20294  0.424   0.310   0.152  0.047    0.166   0.030    9  15
    1       mortar       -1      18 (18) 181894  0.112   0.020   0.053  0.0067   0.048   0.019    9  234
    1       mortar-dual  -3      5 (5)    20294  0.065   0.042   0.088  0.047    0.064   0.087    7  14
    1       mortar-dual  -1      18 (18) 181894  0.026   0.0094  0.019  0.0067   0.025   0.019    7  187

(-2 of the non-matching runs and the matching -3 runs of the whole sphere, ``--slave
sphere``, read the same to the digits shown; the -2 ones took 51 s and 60 s with the
cap of ``2 a`` first tried, the whole sphere 46 s and 52 s at -3.)

**Matching (base_h = 1).**  The two graded grids coincide under the contact (their
nodes within ``3e-4 h0``, the same diagonals), so mortar-dual reads NTS's pressures to
three digits (0.065 and 0.088 at -3; at -1 mortar-dual's window error is 0.0094, its
oscillation 0.019): the tet/tet question is not asked there.  Standard mortar's error
there is the contact edge: its weighted gap ``int N_A g`` reaches one ring beyond the
edge, so the ring of nodes inside ``a`` nearest it stays inactive (``p = 0``, Hertz
0.16 to 0.50 p0 at -3), while the active ring inside is pushed up (1.1 to 1.2 p0
where Hertz reads 0.70 to 0.74): the consistent ``D`` spreads the edge's jump inwards.
Its forces over the tributary areas (err f 0.166) do not show it.  It falls with
``h``: at -1 the window error is 0.020 and the oscillation 0.053 (-3: 0.310, 0.152;
peak RSS 6.1 GB at 1.8e5 dofs).

**Non-matching (base_h = 1.5).**  Both spaces converge and neither locks: from -3 to
-2 to -1 standard mortar's window error falls 0.438, 0.262, 0.036 and its oscillation
0.287, 0.196, 0.102; mortar-dual's 0.171, 0.049, 0.019 and 0.223, 0.073, 0.037 (its
error over ``r < a`` 0.223, 0.116, 0.056).  The levels between keep the falls
(``tests/test_hertz3d_tet_series.py``: -3, -2.585, -2, both spaces, the two claims) as
long as the two meshes keep their ratio: at -2.5 the cell counts round up to 7 and 5
(ratio 1.4, the master relatively finer) and mortar-dual reads better than at -2.
The error over the whole zone ``r < a`` is the edge ring's (mortar-dual 0.109 at -2.585,
0.116 at -2, whose edge nodes sit at 0.94 to 0.97 a and read 0.04 to 0.12 p0).
Standard multipliers oscillate 1.5 to 4.5 times their forces (``lam = D^-1 f``, as
in tied3d); the forces' L2 error falls at every level (0.214, 0.160, 0.146, 0.069).
NTS between the non-matching meshes: its oscillation does not fall (0.202, 0.219),
as NTS fails the patch test between deformable bodies.

Before (bisection meshes, whose surface patches came in three kinds): NTS's
oscillation stayed at 0.4 on the elastic base and standard mortar's at 0.62 to 0.65
over -3 and -2, a checkerboard of the patch kinds that the dual space and the forces
did not show.  The structured grids have one patch kind, and the checkerboard is
gone with it.
"""
from __future__ import annotations

import argparse
import json
import time
import warnings

import numpy as np

from skfem_mortar.app.runner import run_scene
from skfem_mortar.contact.mortar_support import tributary_weights
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.contact.segmentation import surface_cell
from skfem_mortar.contact.tie import TiePair
from skfem_mortar.scenes._hertz3d import exact_hertz3d
from skfem_mortar.scenes._tied3d import cut_plane, oscillation
from skfem_mortar.scenes.tied3d import _reference, tie_readings
from skfem_mortar.solver.newton import NewtonOptions

#: tied3d's series: tet1 cut across, the interface a thickness from clamp and tip
TIED = {"element": "tet1", "length": 2, "interface": "across", "kinematics": "small"}
#: hertz3d's series: tetrahedra, small strain (Hertz's theory is linear)
HERTZ = {"element": "tet1", "kinematics": "small"}
#: Hertz's fit window over a: the oscillation's nodes
WINDOW = 0.8


def _item(setup, kind):
    return next(it for it in setup.model.items if isinstance(it, kind))


def _solve(name: str, params: dict, method: str | None) -> tuple[dict, object, object, float]:
    t0 = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        summary, result, setup = run_scene(name, {k: str(v) for k, v in params.items()},
                                           method, steps=1, return_result=True,
                                           newton=NewtonOptions(rtol=1e-12))
    return summary, result, setup, time.process_time() - t0


def tied3d_row(level: int, space: str, fine_cut: tuple | None) -> dict:
    """One run of ``tied3d`` (:data:`TIED`) at ``level`` with ``space`` multipliers."""
    params = {**TIED, "refine": level, "multipliers": space}
    summary, result, setup, cpu = _solve("tied3d", params, None)
    m = summary["metrics"]
    row = {"scene": "tied3d", "space": space, "level": level,
           "h": 1.0 / (3 * 2 ** (level - 1)), "dofs": int(result.z.size),
           "err_same": m["traction_error"], "oscillation": m["oscillation"],
           "osc_ref": m["oscillation_exact"], "err_force": m["force_traction_error"],
           "osc_force": m["force_oscillation"],
           "iterations": sum(s["newton_iterations"] for s in summary["steps"]), "cpu": cpu}
    if fine_cut is not None:
        tie = _item(setup, TiePair)
        fine = tie_readings(tie, result.z, fine_cut, cut_plane(params)[0], 1.0)
        row["err_fine"] = fine["traction_error"]
    return row


def hertz_readings(pair: ContactPair, z: np.ndarray, exact: dict) -> dict:
    """``l2_error``, ``l2_window``, ``oscillation``, ``osc_ref``, ``err_force`` and
    ``osc_force`` of the module docstring."""
    s = pair.slave
    cell = surface_cell(s)
    x = s.x(z)
    p = np.nan_to_num(np.asarray(pair.pressure_and_gap(z)[0], dtype=float))
    a, p0 = exact["contact_radius"], exact["peak_pressure"]
    r = np.hypot(x[0], x[1])
    ph = p0 * np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None))
    area = tributary_weights(s.X, s.segments, cell, 2)
    force = pair.forces(z)[0][2] / area
    w = area * (r < a)
    window = r < WINDOW * a

    def l2(q, wq=w):
        return float(np.sqrt(np.sum(wq * (q - ph) ** 2) / np.sum(wq * ph ** 2)))

    return {"l2_error": l2(p), "l2_window": l2(p, w * window),
            "oscillation": oscillation(p[None], s.segments, cell, window),
            "osc_ref": oscillation(ph[None], s.segments, cell, window),
            "err_force": l2(force),
            "osc_force": oscillation(force[None], s.segments, cell, window),
            "n_window": int(window.sum())}


def hertz3d_row(level: int, method: str, base: str, **extra) -> dict:
    """One run of ``hertz3d`` (:data:`HERTZ`) at ``refine = level`` (``extra``: more of
    its parameters, e.g. ``base_h``, ``slave``)."""
    params = {**HERTZ, "refine": level, "base": base, **extra}
    summary, result, setup, cpu = _solve("hertz3d", params, method)
    pair = _item(setup, ContactPair)
    m = summary["metrics"]
    row = {"scene": "hertz3d", "space": method, "level": level, "h": m["element_size"],
           "base_h": float(params.get("base_h", 1.0)),
           "dofs": int(result.z.size),
           **hertz_readings(pair, result.z, exact_hertz3d(setup_params(params))),
           "peak_fit_error": _relative(m["peak_pressure_fit"], m["peak_pressure_exact"]),
           "radius_error": _relative(m["contact_radius"], m["contact_radius_exact"]),
           "iterations": sum(s["newton_iterations"] for s in summary["steps"]), "cpu": cpu}
    return row


def _relative(value: float | None, exact: float) -> float:
    """``|value - exact| / exact``; nan where the fit failed (the summary's None: fewer
    than two nodes in compression in the window, or ``p^2`` not falling with ``r^2``)."""
    return float("nan") if value is None else abs(value - exact) / exact


def setup_params(params: dict) -> dict:
    """hertz3d's parameters with ``params`` over the defaults."""
    from skfem_mortar.scenes import get_scene

    return get_scene("hertz3d").resolve({k: str(v) for k, v in params.items()})


def _table(rows: list[dict], keys: tuple) -> str:
    head = "  ".join(f"{k:>11}" for k in keys)
    lines = [head]
    for r in rows:
        lines.append("  ".join(f"{r[k]:>11.3g}" if isinstance(r.get(k), float)
                               else f"{str(r.get(k, '-')):>11}" for k in keys))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", choices=("tied3d", "hertz3d"))
    ap.add_argument("--levels", type=int, nargs="+")
    ap.add_argument("--spaces", nargs="+", default=["standard", "dual"])
    ap.add_argument("--methods", nargs="+", default=["nts", "mortar", "mortar-dual"])
    ap.add_argument("--base", default="elastic", choices=("elastic", "rigid"))
    ap.add_argument("--base-h", type=float, default=1.0, help="hertz3d: the base's cells "
                    "under the contact over the sphere's (1: matching, 1.5: non-matching)")
    ap.add_argument("--slave", default="cap", choices=("cap", "sphere"), help="hertz3d: "
                    "the sphere's contact surface (cap: its faces within 2 a, the same answer)")
    ap.add_argument("--fine", type=int, default=5, help="tied3d: the fine reference's level "
                    "(0: none)")
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    rows = []
    if args.scene == "tied3d":
        fine = None
        if args.fine:
            t0 = time.process_time()
            fine = _reference({**setup_params_tied({**TIED, "refine": args.fine})}, 1)[1]
            print(f"fine reference (level {args.fine}): {time.process_time() - t0:.1f} s CPU",
                  flush=True)
        for space in args.spaces:
            for level in args.levels or (1, 2, 3):
                rows.append(tied3d_row(level, space, fine))
                print(_table(rows[-1:], ("space", "level", "h", "dofs", "err_same",
                                         "err_fine", "oscillation", "osc_ref", "iterations",
                                         "cpu")), flush=True)
        keys = ("space", "level", "h", "dofs", "err_same", "err_fine", "oscillation",
                "osc_ref", "err_force", "osc_force", "iterations", "cpu")
    else:
        for method in args.methods:
            for level in args.levels or (-3, -2, -1):
                rows.append(hertz3d_row(level, method, args.base, base_h=args.base_h,
                                        slave=args.slave))
                print(_table(rows[-1:], ("space", "level", "h", "dofs", "l2_error",
                                         "oscillation", "osc_ref", "iterations", "cpu")),
                      flush=True)
        keys = ("space", "level", "h", "dofs", "l2_error", "l2_window", "oscillation",
                "osc_ref", "err_force", "osc_force", "peak_fit_error", "radius_error", "iterations",
                "cpu")
    print(_table(rows, keys))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


def setup_params_tied(params: dict) -> dict:
    """tied3d's parameters with ``params`` over the defaults, unchecked: the fine
    reference is one body, which the scene's memory estimate (two parts and the
    one-piece beam) overstates."""
    from skfem_mortar.scenes.tied3d import SCENE

    return {**{p.name: p.default for p in SCENE.params}, **params}


if __name__ == "__main__":
    main()
