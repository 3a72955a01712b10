"""The line2 steps of the mortar segmentation and the one kernel's D and M, each against a
hand-computable case.

Steps: 1 nodal normals, 2 projections, 3 segments
(:mod:`skfem_mortar.contact.mortar_segmentation`, first derivatives of every
differentiated step against finite differences; the segment end points' derivatives
through the kernel's G in ``test_mortar.py``), then the one kernel's ``D`` and
``M`` (:func:`skfem_mortar.contact.mortar_kernel.evaluate`) on matching cells.  The
weighted gap against a brute-force reference and its exact derivatives against
finite differences: ``test_mortar.py``.
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact.jets import Jet
from skfem_mortar.contact.mortar_kernel import evaluate
from skfem_mortar.contact.mortar_segmentation import (nodal_normals, project_on_slave, segment,
                                                      slave_element)

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


def test_projections_first_derivatives():
    """Jets of project_on_slave against FD in the 10 coordinates x_a, x_b, n_a, n_b, x_c."""
    z0 = np.array([1.0, 0.05, -1.0, -0.1, 0.3, 1.0, -0.2, 1.0, 0.35, 0.4])
    J = jets(z0)

    def proj(z):
        P = [pair(z[i:i + 2]) for i in range(0, 10, 2)]
        return project_on_slave(slave_element(*P[:4]), P[4])[0][0]
    xi, _ = project_on_slave(slave_element(*J[:4]), J[4])
    np.testing.assert_allclose(xi.g[:, 0], fd_gradient(proj, z0), atol=FD_TOL)


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
    np.testing.assert_allclose(sg.xi_m, [[0.0, -1.0]], atol=1e-15)   # s = 0.5 and 0


# ------------------------------------------- 4. the one kernel's D and M
@pytest.mark.parametrize("dual", [False, True])
def test_D_and_M_one_matching_element(dual):
    """One slave element of length L matching its master element: standard
    D = M = L/6 [[2, 1], [1, 2]] (the 1D mass matrix), dual D = M = diag(L/2, L/2)
    (biorthogonal), supports L/2.  1e-14: sums of a few O(L) products."""
    L = 0.7
    xs = np.array([[L, 0.0], [0.0, 0.0]])              # slave right to left
    xm = np.array([[0.0, L], [0.0, 0.0]])
    r = evaluate(xs, chain(2), xm, chain(2), tangent=False, space="dual" if dual else "standard")
    mass = L / 6 * np.array([[2.0, 1.0], [1.0, 2.0]])
    ref = np.diag(mass.sum(1)) if dual else mass
    np.testing.assert_allclose(r.info["D"].toarray(), ref, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(r.info["M"].toarray()[:, ::-1], ref, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(r.area, [L / 2, L / 2], rtol=1e-14)


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
def test_D_and_M_flat_tilted_matching(dual):
    """Matching flat surfaces tilted by 0.3 rad: standard D = the mass matrix, M the
    same with the master nodes numbered the other way; dual: D diagonal (the
    tributary lengths) and M = D (N_C = N_B on matching meshes); the weighted gap of
    touching surfaces is zero.  1e-14: sums of a few O(h) products."""
    x = np.linspace(0, 1, 5)
    xs, ss, xm, sm, n = rotated_flat(0.3, x, x)
    r = evaluate(xs, ss, xm, sm, tangent=False, space=("dual" if dual else "standard"))
    D, M = r.info["D"].toarray(), r.info["M"].toarray()
    mass = mass_matrix(x)[::-1, ::-1]              # slave nodes right to left
    if dual:
        np.testing.assert_allclose(D, np.diag(mass.sum(1)), atol=1e-14)
    else:
        np.testing.assert_allclose(D, mass, atol=1e-14)
    np.testing.assert_allclose(M[:, ::-1], D, atol=1e-14)  # master node C faces slave node n-1-C
    np.testing.assert_allclose(r.g, 0.0, atol=1e-15)
