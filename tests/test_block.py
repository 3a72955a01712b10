"""Scene ``block``: the homogeneous uniaxial state, exact on any mesh (benchmarks section 1)."""
import math

import numpy as np
import pytest

from skfem_mortar.bodies.materials import NeoHooke, SaintVenantKirchhoff
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.app.runner import build_scene, run_scene
from skfem_mortar.scenes.block import block_mesh, exact_uniaxial, svk_stretch_range

ELEMENTS = ["tri1", "tri2", "quad1", "quad2"]
ERRORS = ("nominal_stress_error", "lateral_stretch_error", "max_stress_error")


@pytest.mark.parametrize("element", ELEMENTS)
@pytest.mark.parametrize("params", [
    dict(material="neo-hooke", stretch=0.5),
    dict(material="neo-hooke", stretch=2.0),
    dict(material="svk", stretch=0.8, nu=0.2),
    dict(material="svk", stretch=1.4, nu=0.2),
    dict(material="neo-hooke", stretch=1.5, nu=-0.5, E=7.0),
], ids=["nh-0.5", "nh-2.0", "svk-0.8", "svk-1.4", "nh-auxetic"])
def test_block_is_exact_to_round_off_on_distorted_meshes(element, params):
    summary = run_scene("block", dict(params, element=element, refine=2, distort=0.25),
                        steps=2, newton=NewtonOptions(rtol=1e-13))
    assert summary["converged"]
    m = summary["metrics"]
    # An affine displacement lies in every element space, so the discrete
    # solution is the exact one; what is left is the Newton tolerance (1e-13
    # relative residual) amplified by the condition number of K (~1e2-1e3 on
    # this small mesh) plus round-off: measured <= 2e-13, so 1e-10 is a safe bound
    # that a real discretization error (>= 1e-4 here) would violate.
    for key in ERRORS:
        assert m[key] <= 1e-10, (key, m)
    assert m["nominal_stress_exact"] == pytest.approx(m["nominal_stress"], rel=1e-10)


@pytest.mark.parametrize("element", ["tri1", "quad2"])
@pytest.mark.parametrize("stretch", [0.1, 10.0])
def test_extreme_stretch_of_nearly_incompressible_block(element, stretch):
    """nu = 0.49 and stretch 0.1 or 10 in one nominal step (the solver cuts it as needed)."""
    summary = run_scene("block", dict(element=element, stretch=stretch, nu=0.49, refine=2),
                        steps=1, newton=NewtonOptions(rtol=1e-13))
    assert summary["converged"]
    # near incompressibility (lambda / mu = 50) makes K worse conditioned than in the
    # round-off test above; the measured errors stay below 1e-11, the bound leaves 100x
    for key in ERRORS:
        assert summary["metrics"][key] <= 1e-9, (key, summary["metrics"])


def test_exact_uniaxial_small_strain_limit():
    """For lx = 1 + eps: P_xx = E / (1 - nu^2) eps and ly = 1 - nu / (1 - nu) eps (plane strain)."""
    E, nu, eps = 3.0, 0.3, 1e-6
    for mat in (NeoHooke(E=E, nu=nu), SaintVenantKirchhoff(E=E, nu=nu)):
        ly, pxx = exact_uniaxial(mat, 1.0 + eps)
        # the next term of the expansion is O(eps^2): relative O(eps) = 1e-6
        assert pxx == pytest.approx(E / (1 - nu ** 2) * eps, rel=1e-5)
        assert (ly - 1.0) == pytest.approx(-nu / (1 - nu) * eps, rel=1e-5)


@pytest.mark.parametrize("mat, lx", [(NeoHooke(E=1.0, nu=0.3), 2.0),
                                     (NeoHooke(E=1.0, nu=0.45), 0.3),
                                     (NeoHooke(E=1.0, nu=-0.6), 1.7),
                                     (SaintVenantKirchhoff(E=1.0, nu=0.2), 1.4)])
