"""Checkpoints and resume of a 3D model, as in 2D: a run resumed from a
checkpointed step ends where the uninterrupted run ends, bit for bit, and the
3D series written on the way read back."""
import numpy as np
import skfem

from skfem_mortar import Dirichlet, Model, NeoHooke, Solid, solve
from skfem_mortar.loads.pressure3d import FollowerPressure3D
from skfem_mortar.output.checkpoint import read_checkpoint
from skfem_mortar.output.io import read_series
from skfem_mortar.solver.observers import CheckpointObserver, SeriesObserver
from skfem_mortar.solver.stepping import Controller, Restart, StepRecord


def _model():
    g = np.linspace(0.0, 1.0, 3)
    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet1.init_tensor(g, g, g)).with_defaults()
    body = Solid(mesh, NeoHooke(E=50.0, nu=0.3), element="tet2", name="body")
    return Model([body, Dirichlet(body, boundary="left", name="clamp"),
                  Dirichlet(body, boundary="right", component="x", value=0.1, name="pull"),
                  FollowerPressure3D(body, 2.0, "top", name="pressure")])


def test_a_3d_run_resumed_from_a_checkpoint_ends_bit_for_bit_where_the_whole_run_ends(
        tmp_path):
    meta = {"scene": "test3d"}
    model = _model()
    whole = solve(model, n_steps=4,
                  observers=[CheckpointObserver(tmp_path / "checkpoint", meta),
                             SeriesObserver(tmp_path, model.outputs())])
    assert whole.converged and len(whole.steps) == 4
    ck = read_checkpoint(tmp_path / "checkpoint", meta)
    assert len(ck.history) == 4
    np.testing.assert_array_equal(ck.states[-1], whole.z)
    r = 2   # resume after the second step, as the runner does
    restart = Restart(ck.states[r].copy(), float(ck.load_factors[r]),
                      [StepRecord.from_dict(h) for h in ck.history[:r]],
                      Controller.from_dict(ck.controllers[r]),
                      previous=ck.states[r - 1].copy(), items=ck.items[r])
    resumed = solve(_model(), n_steps=4, restart=restart)
    assert len(resumed.steps) == 4
    np.testing.assert_array_equal(resumed.z, whole.z)
    # the series: one frame per state, quadratic cells, the displacement as solved
    frames = read_series(tmp_path / "body.pvd")
    assert len(frames) == 5 and list(frames[-1][1].cells_dict) == ["tetra10"]
    body = model.item("body")
    np.testing.assert_array_equal(frames[-1][1].point_data["displacement"],
                                  body.output_data(whole.z)[0]["displacement"])
    assert frames[-1][1].point_data["displacement"].shape[1] == 3
