"""NTS onto curved 3-node master segments: projection, exact G and H, balance.

Finite differences: central, h = 1e-6 on unit-size geometry, so truncation
O(h^2 g''') ~ 1e-12 and round-off O(eps |g| / h) ~ 1e-10: G to 1e-8 and H (a
difference of G) to 1e-6 of their largest entries; a missing term of the
projection's derivative is O(1) (checked by the bent master: the curvature
terms are 0.6 of the entries).
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import curves, nts
from skfem_mortar.contact.cells import cell_type
from skfem_mortar.core.chain import curve_points

H_FD = 1e-6


def _master(bend: float = 0.3, shift: float = 0.0):
    """Three 3-node segments along y = bend (x - 0.4)^2, right to left (normal +y),
    mid nodes off-centre (so the parametrization is not uniform)."""
    xv = np.array([1.2, 0.7, 0.2, -0.3]) + shift
    xmid = 0.5 * (xv[:-1] + xv[1:]) + np.array([0.03, -0.02, 0.01])
    X = np.r_[xv, xmid]
    return np.vstack([X, bend * (X - 0.4 - shift) ** 2]), np.array([[0, 1, 4], [1, 2, 5], [2, 3, 6]])


def _slave(n: int = 6, y0: float = 0.02, seed: int = 0, x0: float = -0.1, x1: float = 1.1):
    rng = np.random.default_rng(seed)
    xs = np.vstack([np.linspace(x0, x1, n), y0 + 0.06 * (rng.random(n) - 0.5)])
    return xs, np.column_stack([np.arange(n - 1), np.arange(1, n)]), rng.random(n)


def _fd(xs, seg_s, xm, seg_m, lam, prefer):
    """G, H of the kernel and their central differences (fixed segment choice)."""
    n_s = xs.shape[1]
    x0 = np.concatenate([xs.T.ravel(), xm.T.ravel()])

    def split(x):
        return x[:2 * n_s].reshape(-1, 2).T, x[2 * n_s:].reshape(-1, 2).T

    def ev(x, tangent):
        a, b = split(x)
        return nts.evaluate(a, seg_s, b, seg_m, lam=lam if tangent else None, tangent=tangent,
                            prefer=prefer, stick=0.5)
    e0 = ev(x0, True)
    eye = np.eye(x0.size) * H_FD
    Gfd = np.array([(ev(x0 + e, False).g - ev(x0 - e, False).g) / (2 * H_FD) for e in eye]).T
    Hfd = np.array([(ev(x0 + e, True).G.T @ lam - ev(x0 - e, True).G.T @ lam) / (2 * H_FD)
                    for e in eye]).T
    return e0, Gfd, Hfd


@pytest.mark.parametrize("case", ["bent", "sliding", "near_ends", "quadratic_slave"])
def test_fd_of_g_and_h_on_curved_masters(case):
    xm, seg_m = _master(shift=0.37 if case == "sliding" else 0.0)
    xs, seg_s, lam = _slave(x0=-0.28 if case == "near_ends" else -0.1,
                            x1=1.19 if case == "near_ends" else 1.1)
    if case == "quadratic_slave":   # 3-node slave segments: mid nodes are contact points too
        seg_s = np.array([[0, 2, 1], [2, 4, 3]])
        xs, lam = xs[:, :5], lam[:5]
    prefer = nts.evaluate(xs, seg_s, xm, seg_m, tangent=False).info["segment"]
    e0, Gfd, Hfd = _fd(xs, seg_s, xm, seg_m, lam, prefer)
    assert e0.mask.sum() >= 4
    G, H = e0.G.toarray(), e0.H.toarray()
    rows = e0.mask
    assert np.abs(G[rows] - Gfd[rows]).max() < 1e-8 * np.abs(G).max()
    assert np.abs(H - Hfd).max() < 1e-6 * np.abs(H).max()
    assert np.abs(H - H.T).max() < 1e-14 * np.abs(H).max()    # a second derivative


def test_projection_is_the_closest_point_on_the_curve():
    xm, seg_m = _master()
    xs, seg_s, _ = _slave(n=9, y0=0.1)
    ev = nts.evaluate(xs, seg_s, xm, seg_m, tangent=False)
    u = np.linspace(-1.0, 1.0, 20001)
    pts = curve_points(xm, seg_m, u)                            # (2, 3, n)
    for k in np.flatnonzero(ev.mask):
        d = np.hypot(pts[0] - xs[0, k], pts[1] - xs[1, k])
        e, i = np.unravel_index(np.argmin(d), d.shape)
        # the dense sampling's nearest point (spacing 1e-4 of xi: distance error 1e-9)
        assert ev.info["segment"][k] == e
        assert abs(abs(ev.g[k]) - d.min()) < 1e-8
        assert ev.info["xi"][k] == pytest.approx(0.5 * (1 + u[i]), abs=2e-4)


def test_straight_three_node_master_gives_the_linear_gaps():
    """Mid nodes at the midpoints: the curve is the chord, so the curved kernel's g
    and G equal the linear kernel's on the same nodes (to round-off)."""
    xv = np.array([1.0, 0.5, 0.0])
    X = np.r_[xv, 0.5 * (xv[:-1] + xv[1:])]
    xm = np.vstack([X, 0.1 * X])
    seg3 = np.array([[0, 1, 3], [1, 2, 4]])
    seg2 = seg3[:, :2]
    xs, seg_s, _ = _slave(n=5, x0=0.05, x1=0.95)
    q, l = nts.evaluate(xs, seg_s, xm, seg3), nts.evaluate(xs, seg_s, xm, seg2)
    np.testing.assert_allclose(q.g, l.g, atol=1e-15)
    np.testing.assert_array_equal(q.mask, l.mask)
    np.testing.assert_allclose(q.info["xi"], l.info["xi"], atol=1e-14)
    # G: the linear kernel's weights (1 - xi), xi split onto start, end and mid as N_A
    Gq, Gl = q.G.toarray(), l.G.toarray()
    np.testing.assert_allclose(Gq[:, :10], Gl[:, :10], atol=1e-14)    # slave columns
    np.testing.assert_allclose(Gq.sum(axis=1), Gl.sum(axis=1), atol=1e-14)


