"""Axisymmetric results revolved into 3D (:func:`skfem_mortar.output.views.revolve`),
written with cylindrical names, and the README's rubber tube: a model written from the
README alone, run, written, read back and drawn revolved."""
import numpy as np
import pytest

from skfem_mortar.output.io import read_series
from skfem_mortar.output.views import render_revolved, revolve
from skfem_mortar.scenes import get_scene
from skfem_mortar.solver.stepping import solve

pv = pytest.importorskip("pyvista")


def _sphere(element="quad2", n=2):
    scene = get_scene("thick_sphere")
    setup = scene.build(scene.resolve({"element": element, "n": n}), None)
    return setup, solve(setup.model, n_steps=1)


def test_revolve_sweeps_the_meridian_and_its_fields(tmp_path):
    setup, result = _sphere()
    body = setup.model.items[0]
    segments = 12
    grid = revolve(result, segments=segments, deformed=False)["sphere"]
    points, cells = body.output_mesh()
    assert grid.n_points == len(points) * (segments + 1)
    assert grid.n_cells == len(cells[0][1]) * segments
    assert set(grid.celltypes) == {12}                            # hexahedra from quads
    # every point at its radius from the axis, the quarter from 0 to pi / 2 left out
    xyz = np.asarray(grid.points)
    r = np.tile(points[:, 0], segments + 1)
    np.testing.assert_allclose(np.hypot(xyz[:, 0], xyz[:, 1]), r, rtol=0, atol=1e-14)
    angle = np.arctan2(xyz[:, 1], xyz[:, 0]) % (2 * np.pi)
    assert not np.any((angle > 1e-9) & (angle < 0.5 * np.pi - 1e-9) & (r > 0))
    # the displacement (u_r, u_z) turned with the angle: its length is kept
    u = body.output_data(result.z)[0]["displacement"]
    np.testing.assert_allclose(np.linalg.norm(grid.point_data["displacement"], axis=1),
                               np.tile(np.linalg.norm(u, axis=1), segments + 1), rtol=1e-14)
    np.testing.assert_array_equal(grid.cell_data["sigma_tt"][:len(cells[0][1])],
                                  body.output_data(result.z)[1]["sigma_tt"][0])
    png = render_revolved(result, tmp_path / "sphere.png", segments=segments)
    assert png.stat().st_size > 10_000                         # a picture, not a blank
    with pytest.raises(ValueError, match="cut must be in"):
        revolve(result, cut=1.0)
    with pytest.raises(ValueError, match="segments must be an integer >= 1"):
        revolve(result, segments=0)


def test_revolve_refuses_a_plane_result():
    from skfem_mortar.app.runner import run_scene

    _, result, _ = run_scene("patch", {}, method="mortar", return_result=True)
    with pytest.raises(ValueError, match="revolve needs an axisymmetric model"):
        revolve(result)


def test_written_fields_are_cylindrical(tmp_path):
    setup, result = _sphere("tri2", 2)
    result.save(tmp_path)
    (_, last), = read_series(tmp_path / "sphere.pvd")[-1:]
    assert {"sigma_rr", "sigma_zz", "sigma_rz", "sigma_tt", "von_mises"} <= set(last.cell_data)
    assert "sigma_xx" not in last.cell_data


def _follower_pressure_is_axisymmetric() -> bool:
    from skfem_mortar.loads.pressure import FollowerPressure

    return "axisymmetric" in (FollowerPressure.geometries or ("axisymmetric",))


_README_AXI = pytest.mark.skipif(
    not _follower_pressure_is_axisymmetric(),
    reason="the axisymmetric follower pressure (issue 35 item 4) is not merged yet")


@_README_AXI
def test_readme_rubber_tube(tmp_path):
    """The README's axisymmetric example, as a user writes it from the README alone.
    Needs the axisymmetric follower pressure (issue 35, item 4) and the preflight's
    axisymmetric rigid modes (the axial translation only: a tube has no axis nodes,
    and a radial translation strains its hoop)."""
    import skfem
    from skfem_mortar import Dirichlet, FollowerPressure, Model, NeoHooke, Solid, solve as run

    mesh = (skfem.MeshQuad.init_tensor(np.linspace(1.0, 2.0, 5), np.linspace(0.0, 1.0, 5))
            .with_defaults())                                   # r in [1, 2], z in [0, 1]
    tube = Solid(mesh, NeoHooke(E=10.0, nu=0.45), element="quad2", name="tube")
    model = Model([tube,
                   FollowerPressure(tube, 2.0, facets="left", side="inward", name="pressure"),
                   Dirichlet(tube, tube.dofs_on("bottom", "y"), name="bottom"),
                   Dirichlet(tube, tube.dofs_on("top", "y"), name="top")],
                  geometry="axisymmetric")
    result = run(model, n_steps=4)
    result.save(tmp_path / "tube")
    (_, frame), = read_series(tmp_path / "tube" / "tube.pvd")[-1:]
    png = render_revolved(result, tmp_path / "tube.png")

    assert result.converged
    u_r = frame.point_data["displacement"][:, 0]
    inner = mesh.p[0] == 1.0
    assert np.all(u_r[inner] > 0.0)                             # the bore widens
    assert frame.cell_data["sigma_tt"][0].max() > 0.0           # hoop tension
    assert png.stat().st_size > 10_000
