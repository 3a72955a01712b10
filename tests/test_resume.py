"""Nothing lost: a run killed by a signal leaves every completed step readable,
and --resume continues to the same final answer as an uninterrupted run."""
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from resume_tools import assert_same_frames, assert_same_summary, copy_run, edit_step, renames

from skfem_mortar.app.cli import main
from skfem_mortar.output.checkpoint import read_checkpoint
from skfem_mortar.output.io import read_series
from skfem_mortar.app.runner import run_scene

ARGS = ["block", "--set", "refine=5", "--set", "stretch=1.8", "--steps", "40"]


def cli(*args, **kw):
    return subprocess.Popen([sys.executable, "-m", "skfem_mortar.app.cli", "run", *args],
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


# -- a checkpoint is validated before use ------------------------------------------

PATCH = ("cable_flat", {"n_elements": 20}, "nts", 3)


def _patch(out, resume=False):
    scene, params, method, steps = PATCH
    return run_scene(scene, params, method, steps=steps, out=out, resume=resume)


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished contact run (3 steps) and its summary."""
    out = tmp_path_factory.mktemp("finished")
    return out, _patch(out)


@pytest.fixture
def interrupted(finished, tmp_path):
    """A copy of the finished run without its summary: a run killed after its
    last checkpoint (a resume reads and checks every step file)."""
    out = copy_run(finished[0], tmp_path / "run")
    (out / "summary.json").unlink()
    return out


def _item(arrays, header, key):
    return f"item_{header['items'].index(['contact', key])}"


def _set(d, key, value):
    d[key] = value


def _truncate(path):
    path.write_bytes(path.read_bytes()[:path.stat().st_size // 2])


def _edit_index(path, edit):
    index = json.loads(path.read_text())
    edit(index)
    path.write_text(json.dumps(index))


CORRUPTIONS = {  # what is done to the checkpoint, which file is named, what it says
    "state shape": (2, lambda p: edit_step(p, lambda a, h: _set(a, "z", a["z"][:-1])),
                    r"state of shape \(\d+,\)"),
    "state NaN": (2, lambda p: edit_step(p, lambda a, h: a["z"].__setitem__(0, np.nan)),
                  "non-finite values in the state"),
    "decreasing load factor": (2, lambda p: edit_step(
        p, lambda a, h: _set(h["record"], "load_factor", 0.1)), "must increase"),
    "load factor above 1": (3, lambda p: edit_step(
        p, lambda a, h: _set(h["record"], "load_factor", 1.5)), "must increase"),
    "negative count": (1, lambda p: edit_step(
        p, lambda a, h: _set(h["record"], "newton_iterations", -1)), "integers >= 0"),
    "another run's step": (1, lambda p: edit_step(p, lambda a, h: _set(h, "run", "x")),
                           "leftover of another run"),
    "truncated step": (1, _truncate, "not a readable step file"),
    "missing step": (2, lambda p: p.unlink(), "missing"),
    "oversized step": (2, lambda p: p.write_bytes(p.read_bytes() + bytes(2 << 20)),
                       "more than"),
    "bad controller": (2, lambda p: edit_step(
        p, lambda a, h: _set(h["controller"], "increment", 0.0)), r"increment must lie"),
    "controller off the steps": (2, lambda p: edit_step(
        p, lambda a, h: _set(h["controller"], "lf_prev", 0.5)), "does not fit"),
    "item state shape": (2, lambda p: edit_step(
        p, lambda a, h: _set(a, _item(a, h, "active"), np.ones(1, bool))),
        "entry 'active' has shape"),
    "item state NaN": (2, lambda p: edit_step(
        p, lambda a, h: a[_item(a, h, "x0_slave")].__setitem__((0, 0), np.inf)),
        "non-finite or not numeric"),
    "truncated index": (None, _truncate, "not a readable index"),
    "index step count": (None, lambda p: _edit_index(p, lambda i: _set(i, "steps", 10**7)),
                         "outside"),
    "index identity": (None, lambda p: _edit_index(
        p, lambda i: i["meta"]["parameters"].__setitem__("n_elements", 21)),
        "belongs to another run"),
}


@pytest.mark.parametrize("what", list(CORRUPTIONS))
def test_a_bad_checkpoint_is_refused_naming_the_file(interrupted, what):
    step, corrupt, message = CORRUPTIONS[what]
    path = interrupted / "checkpoint" / (f"step_{step:06d}.npz" if step else "index.json")
    corrupt(path)
    with pytest.raises(ValueError, match=message) as err:
        _patch(interrupted, resume=True)
    assert str(path) in str(err.value)
    assert not (interrupted / "summary.json").exists()  # never a forged result


def test_the_cli_refuses_a_bad_checkpoint_in_one_line(interrupted, capsys):
    path = interrupted / "checkpoint" / "step_000002.npz"
    _truncate(path)
    scene, params, method, steps = PATCH
    argv = ["run", scene, "--method", method, "--steps", str(steps), "--no-progress",
            "--out", str(interrupted), "--resume"]
    argv += [a for k, v in params.items() for a in ("--set", f"{k}={v}")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(path) in err and "Traceback" not in err


def test_a_checkpoint_of_the_old_format_is_refused(tmp_path):
    (tmp_path / "checkpoint.npz").write_bytes(b"old")
    with pytest.raises(ValueError, match="older version"):
        run_scene("block", {"refine": 1}, steps=2, out=tmp_path, resume=True)


def test_resume_of_a_finished_contact_run_changes_nothing(finished, tmp_path):
    # the last step is redone from the checkpoint: the contact state the metrics
    # read (active set, segment choices) comes out as it was, not as a fresh model's
    ref, first = finished
    for drop in ((), ("summary.json", "contact.csv")):  # killed before the summary too
        out = copy_run(ref, tmp_path / f"again{len(drop)}")
        for name in drop:
            (out / name).unlink()
        again = _patch(out, resume=True)
        assert_same_frames(ref, out)
        assert_same_summary(first, again)
        assert json.loads((out / "summary.json").read_text())["metrics"] == again["metrics"]


# -- a kill during the checkpoint write --------------------------------------------

ROOT = Path(__file__).resolve().parents[1]
#: runs the CLI and kills the process (os._exit) at the rename onto ``target``:
#: "partial" leaves the temporary file half written, "after" kills right after the
#: rename (the step file is in place, the index does not list it yet)
DRIVER = """
import os, sys
from pathlib import Path
target, mode = sys.argv[1], sys.argv[2]
real = os.replace
def replace(src, dst):
    if str(dst).endswith(target):
        if mode == "partial":
            Path(src).write_bytes(Path(src).read_bytes()[:Path(src).stat().st_size // 2])
        else:
            real(src, dst)
        os._exit(9)
    return real(src, dst)
os.replace = replace
from skfem_mortar.app.cli import main
sys.exit(main(sys.argv[3:]))
"""


@pytest.mark.parametrize("mode", ["partial", "after"])
def test_a_kill_during_the_checkpoint_write_leaves_the_previous_one(finished, tmp_path, mode):
    scene, params, method, steps = PATCH
    out = tmp_path / "run"
    argv = ["run", scene, "--method", method, "--steps", str(steps), "--no-progress",
            "--out", str(out)] + [a for k, v in params.items() for a in ("--set", f"{k}={v}")]
    proc = subprocess.run([sys.executable, "-c", DRIVER, "step_000002.npz", mode, *argv],
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 9, proc.stderr
    ckpt = read_checkpoint(out / "checkpoint", n=None)
    assert len(ckpt.history) == 1  # step 2 was being written: step 1 stands
    assert ckpt.load_factors.tolist() == [0.0, 1.0 / 3.0]
    left = {p.name for p in (out / "checkpoint").iterdir()}
    if mode == "partial":  # the half-written temporary file of step 2 is there
        assert any(n.startswith(".step_000002.npz.") for n in left)
    else:  # step 2 is complete but not listed
        assert "step_000002.npz" in left
    got = _patch(out, resume=True)
    assert_same_frames(finished[0], out)
    assert_same_summary(finished[1], got)
    # the unlisted step file and the temporary file are gone once the resume writes
    assert sorted(p.name for p in (out / "checkpoint").iterdir()) == [
        "index.json"] + [f"step_{k:06d}.npz" for k in range(steps + 1)]


# -- writing the checkpoint costs one state per step ---------------------------------

def test_checkpoint_bytes_per_step_do_not_grow_with_the_steps_done(tmp_path):
    n_steps = 60
    with renames() as log:
        _, result, setup = run_scene("ring", {"n_elements": 8}, steps=n_steps, out=tmp_path,
                                     return_result=True)
    per_step = np.zeros(n_steps + 1)
    for dst, size in log:
        m = re.search(r"checkpoint/step_(\d{6})\.npz$", dst)
        if m:
            k = int(m.group(1))
        if "/checkpoint/" in dst:
            per_step[k] += size  # the step file and the index written after it
    state = 8 * setup.model.n
    # a step's file holds its state, its record and the contact state; the old
    # checkpoint rewrote all states so far: (k + 1) states at step k
    assert per_step[1:].max() < 4 * state + 4096
    # the records differ by a few residual norms (24 bytes each): 5 % of a step
    assert per_step[-10:].mean() <= 1.05 * per_step[1:11].mean()
