"""Atomic, NaN-free output files."""
import json
import math

import meshio
import numpy as np
import pytest

from skfem_mortar.cli import main
from skfem_mortar.io import write_contact_csv, write_json, write_series

MESH = (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), [("triangle", np.array([[0, 1, 2]]))])


def test_series_round_trip(tmp_path):
    frames = [(t, {"u": np.full((3, 2), t)}, {"s": [np.array([2.0 * t])]}) for t in (0.0, 0.5, 1.0)]
    write_series(tmp_path / "body.xdmf", MESH, frames)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["body.h5", "body.xdmf"]
    with meshio.xdmf.TimeSeriesReader(str(tmp_path / "body.xdmf")) as r:
        r.read_points_cells()
        t, pd, cd = r.read_data(2)
    assert t == 1.0 and np.all(pd["u"] == 1.0)


def test_nan_never_reaches_a_file(tmp_path):
    frames = [(0.0, {"u": np.array([[0.0, np.nan]] * 3)}, {})]
    with pytest.raises(ValueError, match="non-finite"):
        write_series(tmp_path / "body.xdmf", MESH, frames)
    with pytest.raises(ValueError, match="non-finite"):
        write_json(tmp_path / "summary.json", {"a": {"b": [1.0, math.inf]}})
    with pytest.raises(ValueError, match="non-finite"):
        write_contact_csv(tmp_path / "contact.csv",
                          {"x": [0.0], "y": [0.0], "gap": [np.nan], "pressure": [1.0]})
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
    assert (out / "block.xdmf").exists() and (out / "block.h5").exists()
