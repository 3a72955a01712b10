"""Before/after comparison of ``skfem-mortar bench``: per-phase time per Newton iteration.

Usage::

    # 1. the numbers of a reference commit (its sources unpacked beside, not checked out)
    git archive <ref> | tar -x -C /tmp/ref
    python benchmarks/bench_compare.py run --src /tmp/ref --out /tmp/bench_before
    # 2. the numbers of the working tree
    python benchmarks/bench_compare.py run --out /tmp/bench_after
    # 3. one table
    python benchmarks/bench_compare.py table /tmp/bench_before /tmp/bench_after

``run`` uses the sizes of :data:`skfem_mortar.app.bench.SIZES` (``--scene``,
``--max-dofs``, ``--steps`` as for ``skfem-mortar bench``) and writes one JSON
line per size to ``rows.jsonl`` as soon as that size is done (a long run can be
stopped and its finished sizes kept).  ``--src`` runs another version of the
package (its directory goes first on ``PYTHONPATH`` of every worker process).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from skfem_mortar.app.bench import PHASES, SIZES, _one, fit_slopes


def run(args) -> None:
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    if args.src:
        src = str(Path(args.src).resolve())
        os.environ["PYTHONPATH"] = os.pathsep.join(
            [src] + [p for p in [os.environ.get("PYTHONPATH")] if p])
        # the workers run ``python -c``, whose sys.path starts with the current
        # directory: inside a checkout that is the checkout's package, not src's
        os.chdir(src)
    sizes = {s: SIZES[s] for s in args.scene}
    with open(out / "rows.jsonl", "a") as f:
        for scene, table in sizes.items():
            for params in table:
                row = _one(scene, params, args.method, args.steps)
                f.write(json.dumps(row) + "\n")
                f.flush()
                print(f"{scene} {params}: {row.get('n_dofs', '?')} dofs, {row['status']}",
                      file=sys.stderr)
                if row["status"] != "ok" or (args.max_dofs and row["n_dofs"] >= args.max_dofs):
                    break


def _rows(d: str) -> dict:
    out: dict = {}
    for line in Path(d, "rows.jsonl").read_text().splitlines():
        r = json.loads(line)
        if r.get("status") == "ok":
            # keyed by the size parameters (a scene's mesh may change by a few dofs
            # between versions); a rerun of a size replaces it
            out.setdefault(r["scene"], {})[json.dumps(r["params"], sort_keys=True)] = r
    return out


def table(args) -> None:
    before, after = _rows(args.before), _rows(args.after)
    for scene in sorted(set(before) | set(after)):
        b, a = before.get(scene, {}), after.get(scene, {})
        print(f"\n## {scene}: time per Newton iteration (ms), before -> after\n")
        print("| params | dofs | " + " | ".join(PHASES[:-1]) + " | total | contact share | "
              "max its/step |")
        print("|---" * (len(PHASES) + 4) + "|")
        for n in sorted(set(b) | set(a), key=lambda k: (b.get(k) or a.get(k))["n_dofs"]):
            cells = []
            for ph in PHASES[:-1] + ("total",):
                v = []
                for r in (b.get(n), a.get(n)):
                    if r is None:
                        v.append("-")
                        continue
                    t = r["time_per_iteration_s"]
                    s = sum(t.values()) if ph == "total" else t[ph]
                    v.append(f"{1e3 * s:.1f}")
                cells.append(" -> ".join(v))
            share = " -> ".join("-" if r is None else f"{100 * r['contact_share']:.1f} %"
                                for r in (b.get(n), a.get(n)))
            its = " -> ".join("-" if r is None else str(r["max_iterations_per_step"])
                              for r in (b.get(n), a.get(n)))
            dofs = " -> ".join("-" if r is None else str(r["n_dofs"]) for r in (b.get(n), a.get(n)))
            print(f"| {n} | {dofs} | " + " | ".join(cells) + f" | {share} | {its} |")
        for name, rows in (("before", b), ("after", a)):
            sl = fit_slopes(list(rows.values()))
            print(f"\nslopes {name}: " + ", ".join(f"{k} {v:.2f}" for k, v in sl.items()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--out", required=True)
    r.add_argument("--src", default=None, help="another version's source directory")
    r.add_argument("--scene", action="append", choices=sorted(SIZES))
    r.add_argument("--method", default="mortar")
    r.add_argument("--max-dofs", type=int, default=None)
    r.add_argument("--steps", type=int, default=None)
    t = sub.add_parser("table")
    t.add_argument("before")
    t.add_argument("after")
    args = ap.parse_args()
    if args.cmd == "run":
        args.scene = args.scene or sorted(SIZES)
        run(args)
    else:
        table(args)


if __name__ == "__main__":
    main()
