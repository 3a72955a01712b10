"""A model written from the README alone: a rubber ring squeezed onto a rigid shaft
(axisymmetric), with every method."""
import numpy as np
import pytest
import skfem

from skfem_mortar import (ContactPair, ContactSurface, Dirichlet, FollowerPressure, Model,
                          NeoHooke, RigidPlane, Solid, solve)

METHODS = ["nts", "mortar", "mortar-dual"]


def _ring_on_shaft(method):
    mesh = (skfem.MeshQuad.init_tensor(np.linspace(1.02, 1.3, 8), np.linspace(0.0, 0.2, 6))
            .with_defaults())
    ring = Solid(mesh, NeoHooke(E=5.0, nu=0.45), element="quad1", name="ring")
    shaft = RigidPlane((1.0, 0.1), (1.0, 0.0), length=2.0)
    pair = ContactPair(ContactSurface.from_solid(ring, "left"), shaft, method=method, name="fit")
    model = Model([ring, pair,
                   FollowerPressure(ring, 0.8, facets="right", side="inward", name="squeeze"),
                   Dirichlet(ring, ring.dofs_on("bottom", "y"), name="bottom")],
                  geometry="axisymmetric")
    return ring, pair, solve(model, n_steps=5)


@pytest.fixture(scope="module")
def runs():
    return {m: _ring_on_shaft(m) for m in METHODS}


@pytest.mark.parametrize("method", METHODS)
def test_the_ring_sits_on_the_shaft(runs, method):
    ring, pair, result = runs[method]
    d = pair.contact_data(result.z)
    assert result.converged and d["has_master"].all()
    # every node of the bore on the shaft: r = 1 to the solver's gap tolerance
    # (the rigid master is exact; 1e-8 of the ring's size is far above round-off)
    np.testing.assert_allclose(d["r"], 1.0, atol=1e-8)
    assert np.all(d["pressure"] > 0.0)
    # the contact pushes the ring outward: a radial total over the revolution, no axial
    f = pair.total_force(result.z)
    assert f[0] > 0.0 and abs(f[1]) <= 1e-12 * f[0]


def test_the_methods_agree(runs):
    """On a straight rigid cylinder every bore node is held at r = 1, so the three
    methods constrain the same displacements: their radial totals agree to the
    Newton tolerance (1e-8 relative is far above it and far below any O(h) difference)."""
    f = [runs[m][1].total_force(runs[m][2].z)[0] for m in METHODS]
    np.testing.assert_allclose(f, f[0], rtol=1e-8)
