"""The outputs as pyvista data (output.views.to_pyvista): what a notebook views."""
import numpy as np
import pytest

from skfem_mortar.app.runner import run_scene
from skfem_mortar.output.views import to_pyvista

pv = pytest.importorskip("pyvista")


def test_outputs_as_a_pyvista_multiblock():
    _, result, setup = run_scene("patch", {}, method="mortar", return_result=True)
    outputs = setup.model.outputs()
    z = result.z
    blocks = to_pyvista(outputs, z)
    ref = to_pyvista(outputs, z, deformed=False)
    assert list(blocks.keys()) == [o.name for o in outputs]
    for o in outputs:
        points, _ = o.output_mesh()
        point_data, _ = o.output_data(z)
        grid, grid0 = blocks[o.name], ref[o.name]
        assert grid.n_points == len(points)
        np.testing.assert_array_equal(grid0.points[:, :2], points)
        # deformed = reference + displacement, exactly (one addition)
        u = point_data["displacement"]
        np.testing.assert_array_equal(grid.points[:, :2], points + u)
        assert np.all(grid.points[:, 2] == 0.0)
    contact = blocks["contact"]
    p = setup.model.item("contact").contact_data(z)["pressure"]
    np.testing.assert_array_equal(contact.point_data["pressure"], p)
