"""Cost of the 3D mortar segmentation per face pair, and its growth (issue 38, item 5).

    python benchmarks/segmentation3d.py [--pairs 1000 10000 100000] [--repeat 3]

For each target number of candidate pairs: a slave and a master surface over the
unit square, non-matching (the master grid 0.77 times as fine), nodes jittered in the
plane by up to 0.25 h and warped out of it by up to 0.02 h (so quad4 faces need Newton
in the back-mapping), the master 0.01 h above, facing down; quad4/quad4 and tri3/tri3
(each quad cut along a diagonal).  The grid size is chosen so that the search
(:func:`~skfem_mortar.contact.search.segment_pairs`, the default margin of
:func:`~skfem_mortar.contact.segmentation3d.segment_faces`) gives about the target
count.  Prints the median wall time of the whole segmentation (search included) and of
the segmentation of the given pairs (search excluded), per candidate pair, and the peak
of Python-side allocations (tracemalloc, one run).  Linear growth shows as a flat
time per pair.
"""
from __future__ import annotations

import argparse
import tracemalloc

import numpy as np

from search_grid import median_time  # benchmarks/ (run as a script)

from skfem_mortar.contact.segmentation3d import segment_faces


def surface(n: int, z: float, up: bool, tri: bool, seed: int):
    """An n x n grid of the unit square (jittered, warped), quad4 or tri3 faces."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(t, t, indexing="ij")
    h = 1.0 / n
    X[1:-1] += rng.uniform(-0.25 * h, 0.25 * h, X[1:-1].shape)
    Y[:, 1:-1] += rng.uniform(-0.25 * h, 0.25 * h, Y[:, 1:-1].shape)
    Z = z + rng.uniform(-0.02 * h, 0.02 * h, X.shape)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    Q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    if tri:
        Q = np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]])
    x = np.vstack([X.ravel(), Y.ravel(), Z.ravel()])
    return x, Q if up else Q[:, ::-1].copy()


def problem(n: int, tri: bool):
    n_m = max(2, int(round(0.77 * n)))
    xs, Ss = surface(n, 0.0, True, tri, 1)
    xm, Sm = surface(n_m, 0.01 / n, False, tri, 2)
    cells = ("tri3", "tri3") if tri else ("quad4", "quad4")
    return xs, Ss, xm, Sm, cells


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args(argv)
    print("| faces | slave faces | candidate pairs | cells | total [s] | per pair [us] | "
          "without search [us] | peak [MB] | per pair [kB] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for tri in (False, True):
        xs, Ss, xm, Sm, cells = problem(30, tri)   # pairs per grid cell, the boundary's share small
        ratio = segment_faces(xs, Ss, xm, Sm, cells).candidates[0].size / 900.0
        for target in a.pairs:
            n = max(2, int(round(np.sqrt(target / ratio))))
            for _ in range(2):          # the boundary's share: correct the grid twice
                xs, Ss, xm, Sm, cells = problem(n, tri)
                got = segment_faces(xs, Ss, xm, Sm, cells).candidates[0].size
                n = max(2, int(round(n * np.sqrt(target / got))))
            xs, Ss, xm, Sm, cells = problem(n, tri)
            t_all, seg = median_time(lambda: segment_faces(xs, Ss, xm, Sm, cells), a.repeat)
            pairs = seg.candidates
            t_seg, _ = median_time(lambda: segment_faces(xs, Ss, xm, Sm, cells, pairs=pairs),
                                   a.repeat)
            tracemalloc.start()
            segment_faces(xs, Ss, xm, Sm, cells)
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            m = pairs[0].size
            print(f"| {cells[0]}/{cells[1]} | {len(Ss)} | {m} | {seg.n} | {t_all:.3f} | "
                  f"{1e6 * t_all / m:.2f} | {1e6 * t_seg / m:.2f} | {peak / 2**20:.1f} | "
                  f"{peak / m / 1024:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
