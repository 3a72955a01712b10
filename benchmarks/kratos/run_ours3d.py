"""Our model of one of Kratos' 3D contact decks (``decks3d.py``), solved, its contact
nodes' results written as JSON: our column of the 3D deck table (``side_by_side3d.py``).

    python benchmarks/kratos/run_ours3d.py DECK METHOD OUT.json [--steps 1] [--consistent]

``DECK`` a key of :data:`decks3d.DECKS`, ``METHOD`` ``nts``, ``mortar`` or
``mortar-dual``.  The model is :func:`decks3d.build_model` with the contact pair of
the deck's slave and master faces (:func:`pair_factory`): bodies, Dirichlet data and
the follower pressure as the deck gives them, solved in ``--steps`` load steps (Kratos:
one step, ``time_step`` 1.1 past ``end_time`` 1).  Written: the Newton iterations,
the analysis time (the model's build and solve; the imports timed apart as
``time_import``), and per slave node (Kratos node id) the current position, the
displacement and our pressure (the method's own nodal traction,
``ContactPair.pressure_and_gap``: per current area, as Kratos' mortar integrals).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

T0 = time.perf_counter()

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import decks3d  # noqa: E402
from skfem_mortar.contact.pair import ContactPair  # noqa: E402
from skfem_mortar.contact.surfaces import ContactSurface  # noqa: E402
from skfem_mortar.solver.stepping import solve  # noqa: E402

T_IMPORT = time.perf_counter() - T0
METHODS = ("nts", "mortar", "mortar-dual")


def surface(face: decks3d.Face, name: str) -> ContactSurface:
    """A deck's contact face (outward tri3/quad4 cells of body vertices) as our surface."""
    nodes = np.unique(face.conn)
    return ContactSurface(face.body, nodes, np.searchsorted(nodes, face.conn), name=name,
                          cell=face.cell)


def pair_factory(method: str):
    """The ``contact_pair_factory`` of :func:`decks3d.build_model` for ``method``."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    return lambda s, m: ContactPair(surface(s, "slave"), surface(m, "master"), method,
                                    name="contact")


def consistent_supports(deck: decks3d.Deck) -> decks3d.Deck:
    """The non-matching patch deck with the punch's in-plane supports moved with
    the foundation's exact lateral expansion: ``u_c = e X_c`` (``c`` = x, z; ``e`` the
    exact lateral strain) at each of its held nodes instead of 0.

    The deck holds the foundation at its corner (0, 0, 0) (and (0, 0, 8)) and the
    punch at (4.7, 6, 4.7) (and (6, 6, 4.7), (4.7, 6, 6)): both expand laterally by
    ``e``, each about its own held point, so the punch slides on the foundation by
    ``e 4.7`` (0.014 at ``e = 0.003``) and the slave's footprint edges no longer meet the
    master's: the deck's solution is not the uniform state of :func:`decks3d.exact_answer`.
    With these supports it is, so the patch test is the deck's own but for that slide."""
    exact = decks3d.exact_answer(deck)
    if deck.name != "patch_nonmatching":
        raise ValueError(f"consistent supports are for patch_nonmatching, got {deck.name!r}")
    e = exact["lateral_strain"]
    top = max(deck.materials, key=lambda n: deck.mdpa.coords(
        deck.mdpa.parts[n]["nodes"])[:, 1].min())
    mine = set(deck.mdpa.parts[top]["nodes"].tolist())
    out = []
    for part, fixed, value in deck.dirichlet:
        ids = deck.mdpa.parts[part]["nodes"]
        if ids.size and set(ids.tolist()) <= mine:
            X = deck.mdpa.coords(ids)
            if ids.size != 1:
                raise ValueError(f"support {part!r} must hold one node to be moved")
            value = np.where(fixed & np.array([True, False, True]), e * X[0], value)
        out.append((part, fixed, value))
    deck.dirichlet = out
    return deck


def run(deck_name: str, method: str, steps: int = 1, consistent: bool = False) -> dict:
    """Build and solve (``consistent``: :func:`consistent_supports`); the result
    dictionary of the module docstring."""
    t0 = time.perf_counter()
    deck = decks3d.read_deck(deck_name)
    if consistent:
        deck = consistent_supports(deck)
    model, info = decks3d.build_model(deck, pair_factory(method))
    pair = model.item("contact")
    res = solve(model, steps)
    t_run = time.perf_counter() - t0
    z = res.z
    slave = info["slave"]
    body = slave.body
    nodes = pair.slave.nodes
    u = (pair.slave.x(z) - body.X[:, nodes]).T
    p = pair.pressure_and_gap(z)[0]
    ids = decks3d.parts(deck)[deck.slave_part].ids[nodes]
    return {"deck": deck_name, "method": method, "consistent": consistent,
            "converged": bool(res.converged),
            "iterations": int(sum(s.newton_iterations for s in res.steps)),
            "steps": len(res.steps), "time_run": t_run, "time_import": T_IMPORT,
            "n_dofs": int(model.n_u),
            "slave_nodes": [{"id": int(i), "u": [float(c) for c in ui], "pressure": float(pi),
                             "active": bool(a)}
                            for i, ui, pi, a in zip(ids, u, p, pair.active)]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("deck", choices=sorted(decks3d.DECKS))
    ap.add_argument("method", choices=METHODS)
    ap.add_argument("out")
    ap.add_argument("--steps", type=int, default=1)
    ap.add_argument("--consistent", action="store_true",
                    help="the punch's supports moved with the exact expansion (patch decks)")
    a = ap.parse_args(argv)
    with open(a.out, "w") as f:
        json.dump(run(a.deck, a.method, a.steps, a.consistent), f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
