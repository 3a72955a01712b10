"""A Dask study survives a grid point that kills its worker again and again."""
import csv
import os
import time

import pytest

from skfem_mortar.app import study
from skfem_mortar.app.study import run_study

pytest.importorskip("distributed", reason="dask.distributed is not installed")


def test_a_point_that_kills_its_worker_is_a_failed_row(tmp_path, monkeypatch):
    import killer

    here = os.path.dirname(killer.__file__)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [here] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    monkeypatch.setattr(study, "execute", killer.execute)
    t0 = time.perf_counter()
    rows = run_study(["ring"], tmp_path, quick=True, sets={"n_elements": "8,10,16"},
                     workers=2)
    assert time.perf_counter() - t0 < 60
    by_n = {int(r["param.n_elements"]): r for r in rows}
    assert sorted(by_n) == [8, 10, 16]
    assert by_n[10]["status"].startswith("failed: worker died")
    assert by_n[8]["status"] == by_n[16]["status"] == "ok"
    with open(tmp_path / "results.csv", newline="") as f:
        written = list(csv.DictReader(f))
    assert [w["status"] for w in written] == [r["status"] for r in rows]
    report = (tmp_path / "report.md").read_text()
    assert "failed: worker died" in report



def test_no_progress_study_on_workers_prints_nothing_of_dask(tmp_path):
    """`study --workers 1 --no-progress` as a user runs it (a process of its own:
    in pytest the root logger's handler is pytest's): dask's scheduler and nanny
    log their start and stop at INFO into the command line's handler unless kept
    to warnings; a quiet study writes only its closing line (stdout)."""
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-m", "skfem_mortar.app.cli", "study", "--scene",
                           "block", "--quick", "--workers", "1", "--no-progress",
                           "--out", str(tmp_path / "st")],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "distributed" not in proc.stderr and "INFO" not in proc.stderr, proc.stderr
    assert "runs (0 failed)" in proc.stdout
