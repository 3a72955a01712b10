"""A p2p1 body's pressure is written on every output node (the linear field
evaluated at the mid-edge nodes too), so its series has no NaN and reads back:
a linear pressure comes out exact at every node, vertices and mid-edges alike."""
import numpy as np
import skfem

from skfem_mortar import Model, NeoHooke, Solid
from skfem_mortar.output.io import read_series


def test_p2p1_pressure_is_written_on_every_node(tmp_path):
    mesh = skfem.MeshTet.init_tensor(*(np.linspace(0.0, 1.0, 3),) * 3).with_defaults()
    body = Solid(mesh, NeoHooke(E=10.0, nu=0.49), element="p2p1", name="b")
    model = Model([body])
    z = np.zeros(model.n)
    X = body.mesh.p[:, np.asarray(body.pbasis.nodal_dofs[0])]
    p = X[0] + 2.0 * X[1] - X[2]                          # a linear pressure field
    z[body.offset + body.n_u + np.asarray(body.pbasis.nodal_dofs[0])] = p / body.pressure_scale
    points, _ = body.output_mesh()
    out = body.output_data(z)[0]["pressure"]
    # P1 interpolation of a linear field is exact: round-off of the probe's barycentric
    # weights, 1e-12 of the field's size (about 3)
    exact = points[:, 0] + 2.0 * points[:, 1] - points[:, 2]
    assert out.shape == (points.shape[0],) and np.abs(out - exact).max() <= 1e-12 * 3
    # and the series writes and reads it back, finite (the writer refuses a NaN)
    from skfem_mortar.solver.stepping import Result
    result = Result(model, steps=[], states=[z.copy()])
    result.save(tmp_path / "o")
    frame = read_series(tmp_path / "o" / "b.pvd")[-1][1]
    assert np.allclose(frame.point_data["pressure"], exact, rtol=0, atol=1e-12 * 3)
