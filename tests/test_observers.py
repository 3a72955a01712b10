"""Output is an observer of the solve (issue 15, item 3)."""
import numpy as np
import pytest

from skfem_mortar.core.errors import ConvergenceError
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.solver.observers import (Callback, CheckpointObserver, ContactCsv, Observer,
                                    SeriesObserver, replay)
from skfem_mortar.app.runner import build_scene
from skfem_mortar.solver.stepping import solve

from toy_items import Spring


class Recording(Observer):
    def __init__(self, log, tag="obs"):
        self.log, self.tag = log, tag
        self.states = []

    def on_start(self, model, z, load_factor):
        self.log.append((self.tag, "start", load_factor))
        self.states.append(z.copy())

    def on_step(self, record, z):
        self.log.append((self.tag, "step", record.load_factor))
        self.states.append(z.copy())

    def on_end(self, result):
        self.log.append((self.tag, "end", result.converged))


def _springs(load=1.0, law="atan"):
    s = Spring(3, k=2.0, load=load, law=law)
    return Model([s, Dirichlet(s, [0])])


def test_an_observer_sees_start_steps_end_in_order_with_the_states_of_the_result():
    log = []
    obs = Recording(log)
    calls = []
    res = solve(_springs(), 3, observers=[obs], callback=lambda rec, z: calls.append(rec))
    assert [e[:2] for e in log] == [("obs", "start")] + [("obs", "step")] * 3 + [("obs", "end")]
    assert log[-1] == ("obs", "end", True)
    assert [e[2] for e in log[1:-1]] == [s.load_factor for s in res.steps]
    assert len(obs.states) == len(res.states)
    assert all(np.array_equal(a, b) for a, b in zip(obs.states, res.states))
    assert calls == res.steps  # the callback: a thin observer after the given ones


def test_observers_are_told_in_the_order_given_and_the_end_of_a_failed_solve():
    log = []
    model = _springs(load=50.0, law="sinh")

    def stop(rec, z):
        raise ConvergenceError(2, 1.0, 1, [1.0], "stopped by the callback")

    with pytest.raises(ConvergenceError):
        solve(model, 2, observers=[Recording(log, "a"), Recording(log, "b")], callback=stop)
    assert [e[:2] for e in log] == [("a", "start"), ("b", "start"), ("a", "step"),
                                    ("b", "step"), ("a", "end"), ("b", "end")]
    assert log[-1] == ("b", "end", False)


def test_observers_must_be_observers():
    with pytest.raises(ValueError, match=r"observers\[0\] must be an Observer"):
        solve(_springs(), 1, observers=[lambda rec, z: None])


def test_replay_tells_what_the_solve_told():
    live, again = [], []
    res = solve(_springs(), 2, observers=[Recording(live)])
    replay(res, [Recording(again)])
    assert live == again


def _files(path):
    return {p.relative_to(path).as_posix(): p.read_bytes()
            for p in sorted(path.rglob("*")) if p.is_file()}


def test_result_save_writes_what_the_observers_write_during_the_solve(tmp_path):
    setup, _, _ = build_scene("patch", {}, method="mortar")
    live = tmp_path / "live"
    res = solve(setup.model, 2, observers=[SeriesObserver(live), ContactCsv(live / "contact.csv")])
    saved = res.save(tmp_path / "saved")
    a, b = _files(live), _files(saved)
    assert sorted(a) == sorted(b) and "contact.csv" in a and "contact.pvd" in a
    assert a == b


def test_a_checkpoint_observer_writes_one_step_per_state(tmp_path):
    from skfem_mortar.output.checkpoint import read_checkpoint

    model = _springs()
    meta = {"scene": "springs"}
    ck = CheckpointObserver(tmp_path / "checkpoint", meta)
    res = solve(model, 3, observers=[ck])
    read = read_checkpoint(tmp_path / "checkpoint", meta, n=model.n)
    assert len(read.states) == len(res.states) == 4
    assert all(np.array_equal(a, b) for a, b in zip(read.states, res.states))
    assert [h["load_factor"] for h in read.history] == [s.load_factor for s in res.steps]


def test_callback_observer_wraps_a_function():
    seen = []
    Callback(lambda rec, z: seen.append((rec, z))).on_step("rec", "z")
    assert seen == [("rec", "z")]


def test_result_plot_needs_no_setup(tmp_path):
    setup, _, _ = build_scene("block", {"refine": 1})
    res = solve(setup.model, 1)
    assert res.plot(tmp_path / "block.png", title="block").stat().st_size > 1000
