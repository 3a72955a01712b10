"""Plane stress: the condensed laws (S_zz = 0), their tangents, the block against the
analytic plane-stress answer, and the bodies that refuse it."""
import math

import numpy as np
import pytest
from skfem import MeshQuad, MeshTri

from fd import dense, fd_tangent
from skfem_mortar.app.runner import run_scene
from skfem_mortar.bodies.materials import (LinearElastic, NeoHooke, SaintVenantKirchhoff,
                                           plane_stress_lambda)
from skfem_mortar.bodies.mixed import MixedSolid
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.bodies.sri import SRISolid
from skfem_mortar.core.model import Model
from skfem_mortar.scenes.block import exact_uniaxial
from skfem_mortar.solver.newton import NewtonOptions

LAWS = [NeoHooke(E=3.0, nu=0.3), SaintVenantKirchhoff(E=3.0, nu=0.2), LinearElastic(E=3.0, nu=0.3),
        NeoHooke(mu=1.0, lmbda=-0.5)]
IDS = ["neo-hooke", "svk", "linear", "neo-hooke-auxetic"]


def random_F(shape=(3, 4), amp=0.3, seed=0):
    rng = np.random.default_rng(seed)
    F = np.eye(2).reshape(2, 2, 1, 1) + amp * rng.standard_normal((2, 2) + shape)
    assert np.all(F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0] > 0.2)
    return F


def central_differences(fun, F, h=1e-6):
    """``(k, L, d fun / d F_kL)`` for the four entries of ``F``, by central differences."""
    for k in range(2):
        for L in range(2):
            dF = np.zeros_like(F)
            dF[k, L] = h
            yield k, L, (fun(F + dF) - fun(F - dF)) / (2 * h)


@pytest.mark.parametrize("mat", LAWS, ids=IDS)
def test_condensed_tangent_matches_central_differences(mat):
    law = mat.with_plane("stress")
    F = random_F()
    P, A = law.stress_and_tangent(F)
    for k, L, fd in central_differences(law.stress, F):
        # central differences: truncation h^2 |d3P| ~ 1e-12, round-off
        # eps |P| / h ~ 1e-10; the out-of-plane stretch is solved to round-off
        # at each evaluation, so 1e-7 is far above both and far below the
        # change the condensation makes (lambda^2 / W_yy ~ 1)
        np.testing.assert_allclose(A[:, :, k, L], fd, rtol=0, atol=1e-7)
    # the condensed tangent differs from the uncondensed (plane-strain) formula
    assert np.abs(A - mat.tangent(F)).max() > 0.1


@pytest.mark.parametrize("mat", LAWS, ids=IDS)
def test_plane_stress_stress_is_derivative_of_condensed_energy(mat):
    law = mat.with_plane("stress")
    F = random_F(seed=1)
    P = law.stress(F)
    for k, L, fd in central_differences(law.energy, F):
        # as above: h^2 |d3W| and eps |W| / h both below 1e-9
        np.testing.assert_allclose(P[k, L], fd, rtol=0, atol=1e-8)


def test_neo_hooke_plane_stress_has_zero_out_of_plane_3d_stress():
    """The 3D neo-Hookean P_zz = mu (y - 1/y) + lambda ln(J y) / y vanishes at the
    solved stretch y = F_zz, and the in-plane P is the 3D one at F_3 = diag(F, y)."""
    mat = NeoHooke(E=2.0, nu=0.35)
    law = mat.with_plane("stress")
    F = random_F(seed=2)
    y = law.stretch_zz(F)
    J = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
    mu, lam = mat.mu, mat.lmbda
    Pzz = mu * (y - 1 / y) + lam * np.log(J * y) / y
    # a residual of the scalar Newton iteration, stopped at 4 eps relative updates
    np.testing.assert_allclose(Pzz, 0.0, atol=1e-14)
    Fi = np.linalg.inv(np.moveaxis(F, (0, 1), (-2, -1)))           # (..., 2, 2)
    FiT = np.moveaxis(np.swapaxes(Fi, -1, -2), (-2, -1), (0, 1))
    P3 = mu * (F - FiT) + lam * np.log(J * y) * FiT
    np.testing.assert_allclose(law.stress(F), P3, rtol=1e-13, atol=1e-14)
    s, szz = law.cauchy(F)
    assert np.all(szz == 0.0)
    np.testing.assert_allclose(s, np.einsum("iJ...,kJ...->ik...", P3, F) / (J * y), rtol=1e-13)


