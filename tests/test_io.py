"""Atomic, NaN-free output files."""
import json
import math

import numpy as np
import pytest

from skfem_mortar.app.cli import main
from skfem_mortar.output.io import SeriesWriter, read_series, write_contact_csv, write_json

MESH = (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), [("triangle", np.array([[0, 1, 2]]))])


def test_series_round_trip(tmp_path):
    w = SeriesWriter(tmp_path, "body", MESH)
    for t in (0.0, 0.5, 1.0):
        w.write(t, {"u": np.full((3, 2), t)}, {"s": [np.array([2.0 * t])]})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["body", "body.pvd"]
    frames = read_series(tmp_path / "body.pvd")
    assert [t for t, _ in frames] == [0.0, 0.5, 1.0]
    u = frames[2][1].point_data["u"]
    # 2D vectors are written with 3 components (ParaView's Warp By Vector needs them)
    assert u.shape == (3, 3) and np.all(u[:, :2] == 1.0) and np.all(u[:, 2] == 0.0)
    assert np.all(frames[1][1].cell_data["s"][0] == 1.0)
    # a resumed run rewrites from a given frame on and drops the later ones
    w.write(0.25, {"u": np.zeros((3, 2))}, {"s": [np.zeros(1)]}, index=1)
    assert [t for t, _ in read_series(tmp_path / "body.pvd")] == [0.0, 0.25]


def test_nan_never_reaches_a_file(tmp_path):
    w = SeriesWriter(tmp_path / "series", "body", MESH)
    with pytest.raises(ValueError, match="non-finite"):
        w.write(0.0, {"u": np.array([[0.0, np.nan]] * 3)}, {})
    assert not (tmp_path / "series" / "body.pvd").exists()
    assert list((tmp_path / "series" / "body").iterdir()) == []
    (tmp_path / "series" / "body").rmdir()
    (tmp_path / "series").rmdir()
    with pytest.raises(ValueError, match="non-finite"):
        write_json(tmp_path / "summary.json", {"a": {"b": [1.0, math.inf]}})
    with pytest.raises(ValueError, match="non-finite"):
        write_contact_csv(tmp_path / "contact.csv",
                          {"x": [0.0], "y": [0.0], "gap": [0.0], "pressure": [np.nan]})
    assert list(tmp_path.iterdir()) == []  # no partial or temporary file left


def test_run_json_and_out(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "block", "--set", "refine=1", "--steps", "2", "--json",
                 "--no-progress", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)  # exactly one JSON object
    for key in ("scene", "method", "parameters", "n_dofs", "n_multipliers", "converged",
                "wall_time_s", "phase_times_s", "steps", "metrics"):
        assert key in summary
    assert summary["parameters"]["refine"] == 1
    assert len(summary["steps"]) == 2
    assert json.loads((out / "summary.json").read_text())["metrics"] == summary["metrics"]
    frames = read_series(out / "block.pvd")
    assert [t for t, _ in frames] == [0.0, 0.5, 1.0]
    assert "von_mises" in frames[-1][1].cell_data




def test_contact_csv_writes_the_distance_and_a_mask_where_no_master(tmp_path):
    """A node facing no master: its distance to the master as the gap and
    has_master 0 (no NaN, no empty cell, no 0 that reads as touching)."""
    write_contact_csv(tmp_path / "contact.csv", {
        "x": [0.0, 1.0], "y": [2.0, 3.0], "gap": [np.nan, -0.5], "pressure": [0.0, 4.0],
        "has_master": [False, True], "distance": [0.25, -0.5]})
    lines = (tmp_path / "contact.csv").read_text().splitlines()
    assert lines == ["x,y,gap,pressure,has_master", "0,2,0.25,0,0", "1,3,-0.5,4,1"]
    with pytest.raises(ValueError, match="non-finite contact data"):
        write_contact_csv(tmp_path / "bad.csv", {"x": [0.0], "y": [0.0], "gap": [np.nan],
                                                 "pressure": [0.0]})


def test_a_failed_temporary_leaves_ctrl_c_deliverable(tmp_path, monkeypatch):
    """atomic_path blocks SIGINT from the temporary's creation to inside its try: when
    the creation itself fails, the block must go with the error, else Ctrl-C stays off
    in this thread and in every process it starts (they inherit the mask)."""
    import errno
    import os
    import signal
    import tempfile

    from skfem_mortar.output.io import atomic_path

    if not hasattr(signal, "pthread_sigmask"):
        pytest.skip("no signal masks on this platform")

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    before = signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # whatever the worker had
    try:
        monkeypatch.setattr(tempfile, "mkstemp", full)
        with pytest.raises(OSError, match="No space left"):
            with atomic_path(tmp_path / "a.json"):
                pass
        assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)
