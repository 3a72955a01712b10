"""The laws on a 3 x 3 deformation gradient (3D bodies, and 2D bodies with their
out-of-plane stretch, the axisymmetric hoop): exact tangents, the energy's
derivative, and the plane-strain 2D law as the 3 x 3 one at ``F_zz = 1``."""
import numpy as np
import pytest

from skfem_mortar.bodies.hyperelastic import NeoHooke, SaintVenantKirchhoff
from skfem_mortar.bodies.material import LinearElastic

LAWS = [NeoHooke(E=10.0, nu=0.3), SaintVenantKirchhoff(E=10.0, nu=0.3),
        LinearElastic(E=10.0, nu=0.3)]

#: central differences of step 1e-6 on stresses of size 10: truncation 1e-12 * |P'''|,
#: round-off 1e-16 * 10 / 1e-6 = 1e-9; 1e-7 of the tangent's size leaves room for both
FD_RTOL = 1e-7


def _central(f, F, k, L, h=1e-6):
    """``(f(F + h e_kL) - f(F - h e_kL)) / 2h``."""
    Fp, Fm = F.copy(), F.copy()
    Fp[k, L] += h
    Fm[k, L] -= h
    return (f(Fp) - f(Fm)) / (2 * h)


def _F(n=5, seed=0):
    rng = np.random.default_rng(seed)
    return np.eye(3)[:, :, None] + 0.2 * rng.standard_normal((3, 3, n))


@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
def test_tangent_3d_matches_finite_differences(law):
    F = _F()
    P, A = law.stress_and_tangent(F)
    assert P.shape == (3, 3, 5) and A.shape == (3, 3, 3, 3, 5)
    for k in range(3):
        for L in range(3):
            fd = _central(law.stress, F, k, L)
            assert np.abs(fd - A[:, :, k, L]).max() <= FD_RTOL * np.abs(A).max()


@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
def test_stress_3d_is_the_energy_derivative(law):
    F = _F(seed=1)
    P = law.stress(F)
    for k in range(3):
        for L in range(3):
            fd = _central(law.energy, F, k, L)
            assert np.abs(fd - P[k, L]).max() <= FD_RTOL * np.abs(P).max()


@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
def test_plane_strain_is_3d_at_unit_out_of_plane_stretch(law):
    F2 = _F(seed=2)[:2, :2]
    F3 = np.zeros((3, 3, 5))
    F3[:2, :2] = F2
    F3[2, 2] = 1.0
    P2, A2 = law.stress_and_tangent(F2)
    P3, A3 = law.stress_and_tangent(F3)
    # the same formulas summed in another order: round-off of the stress size
    tol = 1e-13 * np.abs(A3).max()
    assert np.abs(P3[:2, :2] - P2).max() <= tol
    assert np.abs(A3[:2, :2, :2, :2] - A2).max() <= tol
    assert np.allclose(law.energy(F3), law.energy(F2), rtol=1e-13, atol=0)
    s2, szz2 = law.cauchy(F2)
    s3, szz3 = law.cauchy(F3)
    assert np.allclose(s3[:2, :2], s2, rtol=0, atol=tol) and np.allclose(szz3, szz2, atol=tol)
    assert np.allclose(law.von_mises(F3), law.von_mises(F2), rtol=1e-12, atol=0)


def test_von_mises_3d_pure_shear_and_uniaxial():
    law = LinearElastic(E=10.0, nu=0.3)
    F = np.eye(3)[:, :, None].copy()
    F[1, 2, 0] = F[2, 1, 0] = 1e-3           # eps_yz = 1e-3: tau = 2 mu eps, vm = sqrt(3) tau
    tau = 2 * law.mu * 1e-3
    assert np.isclose(law.von_mises(F)[0], np.sqrt(3) * tau, rtol=1e-12)
