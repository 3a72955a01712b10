"""Issue 32, class 7: the public constructors refuse the inputs a user got through
silently, by class (a number given as a string, a bool, NaN or infinity; a count
that is not an integer or would allocate beyond a stated bound; a flag that is not
a bool; indices that are not integers; a duplicate element, dof or facet; interior
facets as a contact surface; an array of the wrong length), each with a ValueError
whose message begins with the parameter's name.  Written as a user calls them."""
import time

import numpy as np
import pytest
import skfem

from skfem_mortar import (Cable, ContactSurface, FollowerPressure, LinearElastic, MixedSolid,
                          NeoHooke, PointLoad, RigidCircle, RigidPlane, SaintVenantKirchhoff,
                          Solid, TiePair, Traction)

NAN, INF = float("nan"), float("inf")
LINE = np.array([[0.0, 1.0, 2.0], [0.0, 0.0, 0.0]])    # a cable of two elements


def _mesh(y0=0.0):
    m = skfem.MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(y0, y0 + 1, 5))
    return m.with_defaults()


def _solid(name="s", y0=0.0):
    return Solid(_mesh(y0), NeoHooke(E=1.0, nu=0.3), name=name)


def _surface_pair():
    a, b = _solid("a"), _solid("b", 1.0)
    return ContactSurface.from_solid(b, "bottom"), ContactSurface.from_solid(a, "top")


def _refused(make, name):
    """``make()`` raises a ValueError whose message begins with ``name`` and says "must"."""
    with pytest.raises(ValueError) as info:
        make()
    msg = str(info.value)
    assert msg.startswith(name) and "must" in msg, msg
    return msg


# ------------------------------------------------------------------ numbers
#: (constructor, parameter): every real-number parameter of the public constructors,
#: called with ``value`` in place of a valid one
NUMBERS = {
    "NeoHooke.E": (lambda v: NeoHooke(E=v, nu=0.3), "E"),
    "NeoHooke.nu": (lambda v: NeoHooke(E=1.0, nu=v), "nu"),
    "NeoHooke.mu": (lambda v: NeoHooke(mu=v, lmbda=1.0), "mu"),
    "NeoHooke.lmbda": (lambda v: NeoHooke(mu=1.0, lmbda=v), "lmbda"),
    "SaintVenantKirchhoff.E": (lambda v: SaintVenantKirchhoff(E=v, nu=0.3), "E"),
    "LinearElastic.nu": (lambda v: LinearElastic(E=1.0, nu=v), "nu"),
    "Cable.EA": (lambda v: Cable(LINE, EA=v), "EA"),
    "Cable.rest_length": (lambda v: Cable(LINE, rest_length=v), "rest_length"),
    "Cable.slack_stiffness": (lambda v: Cable(LINE, tension_only=True, slack_stiffness=v),
                              "slack_stiffness"),
    "Cable.tension_floor": (lambda v: Cable(LINE, tension_floor=v), "tension_floor"),
    "Cable.X": (lambda v: Cable(np.array([[0.0, 1.0], [0.0, v]], dtype=object)), "X"),
    "Cable.between.length0": (lambda v: Cable.between((0, 0), (1, 0), v, 4), "length0"),
    "Cable.between.start_sag": (lambda v: Cable.between((0, 0), (1, 0), 1.0, 4,
                                                        start_sag=v), "start_sag"),
    "Cable.between.end": (lambda v: Cable.between((0, 0), (1, v), 1.5, 4), "end"),
    "Cable.ring.radius0": (lambda v: Cable.ring(v, 8), "radius0"),
    "FollowerPressure.pressure": (lambda v: FollowerPressure(_solid(), v, facets="top"),
                                  "pressure"),
    "Traction.traction": (lambda v: Traction(_solid(), "top", (0.0, v)), "traction"),
    "PointLoad.values": (lambda v: PointLoad(_solid(), [0, 1], v), "values"),
    "RigidPlane.length": (lambda v: RigidPlane((0, 0), (0, 1), length=v), "length"),
    "RigidPlane.point": (lambda v: RigidPlane((0, v), (0, 1)), "point"),
    "RigidCircle.radius": (lambda v: RigidCircle((0, 0), v), "radius"),
    "RigidCircle.arc": (lambda v: RigidCircle((0, 0), 1.0, arc=(0.0, v)), "arc"),
}


