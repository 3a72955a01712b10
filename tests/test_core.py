"""The block Newton solver and the load stepping, on analytic toy items."""
import numpy as np
import pytest

from skfem_mortar.core.errors import ConvergenceError
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve

from toy_items import Spring


def spring_model(load, n=3, law="atan"):
    s = Spring(n, k=2.0, load=load, law=law)
    return Model([s, Dirichlet(s, [0])]), s


def test_exact_answer_and_quadratic_rate():
    # every spring carries the load: 2 atan(e) = F, so the end moves (n-1) tan(F/2)
    F = 2.0 * np.arctan(0.8)
    model, s = spring_model(F)
    res = solve(model, 1)
    u = res.z[s.dofs]
    # 1e-12: Newton stops at rtol 1e-10 of the force scale and is quadratic, so the
    # last update leaves an error far below that; round-off is ~1e-16
    assert np.allclose(np.diff(u), 0.8, rtol=0, atol=1e-12)
    r = np.array(res.steps[0].residual_norms)
    # order estimate log(r_k+1/r_k) / log(r_k/r_k-1), using only residuals above
    # round-off (1e-13 of the first), where the estimate means something
    r = r[r > 1e-13 * r[0]]
    assert len(r) >= 4
    orders = np.log(r[2:] / r[1:-1]) / np.log(r[1:-1] / r[:-2])
    assert orders[-1] > 1.8, orders


def test_step_cutting_reaches_a_load_that_fails_in_one_step():
    # 2 sinh(e) = 2 sinh(5): from e = 0 the first Newton update is e = sinh(5) = 74,
    # where the residual is ~1e31: divergence, so the step must be cut
    F = 2.0 * np.sinh(5.0)
    model, s = spring_model(F, n=2, law="sinh")
    res = solve(model, 1)
    assert res.converged
    assert any(st.cuts > 0 for st in res.steps)
    # 1e-12: the tangent 2 cosh(5) = 148 makes the answer well conditioned
    assert np.isclose(np.diff(res.z[s.dofs])[0], 5.0, rtol=1e-12)


def test_impossible_load_raises_convergence_error():
    # 2 atan(e) < pi for every e: a load of 4 has no equilibrium
    model, _ = spring_model(4.0, n=2)
    with pytest.raises(ConvergenceError) as info:
        solve(model, 2, newton=NewtonOptions(max_iter=10), min_step=1e-3)
    err = info.value
    assert err.residual_history and np.all(np.isfinite(err.residual_history))
    assert 0.0 < err.load_factor <= 1.0 and err.step >= 1
    assert "load factor" in str(err)


def test_prescribed_displacement_and_reaction():
    s = Spring(3, k=2.0)
    # pull the end to 1.2: both springs stretch 0.6, reaction 2 atan(0.6)
    model = Model([s, Dirichlet(s, [0]), Dirichlet(s, [2], 1.2, name="pull")])
    res = solve(model, 2)
    R = res.residual()
    assert np.isclose(res.z[1], 0.6, atol=1e-12)
    assert np.isclose(R[2], 2.0 * np.arctan(0.6), rtol=1e-12)


def test_line_search_avoids_the_cut():
    # the same overshooting step: backtracking keeps each update inside the
    # region where the residual decreases, so no step cut is needed
    F = 2.0 * np.sinh(5.0)
    model, s = spring_model(F, n=2, law="sinh")
    res = solve(model, 1, newton=NewtonOptions(max_iter=60, line_search=True))
    assert [st.cuts for st in res.steps] == [0]
    assert np.isclose(np.diff(res.z[s.dofs])[0], 5.0, rtol=1e-12)


@pytest.mark.parametrize("kw", [dict(n_steps=0), dict(min_step=0.0), dict(start=1.0)])
def test_bad_stepping_input(kw):
    model, _ = spring_model(1.0)
    args = {"n_steps": 1, **kw}
    with pytest.raises(ValueError):
        solve(model, **args)


def test_bad_newton_options():
    with pytest.raises(ValueError, match="rtol"):
        NewtonOptions(rtol=2.0)
    with pytest.raises(ValueError, match="max_iter"):
        NewtonOptions(max_iter=0)


def test_dirichlet_load_path():
    # a two-phase path: pull to 0.6 in the first half, then back to 0.2
    s = Spring(3, k=2.0)
    path = lambda lf: 1.2 * lf if lf <= 0.5 else 0.6 - 0.8 * (lf - 0.5)  # noqa: E731
    model = Model([s, Dirichlet(s, [0]), Dirichlet(s, [2], path, name="path")])
    res = solve(model, 4)
    ends = [z[2] for z in res.states]
    assert np.allclose(ends, [0.0, 0.3, 0.6, 0.4, 0.2], atol=1e-14)
    assert np.isclose(res.z[1], 0.1, atol=1e-12)  # two equal springs share the stretch
