"""One test per named step of the mortar kernel, each against a hand-computable case.

Steps (see :mod:`skfem_mortar.contact.mortar`): 1 nodal normals, 2 projections, 3
segment end points, 4 Gauss rule, 5 multiplier functions, 6 n_AB / n_AC / D /
M, 7 the weighted gap by the identity, 8 the exact derivatives (first
derivatives of every differentiated step against finite differences).
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact.jets import Jet
from test_mortar import curved_pair
from skfem_mortar.contact.mortar import (Quadrature, dual_coefficients, evaluate, gauss_rule, integrals,
                                 mortar_integrals, multiplier_coefficients,
                                 multiplier_shape_functions, segment_quadrature, weighted_gap)
from skfem_mortar.contact.mortar_segmentation import (nodal_normals, project_on_master, project_on_slave,
                                              segment, segment_end_points, slave_element)

S2 = np.sqrt(0.5)


def chain(n: int) -> np.ndarray:
    return np.c_[np.arange(n - 1), np.arange(1, n)]


def pair(p):
    """A point or vector (x, y) as a pair of 1-entry arrays."""
    return (np.array([float(p[0])]), np.array([float(p[1])]))


def jets(coords, second=False):
    """The coordinates (x0, y0, x1, y1, ...) as jets of as many variables, in pairs."""
    nv = len(coords)
    J = [Jet.variable(np.array([c]), i, nv, second) for i, c in enumerate(coords)]
    return [(J[i], J[i + 1]) for i in range(0, nv, 2)]


def fd_gradient(f, z, h=1e-6):
    """Central differences of the scalar-valued f at z (one variable at a time)."""
    out = []
    for i in range(len(z)):
        e = np.zeros(len(z))
        e[i] = h
        out.append((f(z + e) - f(z - e)) / (2 * h))
    return np.array(out)


# Tolerance of the finite-difference checks below: h = 1e-6 on O(1) data gives a
# truncation error ~h^2 |f'''| ~ 1e-12 and a round-off error ~eps |f| / h ~ 2e-10,
# so an exact derivative agrees to ~1e-9; a missing chain-rule term shows at O(1e-2..1).
FD_TOL = 1e-8


# ----------------------------------------------------------- 1. nodal normals
def test_nodal_normals_of_a_polyline():
    """Polyline (0,0) -> (1,0) -> (1,1): segment normals (right-hand) (0,-1) and
    (1,0); the corner takes their normalized average (1,-1)/sqrt 2, the ends their
    own segment's normal."""
    xs = np.array([[0.0, 1.0, 1.0], [0.0, 0.0, 1.0]])
    (nx, ny), pnode, nnode = nodal_normals(xs, chain(3), second=False, nv=0)
    np.testing.assert_allclose(np.c_[nx.v, ny.v], [[0, -1], [S2, -S2], [1, 0]], atol=1e-15)
    assert list(pnode) == [0, 0, 1] and list(nnode) == [1, 2, 2]


def test_nodal_normals_first_derivatives():
    """The corner's normal jet (variables x_p, y_p, x_k, y_k, x_n, y_n) against FD."""
    xs = np.array([[0.0, 1.0, 1.3], [0.0, 0.1, 1.0]])
    (nx, ny), _, _ = nodal_normals(xs, chain(3), second=False, nv=6)

    def corner(z, c):
        x = z.reshape(3, 2).T
        (mx, my), _, _ = nodal_normals(x, chain(3), second=False, nv=0)
        return (mx.v, my.v)[c][1]
    z = xs.T.ravel()
    for c, n in enumerate((nx, ny)):
        np.testing.assert_allclose(n.g[:, 1], fd_gradient(lambda q: corner(q, c), z), atol=FD_TOL)


# ------------------------------------------------------------- 2. projections
def curved_element():
    """x_s(xi) = (-xi, 0) and, with n_a = (1, 1), n_b = (-1, 1), n~(xi) = (-xi, 1)."""
    return slave_element(pair((1, 0)), pair((-1, 0)), pair((1, 1)), pair((-1, 1)))


