"""A friction law and a multiplier space defined and registered here, solved
through the unchanged contact pair.

(a) ``ScaledTresca(bound, factor)``: Tresca's bound times ``factor``, a
    :class:`~skfem_mortar.contact.friction.FrictionLaw` that is not a
    :class:`Tresca`.  With ``factor = 1`` its ``slide`` run is Tresca's bit for bit
    (same iterations, same states to the last bit: the law computes the same
    numbers, ``bound * 1.0 * w``, and the pair asks a law only through the
    protocol); with ``factor = 0.5`` the contact slides at half the force.
(b) The space "standard multipliers scaled by 2" (``Phi'_A = 2 Phi_A``): the
    method's gaps, slips and their derivatives doubled, so ``lam' = lam / 2``
    carries the same traction.  Every scaling is by a power of two (exact in
    floating point): the rows are the standard space's ones exactly (row scale
    ``2 h``, ``c' = c / 4``) and the multiplier columns twice as large, so the
    Newton steps are the ``mortar`` ones with the multipliers halved: the same
    iterations and active sets.  The states agree to round-off, not bit for bit:
    the sparse LU factors a matrix whose multiplier columns are doubled, and its
    pivoting and scaling round differently (measured: 1.2e-15 of the largest
    displacement on patch, 1.4e-15 on slide; 4e-15 and 5e-15 of the largest
    multiplier); the test allows 1e-12, three decades above that and two below
    Newton's own tolerance (1e-10 of the force scale), which a wrong scaling of
    the space (any factor but a power of two, or a missed one) would exceed.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pytest

import skfem_mortar.scenes.slide as slide_scene
from skfem_mortar.app.runner import run_scene
from skfem_mortar.contact.discretization import register_method, unregister_method
from skfem_mortar.contact.friction import SLIP, STICK, FrictionLaw, Tresca
from skfem_mortar.contact.mortar_method import Mortar
from skfem_mortar.contact.multiplier_spaces import (StandardSpace, register_space,
                                                    unregister_space)
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.core.validate import real
from skfem_mortar.scenes import Scene


@dataclass(frozen=True, repr=False)
class ScaledTresca(FrictionLaw):
    """Tresca's bound times ``factor``: ``Xi = factor * bound * w``."""

    bound: float
    factor: float = 1.0
    start: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "bound", real("bound", self.bound, 0.0, low_open=True))
        object.__setattr__(self, "factor", real("factor", self.factor, 0.0, low_open=True))

    def slip_bound(self, lam_n, g_n, c_n, weight=1.0):
        shape = np.broadcast_shapes(np.shape(lam_n), np.shape(weight))
        b = self.bound * self.factor
        return (np.broadcast_to(b * np.asarray(weight, float), shape).copy(), np.zeros(shape),
                np.zeros(shape))

    def weight_derivative(self) -> float:
        return self.bound * self.factor


class Doubled(StandardSpace):
    """Standard mortar multipliers scaled by 2: ``g' = 2 g``, ``lam' = lam / 2``."""

    name = "standard-x2"

    def evaluate(self, method, xs, xm, lam, tangent):
        ev = method.evaluate(xs, xm, None if lam is None else 2.0 * lam, tangent)
        return replace(ev, g=2.0 * ev.g, G=None if ev.G is None else 2.0 * ev.G)

    def slip(self, method, xs, xm, history, lam_t, tangent, ev):
        sl = method.slip(xs, xm, history, None if lam_t is None else 2.0 * lam_t, tangent, ev)
        return replace(sl, u=2.0 * sl.u, G=None if sl.G is None else 2.0 * sl.G)

    def pressure(self, lam, area):
        return 2.0 * lam

    def multipliers(self, p, area):
        return 0.5 * p

    def gap_length(self, g, area):
        return super().gap_length(g, 2.0 * area)

    def slip_length(self, u, area):
        return super().slip_length(u, 2.0 * area)

    def row_scale(self, area):
        return 2.0 * super().row_scale(area)

    def complementarity(self, k, area):
        return super().complementarity(k, area) / 4.0

    def p_ref(self, c, area):
        return 2.0 * super().p_ref(c, area)

    def bound_weight(self, area):
        return 0.5


def _doubled_mortar(slave, master, **options):
    m = Mortar(slave, master, **options)
    m.multiplier_space = "standard-x2"   # the method names its space; nothing else changes
    return m


@pytest.fixture(scope="module")
def doubled():
    register_space(Doubled())
    register_method("mortar-x2", _doubled_mortar)
    yield "mortar-x2"
    unregister_method("mortar-x2")
    unregister_space("standard-x2")


