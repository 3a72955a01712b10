"""The one mortar kernel on curved 3-node segments (contact/mortar_kernel.py).

Exact derivatives against central differences on curved, partly overlapping,
sliding configurations (3-node on 3-node, 3-node on 2-node, 2-node on 3-node;
standard and dual; at a crosspoint), the dual basis's biorthogonality, the
patch and consistency cases with exact answers, the cross-checks against the
linear kernel, and the dispatch of :class:`~skfem_mortar.contact.mortar_method.Mortar`.
"""
from __future__ import annotations

import types

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.line_points import LineSegmentation
from skfem_mortar.contact.mortar_method import Mortar
from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.mortar_support import N_GAUSS_ELEMENT, merge_matrix, tributary_weights
from skfem_mortar.contact.mortar_quadratic_segmentation import (
    element_polynomial, nodal_normals, project_on_master, project_on_slave, shape_values)

# Central differences with h = 1e-6 on unit-size data: truncation ~h^2 |g'''| ~ 1e-12,
# round-off ~eps |g| / h ~ 1e-12 for G (|g| ~ 1e-2) and ~eps |G| / h ~ 1e-10 for H
# (|G| ~ 1e-1); a missing chain-rule term shows at the size of the entries (1e-2 .. 1).
LINE3 = cell_type("line3")
H_FD = 1e-6
TOL_G = 1e-9
TOL_H = 1e-7


def chain(n: int, f, x0: float, x1: float, k: int = 3, jitter: float = 0.0, seed: int = 0):
    """``n`` segments with vertices on ``y = f(x)`` from ``x0`` to ``x1``; for ``k = 3``
    mid nodes on the curve too, moved along it by up to ``jitter`` of the segment."""
    rng = np.random.default_rng(seed)
    xv = np.linspace(x0, x1, n + 1)
    X, Y, seg = list(xv), list(f(xv)), []
    for i in range(n):
        if k == 3:
            xm = 0.5 * (xv[i] + xv[i + 1]) + jitter * (xv[i + 1] - xv[i]) * rng.uniform(-1, 1)
            X.append(xm)
            Y.append(f(xm))
            seg.append([i, i + 1, n + 1 + i])
        else:
            seg.append([i, i + 1])
    return np.array([X, Y], float), np.array(seg)


def disk(x):
    """Bottom of a unit disk lifted by 0.02 (the slave, outward normal down)."""
    return 1.02 - np.sqrt(1.0 - x * x)


def base(x):
    """A curved base (the master, outward normal up), penetrated in the middle."""
    return 0.05 * x * x - 0.01 * x + 0.005


def configuration(ks: int, km: int, x_right: float, shift: float = 0.0):
    """Slave on the disk from -0.3 to 0.3 (4 segments); master from x_right to
    -0.41 + shift (3 segments, right to left so its normal points up)."""
    xs, ss = chain(4, disk, -0.3, 0.3, ks, 0.1, seed=1)
    xm, sm = chain(3, base, x_right + shift, -0.41 + shift, km, 0.1, seed=2)
    return xs, ss, xm, sm


def fd_errors(xs, ss, xm, sm, **kw):
    """Largest |G - G_fd|, |H - H_fd| (H_fd from G^T lam) and the evaluation."""
    n_s = xs.shape[1]
    lam = np.linspace(0.5, 1.5, n_s)
    z = np.concatenate([xs.T.ravel(), xm.T.ravel()])

    def ev(q, tangent=False, lam=None):
        return mortar_kernel.evaluate(q[:2 * n_s].reshape(-1, 2).T, ss, q[2 * n_s:].reshape(-1, 2).T, sm,
                           lam=lam, tangent=tangent, **kw)
    return fd_check(ev, z, lam)


