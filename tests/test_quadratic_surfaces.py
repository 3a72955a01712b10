"""Contact surfaces of quadratic solids: 3-node segments (start, end, mid)."""
from __future__ import annotations

import numpy as np
import pytest
import skfem

from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.contact.active_set import chain_order
from skfem_mortar.contact.search import segment_boxes
from skfem_mortar.contact.surfaces import ContactSurface
from skfem_mortar.core.chain import curve_points, segment_lengths, tributary_lengths


def _block(element: str, nx: int = 3):
    cls = skfem.MeshTri if element.startswith("tri") else skfem.MeshQuad
    mesh = cls.init_tensor(np.linspace(0, 1, nx + 1), np.linspace(0, 0.5, 2)).with_defaults()
    return Solid(mesh, NeoHooke(E=1.0, nu=0.3), element=element)


@pytest.mark.parametrize("element", ["tri2", "quad2"])
def test_surface_of_a_quadratic_solid_has_its_mid_nodes(element):
    body = _block(element)
    s = ContactSurface.from_solid(body, "top")
    assert s.order == 2 and s.segments.shape == (3, 3)
    assert s.n_nodes == 7                                   # 4 vertices, 3 mid nodes
    X = s.X
    # outward (+y): the top runs right to left; every mid node halfway between its ends
    assert np.all(X[0, s.segments[:, 1]] < X[0, s.segments[:, 0]])
    np.testing.assert_allclose(X[:, s.segments[:, 2]],
                               0.5 * (X[:, s.segments[:, 0]] + X[:, s.segments[:, 1]]), atol=1e-15)
    # the mid nodes' dofs are the facets' P2 dofs: moving them moves the surface node
    z = np.zeros(body.n_dofs)
    z[body.dofs_on("top", "y")] = 0.25
    np.testing.assert_allclose(s.x(z)[1], 0.75)
    assert np.all(s.nodes[s.segments[:, 2]] == -1)          # not vertices
    assert np.all(s.nodes[s.segments[:, :2]] >= 0)


def test_tributary_weights_are_the_consistent_ones():
    body = _block("tri2")
    s = ContactSurface.from_solid(body, "top")
    w = tributary_lengths(s.X, s.segments)
    L = 1.0 / 3.0
    # straight segments with centred mid nodes: L/6 at an end (L/3 where two meet), 2L/3 mid
    np.testing.assert_allclose(w[s.segments[:, 2]], 2 * L / 3, rtol=1e-14)
    ends = np.bincount(s.segments[:, :2].ravel(), minlength=s.n_nodes)[s.segments[:, 0]]
    np.testing.assert_allclose(w[s.segments[:, 0]], ends * L / 6, rtol=1e-14)
    assert w.sum() == pytest.approx(1.0, rel=1e-14)


def test_curved_surface_lengths_and_weights_sum_to_the_curve_length():
    mesh = skfem.MeshTri2.init_circle(2)          # isoparametric: boundary mid nodes on the circle
    body = Solid(mesh, NeoHooke(E=1.0, nu=0.3), element="tri2")
    s = ContactSurface.from_solid(body, mesh.boundary_facets())
    assert s.closed and s.order == 2
    r = np.hypot(*s.X)
    np.testing.assert_allclose(r, 1.0, atol=1e-14)
    length = segment_lengths(s.X, s.segments).sum()
    # the 3-node curves through points of the circle: length within the interpolation
    # error O(h^4) of 2 pi (h = 2 pi / 32), and weights summing to that length
    assert abs(length - 2 * np.pi) < 1e-3
    assert tributary_lengths(s.X, s.segments).sum() == pytest.approx(length, rel=1e-13)
    # the curve itself stays near the circle between the nodes (chords would not)
    pts = curve_points(s.X, s.segments, np.array([-0.5, 0.5]))
    assert np.abs(np.hypot(*pts) - 1.0).max() < 2e-4
    chord = 0.5 * (s.X[:, s.segments[:, 0]] + s.X[:, s.segments[:, 2]])
    assert np.abs(np.hypot(*chord) - 1.0).max() > 1e-3


