"""hertz3d's parts before the 3D contact pair: graded meshes of the quarter sphere and
cylinder (valid, on their surfaces, graded), the half as the quarter's mirror image,
the symmetry planes read from the rollers, the load, and the Hertz fit."""
import math

import numpy as np
import pytest
from skfem import MeshTet1

from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.scenes._contact3d import (graded_axis, graded_octant,
                                            graded_quarter_cylinder, symmetry_planes)
from skfem_mortar.scenes._hertz3d import PARAMS, build_bodies, exact_hertz3d, hertz_metrics

DEFAULTS = {p.name: p.default for p in PARAMS}
COARSE = {**DEFAULTS, "refine": -3, "element": "tet1"}
R, A = 8.0, 0.2

#: corners of scikit-fem's reference hexahedron pulled 1 % inside (the Jacobian there)
CORNERS = np.array([[0, 1, 0, 0, 1, 0, 1, 1], [0, 0, 1, 0, 1, 1, 0, 1],
                    [0, 0, 0, 1, 0, 1, 1, 1]]) * 0.98 + 0.01


def _volumes(mesh):
    p, t = mesh.p, mesh.t
    a, b, c, d = (p[:, t[k]] for k in range(4))
    return np.einsum("ij,ij->j", np.cross(b - a, c - a, axis=0), d - a) / 6.0


def _longest(mesh):
    e = mesh.p[:, mesh.t]
    n = e.shape[1]
    return np.max([np.linalg.norm(e[:, i] - e[:, j], axis=0)
                   for i in range(n) for j in range(i + 1, n)], axis=0), e.mean(axis=1)


def test_octant_is_valid_on_its_sphere_and_graded():
    h0 = A / 3.75
    mesh = graded_octant(R, h0, 1.2 * A)
    assert isinstance(mesh, MeshTet1) and _volumes(mesh).min() > 0.0
    # the ball's eighth: the polyhedron lies inside, within the chords' sagitta
    assert _volumes(mesh).sum() == pytest.approx(math.pi * R ** 3 / 6.0, rel=0.03)
    on = np.unique(mesh.facets[:, mesh.boundaries["sphere"]])
    dist = np.linalg.norm(mesh.p[:, on] - np.array([[0.0], [0.0], [R]]), axis=0)
    assert np.abs(dist - R).max() < 1e-12 * R
    for tag, (k, v) in {"x0": (0, 0.0), "y0": (1, 0.0), "top": (2, R)}.items():
        nodes = np.unique(mesh.facets[:, mesh.boundaries[tag]])
        assert np.abs(mesh.p[k, nodes] - v).max() < 1e-12 * R, tag
    h, c = _longest(mesh)
    near = np.linalg.norm(c, axis=0) < 1.2 * A - h
    # a Kuhn tetrahedron's longest edge is its cube's diagonal, sqrt(3) h0; the map
    # stretches the cells within 1.2 a of the contact point by at most 3 % (its
    # in-plane factor sqrt(1 - w^2 / 2) at the depth 1.2 a / R = 0.03)
    assert near.sum() > 100 and h[near].max() <= math.sqrt(3.0) * 1.03 * h0
    assert h[near].min() >= 0.97 * h0         # and by at least -3 % (cube edges, h0)
    assert h.max() > 20 * h0                  # graded: large far from the contact
    assert mesh.p[2].min() == 0.0             # the contact point is a node


def test_quarter_cylinder_is_valid_and_on_its_side():
    W = 30 * A
    mesh = graded_quarter_cylinder(W, A / 3.75, 1.2 * A)
    assert _volumes(mesh).min() > 0.0
    side = np.unique(mesh.facets[:, mesh.boundaries["side"]])
    assert np.abs(np.hypot(*mesh.p[:2, side]) - W).max() < 1e-12 * W
    assert _volumes(mesh).sum() == pytest.approx(math.pi * W ** 3 / 4.0, rel=0.03)