def fd_check(ev, z: np.ndarray, lam: np.ndarray, skip=()):
    """Largest |G - G_fd|, |H - H_fd| of ``ev(q, tangent, lam)`` at ``z`` and the
    evaluation there (the variables ``skip`` not varied)."""
    e0 = ev(z, True, lam)
    G, H = e0.G.toarray(), e0.H.toarray()
    eg = eh = 0.0
    for i in np.setdiff1d(np.arange(z.size), skip):
        d = np.zeros(z.size)
        d[i] = H_FD
        gfd = (ev(z + d).g - ev(z - d).g) / (2 * H_FD)
        hfd = (ev(z + d, True).G.T @ lam - ev(z - d, True).G.T @ lam) / (2 * H_FD)
        eg = max(eg, np.abs(G[:, i] - gfd).max())
        eh = max(eh, np.abs(H[:, i] - hfd).max())
    return eg, eh, e0


@pytest.mark.parametrize("ks,km", [(3, 3), (3, 2), (2, 3)])
@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("x_right,shift", [(0.37, 0.0), (0.17, 0.0), (0.17, 0.13)])
def test_exact_derivatives(ks, km, dual, x_right, shift):
    """G and H against central differences: fully covered (0.37), partly covered
    slave end (0.17: the last slave element is bounded by a master vertex, its far
    vertex masked), and slid by 0.13 (master vertices inside other slave elements)."""
    xs, ss, xm, sm = configuration(ks, km, x_right, shift)
    eg, eh, ev = fd_errors(xs, ss, xm, sm, space=("dual" if dual else "standard"))
    assert ev.mask.sum() >= 4 and ev.info["n_segments"] >= 6
    if x_right < 0.3 and ks == 3:   # the partial case really has a partly projectable element
        sg = ev.info["segmentation"]
        assert (sg.elem_node >= 0).any()
    assert eg < TOL_G and eh < TOL_H


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("crosspoints", [[0], [0, 5]])
def test_exact_derivatives_at_a_crosspoint(dual, crosspoints):
    """The surface end 0 pinned (its function handed to the mid node 5), and both
    the end and that mid node pinned (handed to the other vertex)."""
    xs, ss, xm, sm = configuration(3, 3, 0.37)
    eg, eh, ev = fd_errors(xs, ss, xm, sm, space=("dual" if dual else "standard"), crosspoints=crosspoints)
    assert not ev.mask[crosspoints].any()
    assert eg < TOL_G and eh < TOL_H


# ------------------------------------------------------------ multiplier functions
def test_merge_matrix_keeps_a_partition_of_unity():
    """Every pattern of merged nodes of a 3-node element: merged rows are zero and
    the columns sum to one (unless all are merged)."""
    for bits in range(8):
        merged = np.array([[(bits >> j) & 1 for j in range(3)]], bool)
        T = merge_matrix(merged, LINE3)[0]
        assert np.all(T[merged[0]] == 0)
        if not merged.all():
            np.testing.assert_array_equal(T.sum(axis=0), np.ones(3))
    T = merge_matrix(np.array([[True, False, False]]), LINE3)[0]
    assert T[2, 0] == 1.0      # a merged vertex goes to the mid node


def _element(curved: bool) -> np.ndarray:
    """One slave element (start, end, mid) from the axis ``x = 0``; straight: the mid node at
    the midpoint (constant Jacobian); curved: moved along and lifted off the chord."""
    return np.array([[0.0, 1.0, 0.55 if curved else 0.5], [0.0, 0.1, 0.2 if curved else 0.05]])


