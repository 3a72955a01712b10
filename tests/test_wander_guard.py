"""The step control's guard against a wandering iterate (``newton.WANDER``): a Newton
attempt whose iterate moves a body node farther than ten times the model's size from
the step's start is cut, so a step does not "converge" to an equilibrium far off the
load path (``cable_flat`` n = 50 with mortar under ``MKL_CBWR=AVX`` did: a looped cable
without contact, contact force error 1.0).

The model that triggers it on every platform: one node on a rod of length 1 (the other
end fixed), moved by ``u`` under the load ``lf F`` against the force
``g(u) = a u + u^3 - b u^5`` (``a = 0.04``, ``b = 0.01``, ``F = 1``): soft at the start
(``g'(0) = a``), stiffening, then softening.  ``g(u) = F`` has the root 0.990 on the
load path (reached by load steps from 0) and another at 9.997.  Newton from ``u = 0``
with the whole load goes first to ``F / a = 25`` (25 times the model's size) and then
converges to 9.997 in 11 iterations; with the guard the attempt ends at that iterate,
the half step (first iterate 12.5) too, and the quarter step (6.25) converges to the
load path's root; the rest follows from there.  Plain float arithmetic on one unknown:
the same iterates on every platform.
"""
import logging

import numpy as np
import pytest

from skfem_mortar import Model, solve
from skfem_mortar.core.item import Contribution, Item
from skfem_mortar.solver import newton as newton_module
from skfem_mortar.solver.newton import NewtonOptions

A, B, F = 0.04, 0.01, 1.0
#: the positive roots of g(u) = F: on the load path, and the far one (module doc)
NEAR, FAR = sorted(r.real for r in np.roots([-B, 0.0, 1.0, 0.0, A, -F])
                   if abs(r.imag) < 1e-12 and r.real > 0)


class Rod(Item):
    """A node at ``(1 + u, 0)`` on a rod from ``(0, 0)``: residual ``g(u) - lf F``."""

    dof_kind = "u"
    n_dofs = 1
    name = "rod"

    def assemble(self, z, load_factor, tangent=True):
        u = float(z[self.offset])
        r = np.array([[A * u + u ** 3 - B * u ** 5 - load_factor * F]])
        k = np.array([[[A + 3 * u * u - 5 * B * u ** 4]]]) if tangent else None
        return Contribution.from_dofs(np.array([[self.offset]]), r, k)

    def x(self, z):
        """Both nodes' positions (2, 2): the fixed end and the moving node."""
        return np.array([[0.0, 1.0 + float(z[self.offset])], [0.0, 0.0]])


def _solve():
    return solve(Model([Rod()]), n_steps=1, newton=NewtonOptions(rtol=1e-12))


def test_wandering_iterates_are_cut_and_the_load_path_root_is_found(caplog):
    with caplog.at_level(logging.INFO, logger="skfem_mortar.solver.stepping"):
        res = _solve()
    assert res.converged
    assert res.z[0] == pytest.approx(NEAR, rel=1e-9)   # Newton to rtol 1e-12
    assert res.steps[0].cuts == 2 and res.steps[0].load_factor == 0.25
    wander = [r for r in caplog.records if "wandering iterate" in r.getMessage()]
    assert len(wander) == 2                       # the whole step and the half step


def test_without_the_guard_the_step_converges_off_the_load_path(monkeypatch):
    """The guard is what changes the answer: with it off the one step converges
    (no cut) to the far root."""
    monkeypatch.setattr(newton_module, "WANDER", np.inf)
    res = _solve()
    assert res.converged and res.steps[0].cuts == 0
    assert res.z[0] == pytest.approx(FAR, rel=1e-9)


def test_wandered_reads_the_prescribed_motion_as_the_size():
    """A prescribed increment larger than the model moves nodes that far by design:
    the yardstick is the larger of the two, so such a step is not cut."""
    model = Model([Rod()])
    z0 = model.zeros()
    z = z0.copy()
    z[0] = 30.0                                   # 30 times the size 1
    home = newton_module._Home(model, z0, np.zeros(0))
    assert "wandering iterate" in newton_module.wandered(model, z, home)
    home = newton_module._Home(model, z0, np.array([5.0]))   # a prescribed 5: L = 5
    assert newton_module.wandered(model, z, home) == ""
