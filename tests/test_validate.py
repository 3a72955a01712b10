"""The checks behind the public constructors' ValueErrors (core/validate.py)."""
import math

import numpy as np
import pytest

from skfem_mortar.core.validate import count, flag, real


@pytest.mark.parametrize("bad", ["100", True, None, 1 + 2j, float("nan"), [1.0]])
def test_real_refuses_what_is_not_a_real_number(bad):
    with pytest.raises(ValueError, match=r"^E must be a finite real number > 0, got"):
        real("E", bad, 0.0, low_open=True)


def test_real_range_and_infinity():
    with pytest.raises(ValueError, match=r"nu must be a finite real number in \[-1, 0.5\), got 0.5"):
        real("nu", 0.5, -1.0, 0.5, high_open=True)
    with pytest.raises(ValueError, match="slack_stiffness"):
        real("slack_stiffness", math.inf, 0.0)
    assert real("c", math.inf, 0.0, finite=False) == math.inf
    assert real("E", np.float32(2.5), 0.0) == 2.5 and type(real("E", np.int64(3))) is float


@pytest.mark.parametrize("bad", [2.5, 2.0, True, "3", None])
def test_count_refuses_non_integers(bad):
    with pytest.raises(ValueError, match=r"^n_elements must be an integer in \[1, 10\]"):
        count("n_elements", bad, 1, 10)


def test_count_range_and_numpy_integers():
    with pytest.raises(ValueError, match=r"got 11$"):
        count("n", 11, 1, 10)
    assert count("n", np.int32(4), 1, 10) == 4


@pytest.mark.parametrize("bad", [1, 0, "True", None, 1.0])
def test_flag_refuses_non_bools(bad):
    with pytest.raises(ValueError, match="^progress must be True or False"):
        flag("progress", bad)
    assert flag("progress", np.True_) is True


def test_an_integer_beyond_floats_range_is_refused_not_a_traceback():
    with pytest.raises(ValueError, match=r"^E must be a finite real number > 0, got an integer of 401 digits"):
        real("E", 10**400, 0.0, low_open=True)
