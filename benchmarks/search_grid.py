"""The contact search's grid (numpy) against scipy's ``cKDTree`` (issue 16).

    python benchmarks/search_grid.py [--sizes 1000 10000 100000] [--repeat 5]

For each size ``n``: ``n`` slave segments on a circle resting on a wavy line
of ``n`` master segments (Hertz-like: a contact zone, the rest apart; the
margin two element lengths), :func:`skfem_mortar.contact.search.box_pairs`
forced onto its grid and onto ``cKDTree.sparse_distance_matrix`` (its
``GRID_POINTS`` set to infinity and to 0; the rest of ``box_pairs`` the
same), and :func:`~skfem_mortar.contact.search.nearest_vertex` likewise
(its grid against ``cKDTree.query``).  Checks that both give the same pairs, distances and
indices, and prints the median times (one thread: set OMP_NUM_THREADS=1).
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from skfem_mortar.contact import search
from skfem_mortar.contact.search import segment_boxes


def surfaces(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Slave nodes on a circle of radius 1 resting on a wavy master line (jittered spacing)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(-1.2, 1.2, n + 1) + rng.uniform(-0.3, 0.3, n + 1) * 2.4 / n
    xs = np.stack([np.sin(t), 1.0 - np.cos(t)])
    u = np.linspace(-1.5, 1.5, n + 1)
    xm = np.stack([u, 1e-3 * np.sin(40 * u) - 1e-3])
    seg = np.stack([np.arange(n), np.arange(1, n + 1)], 1)
    return xs, xm, seg


def median_time(f, repeat: int) -> tuple[float, object]:
    ts, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts)), out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args(argv)
    print("| boxes | pairs | grid [ms] | cKDTree [ms] | nearest: grid [ms] | cKDTree [ms] |")
    print("|---|---|---|---|---|---|")
    for n in a.sizes:
        xs, xm, seg = surfaces(n)
        lo_a, hi_a = segment_boxes(xs, seg)
        lo_b, hi_b = segment_boxes(xm, seg)
        margin = 2.0 * 3.0 / n
        res = {}
        keep = search.GRID_POINTS
        try:
            for way, limit in (("grid", 10**12), ("tree", 0)):
                search.GRID_POINTS = limit
                res[way] = (median_time(lambda: search.box_pairs(lo_a, hi_a, lo_b, hi_b, margin),
                                        a.repeat),
                            median_time(lambda: search.nearest_vertex(xm, xs), a.repeat))
        finally:
            search.GRID_POINTS = keep
        (t_grid, (i_g, j_g)), (tn_grid, (d_g, k_g)) = res["grid"]
        (t_kd, (i_k, j_k)), (tn_kd, (d_k, k_k)) = res["tree"]
        if not (np.array_equal(i_g, i_k) and np.array_equal(j_g, j_k)):
            raise SystemExit(f"n = {n}: the grid's pairs differ from cKDTree's")
        if not (np.array_equal(d_g, d_k) and np.array_equal(k_g, k_k)):
            raise SystemExit(f"n = {n}: the nearest vertices differ from cKDTree's")
        print(f"| {n} | {i_g.size} | {1e3 * t_grid:.2f} | {1e3 * t_kd:.2f} | "
              f"{1e3 * tn_grid:.2f} | {1e3 * tn_kd:.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