#: small runs (seconds): the slide block 8 elements wide in 8 load steps
PARAMS = {"slide": {"n": 8, "n_steps": 8}, "patch": {}}


def _run(scene, method):
    summary, result, setup = run_scene(scene, PARAMS[scene], method, return_result=True)
    pair = next(it for it in setup.model.items if isinstance(it, ContactPair))
    return summary, result, setup.model, pair


def _steps(summary):
    return [(s["newton_iterations"], s["n_active"], s["cuts"]) for s in summary["steps"]]


#: Tresca's bound in slide: mu N / W (Coulomb's slide bound at the scene's defaults)
BOUND = 0.3 * 0.02 / slide_scene.WIDTH


@pytest.mark.parametrize("method", ["nts", "mortar-dual"])
def test_scaled_tresca_with_factor_1_is_tresca_bit_for_bit(method, monkeypatch):
    runs = {}
    for name, law in (("tresca", Tresca(BOUND)), ("scaled", ScaledTresca(BOUND, 1.0))):
        monkeypatch.setattr(slide_scene, "Coulomb", lambda mu, law=law: law)
        runs[name] = _run("slide", method)
    (s0, r0, _, p0), (s1, r1, _, p1) = runs["tresca"], runs["scaled"]
    assert type(p1.friction) is ScaledTresca and type(p0.friction) is Tresca
    assert s1["converged"] and _steps(s1) == _steps(s0)
    assert all(np.array_equal(a, b) for a, b in zip(r0.states, r1.states))  # bit for bit
    assert s1["metrics"] == s0["metrics"]
    # a sliding contact: some node slides at the bound
    assert (p1.statuses.converged == SLIP).any()


def test_scaled_tresca_slides_at_the_scaled_bound(monkeypatch):
    """Sliding under displacement control: the tangential resultant is the bound
    times the current contact length, so half of it with ``factor = 0.5`` (NTS:
    the nodal bounds ``factor * bound * a_A(x)`` sum to ``factor * bound * L``, ``L``
    the current tributary length of the sliding nodes; to 1e-6, the KKT check's tolerance
    of a sliding node's traction relative to its bound, ``K_LAM``)."""
    for f in (1.0, 0.5):
        monkeypatch.setattr(slide_scene, "Coulomb", lambda mu, f=f: ScaledTresca(BOUND, f))
        s, r, _, pair = _run("slide", "nts")
        st = pair.statuses.converged
        assert s["converged"] and not (st == STICK).any()   # sliding as a whole (an edge lifts)
        area = pair.evaluate(r.z, tangent=False, with_lam=False).area   # current a_A
        length = float(np.sum(area[st == SLIP]))
        assert -pair.total_force(r.z)[0] == pytest.approx(f * BOUND * length, rel=1e-6)


def test_scaled_tresca_refuses_a_bad_factor():
    with pytest.raises(ValueError, match="factor"):
        ScaledTresca(1.0, -1.0)


@pytest.mark.parametrize("scene", ["patch", "slide"])
def test_doubled_space_halves_the_multipliers_exactly(scene, doubled, monkeypatch):
    """Displacements identical to standard mortar, multipliers exactly half, the
    same pressures read back (the space's pressure is ``2 lam'``)."""
    # the scenes offer the built-in methods; this one is registered here
    monkeypatch.setattr(Scene, "check_method", lambda self, method: method)
    s0, r0, m0, p0 = _run(scene, "mortar")
    s1, r1, m1, p1 = _run(scene, doubled)
    assert p1.space.name == "standard-x2" and p0.space.name == "standard"
    assert s1["converged"] and _steps(s1) == _steps(s0)
    n_u = m0.n_u   # round-off, module doc
    u0, u1 = r0.z[:n_u], r1.z[:n_u]
    assert np.abs(u1 - u0).max() <= 1e-12 * np.abs(u0).max()
    lam0 = r0.z[p0.offset:p0.offset + p0.n_dofs]
    lam1 = r1.z[p1.offset:p1.offset + p1.n_dofs]
    assert np.any(lam0 != 0) and np.abs(2.0 * lam1 - lam0).max() <= 1e-12 * np.abs(lam0).max()
    d0, d1 = p0.contact_data(r0.z), p1.contact_data(r1.z)
    p = np.abs(d0["pressure"]).max()
    assert np.abs(d1["pressure"] - d0["pressure"]).max() <= 1e-12 * p
    assert np.array_equal(np.isnan(d0["gap"]), np.isnan(d1["gap"]))