def test_project_master_node_on_slave():
    """The ray x_s(xi) + t n~(xi) = (-xi (1 + t), t) passes through (x_c, y_c) at
    t = y_c, xi = -x_c / (1 + y_c): (0.6, 0.5) -> xi = -0.4."""
    xi, ok = project_on_slave(curved_element(), pair((0.6, 0.5)))
    assert ok.all()
    np.testing.assert_allclose(xi, [-0.4], atol=1e-15)


def test_project_slave_points_on_master():
    """Master line y = 0.2 + 0.2 s from (-1, 0.2) to (1, 0.4) (x = -1 + 2 s).
    Flat slave (n~ = (0, 1)): the point (-xi, 0) meets it at s = (1 - xi)/2 with
    alpha = 0.2 + 0.2 s.  Curved slave (n~ = (-xi, 1)) against the horizontal
    master y = 0.3: alpha = 0.3 (n~_y = 1), x = -xi (1 + 0.3) = -1 + 2 s."""
    xi = np.array([[-0.5, 0.25]])
    flat = slave_element(pair((1, 0)), pair((-1, 0)), pair((0, 1)), pair((0, 1)))
    pr = project_on_master(flat, pair((-1, 0.2)), pair((1, 0.4)))
    s = (1 - xi) / 2
    np.testing.assert_allclose(pr.s(xi), s, atol=1e-15)
    np.testing.assert_allclose(pr.alpha(xi), 0.2 + 0.2 * s, atol=1e-15)
    pr = project_on_master(curved_element(), pair((-1, 0.3)), pair((1, 0.3)))
    np.testing.assert_allclose(pr.alpha(xi), 0.3, atol=1e-15)
    np.testing.assert_allclose(pr.s(xi), (1 - 1.3 * xi) / 2, atol=1e-15)


def test_projections_first_derivatives():
    """Jets of project_on_slave and of alpha (project_on_master) against FD in the
    10 coordinates x_a, x_b, n_a, n_b, x_c (or x_m1 for alpha at xi = 0.3)."""
    z0 = np.array([1.0, 0.05, -1.0, -0.1, 0.3, 1.0, -0.2, 1.0, 0.35, 0.4])
    J = jets(z0)

    def proj(z):
        P = [pair(z[i:i + 2]) for i in range(0, 10, 2)]
        return project_on_slave(slave_element(*P[:4]), P[4])[0][0]

    def alpha(z):
        P = [pair(z[i:i + 2]) for i in range(0, 10, 2)]
        return project_on_master(slave_element(*P[:4]), P[4], pair((1.2, 0.6))).alpha(
            np.array([[0.3]]))[0, 0]
    xi, _ = project_on_slave(slave_element(*J[:4]), J[4])
    np.testing.assert_allclose(xi.g[:, 0], fd_gradient(proj, z0), atol=FD_TOL)
    al = project_on_master(slave_element(*J[:4]), J[4], pair((1.2, 0.6))).alpha(
        Jet.constant(np.array([[0.3]]), 10, False))
    np.testing.assert_allclose(al.g[:, 0, 0], fd_gradient(alpha, z0), atol=FD_TOL)


def test_projection_exact_second_derivatives():
    """The Hessian of the projected xi (Newton step + implicit-function term)
    against FD of its exact gradient."""
    z0 = np.array([1.0, 0.05, -1.0, -0.1, 0.3, 1.0, -0.2, 1.0, 0.35, 0.4])
    xi, _ = project_on_slave(slave_element(*jets(z0, True)[:4]), jets(z0, True)[4])

    def grad(z, i):
        J = jets(z)
        return project_on_slave(slave_element(*J[:4]), J[4])[0].g[i, 0]
    H = xi.hessian()[:, :, 0]
    for i in range(10):
        np.testing.assert_allclose(H[i], fd_gradient(lambda q: grad(q, i), z0), atol=FD_TOL)


# ----------------------------------------------------------- 3. segmentation
def overlapping_pair():
    """Slave element from x = 1 (node a) to x = 0 (node b) at y = 0, so
    x_s(xi) = (1 - xi)/2; master element from x = 0.4 to x = 1.6 at y = 0.1."""
    xs = np.array([[1.0, 0.0], [0.0, 0.0]])
    xm = np.array([[0.4, 1.6], [0.1, 0.1]])
    return xs, chain(2), xm, chain(2)


