"""Examples are tests: import each script and check what it computed."""
import importlib.util
from pathlib import Path

import numpy as np

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_cable_cushion_example():
    ex = load("cable_cushion")
    assert ex.result.converged
    assert ex.pair.active.sum() > 5
    f_cable, f_cushion = ex.f_cable.sum(axis=1), ex.f_cushion.sum(axis=1)
    # both sides come from one G^T lam: they cancel to round-off of the force (~8)
    assert np.linalg.norm(f_cable + f_cushion) < 1e-12 * np.linalg.norm(f_cable)
    # the contact pushes the cable down (-y) and the cushion up
    assert f_cable[1] < 0 < f_cushion[1]
    # the saved series hold one frame per state, with the contact pressure
    from skfem_mortar.io import read_series
    frames = read_series(f"{ex.out}/contact.pvd")
    assert len(frames) == len(ex.result.states)
    assert (frames[-1][1].point_data["pressure"] > 0).sum() == ex.pair.active.sum()
    assert ex.picture.stat().st_size > 10000
