"""The limit point under load control (solver/limit_point.py): Bergan's S_p on a
linear model and a softening one, the verdict's rules, and the balloon under
pressure control stopped near p_max after at most two cuts."""
import numpy as np
import pytest

from skfem_mortar import Model
from skfem_mortar.bodies.membrane import Membrane
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.loads.pressure import FollowerPressure
from skfem_mortar.scenes.balloon import P_MAX_FACTOR
from skfem_mortar.solver.limit_point import (LimitPointError, LimitWatch, MAX_LIMIT_CUTS,
                                             load_controlled)
from skfem_mortar.solver.stepping import solve


def _balloon(n, ratio):
    th = np.linspace(0.0, 0.5 * np.pi, n + 1)
    m = Membrane(np.vstack([np.cos(th), np.sin(th)]), H=0.01, mu=1.0)
    p = FollowerPressure(m, ratio * P_MAX_FACTOR * 0.01, side="right")
    return m, Model([m, p, Dirichlet(m, m.node_dofs[1, [0]], 0.0)], geometry="axisymmetric")


def test_stiffness_parameter_falls_to_the_limit():
    """Below p_max (0.9 of it) the run converges; S_p starts at 1 and falls
    monotonically (the balloon softens all the way to its limit point)."""
    seen = []
    _, model = _balloon(16, 0.9)
    res = solve(model, 6, callback=lambda rec, z: seen.append(rec.info["stiffness_parameter"]))
    assert res.converged and seen[0] == 1.0
    assert np.all(np.diff(seen) < 0) and 0.0 < seen[-1] < 0.5


def test_pressure_control_stops_at_the_limit_point(monkeypatch):
    """p rises to 1.2 p_max in 20 steps: the run stops with the named limit point,
    the last converged pressure within 2 % below p_max, after at most 2 cuts
    (failed attempts: one per cut and the last one)."""
    import skfem_mortar.solver.stepping as stepping
    failed, real = [], stepping.newton_step

    def counting(*args, **kwargs):
        rep = real(*args, **kwargs)
        failed.append(not rep.converged)
        return rep
    monkeypatch.setattr(stepping, "newton_step", counting)
    steps = []
    _, model = _balloon(32, 1.2)
    with pytest.raises(LimitPointError, match=r"limit point near load factor [0-9.]+ "
                       r"\(pressure [0-9.e-]+\): pressure control cannot pass it; "
                       r"prescribe the enclosed volume instead") as err:
        solve(model, 20, callback=lambda rec, z: steps.append(rec))
    p_last = 1.2 * err.value.last_load_factor
    assert 0.98 <= p_last <= 1.0
    assert sum(failed) <= MAX_LIMIT_CUTS + 1 and failed[-1]
    assert err.value.pressure == pytest.approx(P_MAX_FACTOR * 0.01, rel=0.02)


def test_verdict_rules():
    _, model = _balloon(4, 1.0)
    watch = LimitWatch(model)
    assert watch.estimate(0.5) is None                    # nothing converged yet
    watch.history = [(0.4, 0.5), (0.5, 0.3)]              # zero of the line at 0.65
    assert watch.estimate(0.6) is None
    assert watch.estimate(0.7) == pytest.approx(0.65)
    watch.history = [(0.4, 0.03), (0.5, 0.04)]            # rising, but below the limit
    assert watch.estimate(0.6) == 0.5
    watch.history = [(0.4, 0.5), (0.5, 0.3)]
    for _ in range(MAX_LIMIT_CUTS):
        watch.failed(3, 0.7, 25, [1.0])
    with pytest.raises(LimitPointError):
        watch.failed(3, 0.7, 25, [1.0])


def test_not_defined_under_displacement_control_or_multipliers():
    m, model = _balloon(4, 1.0)
    assert load_controlled(model)
    moving = Model([m, Dirichlet(m, m.node_dofs[1, [0]], 0.1)], geometry="axisymmetric")
    assert not load_controlled(moving)
    from skfem_mortar.loads.volume import VolumeControl
    assert not load_controlled(Model([m, VolumeControl(m, 3.0)], geometry="axisymmetric"))
