"""An axisymmetric scene run with an output directory names its contact columns r, z."""
import csv

import numpy as np

from skfem_mortar.app.runner import run_scene


def test_contact_csv_of_an_axisymmetric_run_names_r_and_z(tmp_path):
    run_scene("hertz_axi", {"refine": -1}, method="nts", out=tmp_path / "run")
    with open(tmp_path / "run" / "contact.csv", newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0][:5] == ["r", "z", "gap", "pressure", "has_master"]
    r = np.array([float(row[0]) for row in rows[1:]])
    assert r.min() == 0.0 and np.all(r >= 0.0)       # the slave reaches the axis, r >= 0
