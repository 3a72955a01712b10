"""TiePair in 3D (issue 38): the glued patch exact on non-matching tri3/quad4 interfaces,
the tangent against finite differences, outputs with x, y, z, the slave nodes of a
clamped face merged (the saddle point nonsingular), a killed run resumed."""
from __future__ import annotations

import numpy as np
import pytest

from fd import dense, fd_tangent
from resume_tools import assert_resumes, checkpoint_moments
from skfem_mortar import Dirichlet, LinearElastic, Model, Solid, TiePair, solve
from skfem_mortar.app.runner import run_scene
from skfem_mortar.contact.surfaces import ContactSurface
from skfem_mortar.contact.tie import TieOutput
from skfem_mortar.loads.traction import Traction
from skfem_mortar.scenes._contact3d import grid_mesh
from skfem_mortar.solver.newton import NewtonOptions

E, NU, P = 100.0, 0.3, 1.0
#: upper (slave) / lower (master) elements: tri3 on tri3, tri3 on quad4, quad4 on tri3,
#: quad4 on quad4 interface faces
PAIRINGS = [("tet1", "tet1"), ("tet1", "hex1"), ("hex1", "tet1"), ("hex1", "hex1")]


def _block(element, n, z0, z1, name):
    """``[0, 1]^2 x [z0, z1]`` in ``n x n x max(1, n // 2)`` cells, tagged."""
    mesh = grid_mesh(element, np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1),
                     np.linspace(z0, z1, max(1, n // 2) + 1))
    mesh = mesh.with_boundaries({
        "bottom": lambda x: np.isclose(x[2], z0), "top": lambda x: np.isclose(x[2], z1),
        "x0": lambda x: np.isclose(x[0], 0.0), "y0": lambda x: np.isclose(x[1], 0.0)})
    return Solid(mesh, LinearElastic(E=E, nu=NU), element, name=name, kinematics="small")


def _glued(upper, lower, dual, n_upper=5, n_lower=4):
    """Two blocks glued along ``z = 1/2`` (the upper one's bottom the slave), the lower
    one on rollers (``z = 0``, ``x = 0``, ``y = 0``), the upper one pulled by ``P``
    on its top: uniaxial tension, ``sigma_zz = P`` everywhere."""
    lo = _block(lower, n_lower, 0.0, 0.5, "lower")
    up = _block(upper, n_upper, 0.5, 1.0, "upper")
    tie = TiePair(ContactSurface.from_solid(up, "bottom"),
                  ContactSurface.from_solid(lo, "top"), dual=dual, name="tie")
    items = [lo, up, tie, Dirichlet(lo, lo.dofs_on("bottom", "z")),
             Dirichlet(lo, lo.dofs_on("x0", "x")), Dirichlet(lo, lo.dofs_on("y0", "y")),
             Traction(up, "top", [0.0, 0.0, P])]
    return lo, up, tie, items


# -------------------------------------------------------------------- the patch test
@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("upper,lower", PAIRINGS)
def test_glued_patch_is_exact_on_non_matching_faces(upper, lower, dual):
    """Uniform tension across a non-matching interface (5 x 5 over 4 x 4 squares): the
    multipliers are the traction ``(0, 0, -P)`` the lower block exerts on the upper
    one, the displacement the homogeneous one, at every node.  A linear solve of ~600
    dofs: round-off of the saddle point's solve, measured 2e-15 to 1.6e-14 with PARDISO
    and up to 1.3e-10 with SuperLU (its pivoting on the zero multiplier block), so 1e-9:
    a mesh error of the non-matching interface would be 1e-3."""
    lo, up, tie, items = _glued(upper, lower, dual)
    res = solve(Model(items, geometry="3d"), 1, newton=NewtonOptions(rtol=1e-13))
    d = tie.tie_data(res.z)
    assert d["tied"].all()
    lam = d["traction"]
    assert np.abs(lam - np.array([[0.0], [0.0], [-P]])).max() < 1e-9 * P
    assert np.abs(d["normal"] - P).max() < 1e-9 * P          # tension on the outward -z
    assert np.abs(d["shear"]).max() < 1e-9 * P
    for body in (lo, up):
        X = body.X
        exact = np.array([-NU * X[0], -NU * X[1], X[2]]) * P / E
        u = np.asarray(body.u(res.z))[body.node_dofs]
        assert np.abs(u - exact).max() < 1e-9 * P / E
    fs, fm = tie.forces(res.z)
    assert np.abs(fs.sum(axis=1) - [0.0, 0.0, -P]).max() < 1e-9 * P    # area 1
    assert np.abs(fs.sum(axis=1) + fm.sum(axis=1)).max() < 1e-14 * P


@pytest.mark.parametrize("dual", [False, True])
def test_tangent_matches_finite_differences_and_is_symmetric(dual):
    """The 3D tie's tangent against central differences of its residual at a random
    state.  The residual is linear in ``z``: central differences are exact but for
    round-off ``eps |R| / h ~ 1e-10`` of the largest entry, so 1e-8."""
    lo, up, tie, _ = _glued("tet1", "hex1", dual, 3, 2)
    model = Model([lo, up, tie], geometry="3d")
    z = 0.05 * np.random.default_rng(5).standard_normal(model.n)
    R, K = dense(tie.assemble(z, 1.0), model.n)
    assert np.abs(K - fd_tangent(tie, z, 1.0)).max() <= 1e-8 * np.abs(K).max()
    assert np.array_equal(K, K.T)
    assert tie.n_dofs == 3 * tie.slave.n_nodes


def test_dual_D_is_diagonal_and_the_supports_sum_to_the_area():
    """Dual multipliers: ``D`` diagonal on faces too; ``sum D = sum M`` = the interface
    area (1) to round-off, the reference gap zero (the two sides coincide)."""
    for dual in (False, True):
        _, _, tie, _ = _glued("hex1", "tet1", dual)
        D = tie.D.toarray()
        if dual:
            assert np.array_equal(D, np.diag(np.diag(D)))
        assert D.sum() == pytest.approx(1.0, abs=1e-14)
        assert tie.M.sum() == pytest.approx(1.0, abs=1e-14)
        assert np.abs(tie.reference_gap).max() < 1e-14


def test_outputs_have_three_coordinates_and_faces():
    lo, up, tie, items = _glued("tet1", "hex1", True, 3, 2)
    model = Model(items, geometry="3d")
    z = model.zeros()
    d = tie.tie_data(z)
    assert {"x", "y", "z"} <= set(d) and d["traction"].shape == (3, tie.slave.n_nodes)
    assert d["shear"].shape == (3, tie.slave.n_nodes)
    (out,) = tie.outputs()
    assert isinstance(out, TieOutput)
    points, cells = out.output_mesh()
    assert points.shape == (tie.slave.n_nodes, 3) and cells[0][0] == "triangle"
    pdata, _ = out.output_data(z)
    assert pdata["traction"].shape == (tie.slave.n_nodes, 3)
    assert pdata["shear"].shape == (tie.slave.n_nodes, 3)


# ------------------------------------------------------------ partly covered slave faces
@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("upper,lower", [("tet1", "hex1"), ("hex1", "tet1")])
@pytest.mark.parametrize("shift", [0.13, 0.2 - 1e-7])
def test_partly_covered_faces_keep_the_constraint_consistent(upper, lower, dual, shift):
    """The master block shifted by ``shift`` along x: the slave faces of the first
    column (h = 0.2) are covered over a strip of width 0.2 - shift (0.07, or 1e-7 of
    the face).  Where the two sides coincide the constraint holds for any linear
    field common to both, ``c_A = 0`` for every tied node (round-off: measured 2e-17
    to 5e-15 against entries of 0.04), with no NaN; the nodes of x = 0 on the 1e-7
    strip are masked (their support below MASK_TOL of their tributary area) and merged
    by the kernel's rule, the others tied."""
    up = _block(upper, 5, 0.5, 1.0, "upper")
    mesh = grid_mesh(lower, np.linspace(shift, 1.0 + shift, 5), np.linspace(0, 1, 5),
                     np.linspace(0.0, 0.5, 3))
    lo = Solid(mesh.with_boundaries({"top": lambda x: np.isclose(x[2], 0.5)}),
               LinearElastic(E=E, nu=NU), lower, name="lower", kinematics="small")
    tie = TiePair(ContactSurface.from_solid(up, "bottom"),
                  ContactSurface.from_solid(lo, "top"), dual=dual, name="tie")
    rng = np.random.default_rng(0)
    A, b = rng.standard_normal((3, 3)), rng.standard_normal((3, 1))
    c = (tie.D @ (A @ tie.slave.X + b).T - tie.M @ (A @ tie.master.X + b).T).T
    assert np.isfinite(tie.D.data).all() and np.isfinite(tie.M.data).all()
    assert np.abs(c).max() < 1e-12 * abs(tie.D).max()
    masked = np.isclose(tie.slave.X[0], 0.0) & (shift > 0.19)
    np.testing.assert_array_equal(tie.tied, ~masked)


# ------------------------------------------------------- where the interface is clamped
def _clamped(dual):
    """The glued blocks with the upper one's side ``x = 0`` clamped: slave nodes on the
    interface with prescribed dofs (the interface meets a clamped face)."""
    lo, up, tie, items = _glued("tet1", "hex1", dual, 3, 2)
    return lo, up, tie, items + [Dirichlet(up, up.dofs_on("x0"), name="clamp_upper")]


@pytest.mark.parametrize("dual", [False, True])
def test_slave_nodes_on_a_clamped_face_are_merged_and_the_saddle_point_is_nonsingular(dual):
    """The clamped slave nodes (``x = 0``) carry no multiplier: their functions are merged
    into the face's nearest kept nodes (the kernel's merge rule), their rows ``lam_A =
    0``.  The tangent restricted to the free dofs (153) has full rank: its smallest
    singular value over the largest is 7e-9 (standard) and 7e-8 (dual), the scale of a
    saddle point whose blocks are E h and h^2; tying those nodes too (no merge) leaves
    it singular, 9e-15 and 3e-24 (round-off: the clamp and the tie fix the same dofs
    twice).  The bounds 1e-10 and 1e-12 sit in the gap of six orders."""
    lo, up, tie, items = _clamped(dual)
    model = Model(items, geometry="3d")
    res = solve(model, 1, newton=NewtonOptions(rtol=1e-12))
    assert res.converged
    on_clamp = np.isclose(tie.slave.X[0], 0.0)
    np.testing.assert_array_equal(tie.tied, ~on_clamp)
    assert np.all(tie.traction(res.z)[:, on_clamp] == 0.0)

    def smallest_singular_value(model):
        _, K, _ = model.assemble(res.z, 1.0)
        free = np.setdiff1d(np.arange(model.n), model.prescribed(1.0)[0])
        s = np.linalg.svd(K[free][:, free].toarray(), compute_uv=False)
        return s[-1] / s[0]

    assert smallest_singular_value(model) > 1e-10
    tie.set_fixed(np.zeros(0, dtype=np.int64))     # every slave node tied again
    assert tie.tied.all()
    assert smallest_singular_value(model) < 1e-12


# ---------------------------------------------------------------- checkpoint and resume
def test_a_tied_3d_run_killed_and_resumed_ends_as_the_whole_run(tmp_path):
    """tied3d at finite strain in 3 steps, killed while writing its second checkpoint
    and resumed: the same frames (the tie's series with the multipliers included) and
    the same summary as the uninterrupted run (resume_tools: to the last bit with
    SuperLU, 1e-10 with PARDISO's reused analysis)."""
    def run(out, resume=False):
        return run_scene("tied3d", {"kinematics": "finite", "multipliers": "dual"},
                         steps=3, out=out, resume=resume)

    assert_resumes(run, tmp_path, lambda log: checkpoint_moments(log)[1:2])
    assert (tmp_path / "ref" / "tie.pvd").exists()
