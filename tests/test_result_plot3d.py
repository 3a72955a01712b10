"""Result.plot of a 3D model: the pyvista render (output.render3d), a PNG a notebook shows;
the 2D FollowerPressure points a 3D body to FollowerPressure3D."""
import numpy as np
import pytest
import skfem

from skfem_mortar import Dirichlet, FollowerPressure, FollowerPressure3D, Model, NeoHooke, \
    Solid, solve

pytest.importorskip("pyvista")


def _block():
    g = np.linspace(0.0, 1.0, 3)
    return Solid(skfem.MeshHex1.init_tensor(g, g, g).with_defaults(),
                 NeoHooke(E=10.0, nu=0.3), element="hex1", name="block")


def test_result_plot_of_a_3d_model_is_a_pyvista_png(tmp_path):
    block = _block()
    model = Model([block, Dirichlet(block, boundary="front"),
                   FollowerPressure3D(block, 1.0, "back")])
    result = solve(model, n_steps=2)
    pic = result.plot(tmp_path / "block.png", title="block", cut="x")
    assert pic._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"
    from PIL import Image
    assert Image.open(pic).size == (1200, 900)      # render3d's window, not matplotlib's


def test_cut_is_refused_for_a_2d_model(tmp_path):
    body = Solid(skfem.MeshTri1().with_defaults(), NeoHooke(E=10.0, nu=0.3))
    result = solve(Model([body, Dirichlet(body, body.dofs_on("left"))]), n_steps=1)
    with pytest.raises(ValueError, match="cut is for 3D models"):
        result.plot(tmp_path / "b.png", cut="x")


def test_the_2d_follower_pressure_points_a_3d_body_to_the_3d_one():
    with pytest.raises(ValueError, match="3D solid.*FollowerPressure3D"):
        FollowerPressure(_block(), 1.0, facets="back")
