"""Which tests ask for the linear solver: CI's second step reruns only those.

``SKFEM_MORTAR_SOLVER`` changes a run in one place only: the backend
:func:`skfem_mortar.solver.linsolve.default_backend` returns (every solve that
names no backend asks it), and only where the test does not set it itself.  A
test that never asks it so, and starts no process (a process inherits the
variable), gives the same result under SuperLU as under PARDISO, so the second
run of it under SuperLU checks nothing new.

``SKFEM_MORTAR_SOLVER_LOG=path`` (CI's first step): every test that passed
without asking (with the variable unset) appends ``{"quiet": nodeid}`` to
``path``; every fixture whose set-up asked appends ``{"fixture": [baseid, name]}`` (a module-scoped fixture
solves in the set-up of whichever test comes first on its worker, the others
only read it: they must rerun too).

``SKFEM_MORTAR_SOLVER_ONLY=path`` (CI's second step): deselect the tests that
``path`` lists as quiet and that use none of the fixtures that asked.  A test
the log does not name (failed, skipped for a missing extra, new since) runs:
unknown means kept, so the list cannot go stale towards skipping a solve.
"""
import json
import multiprocessing.process
import os
import subprocess

import pytest

_LOG = os.environ.get("SKFEM_MORTAR_SOLVER_LOG")
_ONLY = os.environ.get("SKFEM_MORTAR_SOLVER_ONLY")
#: how many times a solve asked for the backend or a process was started
_ASKED = [0]


def _counted(function, unless_set: str | None = None):
    def counted(*args, **kwargs):
        if unless_set is None or unless_set not in os.environ:
            _ASKED[0] += 1
        return function(*args, **kwargs)
    counted.__wrapped__ = function
    return counted


def install() -> None:
    """With ``SKFEM_MORTAR_SOLVER_LOG``: count the asks and the processes."""
    if not _LOG:
        return
    if os.environ.get("SKFEM_MORTAR_SOLVER"):
        raise pytest.UsageError("SKFEM_MORTAR_SOLVER_LOG logs the default backend's run: "
                                "unset SKFEM_MORTAR_SOLVER")
    import skfem_mortar.solver.linsolve as linsolve
    # an ask while the test itself sets SKFEM_MORTAR_SOLVER (monkeypatch, a
    # study's solver column) gets the test's backend under CI's too: not counted
    linsolve.default_backend = _counted(linsolve.default_backend, "SKFEM_MORTAR_SOLVER")
    subprocess.Popen.__init__ = _counted(subprocess.Popen.__init__)
    process = multiprocessing.process.BaseProcess
    process.start = _counted(process.start)
    os.fork = _counted(os.fork)


def _write(entry: dict) -> None:
    with open(_LOG, "a") as f:  # one short line: appends from workers interleave whole
        f.write(json.dumps(entry) + "\n")


@pytest.hookimpl(hookwrapper=True)
def pytest_fixture_setup(fixturedef, request):
    before = _ASKED[0]
    yield
    if _LOG and _ASKED[0] != before:
        _write({"fixture": [fixturedef.baseid, fixturedef.argname]})


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    before = _ASKED[0]
    item._solver_passed = True
    yield
    if _LOG and _ASKED[0] == before and item._solver_passed:
        _write({"quiet": item.nodeid})


def note(item, rep) -> None:
    """A phase that did not pass: the test is not logged quiet (unknown: kept)."""
    if not rep.passed:
        item._solver_passed = False


def pytest_collection_modifyitems(config, items):
    """With ``SKFEM_MORTAR_SOLVER_ONLY``: deselect the quiet tests."""
    if not _ONLY:
        return
    quiet, asking = set(), set()
    with open(_ONLY) as f:
        for line in f:
            entry = json.loads(line)
            if "quiet" in entry:
                quiet.add(entry["quiet"])
            else:
                asking.add(tuple(entry["fixture"]))
    keep, drop = [], []
    for item in items:
        info = getattr(item, "_fixtureinfo", None)
        defs = info.name2fixturedefs.values() if info is not None else ()
        uses = any((d.baseid, d.argname) in asking for ds in defs for d in ds)
        (drop if item.nodeid in quiet and not uses else keep).append(item)
    if drop:
        config.hook.pytest_deselected(items=drop)
        items[:] = keep
