import os
import sys

sys.path.insert(0, os.path.dirname(__file__))  # toy_items and shared helpers

import json  # noqa: E402

import pytest  # noqa: E402

#: ``SKFEM_MORTAR_RECORD=path``: every test appends one JSON line to ``path``
#: with its outcome and what its load steps did (benchmarks/extremes_table.py)
_RECORD = os.environ.get("SKFEM_MORTAR_RECORD")


@pytest.fixture(autouse=True)
def _record_load_steps(request, monkeypatch):
    """Counts, per test, the attempts of load steps (``stepping.newton_step``):
    converged steps, Newton iterations per converged step and failed attempts
    (step cuts).  Active only when ``SKFEM_MORTAR_RECORD`` names a file."""
    if not _RECORD:
        yield
        return
    import skfem_mortar.stepping as stepping
    seen = {"iterations": [], "cuts": 0}
    real = stepping.newton_step

    def counting(*args, **kwargs):
        rep = real(*args, **kwargs)
        if rep.converged:
            seen["iterations"].append(rep.iterations)
        else:
            seen["cuts"] += 1
        return rep
    monkeypatch.setattr(stepping, "newton_step", counting)
    request.node._load_steps = seen  # filled during the call, read by the report hook
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    rep = outcome.get_result()
    if not _RECORD or rep.when != "call":
        return
    seen = getattr(item, "_load_steps", None) or {"iterations": [], "cuts": 0}
    with open(_RECORD, "a") as f:
        f.write(json.dumps({"test": item.nodeid, "outcome": rep.outcome,
                            "doc": (item.function.__doc__ or "").strip().split("\n")[0],
                            **seen}) + "\n")
