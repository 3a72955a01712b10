"""An output directory holds one run (issue #14): a busy --out is refused, a stale
lock is taken over with a note, another run's files are refused unless --replace
(which removes exactly them), summary.json is never an older run's, a write
error leaves no mix of two runs, and Ctrl-C ends with exit 130, outputs intact."""
import errno
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from resume_tools import Killed

import skfem_mortar.app.runner as runner
from skfem_mortar.app.cli import main
from skfem_mortar.core.errors import ConvergenceError
from skfem_mortar.output.checkpoint import read_checkpoint
from skfem_mortar.output.io import read_series
from skfem_mortar.output.outdir import LOCK_NAME, MANIFEST_NAME, read_manifest

ROOT = Path(__file__).resolve().parents[1]
#: the long run's steps: a run of a few seconds, long enough that it cannot end
#: between the test seeing two steps and its signal (40 steps took 0.7 s in all,
#: and a loaded test process missed them: the run ended with 0), short enough to let
#: it finish in the resume test
N_LONG = 200
LONG = ["block", "--set", "refine=5", "--set", "stretch=1.8", "--steps", str(N_LONG), "--no-progress"]
#: a run that no test lets finish (the Ctrl-C test): the four refused commands run
#: in the test's process first, and under a full -n 2 suite they took as long as
#: 200 steps, so the run had ended before its signal (return code 0)
ENDLESS = [*LONG[:-2], "20000", "--no-progress"]
SHORT = ["block", "--set", "refine=1", "--steps", "2", "--no-progress"]
#: how long to wait for a subprocess to reach a state: its start (interpreter,
#: imports, model build) takes about 1 s alone and more on a loaded 2-core
#: machine; a run that reaches none in 60 s is broken, not slow
WAIT_S = 60.0