def test_hexahedra_are_valid_and_on_the_sphere_and_share_the_tetrahedras_nodes():
    mesh = graded_octant(R, A / 3.75, 1.2 * A, element="hex1")
    assert mesh._mapping().detDF(CORNERS).min() > 0.0
    on = np.unique(mesh.facets[:, mesh.boundaries["sphere"]])
    dist = np.linalg.norm(mesh.p[:, on] - np.array([[0.0], [0.0], [R]]), axis=0)
    assert np.abs(dist - R).max() < 1e-12 * R
    tets = graded_octant(R, A / 3.75, 1.2 * A)          # the same grid, split
    assert np.array_equal(tets.p, mesh.p) and tets.t.shape[1] == 6 * mesh.t.shape[1]


def test_graded_axis_is_fine_then_grows():
    x = graded_axis(0.01, 0.05)
    d = np.diff(x)
    assert x[0] == 0.0 and x[-1] == 1.0
    assert np.allclose(d[:5], 0.01, rtol=1e-12) and np.all(d[5:] > 0.01)
    ratio = d[1:] / d[:-1]
    # 1.5 a cell; the last cell (stretched to end at 1, or merged) within 0.5 to 2.5
    assert np.allclose(ratio[4:-1], 1.5, rtol=1e-12) and 0.5 <= ratio[-1] <= 2.5
    with pytest.raises(ValueError, match="growth"):
        graded_axis(0.01, 0.05, growth=1.0)


@pytest.mark.parametrize("model,planes", [("quarter", [(0, 0.0), (1, 0.0)]),
                                          ("half", [(1, 0.0)])])
@pytest.mark.parametrize("base", ["rigid", "elastic"])
def test_symmetry_planes_are_read_from_the_rollers(model, planes, base):
    parts = build_bodies({**COARSE, "model": model, "base": base})
    assert symmetry_planes(parts.items) == planes == parts.symmetry
    # the clamp (every component) and a moved roller declare nothing
    body = parts.sphere
    moved = Dirichlet(body, boundary="y0", component=1, value=1e-3, name="moved")
    clamp = Dirichlet(body, boundary="top", name="clamp")
    assert symmetry_planes([moved, clamp]) == []


def test_half_model_is_the_quarter_and_its_mirror_image():
    quarter = build_bodies(COARSE).sphere.mesh
    half = build_bodies({**COARSE, "model": "half"}).sphere.mesh
    assert _volumes(half).min() > 0.0
    assert half.t.shape[1] == 2 * quarter.t.shape[1]
    mirror = half.p * np.array([[-1.0], [1.0], [1.0]])
    key = lambda p: np.round(p.T / R, 12).tolist()  # noqa: E731
    assert sorted(key(half.p)) == sorted(key(mirror))


@pytest.mark.parametrize("model,share", [("quarter", 4.0), ("half", 2.0)])
def test_the_load_is_the_models_share_of_F(model, share):
    parts = build_bodies({**COARSE, "model": model})
    load = next(it for it in parts.items if getattr(it, "name", "") == "load")
    body = parts.sphere
    f = np.asarray(load.force)[body.node_dofs]
    # the polygonal top carries the model's share of F exactly: a sum over ~30 faces
    assert f[2].sum() == pytest.approx(-COARSE["load"] / share, rel=1e-13)
    assert np.abs(f[:2]).max() == 0.0


