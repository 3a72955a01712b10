"""Tests of the mortar geometry: jets, nodal normals, projections, segments."""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact.mortar_segmentation import (Jet, XI_TOL, nodal_normals, project_point_on_slave,
                                              segment)


def chain(n: int) -> np.ndarray:
    return np.c_[np.arange(n - 1), np.arange(1, n)]


# ------------------------------------------------------------------------ jets
def test_jet_gradient_and_hessian_against_analytic():
    """f(x, y) = x^2 y / (x + y) + sqrt(x y): compare with hand-derived derivatives."""
    x0 = np.array([0.7, 1.3])
    y0 = np.array([1.9, 0.4])
    x, y = Jet.variable(x0, 0, 2, True), Jet.variable(y0, 1, 2, True)
    f = x * x * y / (x + y) + (x * y).sqrt()
    s = x0 + y0
    r = np.sqrt(x0 * y0)
    # f1 = x^2 y / s:  f1_x = (x^2 y + 2 x y^2) / s^2,  f1_y = x^3 / s^2
    f1x, f1y = (x0**2 * y0 + 2 * x0 * y0**2) / s**2, x0**3 / s**2
    f1xx = 2 * y0**3 / s**3
    f1yy = -2 * x0**3 / s**3
    f1xy = (3 * x0**2 * s - 2 * x0**3) / s**3
    # f2 = sqrt(x y)
    f2x, f2y = y0 / (2 * r), x0 / (2 * r)
    f2xx, f2yy, f2xy = -y0**2 / (4 * r**3), -x0**2 / (4 * r**3), 1 / (4 * r)
    np.testing.assert_allclose(f.v, x0**2 * y0 / s + r, rtol=1e-15)
    np.testing.assert_allclose(f.g, [f1x + f2x, f1y + f2y], rtol=1e-14)   # variables first
    H = f.hessian()
    np.testing.assert_allclose(H[0, 0], f1xx + f2xx, rtol=1e-13)
    np.testing.assert_allclose(H[1, 1], f1yy + f2yy, rtol=1e-13)
    np.testing.assert_allclose(H[0, 1], f1xy + f2xy, rtol=1e-13)
    np.testing.assert_allclose(H[1, 0], f1xy + f2xy, rtol=1e-13)


def test_jet_broadcast_over_gauss_axis():
    """A segment jet (n,) expanded to (n, 1) combines with Gauss-point arrays (n_gauss,)."""
    a = Jet.variable(np.array([1.0, 2.0, 3.0]), 0, 1, True)
    eta = np.array([-0.5, 0.5])
    b = (a.expand() * eta + 1.0) * a.expand()              # a^2 eta + a
    assert b.v.shape == (3, 2) and b.g.shape == (1, 3, 2) and b.h.shape == (1, 1, 3, 2)
    np.testing.assert_allclose(b.hessian()[0, 0], 2 * np.broadcast_to(eta, (3, 2)))
    np.testing.assert_allclose(b.sum(1).g[0], (2 * a.v[:, None] * eta + 1).sum(1))


# -------------------------------------------------------------- nodal normals
def test_nodal_normals_polygon_on_circle_are_radial():
    """Uniform polygon on a circle, run counterclockwise so the right-hand normal is
    outward: the averaged normal of an interior node is radial (symmetry); the
    end nodes of the open arc take their single segment's normal."""
    th = np.linspace(np.pi * 0.1, np.pi * 0.9, 9)       # counterclockwise over the top
    xs = np.vstack([np.cos(th), np.sin(th)])
    (nx, ny), pnode, nnode = nodal_normals(xs, chain(9), second=True)
    np.testing.assert_allclose(nx.v[1:-1], np.cos(th[1:-1]), atol=1e-15)
    np.testing.assert_allclose(ny.v[1:-1], np.sin(th[1:-1]), atol=1e-15)
    mid = 0.5 * (th[0] + th[1])                          # first segment's normal direction
    np.testing.assert_allclose([nx.v[0], ny.v[0]], [np.cos(mid), np.sin(mid)], atol=1e-15)
    assert pnode[0] == 0 and nnode[-1] == 8              # missing neighbours point to the node
    # the normal is a unit vector: its gradient is orthogonal to it (d|n|^2 = 0)
    np.testing.assert_allclose(nx.v * nx.g + ny.v * ny.g, 0, atol=1e-14)


