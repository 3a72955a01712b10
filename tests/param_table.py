"""The hostile-value table of every scene parameter, and a probe that runs it.

``TABLE`` lists, for every (scene, parameter, hostile value), what must
happen: ``"refuse"`` (a one-line ValueError naming the parameter) or
``"valid"`` (the value is in the parameter's range: the scene must build, and
its run must work or be refused cleanly). Used by ``tests/test_scene_params.py``;
``python tests/param_table.py`` prints the per-category count of cases handled
cleanly by the ``skfem_mortar`` on ``PYTHONPATH`` (each case in a forked child
with a 5 s alarm and a 3 GB address-space limit, so that an old version that
allocates or hangs is measured, not waited for).
"""
from __future__ import annotations

import json
import math
import os
import resource
import signal
import sys
import time

#: category -> the Python value passed to ``build_scene``
VALUES = {"nan": math.nan, "inf": math.inf, "1e308": 1e308, "1e-308": 1e-308, "0": 0,
          "-1": -1, "''": "", "1e9": 10 ** 9}

#: valid values whose build takes longer than the 5 s a hostile value may: (scene, param,
#: category) -> seconds allowed, with why (measured on 2 quiet cores)
SLOW_BUILDS = {("hertz3d", "refine", "-1"): 30.0}   # 9.2e4 dofs: 1.5 s hex1, 1.9 s tet1

#: per scene, the parameters for which a hostile value lies in the range:
#: {param: categories that are valid}. Every other (parameter, category) is refused.
VALID = {
    "block": {"nu": {"0"}, "refine": {"0"}, "distort": {"0"}},
    "ring": {"tension_only": {"0"}, "tension_floor": {"0"}},
    "cable_arc": {"tension_only": {"0"}, "tension_floor": {"0"}},
    "cable_flat": {},
    "patch": {"nu": {"0"}, "offset": {"0"}},
    "hertz": {"nu": {"0"}, "nu_base": {"0"}, "refine": {"0", "-1"}},
    "ironing": {"slide": {"0"}, "x_start": {"0"}, "nu": {"0"}, "mu": {"0"}},
    "seed": {"nu_cushion": {"0"}, "refine_cushion": {"0"}, "mu": {"0"}},
    "thick_sphere": {"nu": {"0"}},
    "block3d": {"shear": {"0", "-1"}, "nu": {"0"}, "distort": {"0"}},
    "thick_sphere3d": {"nu": {"0"}},
    "cantilever3d": {"nu": {"0"}},
    "tied3d": {"nu": {"0"}},
    "patch3d": {"nu": {"0"}, "margin": {"0"}, "distort": {"0"}},
    "hertz3d": {"nu": {"0"}, "nu_base": {"0"}, "refine": {"-1"}},
    "hertz_axi": {"nu": {"0"}, "nu_base": {"0"}, "refine": {"0", "-1"}},
    "oring": {"mu": {"0"}, "hold_centre": {"0"}, "refine": {"0", "-1"}},
    "seed_axi": {"tube": {"0"}, "nu_tube": {"0"}, "refine": {"0", "-1"}},
}


def table() -> list[tuple[str, str, str, str]]:
    """``(scene, parameter, category, expected)`` for every scene parameter; the
    ``1e9`` category only for integer parameters (sizes, counts, levels)."""
    from skfem_mortar.scenes import list_scenes

    rows = []
    for scene in list_scenes():
        for p in scene.params:
            for cat in VALUES:
                if cat == "1e9" and p.kind is not int:
                    continue
                valid = cat in VALID.get(scene.name, {}).get(p.name, set())
                rows.append((scene.name, p.name, cat, "valid" if valid else "refuse"))
    return rows


def _child(scene: str, param: str, value, run: bool) -> dict:
    from skfem_mortar.app.runner import build_scene, run_scene

    t0 = time.perf_counter()
    try:
        build_scene(scene, {param: value})
    except ValueError as exc:
        return {"outcome": "refused", "message": str(exc), "time": time.perf_counter() - t0}
    if not run:
        return {"outcome": "accepted", "time": time.perf_counter() - t0}
    try:
        run_scene(scene, {param: value})
    except ValueError as exc:
        return {"outcome": "run-refused", "message": str(exc),
                "time": time.perf_counter() - t0}
    return {"outcome": "ran", "time": time.perf_counter() - t0}


def probe(scene: str, param: str, category: str, run: bool = False,
          seconds: int = 5, memory_gb: float = 3.0) -> dict:
    """One case in a forked child: its outcome (``refused``, ``accepted``, ``ran``,
    ``run-refused``, ``error: <type>``, ``timeout``), message and time."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # child
        os.close(r)
        limit = int(memory_gb * 2 ** 30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        signal.alarm(seconds)
        try:
            out = _child(scene, param, VALUES[category], run)
        except BaseException as exc:  # noqa: BLE001 - the probe classifies it
            out = {"outcome": f"error: {type(exc).__name__}", "message": str(exc)[:300]}
        with os.fdopen(w, "w") as f:
            f.write(json.dumps(out))
        os._exit(0)
    os.close(w)
    with os.fdopen(r) as f:
        text = f.read()
    _, status = os.waitpid(pid, 0)
    if not text:
        sig = os.WTERMSIG(status) if os.WIFSIGNALED(status) else None
        return {"outcome": "timeout" if sig == signal.SIGALRM else f"died: {status}"}
    return json.loads(text)


def clean(case: tuple[str, str, str, str], result: dict) -> bool:
    """Whether the outcome is a clean one for the case's expectation."""
    scene, param, category, expected = case
    named = param in result.get("message", "") and "\n" not in result.get("message", "")
    if result["outcome"] == "refused":
        return named
    if expected == "refuse":
        return False
    return result["outcome"] in ("accepted", "ran", "run-refused")


def main() -> None:
    """Probe the whole table; print the per-category counts and the unclean cases."""
    run = "--run" in sys.argv
    counts: dict[str, list[int]] = {c: [0, 0] for c in VALUES}
    bad = []
    for case in table():
        res = probe(*case[:3], run=run and case[3] == "valid", seconds=60 if run else 5)
        ok = clean(case, res)
        counts[case[2]][0] += ok
        counts[case[2]][1] += 1
        if not ok:
            bad.append((case, res))
    for case, res in bad:
        print("UNCLEAN", case, res.get("outcome"), res.get("message", "")[:160])
    print("category  clean/total")
    for cat, (ok, n) in counts.items():
        print(f"{cat:>8}  {ok}/{n}")
    total = sum(c[0] for c in counts.values()), sum(c[1] for c in counts.values())
    print(f"{'all':>8}  {total[0]}/{total[1]}")


if __name__ == "__main__":
    main()