@pytest.mark.parametrize("value", ["10", True, NAN, INF, 1 + 2j],
                         ids=["string", "bool", "nan", "inf", "complex"])
@pytest.mark.parametrize("case", sorted(NUMBERS))
def test_a_number_must_be_a_finite_real_number(case, value):
    """``NeoHooke(E="100")`` and ``FollowerPressure(body, "10")`` were converted by float();
    a bool was read as 0 or 1; ``slack_stiffness=inf`` made every slack row infinite."""
    make, name = NUMBERS[case]
    _refused(lambda: make(value), name)


@pytest.mark.parametrize("make, name, text", [
    (lambda: NeoHooke(E=1.0, nu=-1.0), "nu", r"in (-1, 0.5), got -1.0"),
    (lambda: NeoHooke(E=1.0, nu=0.5), "nu", r"in (-1, 0.5), got 0.5"),
    (lambda: NeoHooke(E=0.0, nu=0.3), "E", "> 0, got 0.0"),
    (lambda: NeoHooke(mu=3.0, lmbda=-2.0), "lmbda", "> -2, got -2.0"),   # bulk modulus 0
    (lambda: Cable(LINE, EA=[1.0, 0.0]), "EA", "got 0.0 at index (1,)"),
    (lambda: Cable.between((0, 0), (1, 0), 1.0, 4, start_sag=0.6), "start_sag",
     "in (0, 0.5], got 0.6"),
])
def test_a_number_at_or_beyond_the_end_of_its_range(make, name, text):
    assert text in _refused(make, name)


# ------------------------------------------------------------------ counts and bounds
COUNTS = {
    "Cable.between.n_elements": (lambda v: Cable.between((0, 0), (1, 0), 1.0, v), "n_elements"),
    "Cable.ring.n_elements": (lambda v: Cable.ring(1.0, v), "n_elements"),
    "RigidPlane.n_segments": (lambda v: RigidPlane((0, 0), (0, 1), n_segments=v), "n_segments"),
    "RigidCircle.n_segments": (lambda v: RigidCircle((0, 0), 1.0, n_segments=v), "n_segments"),
    "Solid.intorder": (lambda v: Solid(_mesh(), NeoHooke(E=1.0, nu=0.3), "tri2", intorder=v),
                       "intorder"),
    "MixedSolid.intorder": (lambda v: MixedSolid(_mesh(), NeoHooke(E=1.0, nu=0.3), intorder=v),
                            "intorder"),
    "TiePair.n_gauss": (lambda v: TiePair(*_surface_pair(), n_gauss=v), "n_gauss"),
}


@pytest.mark.parametrize("value", [4.5, 4.0, "4", True, -1],
                         ids=["fraction", "integral-float", "string", "bool", "negative"])
@pytest.mark.parametrize("case", sorted(COUNTS))
def test_a_count_must_be_an_integer(case, value):
    """``Cable.between(..., 2.5)`` built 2 elements (int() truncated it); 4.0 is refused too:
    a count is an integer."""
    make, name = COUNTS[case]
    assert "integer" in _refused(lambda: make(value), name)


@pytest.mark.parametrize("case, bound", [
    ("Cable.between.n_elements", "MAX_ELEMENTS = 10000000"),
    ("Cable.ring.n_elements", "MAX_ELEMENTS = 10000000"),
    ("RigidPlane.n_segments", "MAX_SEGMENTS = 10000000"),
    ("RigidCircle.n_segments", "MAX_SEGMENTS = 10000000"),
    ("Solid.intorder", "at most 19"),
    ("TiePair.n_gauss", "in [1, 10]"),
])
def test_a_size_is_bounded_before_anything_is_allocated(case, bound):
    """``Cable.between(..., 10**9)`` ended in a MemoryError traceback after allocating
    7.45 GiB; now the message names the parameter and the bound at once (0.5 s is
    generous for a check that allocates nothing: a build of 1e9 nodes takes minutes)."""
    make, name = COUNTS[case]
    t0 = time.perf_counter()
    assert bound in _refused(lambda: make(10 ** 9), name)
    assert time.perf_counter() - t0 < 0.5


