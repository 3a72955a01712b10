"""MINI (:class:`~skfem_mortar.bodies.mixed.MixedSolid`) and the one-point volumetric
quads (:class:`~skfem_mortar.bodies.sri.SRISolid`) for every law of
:mod:`skfem_mortar.bodies.volumetric` (NeoHooke, SaintVenantKirchhoff, LinearElastic),
finite and small strain, plane strain and axisymmetric: exact tangents, homogeneous
deformations reproduced to round-off on distorted meshes, and the split's forms equal
to the closed NeoHooke forms the finite-strain NeoHooke bodies keep."""
import numpy as np
import pytest
from skfem import MeshQuad, MeshTri

from skfem_mortar import Model
from skfem_mortar.bodies.hyperelastic import NeoHooke, SaintVenantKirchhoff
from skfem_mortar.bodies.material import LinearElastic
from skfem_mortar.bodies.mixed import (MixedSolid, mixed_axisymmetric, mixed_split,
                                       mixed_stress_and_tangent)
from skfem_mortar.bodies.sri import SRISolid
from skfem_mortar.bodies.volumetric import VolumetricSplit
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.solver.stepping import solve

E = 10.0
#: law name -> (material class, kinematics)
LAWS = {"neohooke": (NeoHooke, "finite"), "svk": (SaintVenantKirchhoff, "finite"),
        "neohooke-small": (NeoHooke, "small"), "svk-small": (SaintVenantKirchhoff, "small"),
        "linear": (LinearElastic, "small")}
BODIES = {"mini": (MixedSolid, MeshTri), "sri": (SRISolid, MeshQuad)}
GEOMETRIES = ("plane", "axisymmetric")


