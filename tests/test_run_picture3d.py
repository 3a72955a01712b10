"""The picture of a 3D contact run (issue 38, item 7): ``run --out`` writes
``figure.png``, the bodies by von Mises beside the slave surface by pressure, listed in
the run's manifest; the pressure view frames the faces that carry pressure."""
from types import SimpleNamespace

import numpy as np
import pytest

from skfem_mortar.app.runner import run_scene
from skfem_mortar.output.outdir import read_manifest
from skfem_mortar.output.render3d import _pressure_view

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_run_out_writes_the_3d_picture_and_lists_it(tmp_path):
    out = tmp_path / "run"
    run_scene("patch3d", {"n_lower": 4, "n_upper": 2, "kinematics": "small"}, "mortar-dual",
              steps=1, out=out)
    assert (out / "figure.png").read_bytes()[:8] == PNG
    assert "figure.png" in read_manifest(out)["files"]


def test_a_2d_run_writes_no_picture(tmp_path):
    # the 2D run's pictures are the demo's and the scenes' own (this one has none)
    run_scene("patch", {"n_top": 2, "n_bottom": 2}, "nts", steps=1, out=tmp_path / "run")
    assert not (tmp_path / "run" / "figure.png").exists()


def _plane_pair(pressed: float):
    """A fake 3D pair: a 10 x 10 grid of quad4 faces on z = 0 facing down, the nodes
    within ``pressed`` of the origin carrying a pressure (1 - r)."""
    t = np.linspace(0.0, 1.0, 11)
    X, Y = np.meshgrid(t, t, indexing="ij")
    x = np.vstack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    i, j = np.meshgrid(np.arange(10), np.arange(10), indexing="ij")
    a = (11 * i + j).ravel()
    faces = np.column_stack([a, a + 1, a + 12, a + 11])            # clockwise from +z
    r = np.hypot(x[0], x[1])
    node = np.flatnonzero(r < pressed)
    normals = np.tile([[0.0], [0.0], [-1.0]], (1, len(faces)))
    slave = SimpleNamespace(n_nodes=x.shape[1], segments=faces, x=lambda z: x,
                            normals=lambda z: (normals, np.full(len(faces), 0.01)))
    pair = SimpleNamespace(name="contact", slave=slave,
                           contact_data=lambda z: {"node": node, "pressure": 1.0 - r[node]})
    return pair, x, faces, r


@pytest.mark.parametrize("pressed", [0.15, 0.0])
def test_the_pressure_view_frames_the_loaded_faces(pressed):
    import pyvista as pv

    pair, x, faces, r = _plane_pair(pressed)
    plotter = pv.Plotter(off_screen=True, window_size=(300, 300))
    try:
        _pressure_view(plotter, [pair], np.zeros(0))
        shown = plotter.renderer.actors["contact:contact"].mapper.dataset
        cam = np.array(plotter.camera.position) - np.array(plotter.camera.focal_point)
    finally:
        plotter.close()
    loaded = (r[faces] < pressed).any(axis=1)
    if pressed:
        # the 2 x 2 faces at the origin carry pressure (their nodes reach 0.2), grown
        # by half their extent (0.1): the faces whose centre lies below 0.3, 3 x 3
        assert loaded.sum() == 4 and shown.n_cells == 9, (loaded.sum(), shown.n_cells)
    else:                                               # nothing loaded: all faces
        assert shown.n_cells == len(faces)
    # seen from the master's side: the camera below the faces, looking up
    assert cam[2] < 0 and abs(cam[2]) > 0.99 * np.linalg.norm(cam)


def test_without_a_way_to_draw_the_run_says_so_and_keeps_its_results(tmp_path, monkeypatch,
                                                                      capsys):
    # a bare Linux without a display, EGL or OSMesa: VTK could not open a window
    import skfem_mortar.output.views as views

    monkeypatch.setattr(views, "can_render", lambda environ=None: False)
    out = tmp_path / "run"
    summary = run_scene("patch3d", {"n_lower": 4, "n_upper": 2, "kinematics": "small"},
                        "nts", steps=1, out=out)
    assert summary["converged"] and (out / "summary.json").exists()
    assert (out / "contact.csv").exists() and not (out / "figure.png").exists()
    assert "figure.png not drawn" in capsys.readouterr().err


def test_can_render_reads_the_display_and_the_libraries(monkeypatch):
    import ctypes.util

    import skfem_mortar.output.views as views

    monkeypatch.setattr(views.sys, "platform", "linux")
    monkeypatch.setattr(ctypes.util, "find_library", lambda name: None)
    assert not views.can_render({})                           # nothing to draw with
    assert views.can_render({"DISPLAY": ":0"})
    assert views.can_render({views._VTK_WINDOW: "vtkXOpenGLRenderWindow"})  # the user's
    monkeypatch.setattr(ctypes.util, "find_library", lambda name: "libEGL.so.1")
    assert views.can_render({})
    monkeypatch.setattr(views.sys, "platform", "darwin")
    monkeypatch.setattr(ctypes.util, "find_library", lambda name: None)
    assert views.can_render({})
