"""The cost of one mortar slip evaluation against one frictionless mortar evaluation.

    python benchmarks/friction_cost.py [n_segments]

Both with the tangent and the second derivatives (``G``, ``H``), on a curved
slave of ``n_segments`` segments (default 25) over a finer curved master; the
median of repeated calls (one core, whatever else the machine runs).
"""
from __future__ import annotations

import sys
import time

import numpy as np

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.slip import mortar_history, mortar_slip


def _median_time(f, repeat: int = 30) -> float:
    f()
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        t.append(time.perf_counter() - t0)
    return float(np.median(t))


def main(n_seg: int = 25) -> None:
    ns, nm = n_seg + 1, int(1.5 * n_seg) + 1
    X = np.linspace(0, 1, ns)
    xs0 = np.array([X, 0.3 * (X - 0.5) ** 2])
    Xm = np.linspace(1.2, -0.2, nm)
    xm0 = np.array([Xm, -1e-3 - 0.1 * (Xm - 0.4) ** 2])
    seg_s, seg_m = np.c_[np.arange(ns - 1), np.arange(1, ns)], np.c_[np.arange(nm - 1),
                                                                        np.arange(1, nm)]
    xs = xs0 + [[0.02], [0.0]]
    lam = np.ones(ns)
    for dual in (False, True):
        hist = mortar_history(xs0, seg_s, xm0, seg_m, space=("dual" if dual else "standard"))
        t_gap = _median_time(lambda: mortar_kernel.evaluate(xs, seg_s, xm0, seg_m, lam=lam, space=("dual" if dual else "standard")))
        t_slip = _median_time(lambda: mortar_slip(xs, seg_s, xm0, seg_m, hist["D_prev"],
                                                  hist["M_prev"], lam_t=lam, space=("dual" if dual else "standard")))
        print(f"{'dual' if dual else 'standard'}: {n_seg} slave segments: frictionless "
              f"evaluate {1e3 * t_gap:.2f} ms, slip {1e3 * t_slip:.2f} ms "
              f"(ratio {t_slip / t_gap:.2f})")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 25)
