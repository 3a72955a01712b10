"""Kratos' 3D frictionless contact patch tests against their exact answers (the
Kratos column of the 3D deck table; ours joins when the 3D contact pair lands).

    python benchmarks/kratos/side_by_side3d.py --out DIR [--repeat 3]
        [--kratos-python /work/kratos-venv/bin/python] [--stored-only]

For every deck of :data:`decks3d.DECKS`: Kratos run ``--repeat`` times, each a
fresh process on one thread (``run_kratos3d.py``; the wall clock around the
process is the whole-process time, the script's own ``time_run`` the analysis
time: model import, solve and finalize, Kratos' imports excluded), interleaved
rounds, medians reported; and Kratos' stored results (``data3d/*_results*.json``,
the reference its own test checks against) compared with the same exact answer.

Measures (:func:`kratos_errors`), against :func:`decks3d.exact_answer`:

* pressure: ``-AUGMENTED_NORMAL_CONTACT_PRESSURE`` on the nodes Kratos flags
  ``SLAVE`` and ``ACTIVE``, divided by the exact contact traction (``p``, per
  current area): its minimum and maximum over the slave nodes;
* displacement: the contact nodes' displacement along the load (``y`` in the
  patch decks, ``z`` in the simplest ones) divided by the exact one (the simplest
  decks: the continuum's, lower and upper face apart): its minimum and maximum.

Writes ``DIR/side_by_side3d.md`` and ``.json``.
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
from side_by_side import ONE_THREAD, compile_bytecode, timed  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
KRATOS_PYTHON = "/work/kratos-venv/bin/python"


def _ratios(ids: np.ndarray, u: np.ndarray, deck: decks3d.Deck, exact: dict) -> np.ndarray:
    """The displacements ``u`` of the contact nodes ``ids`` over their exact value."""
    if exact["kind"] == "patch":
        return u / exact["u_interface"]
    upper = np.isin(ids, deck.mdpa.parts[deck.slave_part]["nodes"])
    lower_part = next(n for n in deck.materials if n != deck.slave_part)
    if deck.mdpa.coords(deck.mdpa.parts[lower_part]["nodes"])[:, 2].max() > \
            deck.mdpa.coords(deck.mdpa.parts[deck.slave_part]["nodes"])[:, 2].max():
        upper = ~upper      # the slave is the lower part
    ref = np.where(upper, exact["u_interface_upper"], exact["u_interface"])
    return u / ref


def slave_weights(deck: decks3d.Deck) -> dict[int, float]:
    """``int N_i dA`` over the slave contact faces (reference, flat faces: a
    tri3 gives each vertex a third of its area, a parallelogram quad4 a quarter),
    by Kratos node id."""
    part = decks3d.parts(deck)[deck.slave_part]
    _, conn = part.faces_on(deck.mdpa.parts[deck.contact_part]["nodes"])
    X = part.mesh.p.T[conn]
    k = conn.shape[1]
    area = np.linalg.norm(np.cross(X[:, 1] - X[:, 0], X[:, -1] - X[:, 0]), axis=1)
    area *= 1.0 if k == 4 else 0.5
    w = np.zeros(part.ids.size)
    np.add.at(w, conn.ravel(), np.repeat(area / k, k))
    return {int(part.ids[i]): float(w[i]) for i in np.unique(conn)}


def kratos_errors(result: dict, deck: decks3d.Deck) -> dict:
    """Pressure and displacement ratios of a ``run_kratos3d.py`` result
    (module docstring); ``n_active`` the active slave nodes; ``p_mean`` the
    mean contact traction, the nodal pressures integrated with the slave faces'
    shape functions over their area (:func:`slave_weights`): the force the
    multiplier field carries per unit reference area."""
    exact = decks3d.exact_answer(deck)
    nodes = result["contact_nodes"]
    ids = np.array([n["id"] for n in nodes])
    u = np.array([n["u"][exact["axis"]] for n in nodes])
    act = np.array([n["slave"] and n["active"] for n in nodes])
    p = -np.array([n["augmented_pressure"] for n in nodes])[act]
    w = slave_weights(deck)
    wa = np.array([w[i] for i in ids[act]])
    r = _ratios(ids, u, deck, exact)
    out = {"n_active": int(act.sum()), "n_slave": len(w), "u_ratio_min": float(r.min()),
           "u_ratio_max": float(r.max()), "p_mean": float(p @ wa / sum(w.values()))}
    if exact["kind"] == "patch":
        out.update(p_ratio_min=float(p.min() / exact["pressure"]),
                   p_ratio_max=float(p.max() / exact["pressure"]))
    else:   # no exact pressure: the spread of the nodal values about their mean
        out.update(p_spread=float((p.max() - p.min()) / out["p_mean"]))
    return out


def stored_errors(deck: decks3d.Deck) -> dict:
    """The same ratios from Kratos' stored test results (``data3d``)."""
    exact = decks3d.exact_answer(deck)
    stem = os.path.join(decks3d.DATA, decks3d.DECKS[deck.name][3])
    with open(stem + ".json") as f:
        res = json.load(f)
    var = "DISPLACEMENT_" + "XYZ"[exact["axis"]]
    ids = np.array([int(k[5:]) for k in res if k.startswith("NODE_")])
    u = np.array([res[f"NODE_{i}"][var][-1] for i in ids])
    r = _ratios(ids, u, deck, exact)
    out = {"u_ratio_min": float(r.min()), "u_ratio_max": float(r.max())}
    if os.path.exists(stem + "_LM.json"):
        with open(stem + "_LM.json") as f:
            lm = json.load(f)
        p = -np.array([v["AUGMENTED_NORMAL_CONTACT_PRESSURE"][-1]
                       for k, v in lm.items() if k.startswith("NODE_")])
        p = p[p != 0.0]      # the test stores zeros on the inactive (master) nodes
        out.update(p_ratio_min=float(p.min() / exact["pressure"]),
                   p_ratio_max=float(p.max() / exact["pressure"]))
    return out


