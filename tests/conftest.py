import os
import sys

sys.path.insert(0, os.path.dirname(__file__))  # toy_items and shared helpers

import json  # noqa: E402

import pytest  # noqa: E402

#: ``SKFEM_MORTAR_RECORD=path``: every test appends one JSON line to ``path``
#: with its outcome and what its load steps did (benchmarks/extremes_table.py)
_RECORD = os.environ.get("SKFEM_MORTAR_RECORD")


_CURRENT: dict = {"iterations": [], "cuts": 0}

#: ``SKFEM_MORTAR_REQUIRE_EXTRAS=1`` (CI's second step, after installing
#: ``[distributed]``; pypardiso comes with the default install): a test skipped
#: for a missing extra is a failure
_REQUIRE_EXTRAS = bool(os.environ.get("SKFEM_MORTAR_REQUIRE_EXTRAS"))


def pytest_configure(config):
    """With ``SKFEM_MORTAR_RECORD``: count the attempts of load steps
    (``stepping.newton_step``) of every test, including those of the
    module-scoped fixtures its set-up runs: converged steps, Newton iterations
    per converged step, failed attempts (step cuts)."""
    if not _RECORD:
        return
    import skfem_mortar.solver.stepping as stepping
    real = stepping.newton_step

    def counting(*args, **kwargs):
        rep = real(*args, **kwargs)
        if rep.converged:
            _CURRENT["iterations"].append(rep.iterations)
        else:
            _CURRENT["cuts"] += 1
        return rep
    stepping.newton_step = counting


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    global _CURRENT
    _CURRENT = item._load_steps = {"iterations": [], "cuts": 0}


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    rep = outcome.get_result()
    if _REQUIRE_EXTRAS and rep.skipped and call.excinfo is not None:
        why = str(call.excinfo.value)
        if "not installed" in why or "could not import" in why:
            rep.outcome = "failed"
            rep.longrepr = f"an extra is required here but missing: {why}"
    if not _RECORD or rep.when != "call":
        return
    seen = getattr(item, "_load_steps", None) or {"iterations": [], "cuts": 0}
    with open(_RECORD, "a") as f:
        f.write(json.dumps({"test": item.nodeid, "outcome": rep.outcome,
                            "doc": (item.function.__doc__ or "").strip().split("\n")[0],
                            **seen}) + "\n")

