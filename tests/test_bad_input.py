"""Bad input raises ValueError naming the parameter and what is allowed
(the table of docs/robustness.md, one test per row)."""
import numpy as np
import pytest
import skfem

from skfem_mortar import (Cable, ContactPair, Dirichlet, FollowerPressure, NeoHooke, Solid,
                          SaintVenantKirchhoff)
from skfem_mortar.bodies.checks import check_mesh
from skfem_mortar.app.cli import main
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve
from skfem_mortar.contact.surfaces import ContactSurface, RigidCircle, RigidPlane, chain_segments

pytestmark = pytest.mark.extremes


def _square(tagged=True):
    m = skfem.MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    return m.with_defaults() if tagged else m


def _solid(**kw):
    return Solid(_square(**kw), NeoHooke(E=1.0, nu=0.3), name="s")


# --------------------------------------------------------------------------- tags
def test_wrong_boundary_tag_on_a_contact_surface():
    with pytest.raises(ValueError, match=r"boundary must be one of the mesh tags .*'nope'"):
        ContactSurface.from_solid(_solid(), "nope")


def test_missing_boundary_tags():
    """A mesh without tags: the message lists the (empty) known tags."""
    with pytest.raises(ValueError, match=r"boundary must be one of the mesh tags \[\]"):
        ContactSurface.from_solid(_solid(tagged=False), "top")


def test_wrong_boundary_tag_for_dofs_and_pressure():
    s = _solid()
    with pytest.raises(ValueError, match="unknown boundary 'nope'; known tags"):
        s.dofs_on("nope")
    with pytest.raises(ValueError, match="facets must be one of the mesh boundaries"):
        FollowerPressure(s, 1.0, facets="nope")


def test_empty_facet_set():
    with pytest.raises(ValueError, match="boundary must contain at least one facet"):
        ContactSurface.from_solid(_solid(), np.zeros(0, dtype=int))


# --------------------------------------------------------------------------- chains
def test_surface_of_two_pieces_is_not_a_chain():
    s = _solid()
    facets = np.concatenate([s.mesh.boundaries["top"], s.mesh.boundaries["bottom"]])
    with pytest.raises(ValueError, match="2 separate pieces"):
        ContactSurface.from_solid(s, facets)


def test_branching_segments_are_not_a_chain():
    with pytest.raises(ValueError, match="branching or inconsistently oriented"):
        chain_segments(np.array([[0, 1], [1, 2], [1, 3]]))


def test_degenerate_segment():
    with pytest.raises(ValueError, match="segments must join two different nodes"):
        chain_segments(np.array([[0, 1], [1, 1]]))


def test_rigid_surface_with_a_zero_length_segment():
    with pytest.raises(ValueError, match="segment of zero length"):
        ContactSurface(None, None, np.array([[0, 1], [1, 2]]),
                       X=np.array([[0.0, 1.0, 1.0], [0.0, 0.0, 0.0]]))


# --------------------------------------------------------------------------- meshes
def test_inverted_element():
    m = skfem.MeshTri().refined(2)
    p = m.p.copy()
    k = np.argmin(np.hypot(p[0] - 0.5, p[1] - 0.5))
    p[:, k] = [0.9, 0.5]  # the centre node pushed across its neighbours: a fold
    with pytest.raises(ValueError, match="inverted element"):
        check_mesh(skfem.MeshTri(p, m.t))


def test_zero_area_element():
    m = skfem.MeshQuad().refined(2)
    p = m.p.copy()
    k = np.argmin(np.hypot(p[0] - 0.5, p[1] - 0.5))
    p[:, k] = [0.25, 0.25]  # onto a corner of its element
    with pytest.raises(ValueError, match="zero area"):
        check_mesh(skfem.MeshQuad(p, m.t))


def test_sliver_element():
    """Two triangles, one of them a sliver whose apex lies 1e-8 above its base
    of length 1: area / longest edge^2 = 5e-9, below the 1e-7 limit (the area
    is still far above the zero-area limit, 1e-12 of the mean)."""
    p = np.array([[0.0, 1.0, 0.5, 0.5], [0.0, 0.0, 1e-8, 1.0]])
    t = np.array([[0, 1, 2], [2, 1, 3]]).T
    with pytest.raises(ValueError, match="sliver element"):
        check_mesh(skfem.MeshTri(p, t))


def test_non_convex_quadrilateral():
    m = skfem.MeshQuad().refined(2)
    p = m.p.copy()
    k = np.argmin(np.hypot(p[0] - 0.5, p[1] - 0.5))
    p[:, k] = [0.5, 0.75]
    with pytest.raises(ValueError, match="non-convex or bow-tie"):
        check_mesh(skfem.MeshQuad(p, m.t))


def test_valid_meshes_pass_the_mesh_check():
    """skfem's own meshes mix clockwise and counter-clockwise triangles: valid."""
    for m in (skfem.MeshTri().refined(3), skfem.MeshQuad().refined(2), _square()):
        check_mesh(m)


def test_solid_rejects_an_inverted_mesh():
    m = skfem.MeshTri().refined(2)
    p = m.p.copy()
    k = np.argmin(np.hypot(p[0] - 0.5, p[1] - 0.5))
    p[:, k] = [0.9, 0.5]
    with pytest.raises(ValueError, match="inverted element"):
        Solid(skfem.MeshTri(p, m.t), NeoHooke(E=1.0, nu=0.3))