def test_segment_of_two_overlapping_elements():
    """Common part x in [0.4, 1]: m1 (x = 0.4) projects to xi = 0.2, m2 lies beyond
    the slave node a: xi_a = -1 (src -1, the slave node), xi_b = 0.2 (src 0, m1);
    the eta map sends eta = -1, 1 to these, where the master parameters are
    s = (1 - 0.4)/1.2 = 0.5 and s = 0."""
    xs, ss, xm, sm = overlapping_pair()
    sg = segment(xs, ss, xm, sm)
    assert sg.n == 1
    np.testing.assert_allclose(sg.xi, [[-1.0, 0.2]], atol=1e-15)
    assert sg.src.tolist() == [[-1, 0]]
    np.testing.assert_allclose(sg.elem_xi, [[-1.0, 0.2]], atol=1e-15)
    n = pair((0, 1))
    el = slave_element(pair(xs[:, 0]), pair(xs[:, 1]), n, n)
    lo, hi = segment_end_points(el, pair(xm[:, 0]), pair(xm[:, 1]), sg.src)
    np.testing.assert_allclose([lo[0], hi[0]], [-1.0, 0.2], atol=1e-15)
    q = segment_quadrature(el, lo, hi, np.array([-1.0, 1.0]), np.ones(2))
    np.testing.assert_allclose(q.xi, [[-1.0, 0.2]], atol=1e-15)
    pr = project_on_master(el, pair(xm[:, 0]), pair(xm[:, 1]))
    np.testing.assert_allclose(pr.s(q.xi), [[0.5, 0.0]], atol=1e-15)


def test_segment_end_points_first_derivatives():
    """xi_b = projection of m1 moves with the coordinates; xi_a = -1 is constant."""
    xs, ss, xm, sm = overlapping_pair()
    sg = segment(xs, ss, xm, sm)
    z0 = np.array([1.0, 0.0, 0.0, 0.02, 0.4, 0.1, 1.6, 0.12])
    n = pair((0.05, 1.0))

    def hi(z):
        P = [pair(z[i:i + 2]) for i in range(0, 8, 2)]
        return segment_end_points(slave_element(P[0], P[1], n, n), P[2], P[3], sg.src)[1][0]
    J = jets(z0)
    c = lambda v: Jet.constant(np.array(v), 8, False)  # noqa: E731
    lo, hi_j = segment_end_points(slave_element(J[0], J[1], (c([0.05]), c([1.0])),
                                                (c([0.05]), c([1.0]))), J[2], J[3], sg.src)
    assert np.all(lo.g == 0.0)
    np.testing.assert_allclose(hi_j.g[:, 0], fd_gradient(hi, z0), atol=FD_TOL)


# ------------------------------------------------------------- 4. Gauss rule
@pytest.mark.parametrize("n_gauss", [1, 2, 3, 4])
def test_gauss_rule_integrates_polynomials_exactly(n_gauss):
    """Degree 2n - 1: int_{-1}^{1} eta^k = 2/(k+1) for even k, 0 for odd k; and on a
    mortar segment [lo, hi] of an element of length 2 |dx| the rule gives
    |dx| int_lo^hi p(xi) dxi (here p = xi^(2n-1) + 1)."""
    eta, w = gauss_rule(n_gauss)
    for k in range(2 * n_gauss):
        np.testing.assert_allclose(w @ eta**k, 2.0 / (k + 1) if k % 2 == 0 else 0.0, atol=1e-14)
    el = slave_element(pair((1, 0)), pair((-2, 0.4)), pair((0, 1)), pair((0, 1)))
    lo, hi = np.array([-0.7]), np.array([0.4])
    q = segment_quadrature(el, lo, hi, eta, w)
    assert isinstance(q, Quadrature)
    d = 2 * n_gauss - 1
    exact = np.hypot(3.0, 0.4) / 2 * ((hi**(d + 1) - lo**(d + 1)) / (d + 1) + hi - lo)
    np.testing.assert_allclose((q.weights() * (q.xi**d + 1)).sum(1), exact, rtol=1e-14)