# ----------------------------------------------------------------- projection
def test_projection_flat_is_linear():
    """Flat slave element from (1, 0) to (-1, 0) (normal +y): a point (x, y)
    projects to xi = -x whatever its height."""
    xa, xb = (np.array([1.0]), np.array([0.0])), (np.array([-1.0]), np.array([0.0]))
    n = (np.array([0.0]), np.array([1.0]))
    for x, y in [(0.3, 0.2), (-0.75, -0.1), (1.4, 3.0)]:
        xi, ok = project_point_on_slave(xa, xb, n, n, (np.array([x]), np.array([y])))
        assert ok[0]
        np.testing.assert_allclose(xi, [-x], atol=1e-15)


def test_projection_curved_normal_field_residual():
    """With differing nodal normals the point lies on the line x_s(xi) + t n(xi)."""
    rng = np.random.default_rng(0)
    xa = (rng.uniform(0.9, 1.1, 50), rng.uniform(-0.1, 0.1, 50))
    xb = (rng.uniform(-1.1, -0.9, 50), rng.uniform(-0.1, 0.1, 50))
    na = (np.full(50, 0.3), np.full(50, 0.95))
    nb = (np.full(50, -0.4), np.full(50, 0.92))
    pc = (rng.uniform(-0.8, 0.8, 50), rng.uniform(0.05, 0.3, 50))
    xi, ok = project_point_on_slave(xa, xb, na, nb, pc)
    assert ok.all()
    N1, N2 = (1 - xi) / 2, (1 + xi) / 2
    dx, dy = N1 * xa[0] + N2 * xb[0] - pc[0], N1 * xa[1] + N2 * xb[1] - pc[1]
    nx, ny = N1 * na[0] + N2 * nb[0], N1 * na[1] + N2 * nb[1]
    # cross product of O(1) vectors vanishes to round-off
    np.testing.assert_allclose(dx * ny - dy * nx, 0, atol=1e-14)


# ---------------------------------------------------------------- segmentation
def flat(xs_x, xm_x, d=0.0):
    xs_x, xm_x = np.asarray(xs_x, float)[::-1], np.asarray(xm_x, float)
    return (np.vstack([xs_x, 0 * xs_x]), chain(xs_x.size),
            np.vstack([xm_x, d + 0 * xm_x]), chain(xm_x.size))


def test_segments_flat_nonmatching_end_points():
    """Slave nodes x = 0, .5, 1 (run right to left), master nodes 0.2, 0.7, 1.3:
    mortar segments are [1, .7], [.7, .5] on the first slave element and
    [.5, .2] on the second; mapped back by x(xi) = x_a + (1 + xi)/2 (x_b - x_a)."""
    xs, ss, xm, sm = flat([0.0, 0.5, 1.0], [0.2, 0.7, 1.3], d=0.01)
    sg = segment(xs, ss, xm, sm)
    xa, xb = xs[0, ss[sg.e_s, 0]], xs[0, ss[sg.e_s, 1]]
    x_lo = xa + (1 + sg.xi[:, 0]) / 2 * (xb - xa)
    x_hi = xa + (1 + sg.xi[:, 1]) / 2 * (xb - xa)
    got = sorted(zip(np.round(x_lo, 14), np.round(x_hi, 14)))
    assert got == sorted([(0.5, 0.2), (0.7, 0.5), (1.0, 0.7)])
    # projectable part of the second slave element (x from .5 to 0): x in [.5, .2],
    # x = .5 - (1 + xi) / 4 gives xi in [-1, 0.2]
    e2 = 1
    np.testing.assert_allclose(sg.elem_xi[e2], [-1.0, 0.2], atol=1e-14)
    assert sg.elem_node[e2, 0] == -1 and sg.elem_node[e2, 1] == 0   # master node at 0.2


