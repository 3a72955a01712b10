"""Failures that name their cause (issue 32, class 4 and parts of 1, 7, 8).

Each model is written as the issue's user wrote it, with the public API:

* a block resting on a rigid plane and pulled up by a load, held by nothing but
  the contact (alone, or driven sideways by a prescribed displacement): the
  ConvergenceError names the body, the free mode and the pair that opens;
* a closed cable ring under an external follower pressure: the error names the
  cable and its compressed elements;
* two blocks in contact at a Young's modulus ratio of 1e15: a PreflightWarning
  before the solve names both bodies and the ratio; the step that used to
  "converge" with a residual larger than its load is a ConvergenceError;
* NTS on non-matching deformable meshes: a PreflightWarning says how far off
  the patch test NTS is and names method="mortar-dual";
* the warnings point at the user's line; a z0 with NaN is a ValueError naming z0.
"""
import warnings

import numpy as np
import pytest
import skfem

from skfem_mortar import (Cable, ContactPair, Dirichlet, FollowerPressure, Model, NeoHooke,
                          Solid, Traction, solve)
from skfem_mortar.contact.preflight import PreflightWarning
from skfem_mortar.contact.surfaces import ContactSurface, RigidCircle, RigidPlane
from skfem_mortar.core.errors import ConvergenceError

METHODS = ("nts", "mortar", "mortar-dual")


def _block(x0=0.0, y0=0.0, w=1.0, h=0.5, nx=4, ny=2, E=10.0, name="block"):
    m = skfem.MeshTri.init_tensor(np.linspace(x0, x0 + w, nx + 1),
                                  np.linspace(y0, y0 + h, ny + 1))
    m = m.with_boundaries({"bottom": lambda x: np.isclose(x[1], y0),
                           "top": lambda x: np.isclose(x[1], y0 + h)})
    return Solid(m, NeoHooke(E=E, nu=0.3), element="tri1", name=name)


def _on_plane(method, up=1.0, drive=None):
    """A block on the plane y = 0, a traction (0, up) on its top; its left side held
    in x (``drive``: prescribed to that x displacement); nothing holds it in y
    but the contact."""
    b = _block()
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"),
                       RigidPlane((0.0, 0.0), (0.0, 1.0)), method=method, name="floor")
    left = np.flatnonzero(np.isclose(b.X[0], 0.0))
    side = Dirichlet(b, b.dofs_at_nodes(left, component=0), drive or 0.0, name="side")
    return Model([b, Traction(b, "top", (0.0, up)), side, pair])


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("drive", [None, 0.2])
def test_block_pulled_off_the_plane_names_the_body_and_the_contact(method, drive):
    with pytest.raises(ConvergenceError) as err:
        solve(_on_plane(method, drive=drive))
    msg = str(err.value)
    assert ("body 'block': its translation in y is held by contact 'floor' alone, and the "
            "load on it") in msg
    assert "pulls it away from the master" in msg
    assert "the contact opens entirely and nothing holds the body" in msg


@pytest.mark.parametrize("method", METHODS)
def test_of_two_stacked_blocks_the_one_pulled_off_is_named(method):
    """A block on a block on the plane, each held in x on its left side; the upper
    one pulled up: it alone is named (the lower one is not loaded)."""
    lower, upper = _block(name="lower"), _block(y0=0.5, name="upper")
    items = [lower, upper, Traction(upper, "top", (0.0, 1.0)),
             ContactPair(ContactSurface.from_solid(lower, "bottom"),
                         RigidPlane((0.0, 0.0), (0.0, 1.0)), method=method, name="floor"),
             ContactPair(ContactSurface.from_solid(upper, "bottom"),
                         ContactSurface.from_solid(lower, "top"), method=method, name="stack")]
    for b in (lower, upper):
        left = np.flatnonzero(np.isclose(b.X[0], 0.0))
        items.append(Dirichlet(b, b.dofs_at_nodes(left, component=0), name=f"{b.name}_side"))
    with pytest.raises(ConvergenceError) as err:
        solve(Model(items))
    msg = str(err.value)
    assert "body 'upper': its translation in y is held by contact 'stack' alone" in msg
    assert "body 'lower'" not in msg


def test_block_pressed_onto_the_plane_converges_without_a_cause():
    """The same block pushed down: the contact holds it; no diagnosis runs."""
    res = solve(_on_plane("mortar-dual", up=-1.0))
    assert res.converged


