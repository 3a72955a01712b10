"""Frictional pressing from a zero gap, the first load step of a model with friction.

Issue 32: a quad2 block pressed onto a wider tri2 base (16 x 2), Coulomb 0.3,
NTS on 3-node segments, failed in the first (pressing) step at every cut down
to load factor 0.000195 ("KKT violated: sliding below the slip bound at 2
nodes", the block's corners), while mortar and mortar-dual converged.

Cause: the tangential rows are ``C_t / p_ref`` and ``C_t`` is of the size
``Xi * (error of lam_t)``, so Newton's residual test meets ``lam_t`` to about
``rtol * S * p_ref / Xi^2``.  A step that starts with no slip bound anywhere
(the first frictional step) had only the guess ``p_ref = c h`` (the multiplier
of a gap of one element length), here 1e5 times the largest bound: the residual
passed with ``lam_t`` off by 2e-3 of the bound at the corners, which the KKT
check refused; a cut step shrinks the bound, not the guess, so every cut
failed alike.  Every method has the rows; which one trips depends on the
numbers (mortar-dual failed the same way on a load-driven variant).  Now a
tracked iteration of such a step re-fixes ``p_ref`` to the iterate's largest
bound (``pair.P_REF_FIT``).

The models are built the way a user builds them (README, "Adding contact to a
scikit-fem model"); every method must converge and the converged state must be
an equilibrium with the friction conditions met (the solver's KKT check).
"""
from __future__ import annotations

import numpy as np
import pytest
import skfem

from skfem_mortar import (ContactPair, ContactSurface, Coulomb, Dirichlet, LinearElastic,
                          Model, Solid, Traction, solve)
from skfem_mortar.contact.friction import SLIP, STICK

METHODS = ("nts", "mortar", "mortar-dual")


def _mesh(kind: str, x0: float, x1: float, y0: float, y1: float, nx: int, ny: int):
    low, high = ((skfem.MeshTri, skfem.MeshTri2) if kind == "tri2"
                 else (skfem.MeshQuad, skfem.MeshQuad2))
    m = low.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    return high.from_mesh(m).with_defaults()


def pressed_block(method: str, n_base: int = 16, block_master: bool = False,
                  press: float = 1e-5, load: float | None = None, x0: float = 0.55,
                  x1: float = 1.37):
    """A steel-like quad2 block (8 x 4) on a wider tri2 base (``n_base`` x 2), both
    deformable, zero gap; the block's top pressed down by ``press`` (held in x), or
    loaded by the traction ``load`` (then free in x: friction holds it)."""
    E = 210000.0
    base = Solid(_mesh("tri2", 0.0, 2.0, 0.0, 0.5, n_base, 2), LinearElastic(E=E, nu=0.3),
                 element="tri2", name="base")
    block = Solid(_mesh("quad2", x0, x1, 0.5, 1.0, 8, 4), LinearElastic(E=E, nu=0.3),
                  element="quad2", name="block")
    slave, master = (ContactSurface.from_solid(block, "bottom"),
                     ContactSurface.from_solid(base, "top"))
    if block_master:
        slave, master = master, slave
    pair = ContactPair(slave, master, method=method, friction=Coulomb(0.3), name="contact")
    items = [base, block, pair, Dirichlet(base, base.dofs_on("bottom"), name="clamp")]
    if load is None:
        items += [Dirichlet(block, block.dofs_on("top", "y"), value=lambda t: -press * t,
                            name="press"),
                  Dirichlet(block, block.dofs_on("top", "x"), name="hold")]
    else:
        items.append(Traction(block, "top", (0.0, -load), name="load"))
    return Model(items), pair, block


def _check(model, pair, block, res, load=None, mu=0.3):
    """The block's equilibrium and Coulomb's cone on the contact resultant."""
    assert pair.violation(res.z, 1.0) == ""         # the KKT check of the last state
    F = pair.total_force(res.z)                    # the contact force on the slave
    on_block = F if pair.slave.body is block else -F
    if load is None:   # the pressing support pulls down what the contact pushes up
        R = model.assemble(res.z, 1.0, tangent=False)[0]
        down = block.reaction(R, block.dofs_on("top", "y"))
    else:              # the load on the top (the block's width is 0.82 or 1)
        down = load * np.ptp(block.mesh.p[0])
    # to Newton's tolerance (rtol 1e-10 of the step's force) and the round-off
    # of summing the nodal forces: 1e-8 is far above both, far below any lost force
    np.testing.assert_allclose(on_block[1], abs(down), rtol=1e-8)
    assert on_block[1] > 0
    assert abs(F[0]) <= mu * abs(F[1]) * (1 + 1e-8)
    assert np.any(pair.statuses.converged == STICK) or np.any(pair.statuses.converged == SLIP)


@pytest.mark.parametrize("method", METHODS)
def test_quadratic_block_pressed_with_coulomb_converges(method):
    """The issue's model (measured before the fix: NTS failed at load factor
    0.000195 after cutting, mortar and mortar-dual converged)."""
    model, pair, block = pressed_block(method)
    res = solve(model, n_steps=10)
    _check(model, pair, block, res)
    assert len(res.steps) == 10                    # no step cut


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("variant", [dict(block_master=True), dict(n_base=8),
                                     dict(n_base=32), dict(load=10.0, x0=0.5, x1=1.5)])
def test_pressing_variants_converge(method, variant):
    """The block as master, a coarser and a finer base, a load instead of a
    prescribed displacement (mortar-dual failed that one at 0.000195)."""
    model, pair, block = pressed_block(method, **variant)
    res = solve(model, n_steps=4)
    _check(model, pair, block, res, variant.get("load"))
