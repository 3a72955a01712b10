# %%
"""The extremes suite as a table: case, method, outcome, Newton iterations, step cuts.

Runs ``pytest -m extremes`` with ``SKFEM_MORTAR_RECORD`` set (tests/conftest.py
then records, per test, the Newton iterations of every converged load step and
the failed attempts, i.e. the step cuts) and writes ``docs/extremes_table.md``.

    python benchmarks/extremes_table.py [--out docs/extremes_table.md]

A test whose check is a clear failure (a ``ConvergenceError`` or
``ValueError`` with a named cause) passes when that failure happens; its row
says so.  The numbers each test checks (errors and their bounds) are in the
test's docstring, the cases in docs/robustness.md.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

METHODS = ("nts", "mortar", "mortar-dual")
CLEAR_FAILURE = re.compile(r"fail|refuse|bad|reject|raises|clear", re.I)


def _method(params: str, case: str) -> tuple[str, str]:
    """The contact method of a test (from its parameters, else its name) and the
    other parameters."""
    m = re.search(r"(?:^|-)(mortar-dual|mortar|nts)(?:-|$)", params)
    if m:
        rest = (params[:m.start()] + "-" + params[m.end():]).strip("-")
        return m.group(1), rest
    m = re.search(r"(?:^|_)(nts|mortar)(?:_|$)", case)
    return (m.group(1) if m else "-"), params


def rows_from(records: list[dict]) -> list[tuple[str, str, str, str, str]]:
    """(case, method, outcome, iterations, cuts) per recorded test."""
    out = []
    for r in records:
        name = r["test"].split("::", 1)[1]
        m = re.match(r"(.*?)\[(.*)\]$", name)
        case, params = (m.group(1), m.group(2)) if m else (name, "")
        method, params = _method(params, case)
        params = params.replace("\\", "")  # pytest escapes the backslashes of ids
        label = case.removeprefix("test_").replace("_", " ") + (f" [{params}]" if params else "")
        its = r["iterations"]
        if r["outcome"] != "passed":
            outcome = "FAILED"
        elif "test_bad_input" in r["test"] and not case.startswith("test_valid"):
            outcome = "ValueError naming the input, as checked"
        elif CLEAR_FAILURE.search(case):
            outcome = "clear failure, as checked"
        elif its:
            outcome = "converged, check held"
        else:
            outcome = "check held (on an earlier test's run, or no solve)"
        it = f"max {max(its)} over {len(its)} steps" if its else "-"
        out.append((label, method, outcome, it, str(r["cuts"])))
    return out


def to_markdown(rows) -> str:
    lines = ["| case | method | outcome | Newton iterations per step | step cuts |",
             "|---|---|---|---|---|"]
    lines += [f"| {' | '.join(r)} |" for r in rows]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/extremes_table.md")
    args = ap.parse_args(argv)
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as tmp:
        rec = Path(tmp) / "record.jsonl"
        env = dict(os.environ, SKFEM_MORTAR_RECORD=str(rec))
        proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                               "-m", "extremes", "tests"], cwd=root, env=env)
        records = [json.loads(line) for line in rec.read_text().splitlines()]
    body = to_markdown(rows_from(records))
    out = root / args.out
    tmp_out = out.with_suffix(".tmp")
    tmp_out.write_text("# The extremes suite, case by case\n\nWritten by "
                       "`python benchmarks/extremes_table.py` from one run of "
                       "`pytest -m extremes` (tests/conftest.py records the load steps). "
                       "Errors and their bounds: each test's docstring; the cases: "
                       "docs/robustness.md.\n\n" + body)
    os.replace(tmp_out, out)
    print(body)
    return proc.returncode


if __name__ == "__main__":
    sys.exit(main())
