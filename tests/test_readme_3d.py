"""A 3D model written from the README alone: a block clamped at one face and
pressed by a follower pressure on the opposite one, solved, written, read back
and drawn.  The README's Python block that uses ``FollowerPressure3D`` is run
(``SNIPPET``, the text proposed for it, until the README has one); it must
name ``result``, ``block``, ``model`` and ``frame`` as ``SNIPPET`` does."""
import re
from pathlib import Path

import numpy as np
import pytest

README = Path(__file__).resolve().parents[1] / "README.md"

SNIPPET = '''\
import numpy as np
import skfem
from skfem_mortar import Dirichlet, Model, NeoHooke, Solid, solve
from skfem_mortar.loads.pressure3d import FollowerPressure3D
from skfem_mortar.output.io import read_series
from skfem_mortar.output.render3d import render3d

g = np.linspace(0.0, 1.0, 4)
mesh = skfem.MeshHex1.init_tensor(g, g, 2 * g).with_defaults()  # tags: left/right (x = 0, 1),
block = Solid(mesh, NeoHooke(E=100.0, nu=0.3), element="hex1",  # bottom/top (y), front/back (z)
              name="block")
model = Model([block,
               Dirichlet(block, boundary="front", name="clamp"),           # z = 0 held
               FollowerPressure3D(block, 10.0, "back", name="pressure")])  # presses z = 2 in
result = solve(model, n_steps=4)

result.save("block3d")                           # block3d/block.pvd + one VTU per step
time, frame = read_series("block3d/block.pvd")[-1]                # meshio.Mesh of the last
print(frame.point_data["displacement"][:, 2].min())               # the top moved down (< 0)
render3d([block], result.states[0], result.z, "block3d/block.png",  # off-screen pyvista PNG,
         items=model.items)                                        # coloured by von Mises
'''


def _example() -> str:
    """The README's 3D example (its block using FollowerPressure3D), else ``SNIPPET``."""
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    return next((b for b in blocks if "FollowerPressure3D" in b), SNIPPET)


def test_the_readme_3d_example_runs_and_its_outputs_hold(tmp_path, monkeypatch, capsys):
    pytest.importorskip("pyvista")
    pytest.importorskip("meshio")
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    exec(compile(_example(), "README.md", "exec"), ns)
    result, block, model, frame = ns["result"], ns["block"], ns["model"], ns["frame"]
    assert result.converged
    # Newton with the exact load stiffness: quadratic, the last residual at round-off
    last = result.steps[-1].residual_norms
    assert last[-1] < 1e-9 * last[0]
    # the file holds the model's displacement at every node, in float64
    points, _ = block.output_mesh()
    u = block.output_data(result.z)[0]["displacement"]
    np.testing.assert_array_equal(frame.points, points)
    np.testing.assert_array_equal(frame.point_data["displacement"], u)
    assert float(capsys.readouterr().out) < 0
    assert set(frame.point_data) >= {"sigma_xx", "sigma_yy", "sigma_zz", "sigma_xy",
                                     "sigma_yz", "sigma_xz", "von_mises"}
    # equilibrium: the clamp's reaction balances the pressure's resultant p * a
    # (a the current area of the pressed face), to Newton's tolerance
    R = result.residual()
    clamp = model.item("clamp")
    dofs, _ = clamp.prescribed(1.0)
    react = np.array([R[dofs][block.dof_component[dofs - block.offset] == c].sum()
                      for c in range(3)])
    force = model.item("pressure").resultant(result.z)
    np.testing.assert_allclose(react, -force, atol=1e-8 * np.abs(force).max())
    assert force[2] < 0 and abs(force[2]) > 10.0 * 0.99   # 10 over a face of area ~1
    png = tmp_path / "block3d" / "block.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