def test_hertz_fit_recovers_a_synthetic_profile():
    parts = build_bodies(COARSE)
    exact = exact_hertz3d(COARSE)
    a, p0 = exact["contact_radius"], exact["peak_pressure"]
    X = parts.sphere.X[:, np.unique(parts.sphere.mesh.facets[
        :, parts.sphere.mesh.boundaries["sphere"]])]
    r = np.hypot(X[0], X[1])
    p = p0 * np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None))
    assert np.count_nonzero(r < 0.8 * a) >= 6
    planes = [(0, 0.0), (1, 0.0)]
    m = hertz_metrics(exact, X, p, COARSE["load"] / 4.0, planes, COARSE["load"])
    assert m["peak_pressure_fit"] == pytest.approx(p0, rel=1e-12)
    assert m["contact_radius"] == pytest.approx(a, rel=1e-12)
    assert m["contact_force_error"] == pytest.approx(0.0, abs=1e-15)
    m = hertz_metrics(exact, X, 1.1 * p, COARSE["load"] / 4.0, planes, COARSE["load"])
    assert m["peak_pressure_error"] == pytest.approx(0.1, rel=1e-12)
    assert m["contact_radius_error"] == pytest.approx(0.0, abs=1e-12)


def test_parameters_are_hertz_axis_and_refused_alike():
    from skfem_mortar.scenes import Scene
    from skfem_mortar.scenes._hertz3d import derived
    from skfem_mortar.scenes.hertz_axi import SCENE as AXI

    axi = {p.name: p for p in AXI.params}
    for p in PARAMS:
        if p.name in axi and p.name not in ("refine", "element"):  # 3D: own meshes
            assert p == axi[p.name], p.name
    scene = Scene("hertz3d_parts", "", PARAMS, build=lambda v, m: None, derived=derived)
    with pytest.raises(ValueError, match="a / R"):
        scene.resolve({"load": "1e6"})


def test_rigid_plane_grid_faces_up_over_its_rectangle():
    from skfem_mortar.scenes._contact3d import plane_grid

    X, faces = plane_grid((-0.6, 0.6), (0.0, 0.6), 0.0, 0.05)
    a, b, c, d = (X[:, faces[:, k]] for k in range(4))
    n = np.cross(c - a, d - b, axis=0)                     # twice the area, along +z
    assert np.all(n[2] > 0.0) and np.abs(n[:2]).max() == 0.0
    assert 0.5 * n[2].sum() == pytest.approx(1.2 * 0.6, rel=1e-13)
    assert X[0].min() == -0.6 and X[1].max() == 0.6 and np.all(X[2] == 0.0)


@pytest.mark.parametrize("base,model", [("rigid", "quarter"), ("elastic", "half")])
def test_dof_estimate_is_the_meshes_count(base, model):
    # the estimate refuses sizes the machine cannot hold: counted from the grids' axes
    from skfem_mortar.scenes._hertz3d import estimate_dofs

    for element in ("tet1", "hex1"):
        params = {**COARSE, "element": element, "base": base, "model": model}
        parts = build_bodies(params)
        n = sum(3 * b.mesh.p.shape[1] for b in (parts.sphere, parts.base) if b is not None)
        # the half shares the quarter's nodes on X = 0 with its mirror image
        assert estimate_dofs(params) == n if model == "quarter" else (
            n < estimate_dofs(params) < 1.1 * n), (element, estimate_dofs(params), n)


def test_quarter_and_half_fit_the_same_points():
    # a profile that is no ellipse: the fit depends on the weights, and the half's
    # nodes (the quarter's and their mirror images) weigh as the quarter's do
    from skfem_mortar.scenes._hertz3d import multiplicity

    exact = exact_hertz3d(COARSE)
    a = exact["contact_radius"]
    fits = []
    for model in ("quarter", "half"):
        parts = build_bodies({**COARSE, "model": model})
        mesh = parts.sphere.mesh
        X = mesh.p[:, np.unique(mesh.facets[:, mesh.boundaries["sphere"]])]
        r = np.hypot(X[0], X[1])
        p = np.clip(1.0 - (r / a) ** 1.5, 0.0, None)
        fits.append(hertz_metrics(exact, X, p, 1.0, parts.symmetry, 1.0)["contact_radius"])
        counts = multiplicity(X, parts.symmetry)
        assert counts.min() == 1 and counts.max() == (4 if model == "quarter" else 2)
    assert fits[0] == pytest.approx(fits[1], rel=1e-12)