def dual_moments(curved: bool, master: tuple, crosspoints=None, measure=None, n: int = 40):
    """The one kernel's dual basis on one slave element (:func:`_element`) under a flat
    master from ``x = master[0]`` to ``master[1]`` at ``y = -0.5``, with the element rule
    (``n_gauss = N_GAUSS_ELEMENT``: the gap's and the mass integrals' rule are one).
    Returns ``m = D T^T`` (``int Phi_A N~_B w dGamma``, ``N~ = T N`` with ``T`` the merge of
    the masked and crosspoint nodes), ``int N~_A w dGamma`` and ``int N_B w dGamma`` over the
    projectable part by an ``n``-point rule (``w = 2 pi x`` for an axisymmetric ``measure``),
    ``D`` and ``T``."""
    xs, xm = _element(curved), np.array([[master[0], master[1]], [-0.5, -0.5]])
    kw = {} if measure is None else {"measure": measure}
    ev = mortar_kernel.evaluate(xs, [[0, 1, 2]], xm, [[0, 1]], tangent=False, space="dual",
                                n_gauss=N_GAUSS_ELEMENT, crosspoints=crosspoints, **kw)
    (lo, hi), = ev.info["segmentation"].xi
    merged = ~ev.mask
    if crosspoints is not None:
        merged[crosspoints] = True
    T = merge_matrix(merged[None, :], LINE3)[0]
    D = ev.info["D"].toarray()
    P = element_polynomial([(xs[0, a:a + 1], xs[1, a:a + 1]) for a in range(3)], LINE3)
    eta, w = np.polynomial.legendre.leggauss(n)
    xi = (lo + hi) / 2 + (hi - lo) / 2 * eta
    dG = np.hypot(P[1][0] + 2 * P[2][0] * xi, P[1][1] + 2 * P[2][1] * xi) * (hi - lo) / 2 * w
    if measure is not None:
        dG = dG * 2 * np.pi * (P[0][0] + P[1][0] * xi + P[2][0] * xi ** 2)
    N = np.array(shape_values(LINE3, xi[None, :]))[:, 0]
    return D @ T.T, (T @ N * dG).sum(1), (N * dG).sum(1), D, T


@pytest.mark.parametrize("curved", [False, True])
@pytest.mark.parametrize("master, crosspoints", [((1.5, -0.5), None), ((1.5, 0.6), None),
                                                 ((0.5, -0.5), None), ((1.5, -0.5), [0])])
def test_dual_biorthogonality(curved, master, crosspoints):
    """int Phi_A N~_B dGamma = delta_AB int N~_A dGamma on the projectable part (whole,
    from the right, from the left; with the start vertex a crosspoint), ``N~ = T N``.

    With the kernel's element rule for both integrals the identity is exact for that rule
    (off the diagonal: round-off, 1e-14 of D).  Measured with a 40-point rule it holds to
    the 5-point rule's error on sqrt(|x'|^2) (straight: exact, 1e-14; the curved element
    bends by 0.3 of its length: ~1e-6 of int N_A, below 1e-5).  The functions sum to one
    (``sum_A Phi_A = 1``, the columns of D are ``int N_B dGamma``) and a merged node's is zero."""
    m, d, dN, D, T = dual_moments(curved, master, crosspoints)
    off = m - np.diag(np.diag(m))
    assert np.abs(off).max() <= 1e-14 * np.abs(m).max()
    tol = (1e-5 if curved else 1e-14) * d.max()
    np.testing.assert_allclose(m, np.diag(d), atol=tol)
    np.testing.assert_allclose(D.sum(0), dN, atol=tol)
    dead = ~T.any(axis=1)
    assert np.all(D[dead] == 0.0) and np.all(d[~dead] > 0)
    if crosspoints is not None:
        assert dead[0] and not dead[1:].any()


# ------------------------------------------------------------ exact answers
def _flat(xv, y, k=3):
    return chain(len(xv) - 1, lambda x: y + 0.0 * x, xv[0], xv[-1], k)


def test_tributary_weights_of_a_straight_segment():
    """L/6, L/6, 2L/3 for start, end, mid (summed where elements meet)."""
    xs, ss = _flat([1.0, 0.0], 0.0)
    np.testing.assert_allclose(tributary_weights(xs, ss, LINE3, 9), [1 / 6, 1 / 6, 2 / 3], rtol=1e-14)


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("km", [3, 2])
def test_patch_uniform_gap(dual, km):
    """Flat non-matching surfaces (5 slave segments on 4 master ones, the master
    wider), uniform gap g0: g_A = g0 area_A to round-off, standard and dual, and
    sum_A g_A = g0 L."""
    g0 = 0.013
    xs, ss = chain(5, lambda x: 0.0 * x, 1.0, 0.0)
    xm, sm = chain(4, lambda x: g0 + 0.0 * x, -0.1, 1.13, km)
    ev = mortar_kernel.evaluate(xs, ss, xm, sm, tangent=False, space=("dual" if dual else "standard"))
    assert ev.mask.all()
    np.testing.assert_allclose(ev.g, g0 * ev.area, rtol=1e-12)
    np.testing.assert_allclose(ev.area, tributary_weights(xs, ss, LINE3, 9), rtol=1e-12)
    np.testing.assert_allclose(ev.g.sum(), g0 * 1.0, rtol=1e-12)


