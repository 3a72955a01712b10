"""The geometry hook: a model hands its geometry to its items, refuses an item
built for another, and a solid's kernel takes a geometry's weight and hoop
term (:mod:`skfem_mortar.bodies.geometry_terms`).  The terms here are the
test's own (``2 pi R`` and ``N_l / R`` under a test name), so the hook is
checked independently of any geometry's module: exact tangent, and a uniform
radial expansion ``u_r = c r`` whose stresses are the closed form."""
import numpy as np
import pytest
from skfem import MeshQuad, MeshTri

from skfem_mortar import Model
from skfem_mortar.bodies import geometry_terms
from skfem_mortar.bodies.hyperelastic import NeoHooke, SaintVenantKirchhoff
from skfem_mortar.bodies.material import LinearElastic
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.core.item import Item


class _Revolved:
    """The test's axisymmetric terms: ``dx 2 pi R`` and ``dF_thth/du_r = N / R``."""

    def quadrature(self, element, intorder):
        return {"intorder": 4 if intorder is None else intorder}

    def weight(self, basis):
        return 2 * np.pi * basis.mapping.F(basis.quadrature[0])[0]

    def hoop(self, basis, component):
        R = basis.mapping.F(basis.quadrature[0])[0]
        N = np.stack([np.asarray(basis.basis[l][0])[0] for l in range(basis.Nbfun)])
        return np.where((component == 0)[:, None, None], N / R, 0.0)


@pytest.fixture
def revolved(monkeypatch):
    monkeypatch.setitem(geometry_terms.TERMS, "test-revolved", _Revolved())
    monkeypatch.setattr("skfem_mortar.core.geometry.GEOMETRIES",
                        ("plane", "axisymmetric", "3d", "test-revolved"))
    return "test-revolved"


def _mesh(kind):
    m = (MeshTri if kind == "tri" else MeshQuad).init_tensor(np.linspace(0.5, 1.5, 4),
                                                            np.linspace(0, 1, 3))
    p = m.p.copy()
    rng = np.random.default_rng(3)
    inner = (p[0] > 0.6) & (p[0] < 1.4) & (p[1] > 0.1) & (p[1] < 0.9)
    p[:, inner] += 0.05 * rng.uniform(-1, 1, (2, inner.sum()))
    return type(m)(p, m.t)


@pytest.mark.parametrize("element", ["tri1", "tri2", "quad1", "quad2"])
@pytest.mark.parametrize("law", [NeoHooke(E=10, nu=0.3), SaintVenantKirchhoff(E=10, nu=0.3),
                                 LinearElastic(E=10, nu=0.3)], ids=lambda m: type(m).__name__)
def test_hoop_tangent_is_the_residual_derivative(revolved, element, law):
    mesh = _mesh(element[:-1] if element[:-1] != "quad" else "quad")
    body = Solid(mesh, law, element=element)
    model = Model([body], geometry=revolved)
    assert body.geometry == revolved and body._hoop is not None
    rng = np.random.default_rng(0)
    z = 0.02 * rng.standard_normal(model.n)
    r, K, _ = model.assemble(z, 1.0)
    K = K.toarray()
    h = 1e-6
    dz = rng.standard_normal(model.n)
    fd = (model.assemble(z + h * dz, 1.0, tangent=False)[0]
          - model.assemble(z - h * dz, 1.0, tangent=False)[0]) / (2 * h)
    # central differences: truncation h^2 |r'''| and round-off 1e-16 |r| / h, both
    # below 1e-7 of the directional derivative's size here
    assert np.abs(fd - K @ dz).max() <= 1e-7 * np.abs(K @ dz).max()


def test_uniform_radial_expansion(revolved):
    """u_r = c r, u_z = 0 in linear elasticity: eps_rr = eps_thth = c, so
    sigma_rr = sigma_thth = 2 (lambda + mu) c, sigma_zz = 2 lambda c, and the
    internal force vanishes at interior nodes (equilibrium, div sigma = 0 with
    sigma_rr = sigma_thth)."""
    law = LinearElastic(E=10, nu=0.3)
    body = Solid(_mesh("quad"), law, element="quad2")
    Model([body], geometry=revolved)
    c = 1e-3
    z = body.interpolate(lambda X: np.stack([c * X[0], 0 * X[1]]))
    F = body.deformation_gradient(z)
    sigma = law.stress(F)
    lm, mu = law.lmbda, law.mu
    assert np.allclose(sigma[0, 0], 2 * (lm + mu) * c, rtol=1e-12, atol=0)
    assert np.allclose(sigma[2, 2], 2 * (lm + mu) * c, rtol=1e-12, atol=0)
    assert np.allclose(sigma[1, 1], 2 * lm * c, rtol=1e-12, atol=1e-15)
    r = Model([body], geometry=revolved).assemble(z, 1.0, tangent=False)[0]
    inner = body.dofs_at_nodes(np.flatnonzero((body.X[0] > 0.55) & (body.X[0] < 1.45)
                                              & (body.X[1] > 0.05) & (body.X[1] < 0.95)))
    # round-off of the element sums: 1e-12 of the nodal forces' size
    assert np.abs(r[inner]).max() <= 1e-12 * np.abs(r).max()


def test_model_hands_its_geometry_and_refuses_what_an_item_was_not_built_for(revolved,
                                                                            monkeypatch):
    monkeypatch.delitem(geometry_terms.TERMS, "axisymmetric")  # its module registers it
    body = Solid(_mesh("tri"), NeoHooke(E=10, nu=0.3))
    assert Model([body]).geometry == "plane" and body.geometry == "plane"

    class PlaneOnly(Item):
        name = "plane-only"
        geometries = ("plane",)

    with pytest.raises(ValueError, match=r"'plane-only' \(PlaneOnly\) works in a 'plane'"):
        Model([body, PlaneOnly()], geometry=revolved)
    with pytest.raises(ValueError, match=r"'solid' \(Solid\) works in a 'plane' or "
                       r"'test-revolved' geometry, and this model's geometry is 'axisymmetric'"):
        Model([body], geometry="axisymmetric")   # no terms registered for it here
    with pytest.raises(ValueError, match="geometry must be one of"):
        Model([body], geometry="axisymetric")
    with pytest.raises(ValueError, match="thickness applies to a plane model only"):
        Model([body], thickness=2.0, geometry="3d")
