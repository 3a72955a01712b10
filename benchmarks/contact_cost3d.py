"""Cost of the 3D contact evaluation per face pair and its growth with the number of
contact faces (issue 38, "Measure and report"): NTS, mortar and mortar-dual.

    python benchmarks/contact_cost3d.py [--faces 1000 10000 100000]
        [--methods nts mortar mortar-dual] [--cells quad4 tri3] [--repeat 3] [--memory]

For each target number of slave faces: ``segmentation3d.py``'s flat surfaces (the
unit square, non-matching: the master grid 0.77 times as fine, nodes jittered by up
to 0.25 h in the plane and warped by 0.02 h out of it, the master 0.01 h above and
facing down), quad4/quad4 or tri3/tri3.  Timed: the process's CPU time (median of
``--repeat``; the wall clock beside it, inflated on shared cores), gaps ``g``, ``G``
and ``H`` (multipliers all 1), the search included:

* ``nts``: :func:`~skfem_mortar.contact.nts.evaluate`;
* ``mortar``/``mortar-dual``: :func:`~skfem_mortar.contact.mortar_kernel.evaluate`
  with :class:`~skfem_mortar.contact.points3d.FacePoints` on the candidate pairs of
  the method's own search (:func:`method_pairs`), as ``Mortar`` calls it (the
  segmentation, the integration points on jets, D, M, the weighted gaps, one scatter).

The face pairs counted are those candidate pairs, the same count for every method
(NTS searches node/face pairs of its own).  The last
lines fit ``t = c n^k`` by least squares in log-log over the sizes of each
method and cell (``k`` = 1: linear growth).

Measured 2026-12-06 (CPU, one thread; per slave face / per face pair): NTS quad4
272 / 7, 165 / 4, 275 / 7 us at 1e3, 1e4, 1e5 faces (k = 0.98; peak 39, 174, 1609 MiB),
tri3 56 / 1, 68 / 1 us at 1e3, 1e4 (k = 1.02); mortar quad4 58, 71, 71 ms / 2.8, 2.6,
2.2 ms at 64, 144, 400 faces (k = 0.90), tri3 26, 27, 32 ms / 0.60, 0.55, 0.45 ms at 72,
128, 392 (k = 0.87); mortar-dual as mortar to 3 %.

The face pairs are the search's candidates; only overlapping ones reach the jets: at 64
quad4 faces 1,357 candidate pairs give 374 integration cells on 181 pairs, at 128 tri3
faces 6,301 give 761 cells on 461 pairs, and the search with the value-only segmentation
(clipping every candidate) takes 12 and 22 ms of the 2 to 3 s.  The cost is the cells'
jets (7 points, Hessians of 36 or 27 variables).  Measured 2026-12-06 after the jets'
variable fast path, the curvature step of the back-projection and the faces' chunk bound
(CPU, median of 2 interleaved processes against main on loaded cores, per slave face):
quad4 36 faces 49 ms (main 57), mortar-dual 80 ms (main 87); quad4 100 faces 51 ms (main
69); tri3 72 faces 25 / 27 ms (main 23 / 25, standard / dual: within the runs' 25 % spread).
After the kernel's scatter on each group's distinct dofs (issue 34's dedup, H26's milestone
M2; CPU, median of 2, one thread, load 5 to 7), quad4 per slave face / per face pair at 64,
144, 400 faces: mortar 27.3 / 1.29, 27.7 / 1.02, 27.0 / 0.84 ms (time ~ slave faces^0.99,
~ pairs^0.81), mortar-dual 41.4 / 1.96, 42.8 / 1.58, 49.8 / 1.55 ms (~ faces^1.10, ~
pairs^0.90); Python-side peak 40, 69, 76 MiB both.

Why the cost per slave face grows a little, then not (2026-12-06, main e29e8e8, CPU, one
thread, nothing else running): per slave face at 64, 400, 1,024 quad4 faces mortar 33.9,
38.9, 39.9 ms, mortar-dual 53.0, 55.7, 57.1 ms (from 400 to 1,024 faces the time grows
like faces^1.03).  The faces on the surface's edge meet fewer master faces (4.3 to 4.8
integration cells against 7.1 to 7.2 inside) and their share falls with the mesh (0.44,
0.19, 0.12), so the integration cells per slave face rise (5.84, 6.49, 6.92).  Per
integration cell the cost is flat: mortar 5.80, 5.99, 5.77 ms, mortar-dual 9.08, 8.58,
8.25 ms: the evaluation is linear in its integration cells.  ``--memory`` adds the peak of Python-side
allocations (tracemalloc) of one more evaluation.  ``--max-seconds`` skips a
method's larger sizes once one evaluation took longer.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import tracemalloc

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from segmentation3d import problem  # noqa: E402  (benchmarks/, run as a script)

METHODS = ("nts", "mortar", "mortar-dual")


def method_pairs(xs, Ss, xm, Sm, cells) -> tuple[np.ndarray, np.ndarray]:
    """The candidate face pairs of :class:`~skfem_mortar.contact.mortar_method.Mortar`'s
    search at its first evaluation (no margin given: each face's box grown by its own
    size, :func:`~skfem_mortar.contact.search.cell_sizes`)."""
    from skfem_mortar.contact.search import cell_sizes, segment_pairs
    return segment_pairs(xs, Ss, xm, Sm, 0.0, cell_sizes(xs, Ss, cells[0]),
                         cell_sizes(xm, Sm, cells[1]), *cells)


def evaluator(method: str, xs, Ss, xm, Sm, cells):
    """A call evaluating ``g, G, H`` of ``method`` on the surfaces (mortar: on the
    pairs of :func:`method_pairs`, searched in the call, as the method does)."""
    lam = np.ones(xs.shape[1])
    if method == "nts":
        from skfem_mortar.contact.nts import evaluate as nts_evaluate
        return lambda: nts_evaluate(xs, Ss, xm, Sm, lam=lam, cells=tuple(cells))
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    from skfem_mortar.contact.mortar_kernel import evaluate
    from skfem_mortar.contact.points3d import FacePoints
    space = "dual" if method == "mortar-dual" else "standard"
    return lambda: evaluate(xs, Ss, xm, Sm, lam=lam, tangent=True, space=space, cells=cells,
                            points=FacePoints(cells, pairs=method_pairs(xs, Ss, xm, Sm, cells),
                                              frozen=False))


def grid_for(faces: int, tri: bool) -> int:
    """Grid cells a side with about ``faces`` slave faces."""
    return max(2, int(round(np.sqrt(faces / (2.0 if tri else 1.0)))))


def measure(method: str, n: int, tri: bool, repeat: int, memory: bool) -> dict:
    """One row: sizes, median time, per face and per pair, (peak memory)."""
    xs, Ss, xm, Sm, cells = problem(n, tri)
    pairs = method_pairs(xs, Ss, xm, Sm, cells)[0].size
    call = evaluator(method, xs, Ss, xm, Sm, cells)
    ts, walls = [], []
    for _ in range(repeat):
        t0, w0 = time.process_time(), time.perf_counter()
        call()
        ts.append(time.process_time() - t0)
        walls.append(time.perf_counter() - w0)
    row = {"method": method, "cells": f"{cells[0]}/{cells[1]}", "slave_faces": len(Ss),
           "slave_nodes": xs.shape[1], "pairs": int(pairs), "time_s": float(np.median(ts)),
           "wall_s": float(np.median(walls))}
    if memory:
        tracemalloc.start()
        call()
        row["peak_mib"] = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()
    return row


def fit_exponent(rows: list[dict]) -> float:
    """``k`` of ``time = c pairs^k`` (least squares in log-log)."""
    x = np.log([r["pairs"] for r in rows])
    y = np.log([r["time_s"] for r in rows])
    return float(np.polyfit(x, y, 1)[0]) if len(rows) > 1 else float("nan")


def line(r: dict) -> str:
    mem = f" {r['peak_mib']:.0f} |" if "peak_mib" in r else " - |"
    return (f"| {r['method']} | {r['cells']} | {r['slave_faces']:,} | {r['pairs']:,} | "
            f"{r['time_s']:.3g} | {r['wall_s']:.3g} | {1e6 * r['time_s'] / r['slave_faces']:.0f} | "
            f"{1e6 * r['time_s'] / r['pairs']:.0f} |{mem}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--faces", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--methods", nargs="+", default=list(METHODS), choices=METHODS)
    ap.add_argument("--cells", nargs="+", default=["quad4", "tri3"], choices=("quad4", "tri3"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--memory", action="store_true")
    ap.add_argument("--max-seconds", type=float, default=600.0)
    a = ap.parse_args(argv)
    if a.repeat < 1:
        raise ValueError(f"--repeat must be >= 1, got {a.repeat}")
    print("| method | faces | slave faces | face pairs | CPU [s] | wall [s] | per slave face "
          "[us] | per face pair [us] | peak [MiB] |\n" + "|---" * 9 + "|", flush=True)
    fits = []
    for method in a.methods:
        for cell in a.cells:
            rows = []
            for faces in sorted(a.faces):
                r = measure(method, grid_for(faces, cell == "tri3"), cell == "tri3",
                            a.repeat, a.memory)
                rows.append(r)
                print(line(r), flush=True)
                if r["time_s"] > a.max_seconds:
                    break
            fits.append(f"{method} {cell}: time ~ pairs^{fit_exponent(rows):.3f} over "
                        f"{rows[0]['pairs']:,} to {rows[-1]['pairs']:,} pairs")
    print("\n" + "\n".join(fits))
    return 0


if __name__ == "__main__":
    sys.exit(main())