@pytest.mark.parametrize("dual", [False, True])
def test_linear_gap_field(dual):
    """A tilted flat master over a flat slave: the gap g(x) = g0 + s x is linear, so
    g_A = int Phi_A g dGamma exactly; standard: int N_A (g0 + s x) by hand
    (per element of length L from x_a to x_b: ends L/6 g(x_end), mid L/6 (g(x_a) + g(x_b))... ),
    dual: by biorthogonality g_A = int N_A g as well when g is in the span."""
    g0, s = 0.01, 0.02
    xs, ss = chain(3, lambda x: 0.0 * x, 1.0, 0.0)
    xm, sm = chain(4, lambda x: g0 + s * x, -0.2, 1.2)   # left to right: normal down
    ev = mortar_kernel.evaluate(xs, ss, xm, sm, tangent=False, space=("dual" if dual else "standard"), n_gauss=3)
    exact = np.zeros(xs.shape[1])
    eta, w = np.polynomial.legendre.leggauss(6)
    for e in ss:
        xa, xb = xs[0, e[0]], xs[0, e[1]]
        x = (xa + xb) / 2 + (xb - xa) / 2 * eta
        N = np.array(shape_values(LINE3, eta))
        exact[e] += N @ ((g0 + s * x) * abs(xb - xa) / 2 * w)
    np.testing.assert_allclose(ev.g, exact, rtol=1e-12, atol=1e-16)


@pytest.mark.parametrize("lift,shift", [(0.05, 0.0), (0.0, 0.02)])
def test_each_slave_cell_covered_once(lift, shift):
    """The slave on the disk from 0 to 0.3 (shifted by ``shift``) under a wider curved
    master (lowered by ``lift``): where the slave start projected onto a master
    cell's quadratic extension has no root, the side of a far master vertex comes
    from the slave chord (_chord_side); before, a spurious root put it on the wrong
    side and one slave cell was integrated twice (measured: sum D = 0.381 for a
    slave of length 0.305).  ``sum D`` = the slave's length (all covered), to the
    3-point rule on the curved Jacobian (1e-6)."""
    xs, ss = chain(4, disk, 0.0, 0.3, 3, 0.1, seed=3)
    xs = xs + [[shift], [0.0]]
    xm, sm = chain(3, base, 0.5 if lift else 0.37, -0.05, 3, 0.1, seed=4)
    xm[1] -= lift
    ev = mortar_kernel.evaluate(xs, ss, xm, sm, tangent=False)
    eta, w = np.polynomial.legendre.leggauss(20)
    length = 0.0
    for e in ss:
        P = element_polynomial([(xs[0, a:a + 1], xs[1, a:a + 1]) for a in e], LINE3)
        length += (np.hypot(P[1][0] + 2 * P[2][0] * eta, P[1][1] + 2 * P[2][1] * eta) * w).sum()
    assert ev.mask.all()
    np.testing.assert_allclose(ev.info["D"].sum(), length, rtol=1e-6)


def test_overlap_length():
    """Partial overlap of straight segments: sum_A g_A = g0 times the overlap (0.55)."""
    g0 = 0.02
    xs, ss = chain(4, lambda x: 0.0 * x, 1.0, 0.0)
    xm, sm = chain(3, lambda x: g0 + 0.0 * x, 0.25, 0.8)
    for dual in (False, True):
        ev = mortar_kernel.evaluate(xs, ss, xm, sm, tangent=False, space=("dual" if dual else "standard"))
        np.testing.assert_allclose(ev.g.sum(), g0 * 0.55, rtol=1e-12)


