"""Membranes of revolution (bodies/membrane.py, membrane_laws.py): the exact
tangent and the residual as the energy's gradient for both laws, the laws'
closed forms, the pole, the outputs, and the refusals."""
import numpy as np
import pytest

from fd import dense, fd_tangent
from skfem_mortar import Model
from skfem_mortar.bodies.cable import Cable
from skfem_mortar.bodies.membrane import Membrane
from skfem_mortar.bodies.membrane_laws import NeoHookeMembrane, SVKMembrane, membrane_law

LAWS = {"neo-hooke": {"mu": 2.0}, "svk": {"E": 3.0, "nu": 0.3}}


def _quarter(n=6, **kw):
    th = np.linspace(0.0, 0.5 * np.pi, n + 1)
    return Membrane(np.vstack([np.cos(th), np.sin(th)]), H=0.1, **kw)


def _moved(m, seed=1, size=0.1):
    """A random state with the pole on the axis (the membrane prescribes it)."""
    z = size * np.random.default_rng(seed).standard_normal(m.n_dofs)
    z[m.node_dofs[0, m.pole]] = 0.0
    return z


@pytest.mark.parametrize("law", sorted(LAWS))
def test_tangent_is_the_residual_derivative(law):
    m = _quarter(law=law, **LAWS[law])
    Model([m], geometry="axisymmetric")
    z = _moved(m)
    R, K = dense(m.assemble(z, 1.0), m.n_dofs)
    # central differences, h = 1e-6: truncation and round-off about 1e-10 of |K|
    assert np.abs(K - fd_tangent(m, z, 1.0)).max() <= 1e-8 * np.abs(K).max()
    assert np.abs(K - K.T).max() <= 1e-13 * np.abs(K).max()    # a potential's Hessian
    h, g = 1e-6, np.zeros(m.n_dofs)
    for k in range(m.n_dofs):
        e = np.zeros(m.n_dofs)
        e[k] = h
        g[k] = (m.energy(z + e) - m.energy(z - e)) / (2 * h)
    assert np.abs(g - R).max() <= 1e-8 * np.abs(R).max()


@pytest.mark.parametrize("law", [NeoHookeMembrane(2.0), SVKMembrane(3.0, 0.3)],
                         ids=lambda w: w.name)
def test_law_derivatives(law):
    l1, l2, h = np.array([1.3]), np.array([0.8]), 1e-6
    W, W1, W2, W11, W12, W22 = law.derivatives(l1, l2)
    d = lambda f, a, b: ((f(a + h, b) - f(a - h, b)) / (2 * h),
                         (f(a, b + h) - f(a, b - h)) / (2 * h))
    assert np.allclose(d(law.energy, l1, l2), (W1, W2), rtol=1e-8)
    first = lambda k: (lambda a, b: law.derivatives(a, b)[k])
    assert np.allclose(d(first(1), l1, l2), (W11, W12), rtol=1e-8)
    assert np.allclose(d(first(2), l1, l2), (W12, W22), rtol=1e-8)
    assert law.derivatives(np.ones(1), np.ones(1))[0] == pytest.approx(0.0, abs=1e-15)


def test_equibiaxial_tension_and_thickness():
    """A sphere inflated to lambda: T = mu H (1 - lambda^-6), h = H / lambda^2 (neo-Hooke);
    SVK: T = H S l1 / l2 = C (1 + nu) E H with E = (lambda^2 - 1) / 2, exactly on a sphere
    scaled by lambda (the Gauss points' r / R is lambda too)."""
    for law, lam in (("neo-hooke", 1.7), ("svk", 1.2)):   # svk: l3 real below ~1.35
        T = 2.0 * 0.1 * (1 - lam ** -6) if law == "neo-hooke" else \
            3.0 / (1 - 0.09) * 1.3 * 0.5 * (lam ** 2 - 1) * 0.1
        m = _quarter(law=law, **LAWS[law])
        Model([m], geometry="axisymmetric")
        z = ((lam - 1.0) * m.X).T.ravel()
        l1, l2 = m.stretches(z)
        assert np.allclose(l1, lam, rtol=1e-14) and np.allclose(l2, lam, rtol=1e-14)
        T1, T2 = m.tensions(z)
        assert np.allclose(T1, T, rtol=1e-13) and np.allclose(T2, T, rtol=1e-13)
        h = m.current_thickness(z)
        if law == "neo-hooke":
            assert np.allclose(h, 0.1 / lam ** 2, rtol=1e-14)
        else:   # l3^2 = 1 - 2 nu / (1 - nu) (lambda^2 - 1)
            assert np.allclose(h, 0.1 * np.sqrt(1 - 2 * 0.3 / 0.7 * (lam ** 2 - 1)), rtol=1e-13)
        _, cells = m.output_data(z)
        assert set(cells) == {"stretch_meridional", "stretch_hoop", "tension_meridional",
                              "tension_hoop", "thickness"}


def test_pole_snapped_and_held_on_the_axis():
    X = np.array([[1e-12, 0.5, 1.0], [1.0, 0.8, 0.0]])
    m = Membrane(X, mu=1.0)
    assert m.X[0, 0] == 0.0 and m.pole.tolist() == [True, False, False]
    model = Model([m], geometry="axisymmetric")
    dofs, vals = model.prescribed(0.5)
    assert dofs.tolist() == [m.node_dofs[0, 0]] and vals.tolist() == [0.0]


def test_refusals():
    with pytest.raises(ValueError, match=r"'m': a node lies left of the axis .* -0\.1"):
        Membrane(np.array([[-0.1, 1.0], [0.0, 1.0]]), mu=1.0, name="m")
    with pytest.raises(ValueError, match="on the axis"):
        Membrane(np.array([[0.0, 0.0], [0.0, 1.0]]), mu=1.0)
    with pytest.raises(ValueError, match="mu"):
        Membrane(np.array([[1.0, 1.0], [0.0, 1.0]]))
    with pytest.raises(ValueError, match="nu"):
        membrane_law("svk", E=1.0, nu=0.5)
    with pytest.raises(ValueError, match="law must be one of"):
        membrane_law("mooney")
    with pytest.raises(ValueError, match="'axisymmetric'"):
        Model([_quarter(mu=1.0)])            # a membrane of revolution in a plane model
    with pytest.raises(ValueError, match="use Membrane"):
        Model([Cable.ring(1.0, 8, center=(2.0, 0.0))], geometry="axisymmetric")