def test_exact_uniaxial_solves_the_scalar_conditions(mat, lx):
    """Check the returned (ly, P_xx) against the formulas of benchmarks section 1,
    written out here independently of the material classes."""
    ly, pxx = exact_uniaxial(mat, lx)
    mu, lam = mat.mu, mat.lmbda
    if isinstance(mat, NeoHooke):
        assert mu * (ly ** 2 - 1) + lam * math.log(lx * ly) == pytest.approx(0.0, abs=1e-14)
        assert pxx == pytest.approx(mu * (lx - 1 / lx) + lam * math.log(lx * ly) / lx, rel=1e-14)
        assert (ly - 1) * (lx - 1) * mat.nu <= 0  # contracts laterally iff nu > 0
    else:
        exx, eyy = (lx ** 2 - 1) / 2, (ly ** 2 - 1) / 2
        assert lam * (exx + eyy) + 2 * mu * eyy == pytest.approx(0.0, abs=1e-14)
        assert pxx == pytest.approx(lx * (lam * (exx + eyy) + 2 * mu * exx), rel=1e-14)


def test_svk_range_and_out_of_range_values_raise():
    low, high = svk_stretch_range(0.25)
    assert low == pytest.approx(1 / math.sqrt(3)) and high == pytest.approx(2.0)
    assert svk_stretch_range(0.0)[1] == math.inf
    for stretch, nu in [(2.0, 0.3), (2.0, 0.25), (0.5, 0.2), (0.57, 0.0)]:
        with pytest.raises(ValueError, match="stretch must lie in"):
            build_scene("block", dict(material="svk", stretch=stretch, nu=nu))


@pytest.mark.parametrize("name, value", [("nu", 0.5), ("nu", 0.7), ("nu", -1.0), ("nu", -2.0),
                                         ("E", 0.0), ("E", -1.0), ("stretch", 0.0),
                                         ("distort", 0.3), ("refine", -1),
                                         ("material", "mooney"), ("element", "tri3")])
def test_bad_parameters_raise_value_error_naming_them(name, value):
    with pytest.raises(ValueError, match=name):
        build_scene("block", {name: value})


@pytest.mark.parametrize("name, value", [("nu", 0.5), ("nu", -1.0), ("E", 0.0),
                                         ("distort", 0.3)])
def test_build_checks_parameters_when_called_directly(name, value):
    from skfem_mortar.scenes.block import SCENE
    params = SCENE.resolve({})
    params[name] = value
    with pytest.raises(ValueError, match=name):
        SCENE.build(params, None)


@pytest.mark.parametrize("kind", ["tri", "quad"])
def test_distorted_mesh_keeps_boundary_and_positive_areas(kind):
    ref = block_mesh(kind, 3, 0.0)
    mesh = block_mesh(kind, 3, 0.29)
    on_boundary = ref.boundary_nodes()
    np.testing.assert_array_equal(mesh.p[:, on_boundary], ref.p[:, on_boundary])
    moved = np.linalg.norm(mesh.p - ref.p, axis=0)
    assert moved.max() <= 0.29 / 8 + 1e-15 and moved.max() > 0.1 / 8
    # every corner triangle keeps the orientation it had before the distortion
    # (skfem does not orient all cells alike); for quads this means convex cells
    nc = mesh.t.shape[0]

    def corner_areas(m):
        out = []
        for i in range(nc):
            a, b, c = (m.p[:, m.t[(i + k) % nc]] for k in range(3))
            out.append((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
        return np.array(out)

    assert np.all(corner_areas(mesh) * corner_areas(ref) > 0)


def test_newton_converges_quadratically_in_one_step():
    """A consistent tangent gives quadratic convergence: at most 7 iterations for
    the neo-Hookean block stretched to 2 in a single load step (measured: 5)."""
    s = run_scene("block", dict(stretch=2.0), steps=1)
    (step,) = s["steps"]
    assert step["newton_iterations"] <= 7
    r = step["residual_norms"]
    # in the last iterations the error is squared: r_k <= C r_{k-1}^2
    assert r[-1] <= 10.0 * r[-2] ** 2 / r[0]


def test_run_writes_output(tmp_path):
    run_scene("block", dict(refine=1), steps=2, out=tmp_path)
    assert (tmp_path / "block.pvd").exists() and (tmp_path / "summary.json").exists()