# ------------------------------------------------------------------ flags
FLAGS = {
    "Cable.tension_only": (lambda v: Cable(LINE, tension_only=v), "tension_only"),
    "Cable.closed": (lambda v: Cable(LINE, closed=v), "closed"),
    "Cable.from_points.closed": (lambda v: Cable.from_points(LINE.T, closed=v), "closed"),
    "FollowerPressure.ramp": (lambda v: FollowerPressure(_solid(), 1.0, facets="top", ramp=v),
                              "ramp"),
    "FollowerPressure.load_stiffness": (lambda v: FollowerPressure(_solid(), 1.0, facets="top",
                                                                   load_stiffness=v),
                                        "load_stiffness"),
    "RigidCircle.inside": (lambda v: RigidCircle((0, 0), 1.0, inside=v), "inside"),
    "TiePair.dual": (lambda v: TiePair(*_surface_pair(), dual=v), "dual"),
}


@pytest.mark.parametrize("value", [1, "no", None], ids=["one", "string", "None"])
@pytest.mark.parametrize("case", sorted(FLAGS))
def test_a_flag_must_be_a_bool(case, value):
    """``"no"`` was read as True by bool()."""
    make, name = FLAGS[case]
    assert "True or False" in _refused(lambda: make(value), name)


@pytest.mark.parametrize("make, name", [
    (lambda: FollowerPressure(Cable(LINE), 1.0, side=True), "side"),
    (lambda: FollowerPressure(Cable(LINE), 1.0, side=1.0), "side"),
    (lambda: Cable.between((0, 0), (1, 0), 2.0, 4, bulge=True), "bulge"),
    (lambda: _solid().dofs_on("top", component=True), "component"),
    (lambda: _solid().dofs_on("top", component=1.0), "component"),
])
def test_a_bool_or_a_float_is_not_a_side_or_a_component(make, name):
    """True == 1 selected the left side and the y component."""
    _refused(make, name)


# ------------------------------------------------------------------ indices
@pytest.mark.parametrize("make, name", [
    (lambda: Cable(LINE, [[0, 1], [1, 1.5]]), "elements"),
    (lambda: Cable(LINE, [[0, 1], [1, 3]]), "elements"),
    (lambda: PointLoad(_solid(), [0.0, 1.0], 1.0), "local_dofs"),
    (lambda: _solid().dofs_at_nodes([0.5]), "nodes"),
    (lambda: Traction(_solid(), [0.0, 1.0], (0.0, 1.0)), "boundary"),
    (lambda: ContactSurface.from_solid(_solid(), np.array([1.0])), "boundary"),
    (lambda: FollowerPressure(_solid(), 1.0, facets=[0.0]), "facets"),
    (lambda: Cable(LINE).support_dofs([2.0]), "nodes"),
])
def test_indices_must_be_integers_in_range(make, name):
    """Float indices were truncated (1.5 -> node 1)."""
    assert "integers in [0, " in _refused(make, name)


# ------------------------------------------------------------------ duplicates
@pytest.mark.parametrize("elements, pair", [
    ([[0, 1], [1, 2], [0, 1]], "elements 0 and 2"),
    ([[0, 1], [1, 2], [2, 1]], "elements 1 and 2"),     # the same pair, either order
])
def test_a_duplicate_cable_element_is_refused(elements, pair):
    """The element was assembled twice: twice the stiffness, silently."""
    msg = _refused(lambda: Cable(LINE, elements), "elements")
    assert pair in msg and "doubles its stiffness" in msg


def test_a_closed_cable_of_two_nodes_is_two_equal_elements():
    assert "elements 0 and 1" in _refused(lambda: Cable(LINE[:, :2], closed=True), "elements")


def test_a_dof_loaded_twice_and_a_facet_listed_twice():
    """Each was counted twice: twice the load on that dof or facet, silently."""
    s = _solid()
    _refused(lambda: PointLoad(s, [3, 3], [1.0, 2.0]), "local_dofs")
    top = s.mesh.boundaries["top"]
    twice = np.r_[top, top[:1]]
    for make, name in ((lambda: ContactSurface.from_solid(s, twice), "boundary"),
                       (lambda: Traction(s, twice, (0.0, 1.0)), "boundary"),
                       (lambda: FollowerPressure(s, 1.0, facets=twice), "facets")):
        assert f"facet {top[0]} is listed more than once" in _refused(make, name)


# ------------------------------------------------------------------ interior facets
def _interior_line(mesh):
    """The facets on the interior line y = 0.5 of the unit square mesh."""
    mid = mesh.p[1, mesh.facets].mean(axis=0)
    flat = np.isclose(mesh.p[1, mesh.facets[0]], mesh.p[1, mesh.facets[1]])
    return np.flatnonzero(flat & np.isclose(mid, 0.5))


