"""PARDISO is asked for reproducible sums (MKL_CBWR) before MKL loads.

Without it, two runs of the same oring scene gave contact forces 1e-15 apart
(MKL's threaded factorization sums in a run-dependent order), so a resumed run
could not repeat an uninterrupted one bit for bit.  Whether MKL honours the
setting is MKL's; what we check is that the variable is set before the import,
and that a user's own setting wins.
"""
import os
import subprocess
import sys

import pytest

CODE = ("import os; from skfem_mortar.solver import pardiso; "
        "ok = pardiso._pardiso_available(); print(ok, os.environ.get('MKL_CBWR'))")


def _run(env_extra: dict) -> str:
    env = {k: v for k, v in os.environ.items() if k != "MKL_CBWR"}
    env.update(env_extra)
    return subprocess.run([sys.executable, "-c", CODE], env=env, capture_output=True,
                          text=True, check=True).stdout.split()


@pytest.mark.parametrize("user, expected", [(None, "AUTO,STRICT"), ("COMPATIBLE", "COMPATIBLE")])
def test_mkl_reproducibility_is_requested(user, expected):
    ok, value = _run({} if user is None else {"MKL_CBWR": user})
    if ok != "True":
        pytest.skip("pypardiso is not installed here: MKL is not loaded")
    assert value == expected
