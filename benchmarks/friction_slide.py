"""What friction costs on the ``slide`` scene: Newton iterations per phase and one assembly.

Runs the scene (displacement control: press, partial slip, gross sliding) with
Coulomb friction and the same model without friction (the block's top then
slides it freely), for each method, and prints

* the Newton iterations per step of each phase (pressing; pushing while some
  node sticks; gross sliding), with and without friction;
* the time of one contact-pair assembly with its tangent at the converged end
  state (median of repeats), with and without friction, and of the whole model's.

Usage: ``python benchmarks/friction_slide.py [n] [repeats]`` (one core, a shared
machine: the times are indicative).
"""
from __future__ import annotations

import sys

import numpy as np

from skfem_mortar.app.runner import build_scene
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.solver.stepping import solve

from friction_cost import _median_time as _timed  # benchmarks/ (run as a script)


def _pair(model):
    return next(it for it in model.items if isinstance(it, ContactPair))


def run(method: str, n: int, repeats: int) -> dict:
    out = {}
    for label, friction in (("friction", True), ("frictionless", False)):
        setup, values, _ = build_scene("slide", {"n": n}, method)
        model = setup.model
        if not friction:  # the same model with a frictionless pair in its place
            from skfem_mortar.core.model import Model
            p = _pair(model)
            plain = ContactPair(p.slave, p.master, method, name="contact")
            model = Model([plain if it is p else it for it in model.items])
        res = solve(model, setup.n_steps)
        pair = _pair(model)
        t = np.asarray(res.load_factors[1:])
        its = np.asarray([s.newton_iterations for s in res.steps])
        stick = np.asarray([s.info.get("n_stick", 0) for s in res.steps])
        press = t <= values["t_press"] + 1e-12
        phases = {"press": press, "partial": ~press & (stick > 0),
                  "sliding": ~press & (stick == 0)}
        if not friction:  # the phases of the friction run, by load factor
            phases = {k: np.isin(np.round(t, 12), np.round(v, 12))
                      for k, v in out["friction"]["phase_lf"].items()}
        z = res.z
        t_pair = _timed(lambda: pair.assemble(z, 1.0, tangent=True), repeats)
        t_model = _timed(lambda: model.assemble(z, 1.0, tangent=True), repeats)
        out[label] = {"iterations": {k: its[m].tolist() for k, m in phases.items()},
                      "phase_lf": {k: t[m] for k, m in phases.items()},
                      "pair_assembly_ms": 1e3 * t_pair, "model_assembly_ms": 1e3 * t_model,
                      "steps": len(res.steps)}
    return out


def main(argv: list[str]) -> None:
    n = int(argv[1]) if len(argv) > 1 else 40
    repeats = int(argv[2]) if len(argv) > 2 else 20
    for method in ("nts", "mortar", "mortar-dual"):
        r = run(method, n, repeats)
        print(f"== {method}, n = {n}")
        for label in ("friction", "frictionless"):
            d = r[label]
            its = ", ".join(f"{k} {np.mean(v):.2f} ({sum(v)} in {len(v)} steps)"
                            for k, v in d["iterations"].items() if v)
            print(f"  {label:12s} iterations/step: {its}; pair assembly "
                  f"{d['pair_assembly_ms']:.2f} ms, model {d['model_assembly_ms']:.2f} ms")


if __name__ == "__main__":
    main(sys.argv)