def test_chain_order_visits_mid_nodes_between_their_ends():
    s = ContactSurface.from_solid(_block("quad2"), "top")
    order = chain_order(s.segments, s.closed, s.n_nodes, "line3")
    seg = s.segments
    np.testing.assert_array_equal(order, [seg[0, 0], seg[0, 2], seg[1, 0], seg[1, 2],
                                          seg[2, 0], seg[2, 2], seg[2, 1]])


def test_boxes_hold_the_curved_segment():
    X = np.array([[0.0, 1.0, 0.5], [0.0, 0.0, 0.3]])      # start, end, mid (bulging up)
    lo, hi = segment_boxes(X, np.array([[0, 1, 2]]))
    pts = curve_points(X, np.array([[0, 1, 2]]), np.linspace(-1, 1, 201))[:, 0]
    assert np.all(pts >= lo - 1e-15) and np.all(pts <= hi + 1e-15)


def test_reversed_flips_the_normals_and_keeps_the_dofs():
    s = ContactSurface.from_solid(_block("tri2"), "bottom")
    r = s.reversed()
    assert r.order == 2
    np.testing.assert_array_equal(np.sort(r.dofs(), axis=1), np.sort(s.dofs(), axis=1))
    n_s, _ = s.normals(np.zeros(s.body.n_dofs))
    n_r, _ = r.normals(np.zeros(s.body.n_dofs))
    np.testing.assert_allclose(n_s[:, ::-1], -n_r, atol=1e-15)


def test_an_element_without_a_lagrange_trace_is_refused():
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 2)).with_defaults()
    body = Solid(mesh, NeoHooke(E=1.0, nu=0.3), element="tri1")
    body.element = "tri3"  # an element contact does not know
    with pytest.raises(ValueError, match="Lagrange line"):
        ContactSurface.from_solid(body, "top")


def test_pictures_draw_three_node_traces_as_curves():
    from skfem_mortar.output.plot_geometry import _shapes
    X = np.array([[0.0, 1.0, 0.5], [0.0, 0.0, 0.3]]).T            # start, end, mid
    _, lines, where = _shapes(X, [("line3", np.array([[0, 1, 2]]))])
    assert where == [1]
    pts = lines[0][0]                                              # (9, 2) along the curve
    assert pts.shape == (9, 2)
    # on the parabola through the three nodes, y = 1.2 x (1 - x), not on the chords
    np.testing.assert_allclose(pts[:, 1], 1.2 * pts[:, 0] * (1 - pts[:, 0]), atol=1e-15)


def test_pressure_profile_follows_the_curve_and_interpolates_the_nodes():
    """On the quadratic patch (mortar, uniform pressure 1e4) the profile is 1e4
    everywhere (round-off of the solve, 1e-9 relative); its arc length is the
    surface's length; at the nodes it equals contact_data."""
    from skfem_mortar import pressure_profile, solve
    from skfem_mortar.app.runner import build_scene
    setup, _, _ = build_scene("patch", {"element": "quad2"}, "mortar")
    res = solve(setup.model, 1)
    pair = setup.model.item("contact")
    prof = pressure_profile(pair, res.z, n_per_segment=4)
    n_seg = len(pair.slave.segments)
    assert prof["pressure"].shape == (4 * n_seg + 1,)
    np.testing.assert_allclose(prof["pressure"], 1e4, rtol=1e-9)
    length = segment_lengths(pair.slave.x(res.z), pair.slave.segments).sum()
    assert prof["s"][-1] == pytest.approx(length, rel=1e-12)
    d = pair.contact_data(res.z)
    # every 4th sample is a segment start: the nodal value
    starts = pair.slave.segments[:, 0]
    order = {int(k): i for i, k in enumerate(d["node"])}
    np.testing.assert_allclose(prof["pressure"][:-1:4], d["pressure"][[order[int(k)] for k in starts]],
                               rtol=1e-14)
    with pytest.raises(ValueError, match="n_per_segment"):
        pressure_profile(pair, res.z, n_per_segment=0)
