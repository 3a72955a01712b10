"""Plane-strain hyperelastic materials: stress, tangent, post-processing, validation."""
import numpy as np
import pytest

from skfem_mortar.core.errors import InversionError
from skfem_mortar.bodies.materials import NeoHooke, SaintVenantKirchhoff, lame_from_young

MATERIALS = [NeoHooke(E=3.0, nu=0.3), SaintVenantKirchhoff(E=3.0, nu=0.2),
             NeoHooke(mu=1.0, lmbda=-0.5)]
IDS = ["neo-hooke", "svk", "neo-hooke-auxetic"]


def random_F(shape=(3, 4), amp=0.3, seed=0):
    """Deformation gradients near I with det F > 0 (amp 0.3 keeps J in about (0.4, 1.8))."""
    rng = np.random.default_rng(seed)
    F = np.eye(2).reshape(2, 2, *([1] * len(shape))) + amp * rng.standard_normal((2, 2) + shape)
    assert np.all(F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0] > 0.2)
    return F


@pytest.mark.parametrize("mat", MATERIALS, ids=IDS)
def test_tangent_matches_central_differences_of_stress(mat):
    F = random_F()
    P, A = mat.stress_and_tangent(F)
    h = 1e-6
    for k in range(2):
        for L in range(2):
            dF = np.zeros_like(F)
            dF[k, L] = h
            fd = (mat.stress(F + dF) - mat.stress(F - dF)) / (2 * h)
            # central differences: truncation h^2 |P'''| ~ 1e-12, round-off
            # eps |P| / h ~ 1e-10 (|P| ~ 10): 1e-7 is far above both and far
            # below any real error in A (entries of size ~1-10).
            np.testing.assert_allclose(A[:, :, k, L], fd, rtol=0, atol=1e-7)


@pytest.mark.parametrize("mat", MATERIALS, ids=IDS)
def test_stress_is_derivative_of_energy(mat):
    F = random_F(seed=1)
    P = mat.stress(F)
    h = 1e-6
    for i in range(2):
        for J in range(2):
            dF = np.zeros_like(F)
            dF[i, J] = h
            fd = (mat.energy(F + dF) - mat.energy(F - dF)) / (2 * h)
            # same error budget as above, one derivative lower
            np.testing.assert_allclose(P[i, J], fd, rtol=0, atol=1e-7)


@pytest.mark.parametrize("mat", MATERIALS, ids=IDS)
def test_tangent_has_major_symmetry(mat):
    # A = d^2 W / dF dF is symmetric in (iJ) <-> (kL): exact up to round-off
    A = mat.tangent(random_F(seed=2))
    np.testing.assert_allclose(A, np.transpose(A, (2, 3, 0, 1, 4, 5)), rtol=0, atol=1e-12)


@pytest.mark.parametrize("mat", MATERIALS, ids=IDS)
def test_reference_state_is_stress_free_with_linear_elastic_tangent(mat):
    F = np.eye(2)
    P, A = mat.stress_and_tangent(F)
    np.testing.assert_allclose(P, 0.0, atol=1e-15)
    d = np.eye(2)
    C = (mat.lmbda * np.einsum("ij,kl->ijkl", d, d)
         + mat.mu * (np.einsum("ik,jl->ijkl", d, d) + np.einsum("il,jk->ijkl", d, d)))
    # both laws reduce to Hooke's law at F = I (a few ulps of rounding)
    np.testing.assert_allclose(A, C, rtol=0, atol=1e-14 * (abs(mat.lmbda) + mat.mu))


@pytest.mark.parametrize("mat", MATERIALS, ids=IDS)
def test_rigid_rotation_is_stress_free(mat):
    c, s = np.cos(1.1), np.sin(1.1)
    Q = np.array([[c, -s], [s, c]])
    np.testing.assert_allclose(mat.stress(Q), 0.0, atol=1e-14)


