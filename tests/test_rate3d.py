"""Quadratic convergence of Newton on 3D contact (issue 38): once the active set and the
clip combinatorics hold, ``r_{k+1} <= C r_k^2`` over the last iterations, with exact G
and H of NTS and of the mortar methods between faces.

``r_k`` is the solver's residual norm (``StepRecord.residual_norms``).  ``C`` is read
over the last three steps ``r_k -> r_{k+1}`` whose ``r_{k+1}`` is above :data:`FLOOR`
times ``r_0`` (the norms end at round-off: 3e-15 to 6e-15 of ``r_0`` on patch3d,
2e-13 on hertz3d, whose system is larger; a step into round-off says nothing of the
rate).  A tangent with a wrong or dropped term converges
linearly, ``r_{k+1} = rho r_k``, so ``r_{k+1} / r_k^2 = rho / r_k`` passes the stated
``C = 1e3`` once ``r_k < rho 1e-3``: within the last steps before the norms reach
1e-13.
"""
import numpy as np
import pytest

from skfem_mortar import ContactPair, ContactSurface, Model, solve
from skfem_mortar.scenes._hertz3d import PARAMS as HERTZ, build_bodies as hertz_bodies
from skfem_mortar.scenes._patch3d import PARAMS as PATCH, build_bodies as patch_bodies
from skfem_mortar.solver.newton import NewtonOptions

#: a step that ends below this times r_0 ends in round-off (module docstring)
FLOOR = 1e-12


def _rate(norms) -> list[float]:
    """``r_{k+1} / r_k^2`` over the last three steps with ``r_{k+1} > FLOOR r_0``."""
    r = list(norms)
    c = [r[k + 1] / r[k] ** 2 for k in range(len(r) - 1) if r[k + 1] > FLOOR * r[0]]
    return c[-3:]


def _patch(method: str, kinematics: str):
    params = {**{p.name: p.default for p in PATCH}, "kinematics": kinematics,
              "n_lower": 4, "n_upper": 2}
    parts = patch_bodies(params)
    pair = ContactPair(ContactSurface.from_solid(*parts.slave, name="slave_face"),
                       ContactSurface.from_solid(*parts.master, name="master_face"), method,
                       name="contact")
    return Model(parts.items + [pair], geometry="3d")


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("method,kinematics", [
    ("mortar", "small"), ("mortar-dual", "small"), ("mortar", "finite"),
    ("mortar-dual", "finite"), ("nts", "small"), ("nts", "finite")])
def test_patch3d_from_a_perturbed_start_converges_quadratically(method, kinematics):
    """patch3d (hex1, 2 on 4 cells) from a start whose every unknown is perturbed by
    1e-3 (random; the block height is 1, the unloaded state 0).  Measured largest C
    of the last three steps: mortar 52 (small) and 6 (finite), mortar-dual 39 and 4,
    NTS 15 and 18."""
    model = _patch(method, kinematics)
    z0 = 1e-3 * np.random.default_rng(38).standard_normal(model.zeros().size)
    res = solve(model, n_steps=1, z0=z0, newton=NewtonOptions(rtol=1e-13))
    norms = res.steps[0].residual_norms
    c = _rate(norms)
    assert res.converged and len(c) >= 2, norms
    assert max(c) <= 1e3, (norms, c)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_hertz3d_nts_converges_quadratically():
    """hertz3d, the quarter on the rigid plane at refine -3 with NTS: measured C 18 and
    57 (the last step, 5e-3 -> 5e-13, is the round-off's: the gap on a flat plane is
    linear in small strain once the active set holds).  The mortar methods' run is
    the next test."""
    _hertz3d_is_quadratic("nts", element="tet1")


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("method", ["mortar", "mortar-dual"])
def test_hertz3d_mortar_converges_quadratically(method):
    """hertz3d's default mesh (hex1: warped quad4 slave faces, their integration cells
    back-projected) at refine -3, the cap on the rigid plane, small strain: the gap is
    no longer linear (the weighted gap integrates over the moving curved faces).
    Measured C over the last three steps: mortar 146, 0.36, 23 (1.3e-2 -> 4.5e-13 in 7
    iterations); mortar-dual 8.6, 2.4, 15 (1.2e-2 -> 4.6e-13 in 6)."""
    _hertz3d_is_quadratic(method, slave="cap")


def _hertz3d_is_quadratic(method: str, **extra) -> None:
    """hertz3d at refine -3 on the rigid plane, small strain (``extra``: more of its
    parameters), one step to rtol 1e-13: converged, C <= 1e3 over the last steps."""
    from skfem_mortar.scenes.hertz3d import contact_surfaces

    params = {**{p.name: p.default for p in HERTZ}, "refine": -3, "base": "rigid",
              "kinematics": "small", **extra}
    parts = hertz_bodies(params)
    pair = ContactPair(*contact_surfaces(parts), method, name="contact")
    res = solve(Model(parts.items + [pair], geometry="3d"), n_steps=1,
                newton=NewtonOptions(rtol=1e-13))
    norms = res.steps[0].residual_norms
    c = _rate(norms)
    assert res.converged and len(c) >= 2, norms
    assert max(c) <= 1e3, (norms, c)
