"""Three 3D models written from the README alone, the way a newcomer would (issue 38).

1. A sphere pressed into a block by a load, with every method: the contact force
   carries the load, the two sides' forces cancel.
2. Two blocks with non-matching meshes under a uniform pressure: mortar and
   mortar-dual give the uniform contact pressure (the 3D patch test); NTS does not,
   and the preflight says so.
3. A contact surface that faces away (the block's bottom taken for its top): refused
   by the preflight before the first step, naming the surface.
"""
import warnings

import numpy as np
import pytest
import skfem

from skfem_mortar import (ContactPair, ContactSurface, Dirichlet, LinearElastic, Model, Solid,
                          Traction, solve)

METHODS = ("nts", "mortar", "mortar-dual")


def _block(n, nz, top, element="tet1", name="block", x0=0.0, width=1.0):
    g = x0 + width * np.linspace(0.0, 1.0, n + 1)
    cls = skfem.MeshTet if element == "tet1" else skfem.MeshHex
    mesh = cls.init_tensor(g, g, np.linspace(top - 0.5, top, nz + 1)).with_boundaries(
        {"bottom": lambda x: np.isclose(x[2], top - 0.5), "top": lambda x: np.isclose(x[2], top)})
    return mesh, Solid(mesh, LinearElastic(E=1.0, nu=0.3), element=element, name=name)


def _sphere_on_block(method):
    R, c = 0.4, np.array([0.5, 0.5, 0.9])
    ball = skfem.MeshTet.init_ball(nrefs=1)
    ball = skfem.MeshTet(ball.p * R + c[:, None], ball.t).with_boundaries(
        {"lower": lambda x: x[2] < c[2] - 0.2 * R, "upper": lambda x: x[2] > c[2] + 0.5 * R})
    _, block = _block(4, 2, 0.5)
    sphere = Solid(ball, LinearElastic(E=1.0, nu=0.3), element="tet1", name="sphere")
    pair = ContactPair(ContactSurface.from_solid(sphere, "lower"),
                       ContactSurface.from_solid(block, "top"), method=method, name="contact")
    rollers = [Dirichlet(sphere, nodes=np.flatnonzero(np.isclose(ball.p[k], c[k])), component=k,
                         name=f"roller_{k}") for k in (0, 1)]
    push = Traction(sphere, "upper", (0.0, 0.0, -0.01), name="push")
    model = Model([sphere, block, pair, push, Dirichlet(block, boundary="bottom", name="clamp"),
                   *rollers], geometry="3d")
    return model, pair, push


@pytest.mark.parametrize("method", METHODS)
def test_a_sphere_pressed_into_a_block_carries_the_load(method):
    model, pair, push = _sphere_on_block(method)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # NTS on non-matching meshes: the preflight warns
        result = solve(model, n_steps=2)
    assert result.converged
    fs, fm = pair.forces(result.z)
    F = pair.total_force(result.z)
    load = 0.01 * push_area(model, push)
    # the vertical resultant is the push (equilibrium of the sphere: its rollers carry
    # only in-plane forces); 1e-8 of the load: the solver's tolerance, not round-off
    assert F[2] == pytest.approx(load, rel=1e-8)
    # the two sides cancel to round-off of the force scale
    assert np.abs(fs.sum(axis=1) + fm.sum(axis=1)).max() <= 1e-12 * load


def push_area(model, push):
    """The area of the faces the push acts on (a traction per unit reference area)."""
    mesh = push.body.mesh
    p = mesh.p[:, mesh.facets[:, mesh.boundaries["upper"]]]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], axis=0)
    return float(0.5 * np.linalg.norm(n, axis=0).sum())


def _stacked(method, slave_tag="bottom"):
    """A hex block (3 x 3 cells) on a tet block (4 x 4), both on [0, 1]^2, a pressure p on
    top; rollers: the lower bottom in z, each block's x = 0 face in x and y = 0 face in y."""
    lower_mesh, lower = _block(4, 2, 0.5, "tet1", "lower")
    g = np.linspace(0.0, 1.0, 4)
    upper_mesh = skfem.MeshHex.init_tensor(g, g, np.linspace(0.5, 1.0, 3)).with_boundaries(
        {"bottom": lambda x: np.isclose(x[2], 0.5), "top": lambda x: np.isclose(x[2], 1.0)})
    upper = Solid(upper_mesh, LinearElastic(E=1.0, nu=0.3), element="hex1", name="upper")
    pair = ContactPair(ContactSurface.from_solid(upper, slave_tag),
                       ContactSurface.from_solid(lower, "top"), method=method, name="contact")
    held = [Dirichlet(lower, boundary="bottom", component="z", name="floor")]
    for body, mesh in ((lower, lower_mesh), (upper, upper_mesh)):
        held += [Dirichlet(body, nodes=np.flatnonzero(np.isclose(mesh.p[k], 0.0)), component=k,
                           name=f"{body.name}_roller_{k}") for k in (0, 1)]
    push = Traction(upper, "top", (0.0, 0.0, -0.02), name="push")
    return Model([lower, upper, pair, push, *held], geometry="3d"), pair


@pytest.mark.parametrize("method", METHODS)
def test_two_blocks_with_non_matching_meshes(method):
    model, pair = _stacked(method)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = solve(model, n_steps=1)
    assert result.converged
    data = pair.contact_data(result.z)
    # the pressure is per current area: the footprint spreads by the lateral strain
    # (nu s / E = 0.006 a side), so the exact pressure is the push over that area
    area = np.ptp(data["x"]) * np.ptp(data["y"])
    error = np.abs(data["pressure"] * area / 0.02 - 1.0).max()
    if method == "nts":
        # NTS fails the patch test on non-matching meshes, and the preflight says so
        assert error > 0.05
        assert any("patch test" in str(w.message) for w in caught)
    else:
        # mortar passes it: uniform stress is exact on any mesh; 1e-10 is round-off of
        # the solve times the conditioning of the saddle point, far below a mesh error
        assert error < 1e-10


def test_a_contact_surface_facing_away_is_refused_before_the_first_step():
    # the upper block's top taken for the face that touches the lower block
    model, _ = _stacked("mortar-dual", slave_tag="top")
    with pytest.raises(ValueError, match=r"'upper_top' is the face turned away .* choose the "
                                         r"boundary \(tag\) that faces it"):
        solve(model, n_steps=1)
