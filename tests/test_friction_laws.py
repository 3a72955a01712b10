"""Friction laws and the tangential complementarity function (contact/friction.py).

Each test names the property it checks: the refusals of bad input, the status
of a node (open, stick, slip) switching where the module doc says, the exact
derivatives of each branch against central differences, the identities of the
zeros of ``C_t`` (stick: no slip; slip: ``lam_t = -Xi sign(u_t)``, friction
opposing the slip), and a semi-smooth Newton solve of a one-node spring and
friction problem with the closed-form answer.
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact.friction import (OPEN, SLIP, STICK, Coulomb, Tresca,
                                           complementarity)

# Central differences with step 1e-7 on O(1) data: C_t is a polynomial of
# degree 2 on each branch, so the truncation error vanishes and the round-off
# error is ~eps |C| / h ~ 1e-9; a wrong derivative is off by O(0.1..1).
H_FD = 1e-7
FD_TOL = 1e-7


# ------------------------------------------------------------------ refusals
@pytest.mark.parametrize("mu", [-0.1, np.nan, np.inf, "a", None, "0.3", True])
def test_coulomb_refuses_a_bad_coefficient(mu):
    with pytest.raises(ValueError, match="mu must be a finite real number >= 0"):
        Coulomb(mu)


@pytest.mark.parametrize("bound", [0.0, -1.0, np.inf, np.nan, "1.0"])
def test_tresca_refuses_a_bad_bound(bound):
    with pytest.raises(ValueError, match="bound must be a finite real number > 0"):
        Tresca(bound)


@pytest.mark.parametrize("start", [-0.1, 1.0, 1.5, np.nan, np.inf, "a", None, "0.5"])
@pytest.mark.parametrize("law", [lambda s: Coulomb(0.3, start=s), lambda s: Tresca(1.0, start=s)])
def test_laws_refuse_a_start_outside_the_load_range(law, start):
    with pytest.raises(ValueError, match=r"start must be a finite real number in \[0, 1\)"):
        law(start)


@pytest.mark.parametrize("law", [Coulomb(0.3, start=0.25), Tresca(1.0, start=0.25)])
def test_friction_acts_in_the_steps_ending_after_its_start(law):
    # the steps ending at or before start are frictionless, the later ones not
    assert [law.acts(t) for t in (0.0, 0.125, 0.25, 0.25 + 1e-12, 0.5, 1.0)] == [
        False, False, False, True, True, True]
    # start 0 (the default): every step, the first one's load factor whatever it is
    for free in (Coulomb(0.3), Tresca(1.0)):
        assert free.start == 0.0 and all(free.acts(t) for t in (0.0, 1e-9, 1.0))
    # a law with start is told apart from one without, and says so
    assert law != type(law)(*([0.3] if isinstance(law, Coulomb) else [1.0]))
    assert "start=0.25" in repr(law) and "start" not in repr(Coulomb(0.3))


def test_laws_are_frozen_and_compare_by_value():
    assert Coulomb(0.3) == Coulomb(0.3) and Tresca(2) == Tresca(2.0)
    with pytest.raises(AttributeError):
        Coulomb(0.3).mu = 0.5


def test_complementarity_refuses_bad_parameters_and_shapes():
    z = np.zeros(3)
    with pytest.raises(ValueError, match="c_n must be a finite real number > 0"):
        complementarity(Coulomb(0.3), z, z, z, z, 0.0, 1.0)
    with pytest.raises(ValueError, match="c_t must be a finite real number > 0"):
        complementarity(Coulomb(0.3), z, z, z, z, 1.0, np.nan)
    with pytest.raises(ValueError, match="u_t must have the shape of lam_n"):
        complementarity(Coulomb(0.3), z, z, z, np.zeros(2), 1.0, 1.0)
    with pytest.raises(ValueError, match="active must have the shape"):
        complementarity(Coulomb(0.3), z, z, z, z, 1.0, 1.0, active=np.ones(2, bool))
    with pytest.raises(ValueError, match="law must be a Coulomb or Tresca"):
        complementarity(0.3, z, z, z, z, 1.0, 1.0)


# ------------------------------------------------------------------ statuses
def test_status_switches_at_the_slip_bound():
    """``u_t = 0``, ``Xi = mu lam_n = 0.5``: stick for ``|lam_t| < 0.5``, slip from it on."""
    lam_t = np.array([-0.9, -0.5, -0.4999, 0.0, 0.4999, 0.5, 0.9])
    n = lam_t.size
    r = complementarity(Coulomb(0.5), np.ones(n), lam_t, np.zeros(n), np.zeros(n), 2.0, 3.0)
    assert list(r.status) == [SLIP, SLIP, STICK, STICK, STICK, SLIP, SLIP]
    np.testing.assert_array_equal(r.bound, 0.5)


def test_status_switches_with_the_augmented_multiplier():
    """Stick or slip is decided by ``s = lam_t - c_t u_t``: a slip ``u_t`` moves the switch."""
    c_t, u_t = 4.0, 0.1                                # s = lam_t - 0.4
    lam_t = np.array([-0.11, -0.09, 0.89, 0.91])       # |s| = 0.51, 0.49, 0.49, 0.51
    n = lam_t.size
    r = complementarity(Coulomb(0.5), np.ones(n), lam_t, np.zeros(n), np.full(n, u_t), 1.0, c_t)
    assert list(r.status) == [SLIP, STICK, STICK, SLIP]


def test_open_nodes():
    """Open where the normal row is inactive (``lam_n - c_n g_n < 0``, or told so), where
    ``Xi = 0`` (the boundary of the active set, or ``mu = 0``): there ``C_t = lam_t``."""
    lam_n = np.array([1.0, 1.0, 0.5, 1.0])
    g_n = np.array([0.0, 0.6, 0.25, 0.0])             # lam_n - 2 g_n = 1, -0.2, 0, 1
    lam_t = np.array([0.3, 0.3, 0.3, 0.3])
    r = complementarity(Coulomb(0.5), lam_n, lam_t, g_n, np.zeros(4), 2.0, 1.0,
                        active=np.array([True, True, True, False]))
    assert list(r.status) == [STICK, OPEN, OPEN, OPEN]
    np.testing.assert_array_equal(r.C[1:], lam_t[1:])
    np.testing.assert_array_equal(r.d_lam_t[1:], 1.0)
    for d in (r.d_lam_n, r.d_g, r.d_u):
        np.testing.assert_array_equal(d[1:], 0.0)
    r0 = complementarity(Coulomb(0.0), lam_n, lam_t, g_n, np.full(4, 0.2), 2.0, 1.0)
    assert (r0.status == OPEN).all()
    # the default normal set is the pair's: lam_n - c_n g_n >= 0
    rd = complementarity(Coulomb(0.5), lam_n, lam_t, g_n, np.zeros(4), 2.0, 1.0)
    assert list(rd.status) == [STICK, OPEN, OPEN, STICK]


# --------------------------------------------------------------- derivatives
def _rows(law, q, c_n=2.0, c_t=3.0, weight=1.0, jacobian="exact"):
    """C_t at q = (lam_n, lam_t, g_n, u_t), each (n,)."""
    return complementarity(law, *q, c_n, c_t, weight=weight, jacobian=jacobian)


def _fd_check(law, q, weight=1.0):
    r = _rows(law, q, weight=weight)
    for i, d in enumerate((r.d_lam_n, r.d_lam_t, r.d_g, r.d_u)):
        qp = [a.copy() for a in q]
        qm = [a.copy() for a in q]
        qp[i] += H_FD
        qm[i] -= H_FD
        rp, rm = _rows(law, qp, weight=weight), _rows(law, qm, weight=weight)
        assert (rp.status == r.status).all() and (rm.status == r.status).all()  # no kink crossed
        np.testing.assert_allclose(d, (rp.C - rm.C) / (2 * H_FD), atol=FD_TOL, rtol=0)
    return r


@pytest.mark.parametrize("law", [Coulomb(0.4), Tresca(0.7)])
def test_derivatives_of_every_branch_against_finite_differences(law):
    """Random points in each branch (away from the kinks by construction), both signs."""
    rng = np.random.default_rng(5)
    n = 200
    lam_n = rng.uniform(0.5, 2.0, n)
    g_n = rng.uniform(-0.1, 0.1, n)                   # active: lam_n - 2 g_n > 0.3
    lam_t = rng.uniform(-2.0, 2.0, n)
    u_t = rng.uniform(-0.3, 0.3, n)
    q = [lam_n, lam_t, g_n, u_t]
    r = _rows(law, q)
    # keep points whose |s| is at least 1e-3 away from Xi (no status change within h)
    far = np.abs(np.abs(r.s) - r.bound) > 1e-3
    q = [a[far] for a in q]
    r = _fd_check(law, q, weight=np.ones(int(far.sum())))
    assert (r.status == STICK).sum() > 20 and (r.status == SLIP).sum() > 20


@pytest.mark.parametrize("law", [Coulomb(0.4), Tresca(0.7)])
def test_projected_slip_derivatives(law):
    """The default derivatives: on slip nodes ``lam_t`` projected onto ``|lam_t| <= Xi``
    in ``dC/dlam_t`` and ``dC/du_t``; the exact ones wherever ``|lam_t| <= Xi`` (so at
    every solution), ``dC/du_t >= 0`` everywhere; values, statuses and the other
    derivatives as the exact ones'."""
    rng = np.random.default_rng(7)
    n = 400
    q = [rng.uniform(0.5, 2.0, n), rng.uniform(-2.0, 2.0, n), rng.uniform(-0.1, 0.1, n),
         rng.uniform(-0.3, 0.3, n)]
    exact, proj = _rows(law, q), _rows(law, q, jacobian="projected")
    assert (complementarity(law, *q, 2.0, 3.0).d_u == proj.d_u).all()   # the default
    for k in ("C", "status", "d_lam_n", "d_g", "bound", "s"):
        np.testing.assert_array_equal(getattr(exact, k), getattr(proj, k))
    slip = exact.status == SLIP
    inside = np.abs(q[1]) <= exact.bound
    over = slip & ~inside
    assert inside[slip].sum() > 20 and over.sum() > 20     # both cases drawn
    for k in ("d_lam_t", "d_u"):
        np.testing.assert_array_equal(getattr(exact, k)[~over], getattr(proj, k)[~over])
    # beyond the disk: lam_t replaced by Xi sign(lam_t) (the formulas of the module doc)
    l, sg, xi = np.sign(q[1][over]) * exact.bound[over], np.sign(exact.s[over]), exact.bound[over]
    np.testing.assert_allclose(proj.d_u[over], 3.0 * (xi - sg * l), rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(proj.d_lam_t[over], np.abs(exact.s[over]) - xi + sg * l,
                               rtol=1e-15, atol=1e-15)
    assert (proj.d_u[slip] >= 0).all() and (exact.d_u[over] < 0).any()
    # at solutions (lam_t = Xi sign(s) on the slip nodes) the two are the same
    qs = [a[slip] for a in q]
    qs[1] = exact.bound[slip] * np.sign(exact.s[slip]) * (1 - 1e-12)
    e2, p2 = _rows(law, qs), _rows(law, qs, jacobian="projected")
    np.testing.assert_array_equal(e2.d_u, p2.d_u)
    np.testing.assert_array_equal(e2.d_lam_t, p2.d_lam_t)
    with pytest.raises(ValueError, match="jacobian must be one of 'projected', 'exact'"):
        complementarity(law, *q, 2.0, 3.0, jacobian="exakt")


def test_tresca_bound_is_weighted_and_independent_of_the_normal_state():
    """``Xi = bound * weight`` (NTS: the tributary length), no dependence on lam_n, g_n."""
    w = np.array([0.1, 0.2, 0.3])
    r = complementarity(Tresca(2.0), np.ones(3), np.zeros(3), np.zeros(3), np.full(3, 0.01),
                        1.0, 1.0, weight=w)
    np.testing.assert_allclose(r.bound, 2.0 * w, rtol=1e-15)
    np.testing.assert_array_equal(r.d_lam_n, 0.0)
    np.testing.assert_array_equal(r.d_g, 0.0)


def test_the_value_is_continuous_at_the_stick_slip_tie():
    """At ``|s| = Xi`` both branches give ``Xi c_t u_t``: C_t has no jump where the
    status switches (only its derivative does, the semi-smooth kink)."""
    xi, c_t = 0.5, 2.0
    for sgn in (1.0, -1.0):
        u_t = 0.125 * sgn                                 # binary fractions: s = Xi exactly
        lam_t_tie = c_t * u_t + xi * sgn                  # s = xi sign
        lam_t = lam_t_tie + np.array([-1e-9, 0.0, 1e-9]) * sgn
        r = complementarity(Tresca(xi), np.ones(3), lam_t, np.zeros(3), np.full(3, u_t),
                            1.0, c_t)
        assert list(r.status) == [STICK, SLIP, SLIP]
        # the jump is O(1e-9) times the slope (~|s| + Xi); tolerance 10x that
        np.testing.assert_allclose(r.C, xi * c_t * u_t, atol=1e-8)


# ---------------------------------------------------------------- identities
def test_stick_zero_iff_no_slip():
    """Stick, ``Xi > 0``: ``C_t = Xi c_t u_t``, zero exactly when ``u_t = 0``."""
    u = np.array([0.0, 1e-6, -1e-6, 0.01])
    r = complementarity(Coulomb(0.3), np.ones(4), np.zeros(4), np.zeros(4), u, 1.0, 1.0)
    assert (r.status == STICK).all()
    np.testing.assert_allclose(r.C, 0.3 * u, rtol=1e-15)
    assert r.C[0] == 0.0 and (r.C[1:] != 0).all()


def test_slip_zero_iff_the_multiplier_sits_on_the_bound_against_the_slip():
    """Slip: ``C_t = 0`` iff ``lam_t = Xi sign(s)``; with ``u_t != 0`` that is
    ``lam_t = -Xi sign(u_t)`` (friction opposes the slip); the other sign is no zero."""
    mu, lam_n = 0.4, np.full(4, 2.0)                   # Xi = 0.8
    u = np.array([0.05, -0.05, 0.2, -0.2])
    on = -0.8 * np.sign(u)
    r = complementarity(Coulomb(mu), lam_n, on, np.zeros(4), u, 1.0, 5.0)
    assert (r.status == SLIP).all()
    np.testing.assert_allclose(r.C, 0.0, atol=1e-15)
    assert (on * u < 0).all()
    wrong = complementarity(Coulomb(mu), lam_n, -on, np.zeros(4), u, 1.0, 5.0)
    assert (np.abs(wrong.C) > 0.1).all()


def _newton_one_node(law, k, d, c=1.0, n_iter=30, jacobian="projected"):
    """Semi-smooth Newton on a slave node held by a spring ``k`` to a support moved by
    ``d`` along the tangent, under friction: unknowns ``(u_t, lam_t)``, rows
    ``k (d - u_t) + lam_t = 0`` (the friction force ``lam_t`` on the node) and ``C_t``."""
    u, lam = 0.0, 0.0
    one = np.ones(1)
    history = []
    for it in range(n_iter):
        r = complementarity(law, one, np.array([lam]), np.zeros(1), np.array([u]), 1.0, c,
                            jacobian=jacobian)
        R = np.array([k * (d - u) + lam, r.C[0]])
        history.append(np.abs(R).max())
        if history[-1] < 1e-13:
            return u, lam, history, int(r.status[0])
        J = np.array([[-k, 1.0], [r.d_u[0], r.d_lam_t[0]]])
        du, dl = np.linalg.solve(J, -R)
        u, lam = u + du, lam + dl
    raise AssertionError("semi-smooth Newton did not converge")


@pytest.mark.parametrize("jacobian", ["projected", "exact"])
@pytest.mark.parametrize("d", [0.05, -0.05, 0.3, -0.3, 2.0])
def test_semismooth_newton_solves_a_spring_under_friction(d, jacobian):
    """``k |d| <= Xi``: stick, ``u_t = 0``, ``lam_t = -k d``; else slip,
    ``u_t = d - Xi sign(d) / k``, ``lam_t = -Xi sign(u_t)``; reached in a few
    iterations: stick is linear (one step once the status settles), slip
    quadratic once the status settles (``|R_k+1| <= 10 |R_k|^2`` near the answer)."""
    k, xi = 2.0, 0.3
    u, lam, res, status = _newton_one_node(Tresca(xi), k, d, jacobian=jacobian)
    if k * abs(d) <= xi:
        assert status == STICK and u == pytest.approx(0.0, abs=1e-13)
        assert lam == pytest.approx(-k * d, abs=1e-13)
    else:
        assert status == SLIP
        assert u == pytest.approx(d - xi * np.sign(d) / k, abs=1e-13)
        assert lam == pytest.approx(-xi * np.sign(u), abs=1e-13)
    # quadratic: every residual below 0.1 is followed by one below 10 times its square
    # (measured |R_k+1| / |R_k|^2: 0.1 to 2.5; a linearly converging Newton, a wrong
    # derivative, keeps |R_k+1| / |R_k| fixed and fails this by decades at |R_k| ~ 1e-6)
    # (plus 1e-15: the round-off of residuals of size 1)
    if jacobian == "projected":
        # the spring and the Tresca slip row are linear once the status is slip and
        # lam_t sits on the disk, which the projected step puts it on: solved
        # exactly in one step after the status settles (measured 2 or 3 residuals)
        assert len(res) <= 3
        return
    near = [(a, b) for a, b in zip(res, res[1:]) if a < 0.1]
    assert all(b <= 10 * a * a + 1e-15 for a, b in near)
    assert status == STICK or len(near) >= 3
    assert len(res) <= 10
