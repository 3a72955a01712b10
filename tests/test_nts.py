"""Tests of the NTS element: projection, gap and finite-difference checks of G and H."""
import numpy as np
import pytest

from skfem_mortar.contact import nts


def _pack(xs, xm):
    return np.concatenate([xs.T.ravel(), xm.T.ravel()])


def _unpack(q, n_s):
    return q[:2 * n_s].reshape(-1, 2).T, q[2 * n_s:].reshape(-1, 2).T


def _config(rng):
    """A curved master chain (convex arc, so the normals rotate from segment to
    segment) and slave nodes above and below it, away from segment ends."""
    th = np.linspace(0.3, 1.2, 6)
    xm = np.vstack([np.cos(th), np.sin(th)]) * 2.0  # counter-clockwise arc
    seg_m = np.column_stack([np.arange(5), np.arange(1, 6)])  # outward = away from origin
    # slave nodes: on each master segment at parameter 0.2..0.8, offset along normal
    mid = np.arange(5)
    xi = rng.uniform(0.2, 0.8, 5)
    x1, x2 = xm[:, mid], xm[:, mid + 1]
    t = x2 - x1
    n = np.vstack([t[1], -t[0]]) / np.hypot(*t)
    xs = x1 + xi * t + rng.uniform(-0.05, 0.05, 5) * n
    seg_s = np.column_stack([np.arange(4, 0, -1), np.arange(3, -1, -1)])
    return xs, seg_s, xm, seg_m


def test_gap_of_a_point_above_a_segment():
    # analytic: segment from (0,0) to (2,0); right-hand normal (0,-1) -> "outside" is y < 0
    xm = np.array([[0.0, 2.0], [0.0, 0.0]])
    xs = np.array([[0.5, 1.5], [-0.3, 0.2]])
    ev = nts.evaluate(xs, np.array([[0, 1]]), xm, np.array([[0, 1]]))
    np.testing.assert_allclose(ev.g, [0.3, -0.2], rtol=0, atol=1e-15)
    np.testing.assert_allclose(ev.info["xi"], [0.25, 0.75], rtol=0, atol=1e-15)
    assert ev.mask.all()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fd_G_and_H(seed):
    """Central differences of g (-> G) and of lam.G (-> H) in all 2 n_s + 2 n_m directions.

    The configuration is perturbed randomly first so that the projection point
    xi and the master normals are generic; each derivative direction moves xi
    along its segment and rotates n. Central differences have an error
    O(eps^2 |g'''|) ~ 1e-12 with eps = 1e-6 (plus round-off 1e-16/1e-6 = 1e-10),
    so 1e-7 relative to the entries (which are O(1)) is a safe but strict bound.
    """
    rng = np.random.default_rng(seed)
    xs, seg_s, xm, seg_m = _config(rng)
    n_s = xs.shape[1]
    lam = rng.uniform(0.5, 2.0, n_s)
    q0 = _pack(xs, xm)
    ev = nts.evaluate(xs, seg_s, xm, seg_m, lam=lam)
    assert ev.mask.all()
    G, H = ev.G.toarray(), ev.H.toarray()
    eps = 1e-6
    Gfd = np.zeros_like(G)
    Hfd = np.zeros_like(H)
    for i in range(len(q0)):
        dq = np.zeros_like(q0)
        dq[i] = eps
        ep = nts.evaluate(*_mix(q0 + dq, n_s, seg_s, seg_m), lam=lam)
        em = nts.evaluate(*_mix(q0 - dq, n_s, seg_s, seg_m), lam=lam)
        np.testing.assert_array_equal(ep.info["segment"], ev.info["segment"])
        Gfd[:, i] = (ep.g - em.g) / (2 * eps)
        Hfd[:, i] = (ep.G.T @ lam - em.G.T @ lam) / (2 * eps)
    np.testing.assert_allclose(G, Gfd, rtol=0, atol=1e-7)
    np.testing.assert_allclose(H, Hfd, rtol=0, atol=1e-7)
    np.testing.assert_allclose(H, H.T, rtol=0, atol=1e-13)  # a Hessian is symmetric
    # the rotation of n and the motion of xi matter: H is not zero
    assert np.abs(H).max() > 0.1


def _mix(q, n_s, seg_s, seg_m):
    xs, xm = _unpack(q, n_s)
    return xs, seg_s, xm, seg_m