def distorted(M, n: int = 4, seed: int = 1):
    """``[0, 1]^2`` on an ``n x n`` grid, interior nodes moved at random by up to 0.2 h
    in each direction (the left edge is the axis in an axisymmetric model)."""
    m = M.init_tensor(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    p = m.p.copy()
    tol = 1e-9
    inner = (p[0] > tol) & (p[0] < 1 - tol) & (p[1] > tol) & (p[1] < 1 - tol)
    p[:, inner] += 0.2 / n * np.random.default_rng(seed).uniform(-1, 1, (2, inner.sum()))
    return M(p, m.t).with_defaults()


def make(body: str, law: str, nu: float, n: int = 4):
    """The body on a distorted ``n x n`` mesh."""
    cls, M = BODIES[body]
    mat, kin = LAWS[law]
    return cls(distorted(M, n), mat(E=E, nu=nu), kinematics=kin, name=body)


def random_state(model, b, scale: float, seed: int = 0) -> np.ndarray:
    """Displacements of ``scale`` (pressures of ``scale`` E for MINI), the axis held."""
    rng = np.random.default_rng(seed)
    z = scale * rng.standard_normal(model.n)
    if isinstance(b, MixedSolid):
        z[b.offset + b.pressure_dofs()] *= E / b.pressure_scale
    held = b.prescribed(1.0)
    if held is not None:
        z[held[0]] = 0.0
    return z


@pytest.mark.parametrize("geometry", GEOMETRIES)
@pytest.mark.parametrize("law", sorted(LAWS))
@pytest.mark.parametrize("body", sorted(BODIES))
def test_tangent_is_the_residual_derivative(body, law, geometry):
    b = make(body, law, 0.45)
    model = Model([b], geometry=geometry)
    z = random_state(model, b, 0.005)          # strains of a few percent
    r, K, _ = model.assemble(z, 1.0)
    rng = np.random.default_rng(3)
    dz = rng.standard_normal(model.n)
    held = b.prescribed(1.0)
    if held is not None:
        dz[held[0]] = 0.0
    h = 1e-6
    fd = (model.assemble(z + h * dz, 1.0, tangent=False)[0]
          - model.assemble(z - h * dz, 1.0, tangent=False)[0]) / (2 * h)
    Kdz = K @ dz
    # central differences: truncation h^2 |r'''| ~ 1e-12, round-off eps |r| / h ~ 1e-10
    # relative; measured 3.1e-9 at most (MINI, SVK, axisymmetric), 3e-12 at small strain
    # (linear: round-off only).  Dropping the hoop row of g, the hoop entry of MINI's
    # strain, p d2q/dF2 or U' d2m/dF2 fails 4 to 9 of these cases: 1e-7 tells them apart
    assert np.abs(fd - Kdz).max() <= 1e-7 * np.abs(Kdz).max()
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()          # symmetric: an energy's


#: u = (a x, c y): in an axisymmetric model u_r = a r, u_z = c z, F = diag(1 + a, 1 + c,
#: 1 + a); large enough that the finite-strain laws are far from linear
HOMOGENEOUS = {"radial": (0.1, 0.0), "axial": (0.0, 0.2), "both": (0.1, -0.15)}


@pytest.mark.parametrize("geometry", GEOMETRIES)
@pytest.mark.parametrize("law", sorted(LAWS))
@pytest.mark.parametrize("body", sorted(BODIES))
def test_homogeneous_deformation_is_reproduced(body, law, geometry):
    """The exact displacements on the boundary (off the axis): the discrete solution is
    the exact field at every node (MINI: its bubbles 0, its pressure ``lambda q(F)``),
    each of the three states of :data:`HOMOGENEOUS` in turn, at nu = 0.49."""
    b = make(body, law, 0.49)
    n_u = getattr(b, "n_u", b.n_dofs)
    for a, c in HOMOGENEOUS.values():
        exact = b.interpolate(lambda X: np.stack([a * X[0], c * X[1]]))
        held = b.dofs_on(b.mesh.boundary_facets())
        model = Model([b, Dirichlet(b, held, exact[held], name="edges")], geometry=geometry)
        result = solve(model, n_steps=1)
        assert result.converged
        u = result.z[b.offset:b.offset + n_u]
        # round-off of one or two Newton iterations on ~100 dofs (lambda / mu = 49):
        # measured 6e-14 of the displacement, 5e-13 of the pressure; bounds 1e-12, 1e-11
        assert np.abs(u - exact[:n_u]).max() <= 1e-12 * np.abs(exact).max()
        if body == "mini":
            F = np.diag([1 + a, 1 + c, 1 + a] if geometry != "plane" else [1 + a, 1 + c])
            q = b.split.log_measure(F[..., None], False)[0][0]
            assert np.allclose(b.pressure(result.z), b.split.lmbda * q, rtol=1e-11, atol=0)


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_mini_split_equals_the_neohooke_closed_form(geometry):
    """:func:`mixed_split` of NeoHooke's split and the closed forms the finite-strain
    NeoHooke MINI keeps: the same numbers to round-off (measured 5e-16 relative)."""
    rng = np.random.default_rng(4)
    d = 2 if geometry == "plane" else 3
    F = np.eye(d)[:, :, None, None] + 0.1 * rng.standard_normal((d, d, 5, 3))
    if d == 3:
        F[:2, 2] = F[2, :2] = 0.0
    p = 0.3 * rng.standard_normal((5, 3))
    mat = NeoHooke(mu=1.3, lmbda=7.0)
    closed = mixed_stress_and_tangent if d == 2 else mixed_axisymmetric
    sig0, D0 = closed(F, p, mat.mu, mat.lmbda)
    sig1, D1 = mixed_split(F, p, VolumetricSplit(mat))
    assert np.abs(sig1 - sig0).max() <= 1e-14 * np.abs(sig0).max()
    assert np.abs(D1 - D0).max() <= 1e-14 * np.abs(D0).max()


@pytest.mark.parametrize("geometry", GEOMETRIES)
def test_sri_split_equals_the_neohooke_forms(geometry):
    """The split's mean dilatation (:meth:`SRISolid.assemble_split`) and the forms the
    finite-strain NeoHooke quads keep (plane: the centre rule; axisymmetric: the ring's
    mean dilatation): the same discrete energy, so the same residual and tangent to
    round-off (measured 1.2e-15 relative; 2 x 2 Gauss integrates ``J`` exactly)."""
    b = make("sri", "neohooke", 0.45)
    model = Model([b], geometry=geometry)
    z = random_state(model, b, 0.02)
    r0, K0, _ = model.assemble(z, 1.0)
    c = b.assemble_split(z)
    model.items[0].assemble = lambda z, lf, tangent=True: c      # the split's path
    r1, K1, _ = model.assemble(z, 1.0)
    assert np.abs(r1 - r0).max() <= 1e-13 * np.abs(r0).max()
    assert abs(K1 - K0).max() <= 1e-13 * abs(K0).max()
    np.testing.assert_allclose(b.internal_force(z), r0[b.dofs], rtol=0,
                               atol=1e-14 * np.abs(r0).max())


@pytest.mark.parametrize("law", ["svk", "linear"])
def test_mini_kernel_equals_the_skfem_forms(law):
    """MINI's batched kernel and the plain skfem forms of ``assemble_forms`` (plane) for
    the split's laws: two codings of the same sums, equal to round-off (measured 2e-16
    relative; bound 1e-12)."""
    b = make("mini", law, 0.45)
    model = Model([b])
    z = random_state(model, b, 0.01)
    r, K, _ = model.assemble(z, 1.0)
    r2, K2 = b.assemble_forms(z)
    assert np.abs(r - r2).max() <= 1e-12 * np.abs(r).max()
    assert abs(K - K2).max() <= 1e-12 * abs(K).max()


def test_plane_stress_stays_refused():
    for cls, M in BODIES.values():
        with pytest.raises(ValueError, match=f"plane must be 'strain' for a {cls.__name__}"):
            cls(M().refined(1), SaintVenantKirchhoff(E=1.0, nu=0.3), plane="stress")
