"""Mesh tying in an axisymmetric model: ``D``, ``M`` in ``2 pi r dGamma``
(:meth:`skfem_mortar.contact.tie.TiePair.set_measure`, set from the model's geometry)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from skfem_mortar import Dirichlet, Model, solve
from skfem_mortar.contact.measures import AXISYMMETRIC, PLANE

from test_tie import stacked

# Newton stops at a residual of 1e-10 of the force scale (test_tie's PATCH_TOL);
# a tie integrated without the weight r misses the uniform traction by O(1)
# (measured: the traction from 0.14 to 1.8 times its mean, the displacements off by
# 2 to 5 % of their size).
PATCH_TOL = 1e-9


def test_the_model_geometry_sets_the_measure():
    """In an axisymmetric model D sums to ``2 pi int_0^1 r dr = pi`` over the
    interface ``r in [0, 1]`` (the plane D: its length 1); back in a plane model
    it is the plane D again."""
    bottom, top, tie = stacked(7, 4, "quad1", False)
    assert tie.measure is PLANE
    np.testing.assert_allclose(tie.D.sum(), 1.0, rtol=1e-14)
    Model([bottom, top, tie], geometry="axisymmetric")
    assert tie.measure is AXISYMMETRIC and tie.geometry == "axisymmetric"
    np.testing.assert_allclose(tie.D.sum(), math.pi, rtol=1e-13)
    np.testing.assert_allclose(tie.M.sum(), math.pi, rtol=1e-13)
    Model([bottom, top, tie])
    assert tie.measure is PLANE
    np.testing.assert_allclose(tie.D.sum(), 1.0, rtol=1e-14)
    with pytest.raises(ValueError, match="measure"):
        tie.set_measure("axisymmetric")


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("element", ["quad1", "tri1"])
@pytest.mark.parametrize("n_top,n_bottom", [(7, 4), (4, 7)])
def test_axisymmetric_patch_through_the_tie(dual, element, n_top, n_bottom):
    """Two stacked cylinders ``r in [0, 1]`` with non-matching meshes, tied at
    ``z = 0.5``; the homogeneous state ``u_r = a r``, ``u_z = c z`` prescribed on
    the outer boundary off the axis and the interface: exact across the tie, and
    the multipliers are the uniform traction ``(0, t)`` at every tied node."""
    bottom, top, tie = stacked(n_top, n_bottom, element, dual)
    a, c = 0.01, -0.02
    items = [bottom, top, tie]
    for body, sides in ((bottom, ("right", "bottom")), (top, ("right", "top"))):
        dofs = np.unique(np.concatenate([body.dofs_on(s) for s in sides]))
        u = body.interpolate(lambda X: np.stack([a * X[0], c * X[1]]))
        items.append(Dirichlet(body, dofs, u[dofs], name=f"affine_{body.name}"))
    res = solve(Model(items, geometry="axisymmetric"), n_steps=1)
    for body in (top, bottom):
        exact = body.interpolate(lambda X: np.stack([a * X[0], c * X[1]]))
        u = res.z[body.offset:body.offset + body.n_dofs]
        assert np.abs(u - exact).max() <= PATCH_TOL * np.abs(exact).max()
    lam = tie.traction(res.z)[:, tie.tied]
    assert tie.tied.sum() >= n_top - 2
    t = lam[1].mean()
    assert abs(t) > 0.1              # E = 100, strains of 1e-2: a traction of O(1)
    np.testing.assert_allclose(lam[1], t, rtol=PATCH_TOL)
    np.testing.assert_allclose(lam[0], 0.0, atol=PATCH_TOL * abs(t))