@pytest.mark.parametrize("mat", [NeoHooke(E=3.0, nu=0.3), SaintVenantKirchhoff(E=3.0, nu=0.3)],
                         ids=["neo-hooke", "svk"])
def test_plane_stress_tangent_at_the_reference_state_is_lambda_star(mat):
    """At F = I every plane-stress law has the linear tangent with lambda* = 2 lambda mu /
    (lambda + 2 mu) = E nu / (1 - nu^2)."""
    A = mat.with_plane("stress").tangent(np.eye(2)[:, :, None])[..., 0]
    lam_star = plane_stress_lambda(mat.mu, mat.lmbda)
    assert lam_star == pytest.approx(3.0 * 0.3 / (1 - 0.3 ** 2), rel=1e-14)
    ref = LinearElastic(mu=mat.mu, lmbda=mat.lmbda).with_plane("stress").tangent(
        np.eye(2)[:, :, None])[..., 0]
    np.testing.assert_allclose(A, ref, rtol=0, atol=1e-14)


@pytest.mark.parametrize("element", ["tri1", "quad2"])
@pytest.mark.parametrize("mat", [NeoHooke(E=1.0, nu=0.3),
                                 SaintVenantKirchhoff(E=1.0, nu=0.3),
                                 LinearElastic(E=1.0, nu=0.3)], ids=["nh", "svk", "linear"])
def test_solid_plane_stress_tangent_matches_central_differences(element, mat):
    mesh = (MeshTri() if element.startswith("tri") else MeshQuad()).refined(1)
    solid = Solid(mesh, mat, element, plane="stress")
    rng = np.random.default_rng(3)
    z = 0.02 * rng.standard_normal(solid.n_dofs)   # small enough to invert nothing
    _, K = dense(solid.assemble(z, 1.0), solid.n_dofs)
    # the fd helper's central differences (1e-10 relative round-off, O(h^2) truncation);
    # entries of K are O(1): 1e-7 separates a wrong term (O(1)) from both
    np.testing.assert_allclose(K, fd_tangent(solid, z, 1.0), rtol=0, atol=1e-7)


@pytest.mark.parametrize("element", ["tri1", "quad1", "quad2"])
@pytest.mark.parametrize("params", [dict(material="neo-hooke", stretch=1.6),
                                    dict(material="neo-hooke", stretch=0.6, nu=0.45),
                                    dict(material="svk", stretch=1.4, nu=0.3),
                                    dict(material="svk", stretch=0.8, nu=0.2)],
                         ids=["nh-1.6", "nh-0.6", "svk-1.4", "svk-0.8"])
def test_block_in_plane_stress_is_exact_to_round_off(element, params):
    summary = run_scene("block", dict(params, element=element, plane="stress", refine=2,
                                      distort=0.25),
                        steps=2, newton=NewtonOptions(rtol=1e-13))
    assert summary["converged"]
    m = summary["metrics"]
    # an affine field lies in every element space: what is left is the Newton
    # tolerance (1e-13) times the condition number of K (~1e3) plus round-off,
    # measured <= 1e-13; a real discretization error (>= 1e-4 here) fails 1e-10
    for key in ("nominal_stress_error", "lateral_stretch_error", "max_stress_error"):
        assert m[key] <= 1e-10, (key, m)


