"""Nothing lost: a run killed by a signal leaves every completed step readable,
and --resume continues to the same final answer as an uninterrupted run."""
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from skfem_mortar.io import read_checkpoint, read_series
from skfem_mortar.runner import run_scene

ARGS = ["block", "--set", "refine=5", "--set", "stretch=1.8", "--steps", "40"]


def cli(*args, **kw):
    return subprocess.Popen([sys.executable, "-m", "skfem_mortar.cli", "run", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


@pytest.mark.slow
def test_killed_run_resumes_to_the_same_answer(tmp_path):
    out = tmp_path / "killed"
    proc = cli(*ARGS, "--no-progress", "--out", str(out))
    ckpt = out / "checkpoint"
    deadline = time.time() + 120
    while time.time() < deadline:  # wait for the third completed step
        if (ckpt / "index.json").exists():
            try:
                if len(read_checkpoint(ckpt).history) >= 3:
                    break
            except (OSError, ValueError):
                pass  # a step file replaced between reading the index and the step
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run finished before it could be killed"
    done = len(read_checkpoint(ckpt).history)
    assert 3 <= done < 40
    frames = read_series(out / "block.pvd")  # every listed frame is complete
    assert len(frames) >= done + 1
    assert all(np.all(np.isfinite(m.point_data["displacement"])) for _, m in frames)
    assert not (out / "summary.json").exists()

    resumed = cli(*ARGS, "--no-progress", "--out", str(out), "--resume", "--json")
    stdout, stderr = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, stderr
    summary = json.loads(stdout)
    whole = run_scene("block", {"refine": 5, "stretch": 1.8}, steps=40)
    assert len(summary["steps"]) == len(whole["steps"]) == 40
    # the resumed run repeats the same sequence of Newton solves from the same
    # checkpointed state, so it agrees to round-off (1e-12 relative)
    for key in ("nominal_stress", "lateral_stretch"):
        assert np.isclose(summary["metrics"][key], whole["metrics"][key], rtol=1e-12, atol=0)
    assert len(read_series(out / "block.pvd")) == 41


def test_resume_refuses_a_checkpoint_of_another_run(tmp_path):
    run_scene("block", {"refine": 1}, steps=2, out=tmp_path)
    with pytest.raises(ValueError, match="belongs to another run"):
        run_scene("block", {"refine": 2}, steps=2, out=tmp_path, resume=True)


def test_resume_of_a_finished_run_changes_nothing(tmp_path):
    first = run_scene("block", {"refine": 1}, steps=3, out=tmp_path)
    again = run_scene("block", {"refine": 1}, steps=3, out=tmp_path, resume=True)
    assert again["metrics"] == first["metrics"]
    assert len(again["steps"]) == 3
