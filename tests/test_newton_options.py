"""NewtonOptions refuses, field by field, what is not of the field's type or
range (issue 32): a bool is no count, a string no number, 2.5 no count; each
message names the field."""
import numpy as np
import pytest

from skfem_mortar import NewtonOptions
from skfem_mortar.solver.krylov import KrylovSolver

NAN, INF = float("nan"), float("inf")

#: per field: values refused (type first, then range) and a value accepted
FIELDS = {
    "max_iter": ([True, 2.5, 3.0, "10", None, 0], np.int64(7)),
    "rtol": ([True, "1e-8", None, NAN, 0.0, 1.0], np.float32(1e-6)),
    "atol": ([False, "0", None, NAN, INF, -1.0], 0),
    "line_search": ([1, 0, "yes", None], np.bool_(True)),
    "max_backtracks": ([True, 2.5, "8", -1], 0),
    "divergence": ([True, "1e8", NAN, INF, 1.0], 10),
    "linear": ([1, True, None, "dir", "Direct"], "auto"),
    "forcing_max": ([True, "0.01", NAN, 0.0, 1.0], 0.5),
    "krylov_max_iter": ([True, 2.5, "12", 0], np.int32(3)),
}


@pytest.mark.parametrize("field, bad", [(f, v) for f, (bad, _) in FIELDS.items() for v in bad],
                         ids=lambda v: repr(v))
def test_each_field_refuses_a_value_of_another_type_or_range(field, bad):
    with pytest.raises(ValueError, match=f"^{field} must be "):
        NewtonOptions(**{field: bad})


@pytest.mark.parametrize("field", sorted(FIELDS))
def test_each_field_keeps_an_accepted_value_as_its_plain_type(field):
    good = FIELDS[field][1]
    value = getattr(NewtonOptions(**{field: good}), field)
    assert value == good
    # a NumPy scalar is stored as the Python type of the default (what the
    # solver, a checkpoint and a repr then see)
    assert type(value) is type(getattr(NewtonOptions(), field))


def test_the_defaults_pass_their_own_checks():
    assert NewtonOptions() == NewtonOptions(**vars(NewtonOptions()))


@pytest.mark.parametrize("bad", [True, 2.5, "12", 0])
def test_the_krylov_solver_refuses_a_count_that_is_not_one(bad):
    with pytest.raises(ValueError, match="^max_iter must be an integer >= 1"):
        KrylovSolver(max_iter=bad)