def test_neo_hooke_cauchy_closed_form():
    mat = NeoHooke(E=2.0, nu=0.35)
    F = random_F(seed=3)
    J = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
    B = np.einsum("iK...,jK...->ij...", F, F)
    I = np.eye(2)[:, :, None, None]
    expected = (mat.mu * (B - I) + mat.lmbda * np.log(J) * I) / J
    sigma, szz = mat.cauchy(F)
    np.testing.assert_allclose(sigma, expected, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(szz, mat.lmbda * np.log(J) / J, rtol=1e-13)


def test_svk_cauchy_closed_form_uniaxial():
    mat = SaintVenantKirchhoff(E=2.0, nu=0.2)
    lx, ly = 1.3, 0.9
    F = np.diag([lx, ly])
    exx, eyy = (lx ** 2 - 1) / 2, (ly ** 2 - 1) / 2
    sxx = mat.lmbda * (exx + eyy) + 2 * mat.mu * exx
    syy = mat.lmbda * (exx + eyy) + 2 * mat.mu * eyy
    sigma, szz = mat.cauchy(F)
    J = lx * ly
    np.testing.assert_allclose(sigma, np.diag([lx * lx * sxx, ly * ly * syy]) / J, rtol=1e-14)
    np.testing.assert_allclose(szz, mat.lmbda * (exx + eyy) / J, rtol=1e-14)


def test_von_mises_of_equibiaxial_neo_hooke_state():
    # F = a I: s_xx = s_yy = (mu (a^2 - 1) + lambda ln J) / J, s_zz = lambda ln J / J,
    # so the von Mises stress is |s_xx - s_zz| = mu |a^2 - 1| / J.
    mat = NeoHooke(E=1.0, nu=0.3)
    a = np.array([0.7, 1.0, 1.5])
    F = np.einsum("ij,n->ijn", np.eye(2), a)
    np.testing.assert_allclose(mat.von_mises(F), mat.mu * np.abs(a ** 2 - 1) / a ** 2,
                               rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("mat", MATERIALS[:2], ids=IDS[:2])
def test_works_on_any_trailing_shape(mat):
    F = random_F(shape=(5,), seed=4)
    P, A = mat.stress_and_tangent(F)
    assert P.shape == (2, 2, 5) and A.shape == (2, 2, 2, 2, 5)
    P0, A0 = mat.stress_and_tangent(F[:, :, 2])
    np.testing.assert_array_equal(P0, P[:, :, 2])
    np.testing.assert_array_equal(A0, A[..., 2])


@pytest.mark.parametrize("mat", MATERIALS[:2], ids=IDS[:2])
@pytest.mark.parametrize("fun", ["stress", "tangent", "energy", "cauchy", "von_mises"])
def test_inverted_point_raises_inversion_error(mat, fun):
    F = random_F(seed=5)
    F[:, :, 1, 2] = np.array([[1.0, 0.0], [0.0, -0.1]])  # det F = -0.1
    with pytest.raises(InversionError):
        getattr(mat, fun)(F)
    F[:, :, 1, 2] = np.array([[1.0, 0.0], [0.0, np.nan]])
    with pytest.raises(InversionError):
        getattr(mat, fun)(F)


@pytest.mark.parametrize("cls", [NeoHooke, SaintVenantKirchhoff])
@pytest.mark.parametrize("kwargs, word", [
    (dict(E=0.0, nu=0.3), "E"), (dict(E=-1.0, nu=0.3), "E"),
    (dict(E=1.0, nu=0.5), "nu"), (dict(E=1.0, nu=0.6), "nu"),
    (dict(E=1.0, nu=-1.0), "nu"), (dict(E=1.0, nu=float("nan")), "nu"),
    (dict(mu=0.0, lmbda=1.0), "mu"), (dict(mu=1.0, lmbda=-1.0), "lmbda"),
    (dict(E=1.0), "nu"), (dict(E=1.0, nu=0.3, mu=1.0), "either"),
])
def test_bad_parameters_raise_value_error(cls, kwargs, word):
    with pytest.raises(ValueError, match=word):
        cls(**kwargs)


def test_lame_constants_round_trip():
    mu, lam = lame_from_young(210.0, 0.3)
    assert mu == pytest.approx(210.0 / 2.6, rel=1e-15)
    assert lam == pytest.approx(210.0 * 0.3 / (1.3 * 0.4), rel=1e-15)
    m = NeoHooke(mu=mu, lmbda=lam)
    assert m.E == pytest.approx(210.0, rel=1e-14) and m.nu == pytest.approx(0.3, rel=1e-14)


def test_lame_from_young_names_its_order_mu_first():
    """``lame_from_young`` returns (mu, lmbda) with named fields; scikit-fem's
    ``lame_parameters`` returns the same two numbers the other way round."""
    from skfem.models.elasticity import lame_parameters

    from skfem_mortar.bodies.materials import Lame

    lame = lame_from_young(200.0, 0.3)
    assert isinstance(lame, Lame)
    mu, lmbda = lame
    assert (lame.mu, lame.lmbda) == (mu, lmbda)
    assert lame_parameters(200.0, 0.3) == pytest.approx((lmbda, mu), rel=1e-15)
