"""Friction in the existing scenes: ``ironing --set mu=...`` and ``seed --set mu=...``.

``mu = 0`` (both scenes' default) builds no friction; ``mu > 0`` gives the
contact pair ``Coulomb(mu)``.  What friction changes is the physics checked
here: the die's force ratio rises by about ``mu`` (ironing), the cable's
tension is no longer constant along the contact (seed).
"""
import numpy as np
import pytest

from skfem_mortar.app.runner import run_scene, build_scene
from skfem_mortar.contact.friction import Coulomb
from skfem_mortar.contact.pair import METHODS

MU = 0.3
SEED_COARSE = {"n_cable": 24, "refine_cushion": 1}


class _Runs(dict):
    """Runs keyed by (scene, method, mu, params), made when first asked for."""

    def __missing__(self, key):
        scene, method, mu, params = key
        self[key] = run_scene(scene, {**dict(params), "mu": mu}, method=method)
        return self[key]


@pytest.fixture(scope="module")
def runs():
    return _Runs()


def _pair(setup):
    return next(it for it in setup.model.items if it.name == "contact")


@pytest.mark.parametrize("scene", ["ironing", "seed"])
def test_mu_zero_builds_no_friction_and_mu_positive_builds_coulomb(scene):
    setup, values, _ = build_scene(scene, {})
    assert values["mu"] == 0.0 and _pair(setup).friction is None
    assert _pair(setup).n_dofs == _pair(setup).slave.n_nodes  # one multiplier per node
    setup, _, _ = build_scene(scene, {"mu": "0.3"})
    assert _pair(setup).friction == Coulomb(0.3)
    with pytest.raises(ValueError, match="'mu'"):
        build_scene(scene, {"mu": "-0.1"})


# -- ironing ----------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("method", METHODS)
def test_ironing_friction_adds_about_mu_to_the_force_ratio(runs, method):
    """Steady sliding (the last third of the slide, steps 30 to 40 of the
    frictionless run): the tangential/normal force ratio of the die with
    ``mu = 0.3`` exceeds the frictionless one by ``mu`` to within
    ``[0.9 mu, 1.35 mu]``.  Not to round-off: the driver's force ratio is
    ``(S + mu C) / (C - mu S)`` with ``S, C`` the pressure-weighted sine and
    cosine of the contact's tilt, so it is ``mu`` plus the tilt's share; friction
    drags the block's surface forward and the contact leans on the die's front
    face (measured excess 0.062 to 0.073: with the friction run's own tilt
    ``t = S / C`` the ratio is ``(t + mu) / (1 - mu t)``, which the measured ratios
    give for ``t`` of 3.2 to 3.7 degrees, against below 1 degree frictionless).  The frictionless ratio is the
    die's geometric resistance, below 0.02 (it changes sign as the die passes
    the block's middle)."""
    dry = runs["ironing", method, 0.0, ()]
    wet = runs["ironing", method, MU, ()]
    assert dry["converged"] and wet["converged"]
    m0, m1 = dry["metrics"], wet["metrics"]
    assert m0["force_ratio_steps"] == [30, 40]
    assert abs(m0["force_ratio_mean"]) < 0.02
    excess = m1["force_ratio_mean"] - m0["force_ratio_mean"]
    assert 0.9 * MU < excess < 1.35 * MU, excess
    # steady: the ratio varies over the window by less than 0.05 (measured 0.020
    # to 0.027; the frictionless one by 0.017 to 0.023, the die crossing the block)
    assert m1["force_ratio_spread"] < 0.05
    # gross sliding at the end: no contact node sticks
    assert m1["n_stick"] == 0 and m1["n_slip"] > 0


# -- seed -------------------------------------------------------------------------
@pytest.mark.parametrize("method, mesh, factor", [
    ("mortar", SEED_COARSE, 5.0), ("mortar-dual", SEED_COARSE, 5.0), ("nts", {}, 3.0)])
def test_seed_friction_varies_the_tension_along_the_contact(runs, method, mesh, factor):
    """With ``mu = 0.3`` the cable, pushed outwards while the cushion holds it,
    carries tangential tractions: its tension over the contact zone varies by
    ``(max - min) / mean`` above 1 % (measured 2.0 % mortar on the coarse mesh,
    2.4 % NTS on the default one) and by a multiple of the frictionless variation
    of the same mesh, which is the discretization's (see the next test): mortar
    0.04 %, 5 times; NTS, whose nodal force acts along the master segment's
    normal, 0.4 % on the default mesh (1.1 % on the coarse one), 3 times."""
    dry = runs["seed", method, 0.0, tuple(mesh.items())]
    wet = runs["seed", method, MU, tuple(mesh.items())]
    assert dry["converged"] and wet["converged"]
    v0, v1 = dry["metrics"]["tension_variation"], wet["metrics"]["tension_variation"]
    assert v1 > 0.01 and v1 > factor * v0, (v0, v1)
    # the body balances hold as without friction (Newton's tolerance)
    assert wet["metrics"]["cable_equilibrium_error"] < 1e-8
    assert wet["metrics"]["cushion_equilibrium_error"] < 1e-8
    # friction holds the cable back: the contact zone's tension drops below the free one
    assert wet["metrics"]["tension_min"] < dry["metrics"]["tension_min"]


@pytest.mark.slow
def test_seed_frictionless_tension_is_constant_up_to_the_discretization(runs):
    """``mu = 0``: no tangential load acts on the cable, so its tension is
    constant along the contact; the discrete contact force is not exactly normal
    to the cable's chords (the averaged normals, the weighted gap), which leaves
    a variation that falls under refinement (measured mortar: 3.7e-4 at 24
    cable elements, 1.6e-4 at 48, 3.2e-5 at 96).  Each halving must bring it
    down by a factor 1.5 at least, and it stays below 1e-3."""
    v = [runs["seed", "mortar", 0.0, (("n_cable", n), ("refine_cushion", r))]
         ["metrics"]["tension_variation"] for n, r in ((24, 1), (48, 2))]
    assert v[0] < 1e-3 and v[1] < v[0] / 1.5, v


def test_seed_sticks_in_the_middle_and_slips_at_the_ends(runs):
    """With a small ``mu = 0.1`` the cable sticks where it touched first (the
    middle) and slips towards the ends of the contact zone (measured on the
    coarse mesh: 6 sticking, 3 sliding nodes)."""
    m = runs["seed", "mortar", 0.1, tuple(SEED_COARSE.items())]["metrics"]
    assert m["n_stick"] > 0 and m["n_slip"] > 0
    assert 0.0 < m["stick_half_width"] < m["slip_half_width"] <= m["contact_half_width"]
    # with mu = 0.3 the whole contact sticks (measured: 9 of 9 nodes)
    m3 = runs["seed", "mortar", MU, tuple(SEED_COARSE.items())]["metrics"]
    assert m3["n_slip"] == 0 and m3["stick_half_width"] == m3["contact_half_width"]
    assert m3["tension_variation"] > m["tension_variation"]  # more friction, more variation
