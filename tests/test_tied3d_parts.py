"""tied3d's parts before the 3D tie: two non-matching parts whose interfaces cover the
same rectangle, the variant meeting the clamp, the one-piece beam (cantilever3d's
model, solved), and the readings."""
import numpy as np
import pytest

from skfem_mortar.core.model import Model
from skfem_mortar.scenes import cantilever3d
from skfem_mortar.scenes._tied3d import (PARAMS, build_bodies, one_piece, tied_metrics,
                                        tip_deflection)
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve

DEFAULTS = {p.name: p.default for p in PARAMS}


def _face_area(body, tag):
    """The area of a flat boundary (tri3 faces, or quad4 faces as two triangles)."""
    mesh = body.mesh
    f = mesh.p[:, mesh.facets[:, mesh.boundaries[tag]]]
    tri = lambda a, b, c: 0.5 * np.linalg.norm(np.cross(b - a, c - a, axis=0), axis=0)  # noqa
    if f.shape[1] == 3:
        return tri(f[:, 0], f[:, 1], f[:, 2]).sum()
    return (tri(f[:, 0], f[:, 1], f[:, 2]) + tri(f[:, 0], f[:, 2], f[:, 3])).sum()


@pytest.mark.parametrize("element", ["tet1", "hex1"])
@pytest.mark.parametrize("interface,area", [("across", 1.0), ("along", 4.0)])
def test_interfaces_cover_one_rectangle_with_non_matching_nodes(element, interface, area):
    parts = build_bodies({**DEFAULTS, "element": element, "interface": interface})
    (b, tb), (a, ta) = parts.slave, parts.master
    for body, tag in ((a, ta), (b, tb)):
        assert _face_area(body, tag) == pytest.approx(area, rel=1e-13)
    xa = a.mesh.p[:, np.unique(a.mesh.facets[:, a.mesh.boundaries[ta]])]
    xb = b.mesh.p[:, np.unique(b.mesh.facets[:, b.mesh.boundaries[tb]])]
    d = np.linalg.norm(xb[:, :, None] - xa[:, None, :], axis=0).min(axis=1)
    assert np.mean(d > 1e-3) > 0.5                    # most slave nodes are no master node


def test_along_interface_meets_the_clamped_face_on_both_parts():
    parts = build_bodies({**DEFAULTS, "interface": "along"})
    clamps = [it for it in parts.items if it.name.startswith("clamp_")]
    assert [c.body.name for c in clamps] == ["part_a", "part_b"]
    for clamp, (body, tag) in zip(clamps, (parts.master, parts.slave)):
        on_interface = body.dofs_on(tag)
        # interface dofs on X = 0 are clamped: the tie's slave nodes there are prescribed
        assert np.intersect1d(on_interface, clamp.local_dofs).size > 0
    # across: only part a is clamped, only part b loaded
    parts = build_bodies(DEFAULTS)
    names = sorted(it.name for it in parts.items if not hasattr(it, "mesh"))
    assert names == ["clamp_part_a", "tip_load_part_b"]


def _solve(parts):
    return solve(Model(parts.items, geometry="3d"), n_steps=1,
                 newton=NewtonOptions(rtol=1e-12))


def test_one_piece_beam_is_cantilever3ds_model():
    # the same beam, mesh, law and load as cantilever3d: the same tip deflection to
    # round-off (a linear solve of ~250 dofs; 1e-12 of a deflection of order 1)
    params = {**DEFAULTS, "parts": "one"}
    parts = build_bodies(params)
    r = _solve(parts)
    w = tip_deflection(parts.bodies, r.z)
    scene = cantilever3d.SCENE.resolve({"length": "4", "load": "0.5", "element": "hex1",
                                        "n": "2"})
    setup = cantilever3d.build(scene)
    ref = solve(setup.model, n_steps=1, newton=NewtonOptions(rtol=1e-12))
    assert w == pytest.approx(setup.metrics(ref)["tip_deflection"], rel=1e-12)


def test_one_piece_beam_approaches_timoshenko_under_refinement():
    errors = []
    for n in (1, 2):
        params = {**DEFAULTS, "parts": "one", "n_a": n}
        parts = one_piece(params)
        w = tip_deflection(parts.bodies, _solve(parts).z)
        errors.append(tied_metrics(params, w, w, None, parts.tip_force)
                      ["tip_deflection_beam_error"])
    assert errors[1] < 0.5 * errors[0], errors   # hex1 in bending: measured 0.37, 0.15


def test_readings_see_the_interface_force_and_a_deflection_miss():
    params = DEFAULTS
    m = tied_metrics(params, 1.01, 1.0, np.array([0.0, 0.0, 2.0]), 2.0)
    assert m["tip_deflection_error"] == pytest.approx(0.01, rel=1e-12)
    assert m["interface_force_error"] == 0.0
    m = tied_metrics({**params, "interface": "along"}, 1.0, 1.0, np.zeros(3), 2.0)
    assert "interface_force" not in m and m["tip_deflection_error"] == 0.0