@pytest.mark.parametrize("mat, lx", [(NeoHooke(E=1.0, nu=0.3), 1.6),
                                     (NeoHooke(E=1.0, nu=0.45), 0.6),
                                     (NeoHooke(E=1.0, nu=-0.4), 1.5),
                                     (SaintVenantKirchhoff(E=1.0, nu=0.3), 1.4)])
def test_exact_plane_stress_uniaxial_solves_the_3d_conditions(mat, lx):
    """The returned (ly, P_xx) against the 3D conditions written out here: F = diag(lx, ly, lz)
    with S_yy = S_zz = 0, so lz = ly by isotropy."""
    ly, pxx = exact_uniaxial(mat.with_plane("stress"), lx)
    mu, lam = mat.mu, mat.lmbda
    if isinstance(mat, NeoHooke):
        lnJ = math.log(lx * ly * ly)
        assert mu * (ly - 1 / ly) + lam * lnJ / ly == pytest.approx(0.0, abs=1e-14)
        assert pxx == pytest.approx(mu * (lx - 1 / lx) + lam * lnJ / lx, rel=1e-14)
    else:
        exx, eyy = (lx ** 2 - 1) / 2, (ly ** 2 - 1) / 2
        # 3D SVK: S_yy = lambda (E_xx + E_yy + E_zz) + 2 mu E_yy = 0 with E_zz = E_yy
        assert lam * (exx + 2 * eyy) + 2 * mu * eyy == pytest.approx(0.0, abs=1e-14)
        assert pxx == pytest.approx(lx * (lam * (exx + 2 * eyy) + 2 * mu * exx), rel=1e-14)


def test_plane_stress_output_has_zero_sigma_zz_and_the_thickness_stretch():
    mesh = MeshTri().refined(1)
    solid = Solid(mesh, NeoHooke(E=1.0, nu=0.3), plane="stress")
    model = Model([solid])
    z = model.zeros()
    z[solid.dofs] = solid.interpolate(lambda X: np.vstack([0.2 * X[0], -0.05 * X[1]]))
    _, cells = solid.output_data(z)
    assert np.all(cells["sigma_zz"][0] == 0.0)
    y = cells["stretch_zz"][0]
    assert np.all(y < 1.0)       # stretched in x: the sheet gets thinner
    assert "stretch_zz" not in Solid(mesh, NeoHooke(E=1.0, nu=0.3)).output_data(z)[1]


NH, LIN = NeoHooke(E=1.0, nu=0.3), LinearElastic(E=1.0, nu=0.3)
REFUSED = {  # body, material, option -> the message
    "solid-plane": (Solid, NH, {"plane": "membrane"}, "plane must be one of 'strain', 'stress'"),
    "mixed-stress": (MixedSolid, NH, {"plane": "stress"}, "plane must be .strain. for a Mixed"),
    "sri-stress": (SRISolid, NH, {"plane": "stress"}, "plane must be 'strain' for a SRISolid"),
    "solid-kinematics": (Solid, NH, {"kinematics": "large"}, "kinematics must be one of"),
    "linear-finite": (Solid, LIN, {"kinematics": "finite"}, "kinematics must be 'small' for a Lin"),
    "mixed-kinematics": (MixedSolid, NH, {"kinematics": "large"}, "kinematics must be one of"),
    "sri-linear-finite": (SRISolid, LIN, {"kinematics": "finite"}, "kinematics must be 'small' for"),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_bodies_refuse_the_options_they_do_not_have(case):
    body, material, option, message = REFUSED[case]
    mesh = (MeshQuad() if body is SRISolid else MeshTri()).refined(1)
    with pytest.raises(ValueError, match=message):
        body(mesh, material, **option)


def test_material_refuses_an_unknown_plane():
    with pytest.raises(ValueError, match="plane must be one of 'strain', 'stress'"):
        NH.with_plane("3d")


def test_block_scene_refuses_an_unknown_plane():
    with pytest.raises(ValueError, match="parameter 'plane' must be one of strain, stress"):
        run_scene("block", {"plane": "shell"})