def fresh_runs(cases: list, repeat: int, out: str, command, env: dict) -> dict:
    """``repeat`` interleaved rounds of a fresh process per case (one thread, ``env``
    added): ``command(case, json_path)`` writes its JSON; per case the list of
    ``(whole-process seconds, the JSON)``.  ``case`` names the files (``str(case)``)."""
    env = {**os.environ, **ONE_THREAD, **env}
    runs: dict = {c: [] for c in cases}
    for i in range(repeat):
        for c in cases:
            stem = os.path.join(out, f"{'.'.join(map(str, c)) if isinstance(c, tuple) else c}.{i}")
            t, rc = timed(command(c, stem + ".json"), env, out, stem + ".log")
            if rc != 0:
                raise RuntimeError(f"the run failed on {c} (log {stem}.log)")
            with open(stem + ".json") as f:
                runs[c].append((t, json.load(f)))
    return runs


def _range(row: dict, key: str) -> str:
    lo, hi = row.get(f"{key}_ratio_min"), row.get(f"{key}_ratio_max")
    return "-" if lo is None else f"{lo:.4f} to {hi:.4f}"


def table(rows: list[dict]) -> str:
    """The Markdown table of :func:`main`'s rows."""
    head = ("| deck | faces (slave/master) | Kratos its | pressure / exact | mean traction | "
            "u / exact | stored u / exact | stored p / exact | analysis [s] | "
            "whole process [s] (n) |\n|---|---|---|---|---|---|---|---|---|---|\n")
    lines = []
    for r in rows:
        k, s = r.get("kratos", {}), r["stored"]
        p = _range(k, "p") if "p_ratio_min" in k else (
            f"no exact (spread {k['p_spread']:.2%})" if k else "-")
        lines.append(
            f"| {r['deck']} | {r['faces']} | {k.get('iterations', '-')} | {p} | "
            f"{k.get('p_mean', float('nan')):.5g} | "
            f"{_range(k, 'u') if k else '-'} | {_range(s, 'u')} | {_range(s, 'p')} | "
            f"{k.get('time_run', float('nan')):.3f} | "
            f"{k.get('time_whole', float('nan')):.2f} ({k.get('n', 0)}) |")
    return head + "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--kratos-python", default=KRATOS_PYTHON)
    ap.add_argument("--stored-only", action="store_true",
                    help="only the stored results against the exact answers (no Kratos)")
    a = ap.parse_args(argv)
    if a.repeat < 1:
        raise ValueError(f"--repeat must be >= 1, got {a.repeat}")
    os.makedirs(a.out, exist_ok=True)
    decks = {n: decks3d.read_deck(n) for n in decks3d.DECKS}
    runs: dict[str, list] = {n: [] for n in decks}
    if not a.stored_only:
        compile_bytecode(a.kratos_python)
        runs = fresh_runs(list(decks), a.repeat, a.out, lambda n, js: [
            a.kratos_python, os.path.join(HERE, "run_kratos3d.py"), n, js], {})
    rows = []
    for n, deck in decks.items():
        ps = decks3d.parts(deck)
        faces = "/".join("quad4" if ps[q].kind == "hex1" else "tri3" for q in (
            deck.slave_part, next(m for m in ps if m != deck.slave_part)))
        row = {"deck": n, "faces": faces, "exact": decks3d.exact_answer(deck),
               "stored": stored_errors(deck)}
        if runs[n]:
            last = runs[n][-1][1]
            row["kratos"] = {**kratos_errors(last, deck), "iterations": last["iterations"],
                             "time_run": statistics.median(r["time_run"] for _, r in runs[n]),
                             "time_whole": statistics.median(t for t, _ in runs[n]),
                             "n": len(runs[n]), "kratos_version": last["kratos_version"]}
        rows.append(row)
    with open(os.path.join(a.out, "side_by_side3d.json"), "w") as f:
        json.dump(rows, f, indent=1, default=float)
    with open(os.path.join(a.out, "side_by_side3d.md"), "w") as f:
        f.write(table(rows))
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
