"""A study ``execute`` that kills its worker process on one grid point (for
tests/test_study_workers.py; the Dask workers import it through PYTHONPATH)."""
import os

from skfem_mortar.app import study

#: ring ``n_elements`` of the grid point that kills its worker
KILL_AT = 10


def execute(run: dict) -> dict:
    """``os._exit`` on the marked point (a worker death), else the real run."""
    if run["params"].get("n_elements") == KILL_AT:
        os._exit(3)
    return study.execute(run)
