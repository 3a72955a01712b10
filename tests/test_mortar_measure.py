"""The measure ``w(x) dGamma`` in the mortar kernels (axisymmetric: ``w = 2 pi r``).

Exact derivatives through :class:`~skfem_mortar.contact.mortar_method.Mortar` after
``set_measure(AXISYMMETRIC)`` against central differences (curved line2 and line3
pairs whose slave starts on the axis, standard and dual, fully and partly
covered); the totals of ``D`` against ``2 pi int r dGamma``; a uniform gap gives
``g_A = g0 area_A``; the dual basis biorthogonal in ``r dGamma``.
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.measures import AXISYMMETRIC, PLANE
from skfem_mortar.contact.mortar_slip_cells import tangential_evaluate
from skfem_mortar.contact.mortar_method import Mortar
from skfem_mortar.contact.mortar_quadratic_segmentation import element_polynomial
from skfem_mortar.contact.slip import mortar_history, mortar_slip

from test_mortar_quadratic import _surfaces, base, chain, disk, dual_moments, fd_check

# Central differences (test_mortar_quadratic.fd_check, h = 1e-6) on unit-size data:
# truncation ~h^2 |g'''| ~ 1e-12, round-off ~eps |g| / h ~ 1e-12 for G and
# ~eps |G| / h ~ 1e-10 for H; the weight 2 pi r <= 2 scales g, G, H by at most 2,
# and a missing term of dw/dr shows at the size of the entries (1e-3 .. 1).
TOL_G = 2e-9
TOL_H = 2e-7
LINE3 = cell_type("line3")


def axisymmetric_pair(k: int, x_right: float):
    """Slave on the disk from r = 0 (a node on the axis) to r = 0.3, 4 segments;
    master on the base from r = x_right to r = -0.05, 3 segments; k nodes per cell."""
    xs, ss = chain(4, disk, 0.0, 0.3, k, 0.1, seed=3)
    xm, sm = chain(3, base, x_right, -0.05, k, 0.1, seed=4)
    assert xs[0, 0] == 0.0
    return xs, ss, xm, sm


def _method(xs, ss, xm, sm, space: str) -> Mortar:
    meth = Mortar(*_surfaces(xs, ss, xm, sm), multiplier_space=space)
    meth.set_measure(AXISYMMETRIC)
    return meth


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("space", ["standard", "dual"])
@pytest.mark.parametrize("x_right", [0.37, 0.17])
def test_exact_derivatives_with_the_axisymmetric_measure(k, space, x_right):
    """G and H of Mortar.evaluate against central differences of g and G^T lam:
    fully covered (0.37) and a partly projectable last slave element (0.17, its
    dual coefficients moving with the bounding master vertex)."""
    xs, ss, xm, sm = axisymmetric_pair(k, x_right)
    meth = _method(xs, ss, xm, sm, space)
    n_s = xs.shape[1]
    lam = np.linspace(0.5, 1.5, n_s)
    z = np.concatenate([xs.T.ravel(), xm.T.ravel()])

    def ev(q, tangent=False, lam=None):
        return meth.evaluate(q[:2 * n_s].reshape(-1, 2).T, q[2 * n_s:].reshape(-1, 2).T,
                             lam, tangent)
    # r of the node on the axis is not varied: its normal is the mirror (axial) one
    # there only (a model holds u_r = 0 on the axis), so a difference leaves it
    eg, eh, e0 = fd_check(ev, z, lam, skip=[0])
    G = e0.G.toarray()
    # line2: the node on the axis carries a multiplier; line3: int N_0 r dGamma ~ 0
    # (exactly 0 on a straight cell), so the axis vertex is masked and merged
    assert e0.mask[0] == (k == 2) and e0.mask[1:].sum() >= 2
    # r_0 enters (g ~ 1e-2 h: d g / d r_0 ~ 1e-4, far above TOL_G)
    assert np.abs(G[:, 0]).max() > 1e-4
    if x_right < 0.3 and space == "dual":  # the partial case really is partial
        assert (e0.info["segmentation"].elem_node >= 0).any()
    assert eg < TOL_G and eh < TOL_H


@pytest.mark.parametrize("k", [2, 3])
def test_tangential_offsets_exact_with_the_axisymmetric_measure(k):
    """The tangential offsets (the slip's configuration-dependent part) in ``r dGamma``:
    G and H against central differences, dual multipliers, partly covered."""
    xs, ss, xm, sm = axisymmetric_pair(k, 0.17)
    kernel = tangential_evaluate
    n_s = xs.shape[1]

    def ev(q, tangent=False, lam=None):
        return kernel(q[:2 * n_s].reshape(-1, 2).T, ss, q[2 * n_s:].reshape(-1, 2).T, sm,
                      lam=lam, tangent=tangent, space="dual", measure=AXISYMMETRIC)
    eg, eh, e0 = fd_check(ev, np.concatenate([xs.T.ravel(), xm.T.ravel()]),
                          np.linspace(0.5, 1.5, n_s), skip=[0])     # r on the axis
    np.testing.assert_allclose(e0.info["tangent"][:, 0], [-1.0, 0.0], atol=1e-15)  # n_0 = (0, -1)
    # curved surfaces: offsets of O(gap h / R) ~ 1e-6, not zero (a missing dw/dr term
    # errs by ~ r_A / r ~ 1e-5, far above TOL_G)
    assert np.abs(e0.g).max() > 1e-7
    assert eg < TOL_G and eh < TOL_H


@pytest.mark.parametrize("k", [2, 3])
def test_mortar_slip_exact_with_the_axisymmetric_measure(k):
    """The weighted objective slip (slip.mortar_slip, its history and its mirrored
    nodal tangents) in ``r dGamma``: G and H against central differences, the
    slave slid by 0.02 from its converged state, standard multipliers (there, before
    the chord side rule, the curved segmentation paired one slave cell twice)."""
    xs0, ss, xm, sm = axisymmetric_pair(k, 0.37)
    hist = mortar_history(xs0, ss, xm, sm, measure=AXISYMMETRIC)
    xs = xs0 + [[0.02], [0.0]]
    xs[0, 0] = 0.0                        # the axis node stays on the axis
    n_s = xs.shape[1]

    def ev(q, tangent=False, lam=None):
        e = mortar_slip(q[:2 * n_s].reshape(-1, 2).T, ss, q[2 * n_s:].reshape(-1, 2).T, sm,
                        hist["D_prev"], hist["M_prev"], lam_t=lam, tangent=tangent,
                        measure=AXISYMMETRIC)
        return SimpleNamespace(g=e.u, G=e.G, H=e.H)
    eg, eh, e0 = fd_check(ev, np.concatenate([xs.T.ravel(), xm.T.ravel()]),
                          np.linspace(0.5, 1.5, n_s), skip=[0])     # r on the axis
    assert np.abs(e0.g).max() > 1e-4      # sliding: u_A ~ 0.02 times the supports
    assert eg < TOL_G and eh < TOL_H


def _flat_pair(k: int, R: float = 0.4, n: int = 5):
    """A flat slave z = 0 from r = 0 to R (n cells) over a wider flat master at
    z = -0.01 (normal up), so the slave is covered whole."""
    xs, ss = chain(n, lambda x: 0.0 * x, 0.0, R, k)
    xm, sm = chain(n - 1, lambda x: 0.0 * x - 0.01, R + 0.05, -0.05, k)
    return xs, ss, xm, sm


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("space", ["standard", "dual"])
def test_D_totals_and_uniform_gap(k, space):
    """Flat surfaces, slave covered whole: sum over the slave nodes of the rows of D
    is ``int Phi_A 2 pi r dGamma = area_A`` (both spaces sum to one), their total
    ``2 pi int_0^R r dr = pi R^2``; the uniform gap g0 = 0.01 gives
    ``g_A = g0 area_A``.  Every integrand is a polynomial the rules integrate
    exactly (degree <= 3 on line2's 2 points, <= 5 on line3's 3), so round-off."""
    R = 0.4
    xs, ss, xm, sm = _flat_pair(k, R)
    ev = _method(xs, ss, xm, sm, space).evaluate(xs, xm, None, False)
    D = ev.info["D"].toarray()
    # line3's axis vertex: int N_0 r dGamma = 0 on a straight cell, masked and merged
    # into the mid node (the functions still sum to one, so the totals hold)
    assert ev.mask[1:].all() and ev.mask[0] == (k == 2)
    np.testing.assert_allclose(D.sum(), math.pi * R * R, rtol=1e-13)
    np.testing.assert_allclose(D.sum(1), ev.area, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(ev.g, 0.01 * ev.area, rtol=1e-10, atol=1e-16)
    assert abs(ev.area[0]) < (1.0 if k == 2 else 1e-14) * ev.area.max()
    if k == 2:   # line2 hats: 2 pi h^2/6 on the axis, 2 pi r_A h inside
        h = R / 5
        np.testing.assert_allclose(ev.area[0], 2 * math.pi * h * h / 6, rtol=1e-13)
        np.testing.assert_allclose(ev.area[1:5], 2 * math.pi * xs[0, 1:5] * h, rtol=1e-13)
    if space == "dual":   # biorthogonal in r dGamma: D diagonal, but on line3's first
        off = D - np.diag(np.diag(D))   # cell (biorthogonal to N~ = T N there, not to N)
        if k == 3:
            off[np.ix_(ss[0], ss[0])] = 0.0
        assert np.abs(off).max() < 1e-14 * np.abs(D).max()
    ep = mortar_kernel.evaluate(xs, ss, xm, sm, tangent=False, space=space, measure=PLANE)
    assert not np.allclose(ep.area, ev.area)       # the measure is not ignored


def test_D_total_on_a_curved_slave():
    """line3 slave on the disk from r = 0, covered whole: the total of D equals
    ``2 pi int r |x'| dxi`` of the slave's own interpolant by a 40-point rule, to
    the 3-point rule's error on ``r |x'|`` (|x'| a square root: ~1e-8 relative)."""
    xs, ss = chain(4, disk, 0.0, 0.3, 3, 0.1, seed=3)
    xm, sm = chain(3, base, 0.5, -0.05, 3, 0.1, seed=4)
    ev = _method(xs, ss, xm, sm, "standard").evaluate(xs, xm, None, False)
    assert ev.mask[1:].all()            # the axis vertex merged: the functions sum to one
    eta, w = np.polynomial.legendre.leggauss(40)
    total = 0.0
    for e in ss:
        P = element_polynomial([(xs[0, a:a + 1], xs[1, a:a + 1]) for a in e], LINE3)
        r = P[0][0] + P[1][0] * eta + P[2][0] * eta ** 2
        tx, ty = P[1][0] + 2 * P[2][0] * eta, P[1][1] + 2 * P[2][1] * eta
        total += 2 * math.pi * (r * np.hypot(tx, ty) * w).sum()
    np.testing.assert_allclose(ev.info["D"].sum(), total, rtol=1e-7)


@pytest.mark.parametrize("part", [(0.0, 0.6), (0.15, 0.6), (0.0, 0.35)])
def test_dual_biorthogonal_in_r_dGamma(part):
    """The one kernel's dual basis on a line2 element from r = 0.5 to r = 0 (a node on the
    axis) under the master ``r in part``: ``D_AB = int Phi_A N_B r dGamma`` is diagonal
    (off the diagonal round-off: 1e-14 of D) with ``D_AA = int N_A 2 pi r dGamma`` over
    the covered part (a 40-point rule; the kernel's 2-point rule is exact for these
    cubic integrands: 1e-13)."""
    xs = np.array([[0.5, 0.0], [0.0, 0.0]])           # slave right to left: normal +z
    xm = np.array([[part[0], part[1]], [0.01, 0.01]])
    ev = mortar_kernel.evaluate(xs, [[0, 1]], xm, [[0, 1]], tangent=False, space="dual",
                                measure=AXISYMMETRIC)
    D = ev.info["D"].toarray()
    assert np.abs(D - np.diag(np.diag(D))).max() <= 1e-14 * np.abs(D).max()
    eta, w = np.polynomial.legendre.leggauss(40)
    r = 0.5 * (part[0] + min(part[1], 0.5)) + 0.5 * (min(part[1], 0.5) - part[0]) * eta
    w = w * 0.5 * (min(part[1], 0.5) - part[0])
    N = np.array([r / 0.5, 1.0 - r / 0.5])             # node 0 at r = 0.5, node 1 at r = 0
    np.testing.assert_allclose(np.diag(D), (N * 2 * math.pi * r * w).sum(1), rtol=1e-13)


@pytest.mark.parametrize("curved", [False, True])
@pytest.mark.parametrize("master, crosspoints", [((1.5, -0.5), None), ((1.5, 0.6), None),
                                                 ((0.5, -0.5), None), ((1.5, -0.5), [0])])
def test_line3_dual_biorthogonal_in_r_dGamma(curved, master, crosspoints):
    """The one kernel's dual basis on a line3 element from r = 0 (the axis vertex: no
    support, merged), ``N~ = T N``: ``int Phi_A N~_B r dGamma = delta_AB int N~_A r dGamma``
    on the projectable part, exact for the kernel's element rule (off the diagonal:
    round-off, 1e-14 of D); by a 40-point rule: straight, 1e-14 (degree 5 <= 9 of the
    5-point rule); curved (bent by 0.3 of its length, the weight r on top) to the
    5-point rule's error, measured 4e-6 of int N~_A (tolerance 1e-5)."""
    m, d, dN, D, _ = dual_moments(curved, master, crosspoints, measure=AXISYMMETRIC)
    assert np.abs(m - np.diag(np.diag(m))).max() <= 1e-14 * np.abs(m).max()
    tol = (1e-5 if curved else 1e-14) * d.max()
    np.testing.assert_allclose(m, np.diag(d), atol=tol)
    np.testing.assert_allclose(D.sum(0), dN, atol=tol)


def test_set_measure_checks_its_argument():
    xs, ss, xm, sm = axisymmetric_pair(2, 0.37)
    meth = Mortar(*_surfaces(xs, ss, xm, sm))
    with pytest.raises(ValueError, match="measure"):
        meth.set_measure("axisymmetric")
