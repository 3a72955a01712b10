"""Off-screen pictures of 3D models (output.render3d): a stretched block drawn."""
import numpy as np
import pytest
import skfem

from skfem_mortar.bodies.material import LinearElastic
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.loads.pressure3d import FollowerPressure3D
from skfem_mortar.output import views
from skfem_mortar.output.render3d import render3d, scene3d

pv = pytest.importorskip("pyvista")
if views._headless_window() is None and not __import__("os").environ.get("DISPLAY"):
    pytest.skip("neither EGL nor OSMesa is installed: VTK cannot draw off screen here",
                allow_module_level=True)


def _stretched_block(element="hex1"):
    g = np.linspace(0.0, 1.0, 3)
    mesh = (skfem.MeshHex1 if element.startswith("hex") else skfem.MeshTet1).init_tensor(
        g, g, 2 * g).with_defaults()
    if element.endswith("2"):
        mesh = (skfem.MeshHex2 if element == "hex2" else skfem.MeshTet2).from_mesh(
            mesh).with_defaults()
    body = Solid(mesh, LinearElastic(E=100.0, nu=0.3), element=element, name="block")
    # a stretch along z and a shear: von Mises varies (the shear grows with x)
    z = body.interpolate(lambda X: np.array([0.1 * X[2] * X[0], 0 * X[1], 0.2 * X[2]]))
    items = [body, Dirichlet(body, boundary="front", name="clamp"),
             FollowerPressure3D(body, -5.0, "back", name="pull")]
    return body, z, items


def test_a_stretched_block_is_drawn_with_its_key_outline_supports_and_loads(tmp_path):
    body, z, items = _stretched_block()
    z0 = np.zeros_like(z)
    plotter = scene3d([body], z0, z, items=items, window_size=(400, 300))
    try:
        img = plotter.screenshot(return_img=True)
        # not blank: a white picture has variance 0, the body in colour over
        # white about 80^2 (measured 6.7e3 here); 400 (20^2) is kept
        assert img.shape == (300, 400, 3)
        assert np.var(img.astype(float)) > 400.0
        # the scalar bar names the quantity and its units
        (title,) = plotter.scalar_bars.keys()
        assert "von Mises stress" in title and "force/length" in title
        # the undeformed outline: the reference block's 12 edges (its corners at the
        # reference positions), drawn: the picture changes without it
        outline = plotter.actors["outline:block"].mapper.dataset
        assert outline.n_cells >= 12
        np.testing.assert_allclose(outline.bounds, [0, 1, 0, 1, 0, 2], atol=1e-12)
        plotter.remove_actor("outline:block")
        assert np.sum(np.any(plotter.screenshot(return_img=True) != img, axis=2)) > 50
        # supports on the clamped face z = 0, loads on the face z = 2 (pulled out)
        held = plotter.actors["supports:block"].mapper.dataset.points
        assert len(held) == 9 and np.allclose(held[:, 2], 0.0)
        assert "loads:block" in plotter.actors
    finally:
        plotter.close()
    pic = render3d([body], z0, z, tmp_path / "block.png", items=items, cut="y",
                   title="stretched block", window_size=(400, 300))
    assert pic.is_file() and pic._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("element", ["tet2", "hex2"])
def test_quadratic_bodies_and_a_cut_plane(element):
    body, z, items = _stretched_block(element)
    plotter = scene3d([body], np.zeros_like(z), z, items=items, cut=((1, 0, 0), (0.5, 0, 0)),
                      window_size=(300, 300))
    try:
        shown = plotter.actors["body:block"].mapper.dataset
        assert shown.bounds[1] <= 0.5 + 1e-9 + 0.1 * 2          # the x > 0.5 half clipped
        assert np.var(plotter.screenshot(return_img=True).astype(float)) > 400.0
    finally:
        plotter.close()


def test_refusals_name_the_argument(tmp_path):
    body, z, items = _stretched_block()
    with pytest.raises(ValueError, match="cut"):
        scene3d([body], z, z, cut="w")
    with pytest.raises(ValueError, match="cut"):
        scene3d([body], z, z, cut=((0, 0, 0), (0, 0, 0)))
    with pytest.raises(ValueError, match="window_size"):
        scene3d([body], z, z, window_size=(10, 10))
    with pytest.raises(ValueError, match="bodies"):
        scene3d([], z, z)


def test_the_2d_figure_refuses_a_3d_body_naming_render3d(tmp_path):
    from skfem_mortar.output.plot import draw

    body, z, items = _stretched_block()
    with pytest.raises(ValueError, match="bodies: 'block' is a 3D body.*render3d"):
        draw([body], np.zeros_like(z), z, tmp_path / "x.png", items=items)


def test_the_outline_is_drawn_at_the_initial_state():
    body, z, items = _stretched_block()
    plotter = scene3d([body], 0.5 * z, z, window_size=(300, 300))
    try:
        outline = plotter.actors["outline:block"].mapper.dataset
        # half the stretch 0.2 z and half the shear 0.1 z x: the top at z = 2.2
        np.testing.assert_allclose(outline.bounds[4:], [0.0, 2.2], atol=1e-12)
    finally:
        plotter.close()