def test_segments_drop_non_facing_and_degenerate():
    # master with the slave's orientation (normals not facing): no segment
    xs, ss, xm, sm = flat([0.0, 0.5, 1.0], [0.0, 0.5, 1.0])
    sg = segment(xs, ss, xm[:, ::-1].copy(), sm)
    assert sg.n == 0
    # a zero-length slave element is dropped, its neighbours keep their segments
    xs2 = np.vstack([[1.0, 0.5, 0.5, 0.0], [0, 0, 0, 0]])
    sg = segment(xs2, chain(4), xm, sm)
    assert 1 not in set(sg.e_s) and {0, 2} <= set(sg.e_s)
    # a master node coinciding with a slave node makes no zero-length segment
    sg = segment(xs, ss, xm, sm)
    assert sg.n == 2 and np.all(np.diff(sg.xi, axis=1) > XI_TOL)


def test_segments_cover_overlap_exactly():
    """The mortar segments tile the overlap of the two surfaces: their total
    slave length equals the analytic overlap length, with random meshes."""
    rng = np.random.default_rng(5)
    xs_x = np.sort(np.r_[0.0, rng.uniform(0, 1, 17), 1.0])
    xm_x = np.sort(np.r_[0.4, rng.uniform(0.4, 1.6, 9), 1.6])
    xs, ss, xm, sm = flat(xs_x, xm_x, d=-0.02)
    sg = segment(xs, ss, xm, sm)
    elem_len = np.abs(np.diff(xs[0][ss[sg.e_s]], axis=1)).ravel()
    lengths = elem_len * np.diff(sg.xi, axis=1).ravel() / 2
    np.testing.assert_allclose(lengths.sum(), 0.6, rtol=1e-14)


def test_segment_with_explicit_pairs_equals_search():
    xs, ss, xm, sm = flat(np.linspace(0, 1, 6), np.linspace(0.1, 1.2, 4), d=0.01)
    i_s = np.repeat(np.arange(5), 3)
    i_m = np.tile(np.arange(3), 5)
    a = segment(xs, ss, xm, sm, pairs=(i_s, i_m))
    b = segment(xs, ss, xm, sm)
    ka, kb = np.lexsort((a.e_m, a.e_s)), np.lexsort((b.e_m, b.e_s))
    assert np.array_equal(a.e_s[ka], b.e_s[kb]) and np.array_equal(a.e_m[ka], b.e_m[kb])
    np.testing.assert_allclose(a.xi[ka], b.xi[kb], atol=0)


@pytest.mark.parametrize("mirror", [False, True])
def test_nodal_normal_values_are_the_jets_values(mirror):
    """The values path of ``nodal_normals`` (``nv = 0``: plain arrays, what every
    segmentation asks) runs the jets' operations in their order, so its normals are the
    jet path's to the last bit: random chains, one with a degenerate segment, with and
    without a symmetry line through the first node."""
    rng = np.random.default_rng(7)
    for t in range(10):
        xv = np.sort(rng.random(20))
        xs = np.array([xv, 0.1 * rng.random(20)])
        if t % 3 == 0:
            xs[:, 7] = xs[:, 8]                       # a zero-length segment
        seg = np.c_[np.arange(19), np.arange(1, 20)]
        kw = {"mirror": [(np.array([1.0, 0.0]), xv[0])]} if mirror else {}
        (ax, ay), ap, an = nodal_normals(xs, seg, second=False, nv=0, **kw)
        (bx, by), bp, bn = nodal_normals(xs, seg, second=False, nv=6, **kw)
        assert np.array_equal(ax.v, bx.v) and np.array_equal(ay.v, by.v)
        assert np.array_equal(ap, bp) and np.array_equal(an, bn)
