"""Every refusal of the command line (issue #14): exit 2 within seconds, one
line on stderr naming the option and what it allows, no traceback; exit 1 means
only "did not converge" (a write error is 3, a bug 4 with its traceback)."""
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import skfem_mortar.app.runner as runner
from skfem_mortar.app.cli import main

ROOT = Path(__file__).resolve().parents[1]
#: a refusal comes before any model is built: the interpreter and the package's
#: imports (about 1 s) are all it costs; 5 s leaves room for a loaded 2-core machine
MAX_S = 5.0

CASES = {
    "out-is-a-file": (["run", "block", "--out", "{file}"], "--out"),
    "out-empty": (["run", "block", "--out", ""], "--out"),
    "resume-without-out": (["run", "block", "--resume"], "--resume needs --out"),
    "replace-without-out": (["run", "block", "--replace"], "--replace needs --out"),
    "resume-and-replace": (["run", "block", "--resume", "--replace", "--out", "{dir}"],
                           "--resume and --replace"),
    "set-repeated": (["run", "block", "--set", "refine=1", "--set", "refine=2"],
                     "--set refine given twice"),
    "set-without-equals": (["run", "block", "--set", "refine"], "NAME=VALUE"),
    "run-steps-0": (["run", "block", "--steps", "0"], "--steps: must be an integer >= 1"),
    "bench-max-dofs-0": (["bench", "--max-dofs", "0"], "--max-dofs: must be an integer >= 1"),
    "bench-steps-x": (["bench", "--steps", "x"], "--steps: must be an integer >= 1"),
    "bench-out-is-a-file": (["bench", "--out", "{file}"], "--out"),
    "study-steps": (["study", "--scene", "block", "--steps", "5,0"],
                    "--steps: must be integers >= 1"),
    "study-workers": (["study", "--scene", "block", "--workers", "-1"],
                      "--workers: must be an integer >= 0"),
    "study-tolerance-inf": (["study", "--scene", "block", "--tolerance", "inf"],
                            "--tolerance: must be a finite number > 0"),
    "study-tolerance-0": (["study", "--scene", "block", "--tolerance", "0"],
                          "--tolerance: must be a finite number > 0"),
    "demo-out-is-a-file": (["demo", "--out", "{file}"], "--out"),
    "unknown-scene": (["run", "no-such-scene"], "unknown scene 'no-such-scene'"),
}


@pytest.mark.parametrize("name", CASES)
def test_a_refusal_is_one_line_and_exit_2(name, tmp_path):
    argv, says = CASES[name]
    (tmp_path / "a_file").write_text("not a directory")
    argv = [a.format(file=tmp_path / "a_file", dir=tmp_path / "d") for a in argv]
    t0 = time.monotonic()
    proc = subprocess.run([sys.executable, "-m", "skfem_mortar.app.cli", *argv],
                          capture_output=True, text=True, timeout=60, cwd=tmp_path,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    elapsed = time.monotonic() - t0
    assert proc.returncode == 2, proc.stderr
    assert elapsed < MAX_S, f"{elapsed:.1f} s"
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert says in lines[0]
    assert proc.stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]  # nothing written


def test_a_bug_is_a_traceback_and_exit_4_not_1(monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise RuntimeError("a bug")

    monkeypatch.setattr(runner, "run_scene", broken)
    assert main(["run", "block"]) == 4
    err = capsys.readouterr().err
    assert "Traceback" in err and "RuntimeError: a bug" in err and "internal error" in err


def test_a_write_error_is_exit_3_not_1(monkeypatch, capsys):
    def full(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(runner, "run_scene", full)
    assert main(["run", "block"]) == 3
    assert "No space left on device" in capsys.readouterr().err


def test_help_is_exit_0(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", "--help"])
    assert exc.value.code == 0
    assert "--replace" in capsys.readouterr().out
