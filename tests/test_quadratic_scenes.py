"""The scenes' quadratic and quadrilateral bodies: meshes and consistent loads.

The contact side of these scenes (3-node segments) is tested in
tests/test_quadratic_contact.py; here the parts that are pure geometry.
"""
from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshTri

from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.scenes.hertz import graded_block, graded_quarter_disk, triangles_to_quads
from skfem_mortar.scenes.patch import uncovered_load


def _quad_areas(mesh) -> np.ndarray:
    """Shoelace areas of the quadrilaterals (positive: counter-clockwise)."""
    x, y = mesh.p[0, mesh.t], mesh.p[1, mesh.t]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0)


def test_triangles_to_quads_covers_the_mesh_counter_clockwise():
    tri = MeshTri.init_symmetric().refined(2)
    # a clockwise triangle must come out counter-clockwise too
    t = tri.t.copy()
    t[[1, 2], 0] = t[[2, 1], 0]
    tri = MeshTri(tri.p, t)
    q = triangles_to_quads(tri)
    assert q.nelements == 3 * tri.nelements
    a = _quad_areas(q)
    assert np.all(a > 0)
    # the quads tile the triangles: same total area (round-off of sums of ~100 terms)
    x, y = tri.p[0, tri.t], tri.p[1, tri.t]
    tri_area = 0.5 * np.abs((x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]))
    assert a.sum() == pytest.approx(tri_area.sum(), rel=1e-13)
    # conforming: the boundary facets are the triangles' boundary facets halved (a
    # midpoint not shared by the two triangles of an edge would add boundary facets)
    assert q.boundary_facets().size == 2 * tri.boundary_facets().size


@pytest.mark.parametrize("element", ["tri1", "tri2", "quad1", "quad2"])
def test_graded_disk_keeps_the_arc_on_the_circle(element):
    R, h0 = 8.0, 0.05
    m = graded_quarter_disk(R, h0, 0.6, element)
    arc = m.boundaries["arc"]
    pts = [m.p[:, np.unique(m.facets[:, arc])]]
    if element.endswith("2"):
        pts.append(m.doflocs[:, m.dofs.get_facet_dofs(arc).flatten()])
    for x in pts:
        # moved radially onto the circle: exact up to the round-off of R * v / |v|
        assert np.abs(np.hypot(x[0], x[1] - R) - R).max() < 1e-13 * R
    # element edges along the arc near the contact point are about h0
    # (quadrilaterals: split from triangles graded to 2 h0)
    ends = m.p[:, m.facets[:, arc]]
    length = np.hypot(*(ends[:, 1] - ends[:, 0]))
    assert 0.3 * h0 < length.min() < 1.6 * h0
    Solid(m, NeoHooke(E=1.0, nu=0.3), element=element)  # a valid mesh for the element
    Solid(graded_block(3.0, h0 * 4, 0.6, element), NeoHooke(E=1.0, nu=0.3), element=element)


@pytest.mark.parametrize("element", ["tri1", "quad1", "tri2", "quad2"])
def test_uncovered_load_is_the_consistent_load_of_the_uncovered_part(element):
    from skfem import MeshQuad
    cls = MeshTri if element.startswith("tri") else MeshQuad
    mesh = cls.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 0.5, 3)).with_defaults()
    body = Solid(mesh, NeoHooke(E=1.0, nu=0.0), element=element)
    lo, hi, t = 0.13, 0.61, -3.0
    load = uncovered_load(body, "top", lo, hi, t, "load")
    f = np.zeros(body.n_dofs)
    f[load.local_dofs] = load.values
    # against the exact virtual work of the traction on [0, lo] and [hi, 1] for the
    # interpolant of a quadratic test field v(x) = 1 + 2x - 3x^2 (exact for a linear
    # element only if v is linear: so use v = 1 + 2x there)
    quadratic = element.endswith("2")
    v = (lambda x: 1 + 2 * x - 3 * x ** 2) if quadratic else (lambda x: 1 + 2 * x)
    V = (lambda x: x + x ** 2 - x ** 3) if quadratic else (lambda x: x + x ** 2)
    vy = body.interpolate(lambda X: np.vstack([0 * X[0], v(X[0])]))
    exact = t * ((V(lo) - V(0.0)) + (V(1.0) - V(hi)))
    # a sum of a dozen products of O(1) terms
    assert f @ vy == pytest.approx(exact, rel=1e-13)
