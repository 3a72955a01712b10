"""The default contact method is dual mortar everywhere a user does not name one
(the pair, ``run``, ``demo``, ``study``'s references, ``bench``), and the command
line says so: a newcomer's first model passes the non-matching patch test."""
import inspect
import subprocess
import sys

import numpy as np
import skfem

from skfem_mortar import ContactPair, Dirichlet, LinearElastic, Model, Solid, solve
from skfem_mortar.app.bench import run_bench
from skfem_mortar.app.cli import build_parser
from skfem_mortar.app.demo import run_demo
from skfem_mortar.contact import DEFAULT_METHOD
from skfem_mortar.contact.surfaces import ContactSurface
from skfem_mortar.scenes import get_scene, list_scenes


def _two_blocks(n_top: int, n_bottom: int):
    """A narrow block on a wide one, meshes not matching at the interface."""
    bottom = skfem.MeshTri.init_tensor(np.linspace(0, 1, n_bottom + 1), np.linspace(0, 0.5, 4))
    top = skfem.MeshTri.init_tensor(np.linspace(0, 1, n_top + 1), np.linspace(0.5, 1.0, 4))
    law = LinearElastic(E=100.0, nu=0.3)
    b = Solid(bottom, law, element="tri1", name="bottom")
    t = Solid(top, law, element="tri1", name="top")
    return b, t


def test_the_pair_defaults_to_dual_mortar():
    b, t = _two_blocks(7, 10)
    top_bottom = t.mesh.facets_satisfying(lambda x: np.isclose(x[1], 0.5), boundaries_only=True)
    bottom_top = b.mesh.facets_satisfying(lambda x: np.isclose(x[1], 0.5), boundaries_only=True)
    pair = ContactPair(ContactSurface.from_solid(t, top_bottom), ContactSurface.from_solid(b, bottom_top))
    assert pair.method == DEFAULT_METHOD == "mortar-dual"
    assert inspect.signature(ContactPair).parameters["method"].default == DEFAULT_METHOD


def test_every_contact_scene_runs_dual_mortar_unless_told():
    with_contact = [s for s in list_scenes() if s.methods != (None,)]
    assert with_contact  # hertz, patch, seed, ...
    for scene in with_contact:
        assert scene.check_method(None) == "mortar-dual", scene.name
    assert get_scene("block").check_method(None) is None  # no contact, no method


def test_demo_bench_and_cli_default_to_dual_mortar():
    assert inspect.signature(run_demo).parameters["method"].default == DEFAULT_METHOD
    assert inspect.signature(run_bench).parameters["method"].default == DEFAULT_METHOD
    parser = build_parser()
    for command in ("demo", "bench"):
        args = parser.parse_args([command])
        assert args.method == DEFAULT_METHOD, command


def test_run_help_names_the_scenes_and_the_default():
    out = subprocess.run([sys.executable, "-m", "skfem_mortar.app.cli", "run", "--help"],
                         capture_output=True, text=True, timeout=60).stdout
    text = " ".join(out.split())
    for scene in list_scenes():
        assert scene.name in text, scene.name
    assert "default: mortar-dual" in text


def test_a_default_patch_test_passes(tmp_path):
    """A user's first non-matching contact model, method not named: the uniform
    pressure comes through exactly (dual mortar passes the patch test; NTS is
    several percent off on these meshes)."""
    b, t = _two_blocks(7, 10)
    pair = ContactPair(
        ContactSurface.from_solid(t, t.mesh.facets_satisfying(lambda x: np.isclose(x[1], 0.5),
                                                              boundaries_only=True)),
        ContactSurface.from_solid(b, b.mesh.facets_satisfying(lambda x: np.isclose(x[1], 0.5),
                                                              boundaries_only=True)))
    top_nodes = t.mesh.nodes_satisfying(lambda x: np.isclose(x[1], 1.0))
    bottom_nodes = b.mesh.nodes_satisfying(lambda x: np.isclose(x[1], 0.0))
    left_b = b.mesh.nodes_satisfying(lambda x: np.isclose(x[0], 0.0))
    left_t = t.mesh.nodes_satisfying(lambda x: np.isclose(x[0], 0.0))
    d = -0.01
    model = Model([b, t, pair,
                   Dirichlet(b, b.dofs_at_nodes(bottom_nodes, component=1)),
                   Dirichlet(b, b.dofs_at_nodes(left_b, component=0)),
                   Dirichlet(t, t.dofs_at_nodes(left_t, component=0)),
                   Dirichlet(t, t.dofs_at_nodes(top_nodes, component=1), value=d)])
    result = solve(model, n_steps=1)
    p = pair.contact_data(result.z)["pressure"]
    # plane-strain uniaxial stress (sides free), small-strain bulk, two equal
    # blocks in series over a height 1: sigma_yy = E / (1 - nu^2) |d|; the contact
    # pressure is per *current* length, stretched by eps_xx = nu / (1 - nu) |d|
    E, nu = 100.0, 0.3
    exact = E / (1 - nu**2) * abs(d) / (1 + nu / (1 - nu) * abs(d))
    # the patch test is exact to round-off for mortar; 1e-8 leaves room for the
    # Newton tolerance (relative 1e-10 residuals) and is far below NTS's error
    assert np.allclose(p, exact, rtol=1e-8), (p.min() / exact, p.max() / exact)