def test_forces_on_the_two_sides_sum_to_zero():
    """The gaps are translation invariant, so sum over the nodes of G^T lam is zero
    per direction (to round-off), and the moment about the origin too (rotation
    invariance: g is a distance)."""
    xm, seg_m = _master()
    xs, seg_s, lam = _slave()
    ev = nts.evaluate(xs, seg_s, xm, seg_m, lam=lam)
    f = (ev.G.T @ (lam * ev.mask)).reshape(-1, 2)
    x = np.vstack([xs.T, xm.T])
    assert np.abs(f.sum(axis=0)).max() < 1e-13 * np.abs(f).max()
    assert abs(np.sum(x[:, 0] * f[:, 1] - x[:, 1] * f[:, 0])) < 1e-13 * np.abs(f).max()


def test_a_node_inside_a_strong_bend_still_projects():
    """A node near the centre of curvature of a bent segment: f' > 0 at the chord's
    guess (a distance maximum); the safeguarded Newton still reaches the minimum."""
    X = np.array([[1.0, -1.0, 0.0], [0.0, 0.0, 0.6]])          # start, end, mid: an arch
    xs = np.array([[0.3], [0.45]])
    xi, ok = curves.project_values(cell_type("line3"), xs, tuple((X[0, [a]], X[1, [a]]) for a in range(3)))
    assert ok
    pts = curve_points(X, np.array([[0, 1, 2]]), np.linspace(-1, 1, 200001))[:, 0]
    d = np.hypot(pts[0] - xs[0, 0], pts[1] - xs[1, 0])
    p = curve_points(X, np.array([[0, 1, 2]]), xi)[:, 0, 0]
    assert np.hypot(p[0] - xs[0, 0], p[1] - xs[1, 0]) == pytest.approx(d.min(), abs=1e-9)
