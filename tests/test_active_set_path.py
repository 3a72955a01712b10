"""The path of the active set: extrapolated release of the tensile tail (NTS, dual mortar).

Releasing only the tensile nodes of a too-wide Hertz zone halves its overshoot
per iteration (the pressure of a zone forced to |x| < b changes sign at
x0^2 = (a^2 + b^2) / 2), so the plain primal-dual active set update needs
O(log(1/h)) iterations a step; ``ContactPair._extrapolate_release`` releases
up to twice the distance to the sign change instead.
"""
import numpy as np
import pytest
from skfem import MeshTri

from skfem_mortar.contact import ContactPair
from skfem_mortar.materials import NeoHooke
from skfem_mortar.runner import run_scene
from skfem_mortar.solid import Solid
from skfem_mortar.surfaces import ContactSurface, RigidPlane


def _pair(method="nts", n=20):
    m = MeshTri.init_tensor(np.linspace(0, 1, n + 1), np.linspace(0, 0.2, 3)).with_defaults()
    b = Solid(m, NeoHooke(E=100.0, nu=0.0), name="strip")
    plane = RigidPlane((0.5, 0.0), (0.0, 1.0), length=10.0)
    return ContactPair(ContactSurface.from_solid(b, "bottom"), plane, method, name="c")


def _run(pair, first, last, lam_run):
    """Active run on chain positions first..last-1 with multipliers lam_run; returns
    the set after the plain rule (lam >= 0) and after the extrapolation."""
    o = pair._chain
    pair.active = np.zeros(pair.n_dofs, dtype=bool)
    pair.active[o[first:last]] = True
    lam = np.zeros(pair.n_dofs)
    lam[o[first:last]] = lam_run
    plain = pair.active & (lam >= 0)
    return plain, pair._extrapolate_release(plain.copy(), lam)


@pytest.mark.parametrize("method", ["nts", "mortar-dual"])
def test_kkt_point_is_a_fixed_point(method):
    pair = _pair(method)
    assert pair._chain is not None
    plain, out = _run(pair, 0, 12, np.linspace(3.0, 0.1, 12))  # no tensile node
    np.testing.assert_array_equal(out, plain)
    np.testing.assert_array_equal(out, pair.active)
    assert not pair._extra.any()


def test_tail_release_doubles_to_the_sign_change():
    pair = _pair("nts")
    o = pair._chain
    # run 0..15 (the chain start is no edge); tensile tail of 3 at the end,
    # sign change interpolated at t0 = 2.5 nodes from the end -> release 5
    lam_run = np.r_[np.linspace(4.0, 1.0, 13), -1.0, -2.0, -3.0][:16]
    lam_run[12] = 1.0
    lam_run[13] = -1.0  # t0 = 2 + 1 / 2 = 2.5 from the end (position 15)
    plain, out = _run(pair, 0, 16, lam_run)
    assert plain[o].sum() == 13
    assert out[o].sum() == 11 and out[o[:11]].all()
    assert pair._extra[o[11:13]].all() and pair._extra.sum() == 2
    # an extrapolated node penetrates again: plain updates for the rest of the step
    pair.active = out
    new = out.copy()
    new[o[11]] = True
    np.testing.assert_array_equal(pair._extrapolate_release(new.copy(), np.zeros(pair.n_dofs)),
                                  new)
    assert pair._accel_off


def test_standard_mortar_is_plain():
    """Standard multipliers alternate in sign at the edge: no tail, no extrapolation."""
    pair = _pair("mortar")
    plain, out = _run(pair, 0, 16, np.r_[np.linspace(4.0, 1.0, 13), -1.0, -2.0, -3.0])
    np.testing.assert_array_equal(out, plain)


@pytest.mark.parametrize("method,before", [("nts", [7, 6, 6, 5]),
                                           ("mortar-dual", [7, 6, 6, 6])])
def test_hertz_refine1_iterations(method, before):
    """hertz refine 1 (14k dofs): plain releases took ``before`` iterations a step
    (the overshoot halving); the extrapolation measured 5,5,5,5 (nts) and
    5,5,5,6 (dual).  Bound: at most 6 a step and 21 in all (before: 24, 25)."""
    s = run_scene("hertz", {"refine": 1}, method=method)
    its = [st["newton_iterations"] for st in s["steps"]]
    assert max(its) <= 6 and sum(its) <= 21, (its, before)
    assert all(st.get("active_set_cycles", 0) == 0 for st in s["steps"])