# --------------------------------------------------------------------------- numbers
@pytest.mark.parametrize("kw,match", [
    ({"E": np.nan, "nu": 0.3}, "E must be a finite real number > 0, got nan"),
    ({"E": -1.0, "nu": 0.3}, "E must be a finite real number > 0, got -1.0"),
    ({"E": 1.0, "nu": np.nan}, r"nu must be a finite real number in \(-1, 0.5\), got nan"),
    ({"E": 1.0, "nu": 0.5}, r"nu must be a finite real number in \(-1, 0.5\), got 0.5"),
])
def test_nan_or_negative_material_parameters(kw, match):
    for cls in (NeoHooke, SaintVenantKirchhoff):
        with pytest.raises(ValueError, match=match):
            cls(**kw)


@pytest.mark.parametrize("kw,match", [
    ({"EA": np.nan}, "EA must be a finite real number > 0, got nan"),
    ({"EA": -1.0}, "EA must be a finite real number > 0, got -1.0"),
    ({"tension_floor": np.nan}, "tension_floor must be a finite real number >= 0, got nan"),
    ({"slack_stiffness": -1.0}, "slack_stiffness must be a finite real number >= 0, got -1.0"),
])
def test_nan_or_negative_cable_parameters(kw, match):
    with pytest.raises(ValueError, match=match):
        Cable.from_points(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), **kw)


@pytest.mark.parametrize("make,match", [
    (lambda s: FollowerPressure(s, np.nan, facets="top"), "pressure must be a finite real number, got nan"),
    (lambda s: Dirichlet(s, s.dofs_on("bottom"), np.nan), "value must be finite"),
    (lambda s: RigidPlane((0, 0), (0, 1), length=-1.0), "length must be a finite real number > 0, got -1.0"),
    (lambda s: RigidPlane((0, 0), (np.nan, 1)), "normal must be finite"),
    (lambda s: RigidCircle((0, 0), -1.0), "radius must be a finite real number > 0, got -1.0"),
    (lambda s: NewtonOptions(rtol=np.nan), r"rtol must be a finite real number in \(0, 1\)"),
    (lambda s: NewtonOptions(max_iter=0), "max_iter must be an integer >= 1"),
])
def test_nan_or_negative_parameters(make, match):
    with pytest.raises(ValueError, match=match):
        make(_solid())


def test_nan_or_negative_contact_and_solver_parameters():
    s = _solid()
    slave = ContactSurface.from_solid(s, "top")
    plane = RigidPlane((0.0, 2.0), (0.0, -1.0))
    with pytest.raises(ValueError, match="c must be a finite real number > 0"):
        ContactPair(slave, plane, c=-1.0)
    with pytest.raises(ValueError, match="touch_tolerance must be a finite real number >= 0"):
        ContactPair(slave, plane, touch_tolerance=np.nan)
    with pytest.raises(ValueError, match="method must be one of nts, mortar, mortar-dual"):
        ContactPair(slave, plane, method="penalty")
    from skfem_mortar import Model
    with pytest.raises(ValueError, match=r"n_steps must be an integer in \[1, 1000000\]"):
        solve(Model([s]), 0)
    with pytest.raises(ValueError, match=r"min_step must lie in \(0, 1\]"):
        solve(Model([s]), 1, min_step=np.nan)


# --------------------------------------------------------------------------- pairs
def test_contact_pair_naming_the_same_surface_twice():
    s = _solid()
    top = ContactSurface.from_solid(s, "top")
    with pytest.raises(ValueError, match="two different surfaces, got the same surface"):
        ContactPair(top, top)
    with pytest.raises(ValueError, match="two different surfaces"):
        ContactPair(top, ContactSurface.from_solid(s, "top", name="again"))


def test_rigid_slave():
    with pytest.raises(ValueError, match="slave must be a deformable surface"):
        ContactPair(RigidPlane((0, 0), (0, 1)), ContactSurface.from_solid(_solid(), "top"))


# --------------------------------------------------------------------------- cables
def test_cable_with_coincident_nodes():
    """Two consecutive nodes at the same point: the element has no direction."""
    X = np.array([[0.0, 1.0, 1.0, 2.0], [0.0, 0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match=r"element 1 joins coincident nodes \(1, 2\)"):
        Cable(X, rest_length=1.0)
    with pytest.raises(ValueError, match="coincident nodes"):
        Cable(X)


def test_cable_between_coincident_supports():
    with pytest.raises(ValueError, match="start and end must differ"):
        Cable.between((0.0, 0.0), (0.0, 0.0), 1.0, 4)


# --------------------------------------------------------------------------- --set
@pytest.mark.parametrize("args,match", [
    (["run", "patch", "--set", "nu=0.7"], r"parameter 'nu' must be a float in \[0, 0.5\)"),
    (["run", "patch", "--set", "nu=nan"], r"parameter 'nu' must be a float in \[0, 0.5\)"),
    (["run", "patch", "--set", "pressure=-1"], r"parameter 'pressure' must be a float in \(0"),
    (["run", "patch", "--set", "n_top=2.5"], r"parameter 'n_top' must be an int in \[1"),
    (["run", "patch", "--set", "element=tri3"],
     "parameter 'element' must be one of tri1, quad1, tri2, quad2"),
    (["run", "patch", "--set", "bogus=1"], "unknown parameter 'bogus' for scene 'patch'"),
    (["run", "ironing", "--set", "press=3"], r"parameter 'press' must be a float in \(0, 2.5\]"),
    (["run", "ironing", "--set", "x_start=8", "--set", "slide=10"],
     "x_start and slide must keep the die over the block"),
    (["run", "patch", "--method", "penalty"], "invalid choice: 'penalty'"),
])
def test_out_of_range_set_values(args, match, capsys):
    with pytest.raises(SystemExit) if "--method" in args else _no_raise():
        code = main(args)
        assert code == 2
    err = capsys.readouterr().err
    assert err.strip()
    import re
    assert re.search(match, err), err


class _no_raise:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False