# ------------------------------------------------------------ cross-checks, linear kernel
@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("crosspoints", [None, [0]])
def test_two_node_surfaces_equal_the_linear_kernel(dual, crosspoints):
    """On 2-node segments (curved polylines, partly covered) the closed forms of affine
    cells equal the general path (Newton in the cells' coordinates,
    ``LineSegmentation(fast=False)``): g, G, H, area, mask, D, M to round-off: 1e-14 of
    the sizes standard; dual 1e-12 (the round-off amplified by the conditioning of
    M_e on the partly projectable element, ~1e2 here)."""
    xs, ss, xm, sm = configuration(2, 2, 0.17)
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    a = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space=("dual" if dual else "standard"), n_gauss=2, crosspoints=crosspoints)
    line2 = (cell_type("line2"),) * 2
    b = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space=("dual" if dual else "standard"),
                               crosspoints=crosspoints, cells=line2,
                               points=LineSegmentation(line2, 2, fast=False, frozen=False))
    assert (a.mask == b.mask).all()
    rel = 1e-12 if dual else 1e-14
    for u, v in ((a.g, b.g), (a.G, b.G), (a.H, b.H), (a.area, b.area),
                 (a.info["D"], b.info["D"]), (a.info["M"], b.info["M"])):
        assert abs(u - v).max() <= rel * abs(v).max()


def _to_three_node(x, seg):
    """2-node segments as 3-node ones with the mid nodes at the midpoints."""
    mids = 0.5 * (x[:, seg[:, 0]] + x[:, seg[:, 1]])
    n = x.shape[1]
    return np.hstack([x, mids]), np.c_[seg, n + np.arange(len(seg))]


@pytest.mark.parametrize("dual", [False, True])
def test_converted_surfaces_give_the_linear_totals(dual):
    """A flat slave on a kinked master (2-node), both converted to 3-node segments:
    the weighted gaps summed over each slave element's nodes (int g_n dGamma, as
    the functions sum to one) equal the linear kernel's to round-off."""
    xs, ss = chain(4, lambda x: 0.0 * x, 1.0, 0.0, 2)
    xm, sm = chain(3, lambda x: 0.01 + 0.03 * np.abs(x - 0.4), -0.05, 1.1, 2)
    lin = mortar_kernel.evaluate(xs, ss, xm, sm, tangent=False, space=("dual" if dual else "standard"))
    assert lin.mask.all() and lin.g.sum() > 0.01
    xs3, ss3 = _to_three_node(xs, ss)
    xm3, sm3 = _to_three_node(xm, sm)
    quad = mortar_kernel.evaluate(xs3, ss3, xm3, sm3, tangent=False, space=("dual" if dual else "standard"))
    np.testing.assert_allclose(quad.g.sum(), lin.g.sum(), rtol=1e-12)
    # per element: each slave element alone (the slave is flat, so its nodal
    # normals do not depend on the neighbours): its nodes' g_A sum to int_e g_n
    for e in range(len(ss)):
        one = mortar_kernel.evaluate(xs3[:, ss3[e]], [[0, 1, 2]], xm3, sm3, tangent=False, space=("dual" if dual else "standard"))
        ref = mortar_kernel.evaluate(xs[:, ss[e]], [[0, 1]], xm, sm, tangent=False, space=("dual" if dual else "standard"))
        np.testing.assert_allclose(one.g.sum(), ref.g.sum(), rtol=1e-12)


# ------------------------------------------------------------ geometry helpers
def test_nodal_normals_of_an_arc():
    """On a circular arc with its mid nodes on the circle the nodal normals are the
    radial directions up to the O(h^2) error of the parabola's end tangents."""
    xs, ss = chain(6, disk, -0.4, 0.4, 3)
    n = nodal_normals(xs, ss)
    radial = (xs - np.array([[0.0], [1.02]]))
    radial /= np.hypot(*radial)
    np.testing.assert_allclose(n, radial, atol=2e-3)   # (h/R)^2 / 8 ~ 2e-3 for h = 0.13


