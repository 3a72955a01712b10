"""Mesh tying of non-matching meshes (skfem_mortar.contact.tie.TiePair) and the scene ``tied``."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
import skfem

from fd import dense, fd_tangent
from skfem_mortar import Dirichlet, Model, NeoHooke, Solid, TiePair, solve
from skfem_mortar.app.runner import build_scene, run_scene
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane
from skfem_mortar.contact.tie import TieOutput
from skfem_mortar.core.item import Output
from skfem_mortar.scenes.block import exact_uniaxial

MATERIAL = NeoHooke(E=100.0, nu=0.3)


def block(x0, x1, y0, y1, nx, ny, element, name):
    cls = skfem.MeshQuad if element == "quad1" else skfem.MeshTri
    mesh = cls.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    return Solid(mesh.with_defaults(), MATERIAL, element=element, name=name)


def stacked(n_top, n_bottom, element, dual):
    """Two blocks ``[0, 1] x [0, 0.5]`` (bottom, master) and ``[0, 1] x [0.5, 1]``
    (top, slave) with non-matching meshes, tied along ``y = 0.5``."""
    bottom = block(0.0, 1.0, 0.0, 0.5, n_bottom, 2, element, "bottom")
    top = block(0.0, 1.0, 0.5, 1.0, n_top, 3, element, "top")
    tie = TiePair(ContactSurface.from_solid(top, "bottom"),
                  ContactSurface.from_solid(bottom, "top"), dual=dual, name="tie")
    return bottom, top, tie


MESHES = [(7, 4), (4, 7), (5, 5)]  # slave finer, slave coarser, matching


# ------------------------------------------------------------------ patch tests
# Tolerance of the patch tests: Newton stops at a residual of 1e-10 of the
# step's force scale, so a uniform state comes out uniform to about that
# relative size (measured: the traction to 1.1e-11 in uniaxial tension, which
# is Newton's stopping error, 4e-15 with rtol = 1e-14; 1e-14 in the general
# case, the deformation gradient to 1e-15); 1e-9 leaves a margin.  A tie that is not exact errs by O(1e-2): NTS-like
# nodal tying on these meshes misses the patch test by 0.06 .. 0.15.
PATCH_TOL = 1e-9


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("element", ["quad1", "tri1"])
@pytest.mark.parametrize("n_top,n_bottom", MESHES)
def test_patch_uniaxial_tension_held_by_the_tie(dual, element, n_top, n_bottom):
    """Uniaxial tension through a non-matching tie (the top block is held by the tie
    alone: its rigid modes too): the homogeneous neo-Hookean state ``F = diag(lx, ly)``
    is exact, and the multiplier is the uniform nominal traction ``(0, -P_yy)``."""
    bottom, top, tie = stacked(n_top, n_bottom, element, dual)
    corner = int(np.argmin(np.hypot(*bottom.X)))
    stretch = 1.2
    model = Model([bottom, top, tie,
                   Dirichlet(bottom, bottom.dofs_on("bottom", "y"), 0.0),
                   Dirichlet(bottom, bottom.dofs_at_nodes([corner], "x"), 0.0),
                   Dirichlet(top, top.dofs_on("top", "y"), stretch - 1.0)])
    res = solve(model, n_steps=2)
    lx, pyy = exact_uniaxial(MATERIAL, stretch)   # the lateral stretch, the stress P_yy
    for body in (top, bottom):
        F = body.deformation_gradient(res.z)
        np.testing.assert_allclose(F[0, 0], lx, rtol=PATCH_TOL)
        np.testing.assert_allclose(F[1, 1], stretch, rtol=PATCH_TOL)
        np.testing.assert_allclose(F[0, 1], 0.0, atol=PATCH_TOL)
        np.testing.assert_allclose(F[1, 0], 0.0, atol=PATCH_TOL)
    assert tie.tied.all()
    lam = tie.traction(res.z)
    np.testing.assert_allclose(lam[0], 0.0, atol=PATCH_TOL * pyy)
    np.testing.assert_allclose(lam[1], -pyy, rtol=PATCH_TOL)
    np.testing.assert_allclose(tie.tie_data(res.z)["jump"], 0.0, atol=1e-13)  # lengths O(1)


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("element", ["quad1", "tri1"])
@pytest.mark.parametrize("n_top,n_bottom", MESHES)
def test_patch_general_homogeneous_state_with_crosspoints(dual, element, n_top, n_bottom):
    """A general homogeneous deformation (stretch, shear and rotation) prescribed on
    the outer boundary of both blocks: exact across the tie, and the traction is
    ``P N`` with ``N = (0, -1)`` the slave's outward normal.  The slave's end nodes
    lie on the prescribed sides: they are not tied (merged like crosspoints)."""
    bottom, top, tie = stacked(n_top, n_bottom, element, dual)
    Fh = np.array([[1.1, 0.15], [-0.05, 0.95]])
    items = [bottom, top, tie]
    for body, sides in ((bottom, ("left", "right", "bottom")), (top, ("left", "right", "top"))):
        dofs = np.unique(np.concatenate([body.dofs_on(s) for s in sides]))
        u = body.interpolate(lambda X: (Fh - np.eye(2)) @ X)
        items.append(Dirichlet(body, dofs, u[dofs], name=f"affine_{body.name}"))
    res = solve(Model(items), n_steps=2)
    for body in (top, bottom):
        np.testing.assert_allclose(body.deformation_gradient(res.z),
                                   np.broadcast_to(Fh[:, :, None, None],
                                                   body.deformation_gradient(res.z).shape),
                                   atol=PATCH_TOL)
    ends = np.isin(np.round(tie.slave.X[0], 12), (0.0, 1.0))
    np.testing.assert_array_equal(tie.tied, ~ends)
    P = MATERIAL.stress(Fh[:, :, None, None])[:, :, 0, 0]
    lam = tie.traction(res.z)
    scale = np.abs(P).max()
    np.testing.assert_allclose(lam[:, tie.tied], np.outer(-P[:, 1], np.ones(tie.tied.sum())),
                               atol=PATCH_TOL * scale)
    assert np.all(lam[:, ~tie.tied] == 0.0)  # untied multipliers are exact zeros


# ------------------------------------------------------------- the tangent (FD)
def quarter_ring(r0, r1, n_theta, n_r, element, name):
    """The quarter annulus ``r0 <= r <= r1``, ``0 <= theta <= pi / 2``, tagged
    ``inner``/``outer`` (a curved interface: the two sides' polygons differ)."""
    cls = skfem.MeshQuad if element == "quad1" else skfem.MeshTri
    m = cls.init_tensor(np.linspace(r0, r1, n_r + 1), np.linspace(0.0, 0.5 * np.pi, n_theta + 1))
    r, th = m.p
    mesh = cls(np.vstack([r * np.cos(th), r * np.sin(th)]), m.t)
    # facet midpoints lie inside the circle by the sagitta (< 0.02 here), the next
    # ring of facets a radial element (0.25) away
    mesh = mesh.with_boundaries({"inner": lambda x: np.abs(np.hypot(*x) - r0) < 0.05,
                                 "outer": lambda x: np.abs(np.hypot(*x) - r1) < 0.05})
    return Solid(mesh, MATERIAL, element=element, name=name)


def curved(dual, element="quad1"):
    inner = quarter_ring(1.0, 1.5, 5, 2, element, "inner")
    outer = quarter_ring(1.5, 2.0, 7, 2, element, "outer")
    tie = TiePair(ContactSurface.from_solid(outer, "inner"),
                  ContactSurface.from_solid(inner, "outer"), dual=dual, name="tie")
    return inner, outer, tie


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("shape", ["curved", "straight", "rigid"])
def test_tangent_matches_finite_differences_and_is_symmetric(dual, shape):
    """The tie's tangent against central differences of its residual, at a random
    state (displacements and multipliers), on a curved non-matching interface, a
    straight one, and glued to a rigid plane.  The residual is linear in ``z``, so
    central differences are exact but for round-off ``eps |R| / h ~ 1e-10`` of the
    largest entry: 1e-8.  Declared symmetric: equal to its transpose exactly."""
    if shape == "curved":
        a, b, tie = curved(dual)
        bodies = [a, b]
    elif shape == "straight":
        a, b, tie = stacked(5, 3, "tri1", dual)
        bodies = [a, b]
    else:
        b = block(0.0, 1.0, 0.0, 0.5, 4, 2, "quad1", "b")
        bodies = [b]
        plane = RigidPlane((0.5, 0.0), (0.0, 1.0), length=3.0, n_segments=3)
        tie = TiePair(ContactSurface.from_solid(b, "bottom"), plane, dual=dual)
    model = Model([*bodies, tie])
    rng = np.random.default_rng(3)
    z = 0.05 * rng.standard_normal(model.n)
    R, K = dense(tie.assemble(z, 1.0), model.n)
    Kfd = fd_tangent(tie, z, 1.0)
    assert np.abs(K - Kfd).max() <= 1e-8 * np.abs(K).max()
    assert np.array_equal(K, K.T)
    R0, _ = dense(tie.assemble(z, 1.0, tangent=False), model.n)
    np.testing.assert_array_equal(R0, R)                  # the trial evaluation is the same


def test_reference_gap_is_zero_on_a_straight_interface_and_small_on_a_curved_one():
    """``g0 = D X_s - M X_m`` (over the support): zero to round-off where the two sides
    coincide, of the size of the polygons' distance ``h^2 / (8 R)`` on the curved one
    (slave chord 0.22 long on R = 1.5: sagitta 4.2e-3; master chords 0.31: 8.2e-3)."""
    _, _, tie = stacked(7, 4, "quad1", False)
    assert np.abs(tie.reference_gap).max() < 1e-14
    _, _, tie = curved(False)
    g = np.hypot(*tie.reference_gap)
    assert 1e-4 < g.max() < 1e-2


# ------------------------------------------------------------------ conservation
@pytest.fixture(scope="module", params=["mortar", "mortar-dual"])
def bent(request):
    """The ``tied`` scene (a cantilever of two non-matching parts, finite rotation)."""
    out, result, setup = run_scene("tied", {"refine": 1}, method=request.param,
                                   return_result=True)
    return out, result, setup.model


def test_tie_forces_cancel_and_balance_the_load(bent):
    """The tie forces on the two sides sum to zero and so do their moments (current
    configuration; the interface is straight and coincident, ``g0 = 0``); the force
    on the right part balances its load.  Round-off: forces O(1) summed over ~20
    nodes, coordinates O(4): 1e-12 relative."""
    out, result, model = bent
    tie = model.item("tie")
    z = result.z
    fs, fm = tie.forces(z)
    xs, xm = tie.slave.x(z), tie.master.x(z)
    scale = np.abs(fs).max()
    np.testing.assert_allclose(fs.sum(axis=1) + fm.sum(axis=1), 0.0, atol=1e-12 * scale)
    moment = (np.sum(xs[0] * fs[1] - xs[1] * fs[0]) + np.sum(xm[0] * fm[1] - xm[1] * fm[0]))
    assert abs(moment) <= 1e-12 * scale * 4.0
    m = out["metrics"]
    # equilibrium of the right part (force and moment): Newton's tolerance 1e-10
    # of the force scale, so 1e-9
    assert m["interface_force_error"] < 1e-9
    assert m["interface_moment_error"] < 1e-9
    assert max(s.newton_iterations for s in result.steps) <= 6  # the tangent is exact


def test_moment_defect_on_a_curved_interface_is_the_reference_gap():
    """On a curved non-matching interface the tie forces' moments cancel up to
    ``sum_A g0_A x lam_A`` (module doc): checked at a state where the constraint
    holds (``u`` a rigid translation, any multipliers).  Round-off 1e-13 of
    ``|lam| |x|`` summed over 8 nodes."""
    inner, outer, tie = curved(False)
    model = Model([inner, outer, tie])
    z = np.zeros(model.n)
    for body in (inner, outer):
        z[body.offset + body.node_dofs[0]] = 0.3
        z[body.offset + body.node_dofs[1]] = -0.1
    rng = np.random.default_rng(0)
    z[tie.dofs] = rng.standard_normal(tie.n_dofs) * np.repeat(tie.tied, 2)
    np.testing.assert_allclose(tie.constraint(z), 0.0, atol=1e-14)
    fs, fm = tie.forces(z)
    xs, xm = tie.slave.x(z), tie.master.x(z)
    moment = (np.sum(xs[0] * fs[1] - xs[1] * fs[0]) + np.sum(xm[0] * fm[1] - xm[1] * fm[0]))
    g0 = tie.reference_gap * np.asarray(tie.D.sum(axis=1)).ravel()
    lam = tie.traction(z)
    expected = np.sum(g0[0] * lam[1] - g0[1] * lam[0])
    assert abs(expected) > 1e-4                     # the defect is there ...
    assert abs(moment - expected) < 1e-13 * 8 * 2.0 * np.abs(lam).max()  # ... and is g0 x lam
    np.testing.assert_allclose(fs.sum(axis=1) + fm.sum(axis=1), 0.0, atol=1e-14)


# ------------------------------------------------- the tied block vs one piece
@pytest.mark.parametrize("method", ["mortar", "mortar-dual"])
@pytest.mark.parametrize("element", ["quad1", "tri1"])
def test_matching_meshes_equal_the_one_piece_block(method, element):
    """With ``n_left == n_right`` the meshes match, ``D = M`` up to the node order, and
    the tied block is the one-piece block: round-off (Newton's 1e-10 of the force
    scale: 1e-9)."""
    m = run_scene("tied", {"refine": 1, "n_left": 3, "n_right": 3, "element": element},
                  method=method)["metrics"]
    assert m["tip_deflection_error"] < 1e-9
    assert m["energy_error"] < 1e-9


@pytest.mark.parametrize("method", ["mortar", "mortar-dual"])
def test_tied_block_converges_to_the_one_piece_block(method):
    """Non-matching 4 : 6 parts against the one-piece block at refine 1, 2, 3.  The
    tip deflection and the energy differ by the discretization error of linear
    elements, O(h^2): measured 3.1e-3, 8.1e-4, 2.1e-4 (rates 1.95, 1.96) for both
    multipliers on quads.  Asserted: each level at least 3x smaller (rate > 1.58;
    a tie that leaked would stall at its own error instead)."""
    errors = []
    for refine in (1, 2, 3):
        m = run_scene("tied", {"refine": refine}, method=method)["metrics"]
        errors.append((m["tip_deflection_error"], m["energy_error"]))
    errors = np.array(errors)
    rates = np.log2(errors[:-1] / errors[1:])
    assert np.all(rates > np.log2(3.0)), rates
    assert errors[0, 0] < 1e-2


# -------------------------------------------------------------------- protocol
def test_item_protocol_and_output():
    bottom, top, tie = stacked(4, 3, "quad1", True)
    model = Model([bottom, top, tie])
    assert tie.symmetric and not tie.has_history and tie.state_dict() == {}
    assert not tie.loaded and tie.dof_kind == "lam" and tie.n_dofs == 2 * tie.slave.n_nodes
    assert tie.referenced_bodies() == [top, bottom]
    (out,) = tie.outputs()
    assert isinstance(out, TieOutput) and isinstance(out, Output)
    points, cells = out.output_mesh()
    pdata, _ = out.output_data(model.zeros())
    assert points.shape == (tie.slave.n_nodes, 2) and cells[0][0] == "line"
    assert set(pdata) == {"displacement", "traction", "normal", "shear", "tied"}
    # the dual D is diagonal
    D = tie.D.toarray()
    assert np.array_equal(D, np.diag(np.diag(D)))


def test_scene_builds_and_the_preflight_sees_the_tie():
    """The tie holds the right part's rigid modes (the preflight reads its rows)."""
    setup, _, _ = build_scene("tied", {}, "mortar-dual")
    z = setup.model.zeros()
    fixed, _ = setup.model.prescribed(0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        setup.model.preflight(z, 0.0, fixed)
    items = [it for it in setup.model.items if not isinstance(it, TiePair)]
    with pytest.raises(ValueError, match="body 'right'"):  # without it: free
        Model(items).preflight(Model(items).zeros(), 0.0, Model(items).prescribed(0.0)[0])


# ------------------------------------------------------------------- bad input
def test_bad_input_is_refused():
    bottom, top, _ = stacked(4, 3, "quad1", False)
    s, m = ContactSurface.from_solid(top, "bottom"), ContactSurface.from_solid(bottom, "top")
    plane = RigidPlane((0.0, 0.0), (0.0, 1.0))
    with pytest.raises(ValueError, match="slave must be a ContactSurface"):
        TiePair(top, m)
    with pytest.raises(ValueError, match="master must be a ContactSurface"):
        TiePair(s, "bottom")
    with pytest.raises(ValueError, match="slave must be a deformable surface"):
        TiePair(plane, m)
    with pytest.raises(ValueError, match="slave and master must be two different"):
        TiePair(s, s)
    with pytest.raises(ValueError, match="dual must be True or False"):
        TiePair(s, m, dual="yes")
    for bad in (0, 11, 2.5, True):
        with pytest.raises(ValueError, match=r"n_gauss must be an integer in \[1, 10\]"):
            TiePair(s, m, n_gauss=bad)


def test_surfaces_that_do_not_overlap_are_refused():
    """Apart (a block beside the other) or facing the same way (the bottom block's
    bottom): no slave element faces a master element."""
    bottom, top, _ = stacked(4, 3, "quad1", False)
    far = block(5.0, 6.0, 0.5, 1.0, 3, 2, "quad1", "far")
    s = ContactSurface.from_solid(top, "bottom")
    for master in (ContactSurface.from_solid(far, "bottom"),
                   ContactSurface.from_solid(bottom, "bottom")):
        with pytest.raises(ValueError, match=r"slave 'top_bottom' and the master .* do not "
                                             r"overlap.*facing each other"):
            TiePair(s, master)


def test_dirichlet_on_the_slave_unties_those_nodes_and_all_of_them_is_refused():
    bottom, top, tie = stacked(4, 3, "quad1", False)
    model = Model([bottom, top, tie])
    left = tie.slave.X[0] < 1e-12
    tie.set_fixed(top.offset + top.dofs_at_nodes(tie.slave.nodes[left], "x"))
    np.testing.assert_array_equal(tie.tied, ~left)
    tie.set_fixed(np.zeros(0, dtype=np.int64))
    assert tie.tied.all()
    with pytest.raises(ValueError, match="tie 'tie': every slave node .* carries Dirichlet"):
        tie.set_fixed(top.offset + top.dofs_on("bottom"))
    assert model.n_lam == tie.n_dofs


def test_scene_parameters_are_checked():
    with pytest.raises(ValueError, match="parameter 'refine'"):
        build_scene("tied", {"refine": 0})
    with pytest.raises(ValueError, match="'load'"):
        build_scene("tied", {"load": 1e3})  # the strain scale 16 > 0.05
    with pytest.raises(ValueError, match="method must be one of mortar, mortar-dual"):
        build_scene("tied", {}, "nts")