def _ring(tension_only=False, side="left", n=32, drum=None):
    """A counter-clockwise ring of radius 1 (EA 10) under a follower pressure 1 on
    ``side`` ("left": pointing into the ring, an external pressure), its rigid
    motions held as in the ring scene; the scene's tangent floor 0.1 p R0.
    ``drum``: a contact method, for a rigid drum of radius 0.5 inside the ring
    (the ring's inside the slave)."""
    ring = Cable.ring(1.0, n, EA=10.0, law="svk", tension_only=tension_only,
                      tension_floor=0.1, name="ring")
    nd = ring.node_dofs
    items = [ring, FollowerPressure(ring, 1.0, side=side, name="pressure"),
             Dirichlet(ring, [nd[0, 0], nd[1, 0], nd[1, n // 2]], name="supports")]
    if drum is not None:
        items.append(ContactPair(ContactSurface.from_cable(ring, side="left"),
                                 RigidCircle((0.0, 0.0), 0.5), method=drum, name="drum"))
    return Model(items)


def test_ring_under_external_pressure_names_the_compressed_cable():
    """Tension only: the first step fails from the reference ring (R = 1), where the
    regular polygon's statics gives every element N = -lf p cos(pi / n) exactly."""
    with pytest.raises(ConvergenceError) as err:
        solve(_ring(tension_only=True), 4)
    msg = str(err.value)
    n_exact = -err.value.load_factor * np.cos(np.pi / 32)
    assert (f"cable 'ring': the load puts 32 of its 32 elements in compression (the axial "
            f"forces {n_exact:.3g} to {n_exact:.3g} balance it") in msg
    assert "a cable carries no compression (it buckles, or goes slack with tension_only)" in msg


def test_ring_in_compression_that_buckles_names_the_compressed_cable():
    """svk law with compression: the first step converges to a smaller ring (every
    element shorter than its rest length), the second finds no equilibrium."""
    with pytest.raises(ConvergenceError) as err:
        solve(_ring(tension_only=False), 4)
    msg = str(err.value)
    assert err.value.step == 2
    assert "cable 'ring': the load puts 32 of its 32 elements in compression" in msg
    assert "32 of its 32 elements are shorter than their rest length" in msg


@pytest.mark.parametrize("method", METHODS)
def test_ring_pressed_towards_a_drum_names_the_compressed_cable(method):
    """The same ring around a rigid drum of radius 0.5: the contact is open while
    the ring shrinks, and the second step fails alike."""
    with pytest.raises(ConvergenceError) as err:
        solve(_ring(drum=method), 4)
    assert "cable 'ring': the load puts 32 of its 32 elements in compression" in str(err.value)


def test_ring_under_internal_pressure_converges():
    assert solve(_ring(side="right"), 4).converged


def _two_blocks(method, ratio):
    """A block of E = ratio on a base of E = 1 (clamped bottom), pressed by 0.01."""
    base = _block(-0.5, -0.5, 2.0, 0.5, 8, 2, E=1.0, name="base")
    top = _block(0.0, 0.0, 1.0, 0.5, 5, 2, E=ratio, name="top")
    pair = ContactPair(ContactSurface.from_solid(top, "bottom"),
                       ContactSurface.from_solid(base, "top"), method=method)
    left = np.flatnonzero(np.isclose(top.X[0], 0.0))
    return Model([base, top, Dirichlet(base, base.dofs_on("bottom"), name="ground"),
                  Dirichlet(top, top.dofs_at_nodes(left, component=0), name="axis"),
                  Traction(top, "top", (0.0, -1e-2)), pair])


@pytest.mark.parametrize("method", METHODS)
def test_stiffness_ratio_1e15_warns_before_and_fails_naming_the_ratio(method):
    with pytest.warns(PreflightWarning, match=r"body 'top' is 1e\+15 times stiffer than body "
                                              r"'base'.*measured \(up to 1e\+06\)"):
        with pytest.raises(ConvergenceError) as err:
            solve(_two_blocks(method, 1e15))
    msg = str(err.value)
    # it used to "converge" with the stiff block's residual (0.02-0.05) above the load
    assert "the step converged only to round-off: its residual" in msg
    assert "is larger than the step's force level" in msg
    assert "body 'top' is 1e+15 times stiffer than body 'base'" in msg


def test_stiffness_ratio_in_the_measured_range_neither_warns_nor_fails():
    """1e6, the largest measured ratio: no warning, converged, the contact force is
    the load (1e-10 relative: Newton's tolerance on the soft body's rows)."""
    model = _two_blocks("mortar-dual", 1e6)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PreflightWarning)
        res = solve(model)
    fs, _ = model.items[-1].forces(res.z)
    assert fs[1].sum() == pytest.approx(1e-2, rel=1e-10)


def test_nts_on_non_matching_blocks_warns_with_the_patch_error_and_the_fix():
    """5 on 4, slave finer: no coarse-slave hint, but NTS is 6 % off the patch test."""
    model = _two_blocks("nts", 1.0)
    with pytest.warns(PreflightWarning, match=r"fails the contact patch test.*6 % to 47 %"
                                              r".*method=\"mortar-dual\" \(the default\)"):
        solve(model)


def test_nts_on_matching_meshes_and_mortar_do_not_warn():
    top = _block(0.0, 0.0, 1.0, 0.5, 4, 2, name="top")
    base = _block(-0.5, -0.5, 2.0, 0.5, 8, 2, name="base")  # its top nodes under the top's
    for method in ("nts", "mortar-dual"):
        pair = ContactPair(ContactSurface.from_solid(top, "bottom"),
                           ContactSurface.from_solid(base, "top"), method=method)
        left = np.flatnonzero(np.isclose(top.X[0], 0.0))
        model = Model([base, top, Dirichlet(base, base.dofs_on("bottom")),
                       Dirichlet(top, top.dofs_at_nodes(left, component=0)),
                       Traction(top, "top", (0.0, -1e-2)), pair])
        with warnings.catch_warnings():
            warnings.simplefilter("error", PreflightWarning)
            assert solve(model).converged


def test_preflight_warning_points_at_the_users_line():
    model = _two_blocks("nts", 1.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = _line() + 1
        solve(model)
    pre = [w for w in caught if issubclass(w.category, PreflightWarning)]
    assert pre
    assert all(w.filename == __file__ and w.lineno == line for w in pre)


def _line():
    import inspect
    return inspect.currentframe().f_back.f_lineno


@pytest.mark.parametrize("z0, match", [
    ("nan", r"z0 must be finite, got 1 non-finite entries \(the first at index 3: nan\)"),
    ("inf", r"z0 must be finite"),
    ("short", r"z0 must have shape \(35,\)"),
    ("text", r"z0 must be an array of 35 finite real numbers .*got str"),
])
def test_bad_z0_is_refused_naming_z0(z0, match, monkeypatch):
    model = _on_plane("mortar-dual", up=-1.0)
    assert model.n == 35
    value = {"nan": np.where(np.arange(35) == 3, np.nan, 0.0),
             "inf": np.full(35, np.inf), "short": np.zeros(34), "text": "0"}[z0]
    # refused before anything is assembled
    monkeypatch.setattr(Model, "assemble", lambda *a, **k: pytest.fail("assembled"))
    with pytest.raises(ValueError, match=match):
        solve(model, z0=value)


def test_hertz_on_a_base_1e15_times_softer_is_no_longer_a_wrong_success():
    """The hertz scene with the cylinder 1e15 times stiffer than its elastic base
    (E = 2e17, E_base = 200) "converged" with NTS to a peak pressure of 0 (error
    1.0): the cylinder's round-off floor (6.7e6) hid a residual above the load."""
    from skfem_mortar.app.runner import run_scene
    with pytest.warns(PreflightWarning, match="1e\\+15 times stiffer"):
        with pytest.raises(ConvergenceError, match="converged only to round-off.*"
                                                   "body 'cylinder' is 1e\\+15 times stiffer"):
            run_scene("hertz", {"base": "elastic", "refine": -2, "E": 2e17}, method="nts")


def test_the_command_line_fails_with_exit_1_naming_the_cause(tmp_path, capsys):
    """The same hertz run from the command line: a step failure, exit 1, the
    cause on stderr after the stiffness-ratio warning."""
    from skfem_mortar.app.cli import main
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PreflightWarning)
        code = main(["run", "hertz", "--method", "nts", "--set", "base=elastic", "--set",
                     "refine=-2", "--set", "E=2e17", "--no-progress", "--out",
                     str(tmp_path / "run")])
    assert code == 1
    err = capsys.readouterr().err
    assert "skfem-mortar: failed: no convergence in load step" in err
    assert "body 'cylinder' is 1e+15 times stiffer than body 'base'" in err