def test_projections_are_roots():
    """A master vertex projected onto a curved slave element along n~ (residual
    zero), and a point projected onto a curved master element."""
    x = _element(True)
    P = element_polynomial([(x[0, a:a + 1], x[1, a:a + 1]) for a in range(3)], LINE3)
    Q = element_polynomial([(np.array([0.1]), np.array([-1.0])), (np.array([0.0]), np.array([-1.0])),
                            (np.array([0.05]), np.array([-1.0]))], LINE3)
    xi, ok = project_on_slave(P, Q, (np.array([0.4]), np.array([-0.3])))
    assert ok.all() and -1 < xi[0] < 1
    R = element_polynomial([(np.array([1.0]), np.array([-0.3])), (np.array([0.0]), np.array([-0.35])),
                            (np.array([0.5]), np.array([-0.25]))], LINE3)
    eta, ok = project_on_master(R, (np.array([0.4]), np.array([0.2])), (np.array([0.0]), np.array([-1.0])))
    mx = R[0][0] + R[1][0] * eta + R[2][0] * eta ** 2
    assert ok.all() and abs(mx[0] - 0.4) < 1e-14


# ------------------------------------------------------------ the method
def _surfaces(xs, ss, xm, sm):
    """Bare surfaces: connectivity, node count and cell type (as a surface carries it)."""
    def cell(seg):
        return {2: "line2", 3: "line3"}[np.shape(seg)[1]]
    return (types.SimpleNamespace(segments=ss, n_nodes=xs.shape[1], cell=cell(ss), X=xs),
            types.SimpleNamespace(segments=sm, n_nodes=xm.shape[1], cell=cell(sm), X=xm))


@pytest.mark.parametrize("ks,km", [(3, 3), (3, 2), (2, 3), (2, 2)])
@pytest.mark.parametrize("dual", [False, True])
def test_mortar_dispatch_and_pattern(ks, km, dual):
    """Mortar takes the curved kernel when a surface has 3-node segments (and the
    linear one otherwise, unchanged); its reserved pattern holds every entry of G,
    and P^T P (what the pair reserves for K_uu) every entry of H."""
    xs, ss, xm, sm = configuration(ks, km, 0.17)
    meth = Mortar(*_surfaces(xs, ss, xm, sm), multiplier_space=("dual" if dual else "standard"))
    assert meth.curved == (ks == 3 or km == 3)
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    ev = meth.evaluate(xs, xm, lam, True)
    ref = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space=("dual" if dual else "standard"))
    assert abs(ev.G - ref.G).max() == 0.0
    P = meth.pattern(xs, xm).toarray() > 0
    S = (P.T.astype(int) @ P.astype(int)) > 0
    G, H = ev.G.tocoo(), ev.H.tocoo()
    assert P[G.row, G.col].all() and S[H.row, H.col].all()


def test_mortar_step_policy_on_curved_segments():
    """Policy ``step``: the segments of the step's start are frozen; G and H are the
    exact derivatives of that frozen g (central differences as above)."""
    xs, ss, xm, sm = configuration(3, 3, 0.17)
    meth = Mortar(*_surfaces(xs, ss, xm, sm), multiplier_space="dual", segmentation="step")
    meth.begin_step(xs, xm, True)
    sg = meth._sg
    assert sg.frozen and sg.n > 0
    eg, eh, _ = fd_errors(xs, ss, xm, sm, space="dual", segmentation=sg)
    assert eg < TOL_G and eh < TOL_H


def test_bad_input():
    xs, ss, xm, sm = configuration(3, 3, 0.37)
    with pytest.raises(ValueError, match="n_gauss"):
        mortar_kernel.evaluate(xs, ss, xm, sm, n_gauss=0)
    with pytest.raises(ValueError, match="seg_s"):
        mortar_kernel.evaluate(xs, np.c_[ss, ss[:, :1]], xm, sm)
