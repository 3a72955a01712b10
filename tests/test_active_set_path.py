"""The path of the active set: extrapolated release of the tensile tail.

Releasing only the tensile nodes of a too-wide Hertz zone halves its overshoot
per iteration (the pressure of a zone forced to |x| < b changes sign at
x0^2 = (a^2 + b^2) / 2), so the plain primal-dual active set update needs
O(log(1/h)) iterations a step; ``ActiveSet.release`` (skfem_mortar/contact/active_set.py) releases
up to twice the distance to the sign change instead (standard mortar: the
sign change of the normal nodal forces, as its multipliers alternate in sign).
"""
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import MeshTri

from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.app.runner import run_scene
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane


def _pair(method="nts", n=20):
    m = MeshTri.init_tensor(np.linspace(0, 1, n + 1), np.linspace(0, 0.2, 3)).with_defaults()
    b = Solid(m, NeoHooke(E=100.0, nu=0.0), name="strip")
    plane = RigidPlane((0.5, 0.0), (0.0, 1.0), length=10.0)
    return ContactPair(ContactSurface.from_solid(b, "bottom"), plane, method, name="c")


def _run(pair, first, last, lam_run):
    """Active run on chain positions first..last-1 with multipliers lam_run; returns
    the set after the plain rule (lam >= 0) and after the extrapolation."""
    o = pair.state.chain
    pair.active = np.zeros(pair.n_dofs, dtype=bool)
    pair.active[o[first:last]] = True
    lam = np.zeros(pair.n_dofs)
    lam[o[first:last]] = lam_run
    plain = pair.active & (lam >= 0)
    return plain, pair.state.release(plain.copy(), lambda: pair._tail_signal(lam, _ev(pair)))


def _ev(pair):
    """Standard mortar reads the nodal forces G^T lam: a unit normal per slave node."""
    n = pair.n_dofs
    G = sp.csr_matrix((np.ones(n), (np.arange(n), 2 * np.arange(n) + 1)), shape=(n, 2 * n + 4))
    return SimpleNamespace(G=G)


@pytest.mark.parametrize("method", ["nts", "mortar-dual", "mortar"])
def test_kkt_point_is_a_fixed_point(method):
    pair = _pair(method)
    assert pair.state.chain is not None
    plain, out = _run(pair, 0, 12, np.linspace(3.0, 0.1, 12))  # no tensile node
    np.testing.assert_array_equal(out, plain)
    np.testing.assert_array_equal(out, pair.active)
    assert not pair.state.extra.any()


@pytest.mark.parametrize("method", ["nts", "mortar"])
def test_tail_release_doubles_to_the_sign_change(method):
    """(standard mortar: the nodal forces of the unit-normal G above equal lam)"""
    pair = _pair(method)
    o = pair.state.chain
    # run 0..15 (the chain start is no edge); tensile tail of 3 at the end,
    # sign change interpolated at t0 = 2.5 nodes from the end -> release 5
    lam_run = np.r_[np.linspace(4.0, 1.0, 13), -1.0, -2.0, -3.0][:16]
    lam_run[12] = 1.0
    lam_run[13] = -1.0  # t0 = 2 + 1 / 2 = 2.5 from the end (position 15)
    plain, out = _run(pair, 0, 16, lam_run)
    assert plain[o].sum() == 13
    assert out[o].sum() == 11 and out[o[:11]].all()
    assert pair.state.extra[o[11:13]].all() and pair.state.extra.sum() == 2
    # an extrapolated node penetrates again: plain updates for the rest of the step
    pair.active = out
    new = out.copy()
    new[o[11]] = True
    lam = np.zeros(pair.n_dofs)
    np.testing.assert_array_equal(pair.state.release(new.copy(), lambda: pair._tail_signal(lam, _ev(pair))), new)
    assert pair.state.accel_off


@pytest.mark.parametrize("method,before,most,total", [
    ("nts", [7, 6, 6, 5], 6, 21),
    ("mortar-dual", [7, 6, 6, 6], 6, 21),
    ("mortar", [13, 10, 7, 7], 7, 25),
])
def test_hertz_refine1_iterations(method, before, most, total):
    """hertz refine 1 (14k dofs): plain releases took ``before`` iterations a step
    (nts, dual: the overshoot halving; standard mortar: the edge walking back one
    or two nodes an iteration); the extrapolation measured 5,5,5,5 (nts),
    5,5,5,6 (dual), 7,6,5,5 (mortar).  Bound: ``most`` a step and ``total`` in
    all, one iteration of slack a step or so, below the plain numbers."""
    s = run_scene("hertz", {"refine": 1}, method=method)
    its = [st["newton_iterations"] for st in s["steps"]]
    assert max(its) <= most and sum(its) <= total, (its, before)
    assert all(st.get("active_set_cycles", 0) == 0 for st in s["steps"])
