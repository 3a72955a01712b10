"""Our column of the 3D deck table: ``run_ours3d.py`` on every deck and method, fresh
processes, the same measures as Kratos' (``side_by_side3d.kratos_errors``).

    python benchmarks/kratos/ours_column3d.py --out DIR [--repeat 3]
        [--methods nts mortar mortar-dual]

Per deck and method: ``--repeat`` fresh processes (one thread), interleaved rounds,
medians of the analysis time (build and solve, ``run_ours3d``'s ``time_run``) and of
the whole process (the wall clock around it, imports included).  Pressure: our nodal
traction (``ContactPair.pressure_and_gap``, per current area) over the exact ``p``
(patch decks), its minimum and maximum over the slave nodes; ``u``: the slave nodes'
displacement along the load over the exact one.  The non-matching patch deck runs
twice: as given, and with the punch's supports moved with the exact lateral expansion
(``run_ours3d.consistent_supports``: the deck as given lets the punch slide on the
foundation by ``e 4.7``, so its solution is not the uniform state).  (The matching
deck's foundation supports turn it by ``w = e``: no uniform solution at the level
``w^2`` with small-strain elements, README.)  Writes
``DIR/ours3d.md`` and ``.json``.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import decks3d  # noqa: E402
from side_by_side3d import _ratios, fresh_runs  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def errors(result: dict, deck: decks3d.Deck) -> dict:
    """Pressure and displacement ratios of a ``run_ours3d.py`` result."""
    exact = decks3d.exact_answer(deck)
    nodes = result["slave_nodes"]
    ids = np.array([n["id"] for n in nodes])
    u = np.array([n["u"][exact["axis"]] for n in nodes])
    p = np.array([n["pressure"] for n in nodes])
    r = _ratios(ids, u, deck, exact)
    out = {"u_ratio_min": float(r.min()), "u_ratio_max": float(r.max()),
           "n_active": int(sum(n["active"] for n in nodes))}
    if exact["kind"] == "patch":
        out.update(p_ratio_min=float(p.min() / exact["pressure"]),
                   p_ratio_max=float(p.max() / exact["pressure"]))
    else:
        out.update(p_spread=float((p.max() - p.min()) / p.mean()), p_mean=float(p.mean()))
    return out


def _cases(methods: list[str]) -> list[tuple[str, str, bool]]:
    out = []
    for n in decks3d.DECKS:
        for m in methods:
            out.append((n, m, False))
            if n == "patch_nonmatching":
                out.append((n, m, True))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--methods", nargs="+", default=["nts", "mortar", "mortar-dual"])
    a = ap.parse_args(argv)
    if a.repeat < 1:
        raise ValueError(f"--repeat must be >= 1, got {a.repeat}")
    os.makedirs(a.out, exist_ok=True)
    cases = _cases(a.methods)
    runs = fresh_runs(cases, a.repeat, a.out, lambda c, js: [
        sys.executable, os.path.join(HERE, "run_ours3d.py"), c[0], c[1], js]
        + (["--consistent"] if c[2] else []), {"PYTHONWARNINGS": "ignore"})
    rows = []
    for c in cases:
        last = runs[c][-1][1]
        rows.append({"deck": c[0], "method": c[1], "consistent": c[2],
                     "iterations": last["iterations"], "converged": last["converged"],
                     **errors(last, decks3d.read_deck(c[0])),
                     "time_run": statistics.median(r["time_run"] for _, r in runs[c]),
                     "time_whole": statistics.median(t for t, _ in runs[c]),
                     "n": len(runs[c])})
    with open(os.path.join(a.out, "ours3d.json"), "w") as f:
        json.dump(rows, f, indent=1)
    with open(os.path.join(a.out, "ours3d.md"), "w") as f:
        f.write(table(rows))
    print(table(rows))
    return 0



def table(rows: list[dict]) -> str:
    head = ("| deck | supports | method | Newton its | pressure / exact | max abs(p / exact - 1) "
            "| u / exact | analysis [s] | whole process [s] (n) |\n"
            "|---|---|---|---|---|---|---|---|---|\n")
    lines = []
    for r in rows:
        p = (f"{r['p_ratio_min']:.4f} to {r['p_ratio_max']:.4f} | "
             f"{max(abs(r['p_ratio_min'] - 1), abs(r['p_ratio_max'] - 1)):.1e}"
             if "p_ratio_min" in r else f"no exact (spread {r['p_spread']:.2%}) | -")
        lines.append(f"| {r['deck']} | {'moved' if r['consistent'] else 'as given'} | "
                     f"{r['method']} | {r['iterations']} | {p} | {r['u_ratio_min']:.4f} to "
                     f"{r['u_ratio_max']:.4f} | {r['time_run']:.2f} | {r['time_whole']:.2f} "
                     f"({r['n']}) |")
    return head + "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