# --------------------------------------------------- 5. multiplier functions
def test_multiplier_functions_standard_dual_and_merged():
    """Standard: Phi_A = N_A.  Dual on the projectable part [l, h]: int_l^h Phi_A N_B
    = delta_AB int_l^h N_A (biorthogonal), on the full element A_e = [[2, -1], [-1, 2]].
    A merged node a: Phi_a = 0 and Phi_b = 1."""
    xi = np.linspace(-1, 1, 5)
    K = multiplier_shape_functions(multiplier_coefficients(np.zeros(1)))
    np.testing.assert_allclose(K[0] + K[1] * xi, (1 - xi) / 2, atol=1e-15)
    np.testing.assert_allclose(K[2] + K[3] * xi, (1 + xi) / 2, atol=1e-15)
    full = multiplier_coefficients(np.zeros(1), True, (np.array([-1.0]), np.array([1.0])))
    np.testing.assert_allclose(np.ravel(full), [2, -1, -1, 2], atol=1e-14)
    lo, hi = np.array([-0.3]), np.array([0.55])
    K = multiplier_shape_functions(multiplier_coefficients(lo, True, (lo, hi)))
    t, w = gauss_rule(3)                    # products of two linear functions: exact
    x = (lo + hi) / 2 + (hi - lo) / 2 * t
    w = w * (hi - lo) / 2
    N = [(1 - x) / 2, (1 + x) / 2]
    Phi = [K[0] + K[1] * x, K[2] + K[3] * x]
    B = np.array([[w @ (P * Nb) for Nb in N] for P in Phi])
    np.testing.assert_allclose(B, np.diag([w @ N[0], w @ N[1]]), atol=1e-14)
    c = multiplier_coefficients(np.zeros(1), True, (lo, hi), (np.array([True]), np.array([False])))
    np.testing.assert_allclose(np.ravel(c), [0, 0, 1, 1], atol=0)
    np.testing.assert_allclose(np.ravel(dual_coefficients(lo, hi)),
                               np.ravel(multiplier_coefficients(lo, True, (lo, hi))), atol=0)


# ------------------------------------------------------ 6. mortar integrals
def test_mortar_integrals_one_matching_element():
    """One slave element of length L matching its master element, n = e_y:
    D = M = L/6 [[2, 1], [1, 2]] (the 1D mass matrix), n_AB = D n, n_AC = M n."""
    L = 0.7
    eta, w = gauss_rule(2)
    xi = eta[None, :]
    K = multiplier_shape_functions(multiplier_coefficients(np.zeros(1)))
    dg = L / 2 * w[None, :]
    s = (1 + xi) / 2                               # master runs the same way
    r = mortar_integrals(K, xi, s, dg, (np.zeros_like(xi), np.ones_like(xi)))
    mass = L / 6 * np.array([[2.0, 1.0], [1.0, 2.0]])
    np.testing.assert_allclose(r.D[0], mass, rtol=1e-14)
    np.testing.assert_allclose(r.M[0], mass, rtol=1e-14)
    np.testing.assert_allclose(r.n_AB[0], np.stack([0 * mass, mass], -1), rtol=1e-14, atol=0)
    np.testing.assert_allclose(r.n_AC[0], np.stack([0 * mass, mass], -1), rtol=1e-14, atol=0)
    np.testing.assert_allclose(r.area[0], [L / 2, L / 2], rtol=1e-14)


def rotated_flat(theta, xs_x, xm_x, d=0.0):
    """Flat slave and master (as in test_mortar: slave nodes right to left), rotated by theta."""
    xs = np.vstack([np.asarray(xs_x, float)[::-1], np.zeros(len(xs_x))])
    xm = np.vstack([np.asarray(xm_x, float), np.full(len(xm_x), d)])
    R = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    return R @ xs, chain(len(xs_x)), R @ xm, chain(len(xm_x)), R @ [0.0, 1.0]


def mass_matrix(x):
    """The 1D mass matrix int N_A N_B of the hat functions on the nodes x."""
    Mm = np.zeros((x.size, x.size))
    for e in range(x.size - 1):
        h = abs(x[e + 1] - x[e])
        Mm[np.ix_([e, e + 1], [e, e + 1])] += h / 6 * np.array([[2, 1], [1, 2]])
    return Mm


