"""Convex polygon clipping (contact/clipping.py) against an independent intersection
(shapely, a test dependency: the ``dev`` extra), and the origins of its vertices."""
import numpy as np
import pytest

from skfem_mortar.contact.clipping import (AREA_TOL, clip_polygons, fan_cells,
                                           polygon_areas)
from skfem_mortar.contact.segmentation import (EDGE_INTERSECTION, MASTER_VERTEX,
                                               SLAVE_VERTEX)


def Polygon(points):
    """shapely's polygon, imported here and not at the top so that the tests are
    collected where shapely is missing (CI's sdist check collects with pytest
    alone); it is in the ``dev`` extra, so a missing shapely fails the tests."""
    from shapely.geometry import Polygon as ShapelyPolygon
    return ShapelyPolygon(points)


def _convex(rng, k):
    """A random convex counter-clockwise polygon of k vertices (points of an ellipse)."""
    while True:
        ang = np.sort(rng.uniform(0.0, 2.0 * np.pi, k))
        P = np.c_[np.cos(ang), np.sin(ang)] @ rng.uniform(-1.0, 1.0, (2, 2))
        area = Polygon(P).area
        if area > 1e-2:
            if Polygon(P).exterior.is_ccw is False:
                P = P[::-1]
            return P + rng.uniform(-1.0, 1.0, 2)


def _pairs(rng, m):
    k_c, k_s = rng.integers(3, 5, m), rng.integers(3, 5, m)
    C, S = np.zeros((m, 4, 2)), np.zeros((m, 4, 2))
    for i in range(m):
        C[i, :k_c[i]] = _convex(rng, k_c[i])
        S[i, :k_s[i]] = _convex(rng, k_s[i])
    return C, k_c, S, k_s


def _line_point(p1, p2, q1, q2):
    d1, d2 = p2 - p1, q2 - q1
    t = ((q1 - p1)[0] * d2[1] - (q1 - p1)[1] * d2[0]) / (d1[0] * d2[1] - d1[1] * d2[0])
    return p1 + t * d1


def _from_origin(C, k_c, S, k_s, clip, i, k):
    """A clip vertex rebuilt from its origin alone."""
    o, (a, b) = clip.origin[i, k], clip.index[i, k]
    if o == SLAVE_VERTEX:
        return C[i, a]
    if o == MASTER_VERTEX:
        return S[i, b]
    assert o == EDGE_INTERSECTION
    return _line_point(C[i, a], C[i, (a + 1) % k_c[i]], S[i, b], S[i, (b + 1) % k_s[i]])


def test_clip_areas_equal_shapely_and_origins_rebuild_the_vertices():
    rng = np.random.default_rng(0)
    C, k_c, S, k_s = _pairs(rng, 400)
    clip = clip_polygons(C, k_c, S, k_s)
    ref = np.array([Polygon(C[i, :k_c[i]]).intersection(Polygon(S[i, :k_s[i]])).area
                    for i in range(len(C))])
    assert (ref > 0).sum() > 50 and (ref == 0).sum() > 50       # both kinds of pairs
    # areas of order 1 from at most 8 vertices: a few ulps of the shoelace sum
    np.testing.assert_allclose(polygon_areas(clip.u, clip.count), ref, rtol=0, atol=1e-14)
    pair, corner, area = fan_cells(clip, polygon_areas(C, k_c))
    np.testing.assert_allclose(np.bincount(pair, area, minlength=len(C)), ref, atol=1e-14)
    assert np.all(area > 0)
    # the origins rebuild every vertex (intersections of lines: conditioned by the
    # angle between them, at worst about 1e2 times round-off for these polygons)
    err = max(np.abs(_from_origin(C, k_c, S, k_s, clip, i, k) - clip.u[i, k]).max()
              for i in range(len(C)) for k in range(clip.count[i]))
    assert err < 1e-12
    kinds = clip.origin[clip.origin >= 0]
    assert {SLAVE_VERTEX, MASTER_VERTEX, EDGE_INTERSECTION} <= set(kinds.tolist())


def test_touching_identical_and_nested_polygons():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    shifted = sq + [1.0, 0.0]                       # shares the edge x = 1
    corner = sq + [1.0, 1.0]                        # shares the vertex (1, 1)
    inner = 0.25 + 0.5 * sq
    C = np.stack([sq, sq, sq, sq, inner])
    S = np.stack([shifted, corner, sq, inner, sq])
    k = np.full(5, 4)
    clip = clip_polygons(C, k, S, k)
    area = polygon_areas(clip.u, clip.count)
    # touching along an edge or at a vertex: a polygon of no area (its vertices on
    # the common line), which makes no cell below
    np.testing.assert_allclose(area[:2], 0.0, atol=1e-15)
    np.testing.assert_allclose(area[2:], [1.0, 0.25, 0.25], atol=1e-15)
    # identical squares: every edge lies on a slave and a master line; the slave's
    # carries it (the touching neighbours' pairs then add nothing to a derivative
    # either), so the vertices are the slave's
    assert np.all(clip.origin[2, :4] == SLAVE_VERTEX)
    assert np.all(clip.origin[3, :4] == MASTER_VERTEX)   # nested master
    assert np.all(clip.origin[4, :4] == SLAVE_VERTEX)    # nested slave
    pair, _, cell_area = fan_cells(clip, np.ones(5))
    assert set(pair.tolist()) == {2, 3, 4} and np.all(cell_area > AREA_TOL)


def test_bad_input_is_refused():
    C = np.zeros((2, 4, 2))
    with pytest.raises(ValueError, match="subject must have shape"):
        clip_polygons(C, [3, 3], np.zeros((2, 3, 2)), [3, 3])
    with pytest.raises(ValueError, match=r"k_s must be \(2,\) vertex counts in \[3, 4\]"):
        clip_polygons(C, [3, 3], C, [3, 5])