def _ctrl_c_as_a_terminal_gives_it() -> None:
    """SIGINT acted on by default and not blocked, as an interactive shell gives a
    command it starts.  A child inherits an ignored SIGINT and a blocked one: a pytest
    worker started from a non-interactive background job (CI's, a script's ``&``) has
    SIGINT ignored, unless a notebook run before in the same worker had turned it into
    Python's default handler (asyncio's ``remove_signal_handler``, which nbclient
    calls), so the command ignored the test's Ctrl-C at random under a full ``-n 2``
    suite (60 s and 1,679 steps after the signal); with SIGINT blocked in the test's
    process it does so every time."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _cli(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "skfem_mortar.app.cli", "run", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": str(ROOT)},
                            preexec_fn=_ctrl_c_as_a_terminal_gives_it)


def _wait(what: str, done) -> None:
    deadline = time.monotonic() + WAIT_S
    while not done():
        assert time.monotonic() < deadline, f"waited {WAIT_S} s for {what}"
        time.sleep(0.02)  # 20 ms: a step takes about 100 ms


def _steps_done(out: Path) -> int:
    try:
        ck = read_checkpoint(out / "checkpoint")
    except (OSError, ValueError):  # a step replaced while reading
        return 0
    return 0 if ck is None else len(ck.history)


def _assert_frames_whole(out: Path, at_least: int) -> None:
    frames = read_series(out / "block.pvd")  # every frame the index lists reads
    assert len(frames) >= at_least
    assert all(np.all(np.isfinite(m.point_data["displacement"])) for _, m in frames)


def _one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_a_busy_out_is_refused_and_ctrl_c_ends_with_130(tmp_path, capsys):
    out = tmp_path / "run"
    proc = _cli(*ENDLESS, "--out", str(out))
    _wait("the lock", lambda: (out / LOCK_NAME).exists())
    held = json.loads((out / LOCK_NAME).read_text())
    assert held["pid"] == proc.pid and held["host"] == socket.gethostname()
    for argv in (["run", *SHORT, "--out", str(out)],
                 ["run", *SHORT, "--out", str(out), "--replace"],
                 ["study", "--scene", "block", "--quick", "--out", str(out)],
                 ["bench", "--quick", "--out", str(out)]):
        assert main(argv) == 2
        line = _one_line(capsys.readouterr().err)
        assert "in use" in line and str(proc.pid) in line
    assert proc.poll() is None, "the first run ended before the second was refused"

    _wait("two steps", lambda: _steps_done(out) >= 2)
    at_signal = _steps_done(out)
    proc.send_signal(signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=WAIT_S)
    except subprocess.TimeoutExpired:  # say whether the run went on or hung
        proc.kill()
        _, err = proc.communicate()
        raise AssertionError(f"no exit {WAIT_S} s after SIGINT: steps {at_signal} at the "
                             f"signal, {_steps_done(out)} at the kill; {err[-400:]}")
    assert proc.returncode == 130, (proc.returncode, _steps_done(out), err[-400:])
    assert "interrupted" in _one_line(err)
    assert not (out / LOCK_NAME).exists()
    assert not (out / "summary.json").exists()  # not finished: no summary
    _assert_frames_whole(out, _steps_done(out) + 1)
    assert not [p for p in out.rglob(".*") if p.name != MANIFEST_NAME]  # no temporaries


def _killed_run(out: Path) -> int:
    """The long run killed (SIGKILL) after two steps; the steps done."""
    proc = _cli(*LONG, "--out", str(out))
    _wait("two steps", lambda: _steps_done(out) >= 2)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=WAIT_S)
    assert proc.returncode == -signal.SIGKILL, "the run finished before it was killed"
    return _steps_done(out)


def test_after_a_kill_a_new_run_needs_replace_and_resume_continues(tmp_path, capsys, caplog):
    out = tmp_path / "killed"
    done = _killed_run(out)
    assert 2 <= done < N_LONG and (out / LOCK_NAME).exists()  # the stale lock stays
    other = shutil.copytree(out, tmp_path / "other")
    # a new run into it: refused without --replace (the stale lock is taken over first)
    assert main(["run", *SHORT, "--out", str(other)]) == 2
    assert "holds the files of another run" in _one_line(capsys.readouterr().err)
    assert "took over the stale lock" in caplog.text
    assert (other / "block" / "block_0002.vtu").exists()  # nothing removed
    # with --replace the old set goes: 3 frames of the new run, nothing of the old
    assert main(["run", *SHORT, "--out", str(other), "--replace"]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in (other / "block").iterdir()) == [
        f"block_{k:04d}.vtu" for k in range(3)]
    assert len(read_checkpoint(other / "checkpoint").history) == 2
    assert json.loads((other / "summary.json").read_text())["parameters"]["refine"] == 1
    assert not (other / LOCK_NAME).exists()

    # --resume of the killed run continues it; the temporary files a kill left go
    leftovers = [out / ".block.pvd.x1.tmp", out / "block" / ".block_0039.vtu.x2.vtu"]
    for p in leftovers:
        p.write_bytes(b"half")
    assert main(["run", *LONG, "--out", str(out), "--resume", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["converged"] and len(summary["steps"]) == N_LONG
    assert not any(p.exists() for p in leftovers)
    _assert_frames_whole(out, N_LONG + 1)


def test_a_stale_lock_is_taken_over_with_a_note(tmp_path):
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()  # reaped: its pid is no process now
    out = tmp_path / "run"
    out.mkdir()
    (out / LOCK_NAME).write_text(json.dumps({"host": socket.gethostname(), "pid": gone.pid,
                                             "started": "earlier", "command": "run"}))
    proc = _cli(*SHORT, "--out", str(out))
    _, err = proc.communicate(timeout=WAIT_S)
    assert proc.returncode == 0, err
    line = _one_line(err)
    assert "took over the stale lock" in line and str(gone.pid) in line
    assert not (out / LOCK_NAME).exists()


@pytest.mark.parametrize("host, pid, why", [("elsewhere.example", 1, "elsewhere.example"),
                                            (None, os.getpid(), "in use")],
                         ids=["another-host", "this-process"])  # stable ids: pytest-xdist workers
                                                                # must collect the same names
def test_a_lock_of_a_live_run_or_another_host_is_refused(tmp_path, capsys, host, pid, why):
    out = tmp_path / "run"
    out.mkdir()
    lock = {"host": host or socket.gethostname(), "pid": pid, "started": "now"}
    (out / LOCK_NAME).write_text(json.dumps(lock))
    assert main(["run", *SHORT, "--out", str(out)]) == 2
    assert why in _one_line(capsys.readouterr().err)
    assert json.loads((out / LOCK_NAME).read_text()) == lock  # left as it was
    assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]


def test_a_full_disk_during_replace_leaves_only_the_new_run(tmp_path, monkeypatch, capsys):
    """--replace removes the old set first: after a write error (ENOSPC) no file
    of the old run remains beside the new run's, no summary, and the new run
    resumes once there is room."""
    out = tmp_path / "run"
    assert main(["run", "block", "--set", "refine=1", "--steps", "6", "--no-progress",
                 "--out", str(out)]) == 0
    new = ["run", "block", "--set", "refine=1", "--set", "stretch=1.5", "--steps", "3",
           "--no-progress", "--out", str(out)]
    real, count = os.replace, [0]

    def replace(src, dst):
        count[0] += 1
        if count[0] == 8:  # manifest, step 0 (file, index), frame 0 (vtu, pvd), frame 1 ...
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(dst))
        return real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    assert main([*new, "--replace"]) == 3
    assert "No space left on device" in _one_line(capsys.readouterr().err)
    monkeypatch.setattr(os, "replace", real)
    assert not (out / "summary.json").exists()
    assert read_manifest(out)["identity"]["parameters"]["stretch"] == 1.5
    assert read_checkpoint(out / "checkpoint").meta["steps"] == 3
    assert sorted(p.name for p in (out / "block").iterdir()) == ["block_0000.vtu",
                                                                 "block_0001.vtu"]
    assert [t for t, _ in read_series(out / "block.pvd")] == pytest.approx([0, 1 / 3])
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST_NAME, "block", "block.pvd",
                                                     "checkpoint"]
    assert main([*new, "--resume"]) == 0  # room again: the new run goes on
    assert [t for t, _ in read_series(out / "block.pvd")] == pytest.approx([0, 1 / 3, 2 / 3, 1])


def test_a_failed_run_leaves_its_own_summary_not_an_older_one(tmp_path, monkeypatch, capsys):
    out = tmp_path / "run"
    assert main(["run", *SHORT, "--out", str(out)]) == 0
    real = runner.solve

    def failing(model, n_steps, **kw):  # converges two steps, then fails the third
        callback, seen = kw["callback"], []

        def cb(record, z):
            callback(record, z)
            seen.append(record)
            if len(seen) == 2:
                raise ConvergenceError(3, 0.75, 4, [1.0, 0.5], "made to fail")
        return real(model, n_steps, **{**kw, "callback": cb})

    monkeypatch.setattr(runner, "solve", failing)
    argv = ["run", "block", "--set", "refine=1", "--steps", "4", "--no-progress",
            "--out", str(out), "--replace"]
    assert main(argv) == 1  # exit 1: only "did not converge"
    assert "made to fail" in _one_line(capsys.readouterr().err)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["converged"] is False and "made to fail" in summary["error"]
    assert len(summary["steps"]) == 2 and summary["metrics"] == {}
    assert not (out / LOCK_NAME).exists()


def test_unrelated_files_are_never_removed(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    for extra in ([], ["--replace"]):
        assert main(["run", *SHORT, "--out", str(out), *extra]) == 2
        assert "notes.txt" in _one_line(capsys.readouterr().err)
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


# -- a kill while the lock is taken (issue 32) --------------------------------------

def _old_empty_lock(out: Path, age_s: float) -> Path:
    """The lock a kill between its creation and its content left (older
    versions created it empty, then wrote it), ``age_s`` seconds ago."""
    lock = out / LOCK_NAME
    lock.write_bytes(b"")
    os.utime(lock, (time.time() - age_s,) * 2)
    return lock


@pytest.mark.parametrize("flag", ["", "--resume", "--replace"])
def test_an_empty_lock_a_minute_old_is_taken_over_with_a_note(tmp_path, capsys, caplog, flag):
    out = tmp_path / "run"
    assert main(["run", *SHORT, "--out", str(out)]) == 0
    (out / "summary.json").unlink()  # killed after its last step
    lock = _old_empty_lock(out, 3600.0)
    argv = ["run", *SHORT, "--out", str(out)] + ([flag] if flag else [])
    code = main(argv)
    err = capsys.readouterr().err
    assert "took over the stale lock" in caplog.text and "unreadable" in caplog.text
    assert not lock.exists()
    if flag:  # resumed or replaced: the run ends as any other
        assert code == 0, err
        assert json.loads((out / "summary.json").read_text())["converged"]
    else:  # the lock is no longer what stops it: the other run's files are
        assert code == 2 and "holds the files of another run" in _one_line(err)


def test_a_young_unreadable_lock_is_refused_as_being_written(tmp_path, capsys):
    out = tmp_path / "run"
    out.mkdir()
    # 1 s old: a run may be writing it (taken over from UNREADABLE_LOCK_AGE_S = 60 s on)
    lock = _old_empty_lock(out, 1.0)
    assert main(["run", *SHORT, "--out", str(out)]) == 2
    assert "being written or unreadable" in _one_line(capsys.readouterr().err)
    assert lock.exists() and lock.read_bytes() == b""
    assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]


def test_a_lock_is_never_seen_without_its_content(tmp_path, monkeypatch):
    """The lock appears by a link of a written temporary file: a kill before
    the link leaves no lock, and the lock is whole once it is there."""
    out = tmp_path / "run"
    out.mkdir()
    real_link = os.link
    seen = []

    def killed_at_link(src, dst, **kw):
        seen.append((Path(dst).exists(), json.loads(Path(src).read_text())["pid"]))
        raise Killed  # the kill, before the lock is in place

    monkeypatch.setattr(os, "link", killed_at_link)
    with pytest.raises(Killed):
        main(["run", *SHORT, "--out", str(out)])
    assert seen == [(False, os.getpid())]  # the content was written before the link
    assert not (out / LOCK_NAME).exists()
    monkeypatch.setattr(os, "link", real_link)
    assert main(["run", *SHORT, "--out", str(out)]) == 0


def test_without_hard_links_the_lock_is_still_taken(tmp_path, monkeypatch, capsys):
    def no_links(src, dst, **kw):
        raise OSError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_links)
    out = tmp_path / "run"
    assert main(["run", *SHORT, "--out", str(out)]) == 0
    assert not (out / LOCK_NAME).exists()
    assert not [p for p in out.iterdir() if p.name.startswith(LOCK_NAME)]


def test_a_dead_runs_lock_does_not_stop_a_resume(tmp_path, capsys, caplog):
    out = tmp_path / "run"
    assert main(["run", *SHORT, "--out", str(out)]) == 0
    (out / "summary.json").unlink()
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()  # reaped: its pid is no process now
    (out / LOCK_NAME).write_text(json.dumps({"host": socket.gethostname(), "pid": gone.pid,
                                             "started": "earlier", "command": "run"}))
    assert main(["run", *SHORT, "--out", str(out), "--resume"]) == 0
    assert "took over the stale lock" in caplog.text and str(gone.pid) in caplog.text
    assert not (out / LOCK_NAME).exists()


def _moved_live_lock(tmp_path):
    """A directory whose lock is another run's live lock, and the 'held' content a
    taker judged stale a moment earlier (another lock: so it must be put back)."""
    from skfem_mortar.output import lock

    path = tmp_path / LOCK_NAME
    live = {"host": socket.gethostname(), "pid": os.getpid(), "command": "run", "token": "live"}
    path.write_text(json.dumps(live))
    return lock, path, {**live, "token": "judged-stale"}


def test_a_live_lock_moved_aside_is_put_back_without_hard_links(tmp_path, monkeypatch):
    lock, path, judged = _moved_live_lock(tmp_path)

    def no_links(src, dst, **kw):
        raise OSError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_links)
    lock._take_over(path, judged)
    assert json.loads(path.read_text())["token"] == "live"      # back in its place
    assert [p.name for p in tmp_path.iterdir()] == [LOCK_NAME]  # nothing left aside


def test_a_live_lock_is_never_put_back_over_a_third_runs_lock(tmp_path, monkeypatch, caplog):
    lock, path, judged = _moved_live_lock(tmp_path)
    real_link = os.link

    def third_run_first(src, dst, **kw):  # a third run creates its lock in between
        Path(dst).write_text(json.dumps({"token": "third"}))
        return real_link(src, dst, **kw)

    monkeypatch.setattr(os, "link", third_run_first)
    lock._take_over(path, judged)
    assert json.loads(path.read_text())["token"] == "third"     # not overwritten
    kept = [p for p in tmp_path.iterdir() if p.name != LOCK_NAME]
    assert len(kept) == 1 and json.loads(kept[0].read_text())["token"] == "live"
    assert "a third run has taken the directory" in caplog.text


def test_a_ctrl_c_that_python_dropped_ends_the_run_at_the_next_step(tmp_path, capsys,
                                                                    monkeypatch):
    """A KeyboardInterrupt raised where Python drops it (a finalizer, a callback from
    compiled code) must not let the run go on: the command's handler records the
    signal and the runner raises it again after the step, so the run ends with 130
    and its steps so far kept.  Here the first step's observer takes the SIGINT and
    swallows it, as such a place would."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signal handlers are set in the main thread only")
    handler, mask = signal.getsignal(signal.SIGINT), signal.pthread_sigmask(signal.SIG_BLOCK, set())
    _ctrl_c_as_a_terminal_gives_it()     # this worker's state, whatever earlier tests left
    swallowed = []
    step = runner._Recorder.on_step

    def on_step(self, record, z):
        if not swallowed:
            try:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(1.0)  # the handler runs at the next bytecode: well within 1 s
            except KeyboardInterrupt:
                swallowed.append(True)
        step(self, record, z)

    monkeypatch.setattr(runner._Recorder, "on_step", on_step)
    monkeypatch.setattr(runner._Recorder, "step", on_step)
    out = tmp_path / "run"
    try:
        assert main(["run", *SHORT[:-3], "--steps", "5", "--no-progress", "--out", str(out)]) == 130
        assert swallowed, "the SIGINT did not reach the observer"
        assert "interrupted" in _one_line(capsys.readouterr().err)
        assert _steps_done(out) == 1  # the step it came in is kept whole, no later one
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        if handler is not None:          # None: a handler set outside Python, left as found
            signal.signal(signal.SIGINT, handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
