"""The solver path (backend and Newton's linear solves) through run, study and bench."""
import json

import numpy as np
import pytest

from skfem_mortar.app.bench import run_bench
from skfem_mortar.app.runner import run_scene
from skfem_mortar.app.study import run_study
from skfem_mortar.app.study_plan import parse_solvers, solver_path

#: one-step hertz at refine=-1 (about 2,400 unknowns): small, and the kept factors
#: answer its settled iterations (tests/test_krylov.py)
HERTZ = {"refine": -1}


def test_solver_paths_parse_and_refuse():
    assert solver_path("pardiso+krylov") == ("pardiso", "krylov")
    assert solver_path("superlu") == ("superlu", None)
    assert parse_solvers("superlu,superlu+krylov,superlu+direct") == ["superlu",
                                                                      "superlu+krylov"]
    with pytest.raises(ValueError, match=r"after '\+' must be one of direct, krylov, auto"):
        parse_solvers("superlu+krylvo")
    with pytest.raises(ValueError, match=r"--solver"):
        parse_solvers("mumps+krylov")


def test_run_refuses_a_bad_linear_before_anything_is_written(tmp_path):
    with pytest.raises(ValueError, match="linear must be one of direct, krylov, auto"):
        run_scene("hertz", HERTZ, method="mortar", steps=1, out=tmp_path / "o",
                  linear="krylow")
    assert not (tmp_path / "o").exists()


def test_run_with_krylov_counts_its_solves_and_gives_the_direct_answer():
    direct, r_d, _ = run_scene("hertz", HERTZ, method="mortar", steps=1, return_result=True)
    krylov, r_k, _ = run_scene("hertz", HERTZ, method="mortar", steps=1, return_result=True,
                               linear="krylov")
    sd, sk = direct["steps"][0], krylov["steps"][0]
    # direct: one factorization a Newton iteration; krylov: the settled ones are
    # answered by FGMRES with the kept factors
    assert sd["factorizations"] == sd["newton_iterations"] and sd["krylov_iterations"] == 0
    assert sk["factorizations"] < sk["newton_iterations"] and sk["krylov_iterations"] > 0
    assert sk["newton_iterations"] == sd["newton_iterations"]
    # both converged to the Newton tolerance rtol = 1e-10 of the force scale: the
    # states agree to a few times that (the displacements are O(1e-1) of the
    # radius 8 here, so 1e-8 relative is far above round-off and far below any
    # difference a wrong solve would make)
    zd, zk = r_d.states[-1], r_k.states[-1]
    assert np.linalg.norm(zk - zd) <= 1e-8 * np.linalg.norm(zd)


def test_study_has_the_solver_path_as_an_axis(tmp_path):
    rows = run_study(["hertz"], tmp_path, quick=True, methods=["mortar"], repeat=1,
                     steps="1", solvers="superlu,superlu+krylov")
    by = {r["solver"]: r for r in rows}
    assert set(by) == {"superlu", "superlu+krylov"}
    assert all(r["status"] == "ok" for r in rows)
    md, mk = (json.loads(by[p]["metrics"]) for p in ("superlu", "superlu+krylov"))
    # the same converged answer (see above): the peak pressure to 1e-7 relative
    assert md["peak_pressure"] == pytest.approx(mk["peak_pressure"], rel=1e-7)


def test_bench_times_each_solver_path(tmp_path):
    report = run_bench(tmp_path, scenes=("hertz",), quick=True, steps=1,
                       solvers=["superlu", "superlu+krylov"])
    assert set(report["scenes"]) == {"hertz (superlu)", "hertz (superlu+krylov)"}
    d = report["scenes"]["hertz (superlu)"]["rows"][0]
    k = report["scenes"]["hertz (superlu+krylov)"]["rows"][0]
    assert d["status"] == k["status"] == "ok" and d["solver"] == "superlu"
    assert d["factorizations"] == d["newton_iterations"] and d["krylov_iterations"] == 0
    assert k["factorizations"] < k["newton_iterations"] and k["krylov_iterations"] > 0
    assert (tmp_path / "bench.png").stat().st_size > 1000
