"""The slip within a load step (contact/slip.py): values, exact derivatives, objectivity.

FD tests of ``u_t``, ``G_t = du_t/dx`` and ``H_t = sum lam_t d2 u_t/dx2`` for NTS
(on one segment, crossing segments forward and backward within the step, a
closed master chain across its seam) and for mortar (standard and dual) on a
curved, sliding configuration; objectivity (a rigid rotation of 30 degrees and
a translation of the whole converged configuration gives no slip, while the
non-objective form with displacement increments does); pure sliding gives
``d`` (NTS) and ``d`` times the mortar support (mortar).
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.mortar_segmentation import nodal_normals
from skfem_mortar.contact.mortar_slip_cells import tangential_evaluate
from skfem_mortar.contact.nts import project
from skfem_mortar.contact.slip import mortar_history, mortar_slip, nts_slip

# Central differences with h = 1e-6 on unit-size geometry: truncation ~h^2 |u'''|
# ~ 1e-12 and round-off ~eps |u| / h ~ 1e-10, so exact derivatives agree to ~1e-9;
# a missing chain-rule term is off by O(1e-3..1).
FD_H = 1e-6
FD_TOL = 2e-8


def chain(n: int) -> np.ndarray:
    return np.c_[np.arange(n - 1), np.arange(1, n)]


def fd_jacobian(f, z, h=FD_H):
    cols = []
    for i in range(len(z)):
        e = np.zeros(len(z))
        e[i] = h
        cols.append((f(z + e) - f(z - e)) / (2 * h))
    return np.array(cols).T


def unpack(z, n_s):
    return z[:2 * n_s].reshape(-1, 2).T, z[2 * n_s:].reshape(-1, 2).T


def pack(xs, xm):
    return np.concatenate([xs.T.ravel(), xm.T.ravel()])


def curved(ns=6, nm=7):
    """A curved slave (above, chain along +x: outward normal down) over a curved master
    (below, chain along -x), slightly apart."""
    X = np.linspace(0, 1, ns)
    xs = np.array([X, 0.3 * (X - 0.5) ** 2])
    Xm = np.linspace(1.3, -0.3, nm)
    xm = np.array([Xm, -0.02 - 0.1 * (Xm - 0.4) ** 2])
    return xs, chain(ns), xm, chain(nm)


def rotate(x, deg, shift):
    a = np.radians(deg)
    Q = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    return Q @ x + np.asarray(shift, float)[:, None]


# ------------------------------------------------------------------ mortar
@pytest.mark.parametrize("dual", [False, True])
def test_mortar_slip_derivatives_against_finite_differences(dual):
    """Curved surfaces, the slave slid by 0.05 and both perturbed: G and H against FD."""
    xs0, seg_s, xm0, seg_m = curved()
    hist = mortar_history(xs0, seg_s, xm0, seg_m, space=("dual" if dual else "standard"))
    rng = np.random.default_rng(0)
    xs = xs0 + [[0.05], [0.0]] + 0.01 * rng.standard_normal(xs0.shape)
    xm = xm0 + 0.01 * rng.standard_normal(xm0.shape)
    lam = rng.standard_normal(xs.shape[1])
    n_s = xs.shape[1]

    def ev(z, **kw):
        a, b = unpack(z, n_s)
        return mortar_slip(a, seg_s, b, seg_m, hist["D_prev"], hist["M_prev"], space=("dual" if dual else "standard"), **kw)
    z = pack(xs, xm)
    e = ev(z, lam_t=lam)
    assert e.mask.all() and np.abs(e.u).max() > 1e-3       # a sliding state, all nodes
    np.testing.assert_allclose(e.G.toarray(), fd_jacobian(lambda q: ev(q, tangent=False).u, z),
                               atol=FD_TOL, rtol=0)
    np.testing.assert_allclose(e.H.toarray(), fd_jacobian(lambda q: ev(q).G.T @ lam, z),
                               atol=FD_TOL, rtol=0)
    np.testing.assert_allclose(e.H.toarray(), e.H.toarray().T, atol=1e-14)


def test_tangential_offset_is_the_mortar_integrals_identity():
    """``r_A`` integrated as ``int Phi_A alpha n~ . tau_A`` equals
    ``tau_A . (M x_m - D x_s)`` from the assembled integrals (round-off)."""
    xs, seg_s, xm, seg_m = curved()
    for dual in (False, True):
        t = tangential_evaluate(xs, seg_s, xm, seg_m, space=("dual" if dual else "standard"), tangent=False)
        v = t.info["M"] @ xm.T - t.info["D"] @ xs.T                       # (n_s, 2)
        np.testing.assert_allclose(t.g, np.sum(t.info["tangent"].T * v, axis=1), atol=1e-15)
        assert np.abs(t.g).max() > 1e-5                    # curved: not trivially zero


def test_mortar_tangent_is_the_turned_nodal_normal():
    xs, seg_s, xm, seg_m = curved()
    t = tangential_evaluate(xs, seg_s, xm, seg_m, tangent=False)
    (nx, ny), _, _ = nodal_normals(xs, seg_s, second=False, nv=0)
    np.testing.assert_allclose(t.info["tangent"], np.stack([ny.v, -nx.v]), atol=1e-15)
    np.testing.assert_allclose(np.hypot(*t.info["tangent"]), 1.0, atol=1e-15)


@pytest.mark.parametrize("dual", [False, True])
def test_mortar_slip_is_objective_and_the_increment_form_is_not(dual):
    """A rigid rotation by 30 degrees and a translation of the whole converged
    configuration: the objective slip is zero to round-off at every node; the
    non-objective ``-tau . [D (x_s - x_s^prev) - M (x_m - x_m^prev)]`` is not."""
    xs0, seg_s, xm0, seg_m = curved()
    hist = mortar_history(xs0, seg_s, xm0, seg_m, space=("dual" if dual else "standard"))
    xs, xm = rotate(xs0, 30.0, (0.4, -0.7)), rotate(xm0, 30.0, (0.4, -0.7))
    e = mortar_slip(xs, seg_s, xm, seg_m, hist["D_prev"], hist["M_prev"], space=("dual" if dual else "standard"),
                    tangent=False)
    assert e.mask.all()
    # round-off of D x - M x with |x| ~ 1 and D, M ~ 0.2: a few 1e-16
    np.testing.assert_allclose(e.u, 0.0, atol=1e-14)
    tau = e.tangent
    bad = -np.sum(tau * (hist["D_prev"] @ (xs - xs0).T - hist["M_prev"] @ (xm - xm0).T).T, axis=0)
    assert np.abs(bad).max() > 1e-3       # the test can fail: measured 7e-3 (round-off 3e-17)
    # a translation alone
    e = mortar_slip(xs0 + [[0.3], [0.2]], seg_s, xm0 + [[0.3], [0.2]], seg_m, hist["D_prev"],
                    hist["M_prev"], space=("dual" if dual else "standard"), tangent=False)
    np.testing.assert_allclose(e.u, 0.0, atol=1e-14)


def flat(ns=5, nm=9, gap=0.0):
    """A flat slave on y = gap (chain +x) over a longer flat master on y = 0 (chain -x)."""
    xs = np.array([np.linspace(0.0, 1.0, ns), np.full(ns, gap)])
    xm = np.array([np.linspace(1.6, -0.6, nm), np.zeros(nm)])
    return xs, chain(ns), xm, chain(nm)


@pytest.mark.parametrize("dual", [False, True])
def test_mortar_pure_sliding_gives_the_distance_times_the_support(dual):
    """The slave slides by ``d`` along its tangent ``tau = -x`` over a fixed flat master
    (full overlap): ``u_t,A = d int Phi_A = d area_A``; the master sliding by ``d``
    gives ``-d area_A`` (the slip is the slave's relative motion)."""
    xs0, seg_s, xm0, seg_m = flat(gap=1e-3)
    hist = mortar_history(xs0, seg_s, xm0, seg_m, space=("dual" if dual else "standard"))
    d = 0.137
    tau = np.array([[-1.0], [0.0]])
    area = mortar_kernel.evaluate(xs0, seg_s, xm0, seg_m, tangent=False, space=("dual" if dual else "standard")).area
    e = mortar_slip(xs0 + d * tau, seg_s, xm0, seg_m, hist["D_prev"], hist["M_prev"],
                    space=("dual" if dual else "standard"), tangent=False)
    np.testing.assert_allclose(e.tangent, np.repeat(tau, xs0.shape[1], 1), atol=1e-15)
    np.testing.assert_allclose(e.u, d * area, atol=1e-15)
    e = mortar_slip(xs0, seg_s, xm0 + d * tau, seg_m, hist["D_prev"], hist["M_prev"],
                    space=("dual" if dual else "standard"), tangent=False)
    np.testing.assert_allclose(e.u, -d * area, atol=1e-15)


def test_mortar_slip_refuses_history_of_another_shape():
    xs, seg_s, xm, seg_m = flat()
    with pytest.raises(ValueError, match="M_prev must have shape"):
        mortar_slip(xs, seg_s, xm, seg_m, np.zeros((5, 5)), np.zeros((5, 8)))
    with pytest.raises(ValueError, match="lam_t must have shape"):
        mortar_slip(xs, seg_s, xm, seg_m, np.zeros((5, 5)), np.zeros((5, 9)), lam_t=np.ones(4))


# --------------------------------------------------------------------- NTS
def nts_case(shift, seed=1, noise=0.01):
    """The curved pair, the slave moved by ``shift`` along x (and perturbed)."""
    xs0, _, xm0, seg_m = curved()
    p0 = project(xs0, xm0, seg_m)
    rng = np.random.default_rng(seed)
    xs = xs0 + [[shift], [0.0]] + noise * rng.standard_normal(xs0.shape)
    xm = xm0 + noise * rng.standard_normal(xm0.shape)
    return xs, xm, seg_m, p0


@pytest.mark.parametrize("shift", [0.02, 0.45, -0.45])
def test_nts_slip_derivatives_against_finite_differences(shift):
    """On one segment (0.02) and crossing up to two segments backward or forward
    along the master chain within the step (+-0.45, master segments 0.27 long)."""
    xs, xm, seg_m, p0 = nts_case(shift)
    seg = project(xs, xm, seg_m)["segment"]
    n_s = xs.shape[1]
    lam = np.random.default_rng(3).standard_normal(n_s)

    def ev(z, **kw):
        a, b = unpack(z, n_s)
        return nts_slip(a, b, seg_m, p0["xi"], p0["segment"], segment=seg, **kw)
    z = pack(xs, xm)
    e = ev(z, lam_t=lam)
    crossed = e.info["crossed"][e.mask]
    if abs(shift) > 0.1:
        assert np.abs(crossed).max() == 2 and np.sign(crossed).max() == -np.sign(shift)
    else:
        assert (crossed == 0).all()
    np.testing.assert_allclose(e.G.toarray(), fd_jacobian(lambda q: ev(q, tangent=False).u, z),
                               atol=FD_TOL, rtol=0)
    np.testing.assert_allclose(e.H.toarray(), fd_jacobian(lambda q: ev(q).G.T @ lam, z),
                               atol=FD_TOL, rtol=0)


def test_nts_slip_is_the_arc_length_travelled_along_the_master():
    """A flat master: the slave sliding by ``d`` along the master tangent ``e`` (crossing
    segments or not) gives ``u_t = d``; sliding the master by ``d`` gives ``-d``."""
    xs0, _, xm0, seg_m = flat(gap=1e-3)
    p0 = project(xs0, xm0, seg_m)
    e_dir = np.array([[-1.0], [0.0]])
    for d in (0.01, 0.3, -0.6):
        e = nts_slip(xs0 + d * e_dir, xm0, seg_m, p0["xi"], p0["segment"], tangent=False)
        assert e.mask.all()
        np.testing.assert_allclose(e.u, d, atol=1e-14)
        np.testing.assert_allclose(e.tangent, np.repeat(e_dir, 5, 1), atol=1e-15)
        e = nts_slip(xs0, xm0 + d * e_dir, seg_m, p0["xi"], p0["segment"], tangent=False)
        np.testing.assert_allclose(e.u, -d, atol=1e-14)
    assert np.abs(nts_slip(xs0 + 0.6 * e_dir, xm0, seg_m, p0["xi"], p0["segment"],
                           tangent=False).info["crossed"]).max() >= 2


def test_nts_slip_is_objective():
    """A rigid rotation by 30 degrees and a translation of the whole converged
    configuration: the same segments and parameters, no slip; the increment of the
    slave positions along the tangent (non-objective) is not zero."""
    xs0, _, xm0, seg_m = curved()
    p0 = project(xs0, xm0, seg_m)
    xs, xm = rotate(xs0, 30.0, (0.4, -0.7)), rotate(xm0, 30.0, (0.4, -0.7))
    e = nts_slip(xs, xm, seg_m, p0["xi"], p0["segment"], tangent=False)
    assert e.mask.all()
    np.testing.assert_allclose(e.u, 0.0, atol=1e-14)      # round-off of unit lengths
    assert np.abs(np.sum(e.tangent * (xs - xs0), axis=0)).max() > 0.1


def test_nts_slip_across_the_seam_of_a_closed_master():
    """A closed square master: a node moving from the last segment across the seam onto
    the first takes the short way round (one crossing), with exact derivatives."""
    xm = np.array([[0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0]])     # ccw: normals outward
    seg_m = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    xs0 = np.array([[-0.001], [0.2]])                              # facing segment 3
    p0 = project(xs0, xm, seg_m)
    assert p0["segment"][0] == 3
    xs = np.array([[0.3], [-0.002]])                              # now facing segment 0
    e = nts_slip(xs, xm, seg_m, p0["xi"], p0["segment"], lam_t=np.array([0.7]))
    assert e.info["crossed"][0] == 1
    np.testing.assert_allclose(e.u, 0.2 + 0.3, atol=1e-12)  # 0.2 down to (0, 0), then 0.3
    z = pack(xs, xm)

    def ev(q, **kw):
        a, b = unpack(q, 1)
        return nts_slip(a, b, seg_m, p0["xi"], p0["segment"], segment=e_seg, **kw)
    e_seg = project(xs, xm, seg_m)["segment"]
    np.testing.assert_allclose(e.G.toarray(), fd_jacobian(lambda q: ev(q, tangent=False).u, z),
                               atol=FD_TOL, rtol=0)
    np.testing.assert_allclose(e.H.toarray(), fd_jacobian(lambda q: ev(q).G.T @ [0.7], z),
                               atol=FD_TOL, rtol=0)


def test_nts_slip_without_history_is_undefined():
    """A node without a converged segment (``segment_prev = -1``) has no slip: masked, 0."""
    xs0, _, xm0, seg_m = flat()
    p0 = project(xs0, xm0, seg_m)
    prev = p0["segment"].copy()
    prev[2] = -1
    e = nts_slip(xs0, xm0, seg_m, p0["xi"], prev)
    assert not e.mask[2] and e.mask.sum() == 4 and e.u[2] == 0.0
    assert e.G[2].nnz == 0


def test_nts_slip_refuses_bad_history():
    xs0, _, xm0, seg_m = flat()
    with pytest.raises(ValueError, match="xi_prev must have shape"):
        nts_slip(xs0, xm0, seg_m, np.zeros(4), np.zeros(5, int))
    with pytest.raises(ValueError, match="segment_prev must index master segments"):
        nts_slip(xs0, xm0, seg_m, np.zeros(5), np.full(5, 8))