def test_vertex_and_end_handling():
    # master: two segments with a convex vertex at (1, 0): (0,0)->(1,0)->(2,-1)
    # traversed so the outward (right-hand) normal points down/right (y < 0 side)
    xm = np.array([[0.0, 1.0, 2.0], [0.0, 0.0, -1.0]])
    seg_m = np.array([[0, 1], [1, 2]])
    xs = np.array([[1.05, -0.5, 3.5, 0.5],
                   [-0.3, -0.1, -2.0, 0.1]])
    seg_s = np.array([[0, 1], [1, 2], [2, 3]])
    ev = nts.evaluate(xs, seg_s, xm, seg_m)
    # node 0 at (1.05, -0.3): inside the Voronoi region of the vertex? distance to
    # segment 0 line clipped = |(0.05,-0.3)|, to segment 1: projection xi =
    # ((0.05,-0.3).(1,-1))/2 = 0.175 inside -> distance 0.25/sqrt2 = 0.1768 < 0.304
    assert ev.info["segment"][0] == 1
    np.testing.assert_allclose(ev.g[0], (0.05 * -1 + -0.3 * -1) / np.sqrt(2), atol=1e-15)
    # node 1 at x = -0.5 is off the free start of the chain: left the surface
    assert not ev.mask[1]
    # node 2 at (3.5, -2.0) is off the free end (xi > 1 on the last segment)
    assert not ev.mask[2]
    # node 3 above segment 0: penetrated (outward normal points to y < 0)
    assert ev.mask[3] and ev.g[3] == pytest.approx(-0.1, abs=1e-15)


def test_far_node_finds_partner():
    # a node 10 segment lengths away from a fine master still gets its closest segment
    xm = np.vstack([np.linspace(0, 1, 101), np.zeros(101)])[:, ::-1]  # normal +y
    seg_m = np.column_stack([np.arange(100), np.arange(1, 101)])
    xs = np.array([[0.333], [-0.1]])
    ev = nts.evaluate(xs, np.zeros((0, 2), dtype=int), xm, seg_m, margin=0.0)
    assert ev.mask[0]
    np.testing.assert_allclose(ev.g[0], -0.1, atol=1e-15)


def test_bad_input():
    with pytest.raises(ValueError, match="lam"):
        nts.evaluate(np.zeros((2, 2)), [[0, 1]], np.array([[0.0, 1], [0, 0]]), [[0, 1]],
                     lam=np.zeros(3))
    with pytest.raises(ValueError, match="end_tolerance"):
        nts.evaluate(np.zeros((2, 2)), [[0, 1]], np.array([[0.0, 1], [0, 0]]), [[0, 1]],
                     end_tolerance=-1)


def test_segment_hysteresis_at_a_kink():
    # concave kink at (1, 0): master (2,0.1) -> (1,0) -> (0,0.1), outward normal up.
    # A node just right of the bisector belongs to segment 0 by distance; with
    # prefer = segment 1 and xi on segment 1 within [-stick, 1 + stick] it stays.
    xm = np.array([[2.0, 1.0, 0.0], [0.1, 0.0, 0.1]])
    seg_m = np.array([[0, 1], [1, 2]])
    xs = np.array([[1.001], [0.05]])
    e0 = nts.evaluate(xs, np.zeros((0, 2), int), xm, seg_m)
    assert e0.info["segment"][0] == 0
    e1 = nts.evaluate(xs, np.zeros((0, 2), int), xm, seg_m, prefer=np.array([1]))
    assert e1.info["segment"][0] == 1
    n1 = np.array([0.1, 1.0]) / np.hypot(0.1, 1.0)
    assert e1.g[0] == pytest.approx(np.dot(xs[:, 0] - xm[:, 1], n1), abs=1e-15)
    # far outside the hysteresis band the closest segment wins again
    xs2 = np.array([[1.5], [0.2]])
    e2 = nts.evaluate(xs2, np.zeros((0, 2), int), xm, seg_m, prefer=np.array([1]))
    assert e2.info["segment"][0] == 0


def test_fd_at_a_convex_vertex():
    """A node facing a convex master vertex (outside both segments' ranges):
    the gap is taken along the segment whose unclipped xi is nearest to [0, 1]
    (here xi slightly > 1 on segment 0), and G, H stay the exact derivatives of
    that smooth branch. Tolerance as in test_fd_G_and_H."""
    th = np.array([0.0, 0.4, 0.8])
    xm = 2.0 * np.vstack([np.cos(th), np.sin(th)])  # convex, outward away from 0
    seg_m = np.array([[0, 1], [1, 2]])
    v = xm[:, 1]
    xs = (v * 1.05 + np.array([0.004, -0.01]))[:, None]  # outside, near the vertex
    seg_s = np.zeros((0, 2), dtype=int)
    lam = np.array([1.3])
    ev = nts.evaluate(xs, seg_s, xm, seg_m, lam=lam)
    assert ev.info["segment"][0] == 0 and ev.info["xi"][0] > 1.0
    q0 = _pack(xs, xm)
    eps = 1e-6
    G, H = ev.G.toarray(), ev.H.toarray()
    for i in range(len(q0)):
        dq = np.zeros_like(q0)
        dq[i] = eps
        ep = nts.evaluate(*_mix(q0 + dq, 1, seg_s, seg_m), lam=lam)
        em = nts.evaluate(*_mix(q0 - dq, 1, seg_s, seg_m), lam=lam)
        assert ep.info["segment"][0] == em.info["segment"][0] == 0
        np.testing.assert_allclose(G[:, i], (ep.g - em.g) / (2 * eps), atol=1e-7)
        np.testing.assert_allclose(H[:, i], (ep.G.T @ lam - em.G.T @ lam) / (2 * eps), atol=1e-7)
