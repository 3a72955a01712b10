"""Friction in the existing scenes: ``ironing --set mu=...``.

``mu = 0`` (both scenes' default) builds no friction; ``mu > 0`` gives the
contact pair ``Coulomb(mu)``.  What friction changes is the physics checked
here: the die's force ratio rises by about ``mu``.
"""
import numpy as np
import pytest

from skfem_mortar.app.runner import run_scene, build_scene
from skfem_mortar.contact.friction import Coulomb
from skfem_mortar.contact.pair import METHODS

MU = 0.3


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


@pytest.mark.parametrize("scene", ["ironing"])
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
    face (measured excess 0.062 to 0.073, an effective tilt of about 3.5
    degrees, against 0.3 degrees frictionless).  The frictionless ratio is the
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