@pytest.mark.parametrize("dual", [False, True])
def test_n_AB_and_n_AC_flat_tilted_matching(dual):
    """Matching flat surfaces tilted by 0.3 rad (n = R e_y constant): n_AB = D n and
    n_AC = M n; standard: D = the mass matrix, M = the same with the master nodes
    numbered the other way; dual: D diagonal (the tributary lengths) and M = D
    (N_C = N_B on matching meshes).  1e-14: sums of a few O(h) products."""
    x = np.linspace(0, 1, 5)
    xs, ss, xm, sm, n = rotated_flat(0.3, x, x)
    r = integrals(xs, ss, xm, sm, space=("dual" if dual else "standard"))
    D, M = r.D.toarray(), r.M.toarray()
    nAB, nAC = r.n_AB.toarray(), r.n_AC.toarray()
    for i in (0, 1):
        np.testing.assert_allclose(nAB[:, i::2], D * n[i], atol=1e-14)
        np.testing.assert_allclose(nAC[:, i::2], M * n[i], atol=1e-14)
    mass = mass_matrix(x)[::-1, ::-1]              # slave nodes right to left
    if dual:
        np.testing.assert_allclose(D, np.diag(mass.sum(1)), atol=1e-14)
    else:
        np.testing.assert_allclose(D, mass, atol=1e-14)
    np.testing.assert_allclose(M[:, ::-1], D, atol=1e-14)  # master node C faces slave node n-1-C


# -------------------------------------------------------- 7. weighted gap
def test_weighted_gap_identity_by_hand():
    """g_A = -sum_B n_AB . x_B + sum_C n_AC . x_C for one matching element at the
    gap d along n = e_y: -D y_s + M y_m = d * (row sums of the mass matrix) = d L/2."""
    L, d = 0.7, 0.03
    mass = L / 6 * np.array([[2.0, 1.0], [1.0, 2.0]])
    nAB = np.stack([0 * mass, mass], -1)[None]
    xB = np.array([[[0.0, 0.0], [L, 0.0]]])
    xC = np.array([[[0.0, d], [L, d]]])
    np.testing.assert_allclose(weighted_gap(nAB, nAB, xB, xC), [[d * L / 2, d * L / 2]], rtol=1e-14)


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("n_gauss", [2, 4])
def test_weighted_gap_identity_equals_direct_integral(dual, n_gauss):
    """Curved, partly overlapping surfaces: the gap assembled from n_AB, n_AC (global
    sparse, and per segment in integrals().g) equals evaluate's direct integral
    int Phi_A (x_m - x_s) . n dGamma.  They differ by the round-off of the identity's
    cancellation, eps times |x| (~1) times the supports (~0.2): atol 1e-15."""
    xs, ss, xm, sm = curved_pair(0.05)
    r = integrals(xs, ss, xm, sm, space=("dual" if dual else "standard"), n_gauss=n_gauss)
    direct = evaluate(xs, ss, xm, sm, space=("dual" if dual else "standard"), n_gauss=n_gauss, tangent=False)
    assert np.abs(direct.g).max() > 1e-3
    np.testing.assert_allclose(r.g, direct.g, atol=1e-15)
    g_sparse = -r.n_AB @ xs.T.ravel() + r.n_AC @ xm.T.ravel()
    np.testing.assert_allclose(g_sparse, direct.g, atol=1e-15)
    np.testing.assert_allclose(r.D.toarray(), direct.info["D"].toarray(), atol=0)
    np.testing.assert_array_equal(r.mask, direct.mask)


# --------------------------------------------------- 8. exact derivatives
@pytest.mark.parametrize("dual", [False, True])
def test_G_is_the_derivative_of_the_identity_gap(dual):
    """G (evaluate, from the jets of step 8) against central differences of the
    gap assembled by the identity (steps 1-7, integrals().g), all coordinates."""
    xs, ss, xm, sm = curved_pair(0.05, seed=1)
    n_s = xs.shape[1]
    G = evaluate(xs, ss, xm, sm, space=("dual" if dual else "standard")).G.toarray()
    z = np.concatenate([xs.T.ravel(), xm.T.ravel()])

    def g(q):
        return integrals(q[:2 * n_s].reshape(-1, 2).T, ss, q[2 * n_s:].reshape(-1, 2).T, sm,
                         space=("dual" if dual else "standard")).g
    Gfd = fd_gradient(g, z).T
    np.testing.assert_allclose(G, Gfd, atol=FD_TOL * np.abs(G).max())