def test_interior_facets_are_not_a_contact_surface():
    """The facets of an interior line chain like a boundary; they were accepted as a
    contact surface (each bounds two elements: the body would press against itself)."""
    s = _solid()
    line = _interior_line(s.mesh)
    assert line.size == 4
    msg = _refused(lambda: ContactSurface.from_solid(s, line), "boundary")
    assert "4 of its 4 facets are interior" in msg and "shared by elements" in msg
    tagged = Solid(_mesh().with_boundaries({"middle": lambda x: np.isclose(x[1], 0.5)},
                                           boundaries_only=False),
                   NeoHooke(E=1.0, nu=0.3))
    assert "boundary 'middle' must hold boundary facets" in _refused(
        lambda: ContactSurface.from_solid(tagged, "middle"), "boundary")
    assert "4 of its 4 facets are interior" in _refused(lambda: Traction(s, line, (0.0, 1.0)),
                                                        "boundary")
    assert "4 of its 4 facets are interior" in _refused(
        lambda: FollowerPressure(s, 1.0, facets=line), "facets")


# ------------------------------------------------------------------ lengths
@pytest.mark.parametrize("make, name", [
    (lambda: Cable(LINE, EA=[1.0, 2.0, 3.0]), "EA"),
    (lambda: Cable(LINE, rest_length=[1.0]), "rest_length"),
    (lambda: PointLoad(_solid(), [0, 1, 2], [1.0, 2.0]), "values"),
    (lambda: Traction(_solid(), "top", (0.0, 1.0, 2.0)), "traction"),
    (lambda: RigidPlane((0, 0, 0), (0, 1)), "point"),
    (lambda: Cable.between((0, 0, 0), (1, 0), 1.0, 4), "start"),
])
def test_an_array_of_the_wrong_length(make, name):
    _refused(make, name)


def test_valid_inputs_still_build():
    """The checks refuse nothing a user means: NumPy scalars, integer arrays, lists."""
    c = Cable(LINE, EA=np.float64(2.0), rest_length=np.array([1, 1]), tension_only=np.bool_(True))
    assert c.EA.tolist() == [2.0, 2.0] and c.tension_only is True
    assert len(Cable.between([0, 0], np.array([1, 0]), 1.0, np.int64(3)).elements) == 3
    assert NeoHooke(E=np.int64(100), nu=0).mu == 50.0
    s = _solid()
    assert PointLoad(s, np.array([0, 1]), 1).values.tolist() == [1.0, 1.0]
    assert RigidCircle((0, 0), 1, n_segments=np.int32(8)).segments.shape == (8, 2)


# ------------------------------------------------------------------ objects of the wrong kind
@pytest.mark.parametrize("make, name", [
    (lambda: Solid("mesh", NeoHooke(E=1.0, nu=0.3)), "mesh"),
    (lambda: Traction(Cable(LINE), "top", (0.0, 1.0)), "body"),
    (lambda: PointLoad("cable", [0], 1.0), "body"),
    (lambda: PointLoad(Cable(LINE), [], 1.0), "local_dofs"),
    (lambda: ContactSurface.from_solid(Cable(LINE), "top"), "solid"),
    (lambda: ContactSurface.from_cable(_solid(), "left"), "cable"),
])
def test_an_object_of_the_wrong_kind_or_an_empty_load(make, name):
    """An AttributeError deep inside (or, for no dofs, a load that did nothing) before."""
    _refused(make, name)


def test_a_facet_mask_is_read_as_a_mask():
    """A boolean facet mask (scikit-fem style) selects its True facets; before, its 0/1
    values were read as facets 0 and 1.  A mask of another length is refused."""
    s = _solid()
    mask = np.zeros(s.mesh.nfacets, dtype=bool)
    mask[s.mesh.boundaries["top"]] = True
    by_tag, by_mask = Traction(s, "top", (0.0, 1.0)), Traction(s, mask, (0.0, 1.0))
    np.testing.assert_array_equal(by_mask.force, by_tag.force)
    assert ContactSurface.from_solid(s, mask).segments.shape == (4, 2)
    np.testing.assert_array_equal(s.dofs_on(mask), s.dofs_on("top"))
    assert "integers in [0, " in _refused(lambda: s.dofs_on([0.5]), "boundary")
    assert "booleans" in _refused(lambda: Traction(s, mask[:-1], (0.0, 1.0)), "boundary")

