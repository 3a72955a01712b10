"""Issue 6 (mortar contact) at the scene level: patch, offset patch, Hertz, cable_flat,
linear momentum and Newton convergence of the mortar methods in whole scenes.

Tolerances say why they have their size.  "Round-off" for the patch tests: the
Newton residual is driven to 1e-10 of the force scale (q times the width) and
the stiffness is E = 1e6 .. 1e9 against q = 1e4, so the contact pressure of
the discrete solution carries a relative error of ~1e-10 at worst (measured
1e-14 .. 6e-11); 1e-8 is the bound the issue asks for.
"""
import csv
import math

import numpy as np
import pytest

from skfem_mortar.contact.mortar_segmentation import segment
from skfem_mortar.app.runner import build_scene, run_scene
from skfem_mortar.solver.stepping import solve

MORTAR = ["mortar", "mortar-dual"]
Q = 1e4  # patch scene default pressure


def _patch(method, **params):
    summary, result, setup = run_scene("patch", params=params, method=method,
                                       return_result=True)
    assert summary["converged"]
    return summary, result, setup


def _stress_error(setup, result):
    """Largest |sigma_yy + q| / q over the elements of both blocks."""
    err = 0.0
    for name in ("top", "bottom"):
        _, cells = setup.model.item(name).output_data(result.z)
        err = max(err, float(np.max(np.abs(cells["sigma_yy"][0] + Q)) / Q))
    return err


# --------------------------------------------------------------------------- 1. patch test
@pytest.mark.parametrize("method", MORTAR)
@pytest.mark.parametrize("n_top, n_bottom", [(7, 10), (10, 7)])
@pytest.mark.parametrize("E_top", [1e6, 1e9])
def test_patch_non_matching_tri1_round_off(method, n_top, n_bottom, E_top):
    """Non-matching meshes (7 against 10 elements and the reverse), tri1, stiffness
    ratios E_top / E_bottom = 1 and 1000: contact pressure q at every slave node and
    sigma_yy = -q in every element, to round-off (measured <= 6e-11 with the ratio
    1000, <= 4e-14 otherwise)."""
    s, res, setup = _patch(method, n_top=n_top, n_bottom=n_bottom, element="tri1",
                           E_top=E_top, E_bottom=1e6)
    m = s["metrics"]
    assert m["pressure_error"] < 1e-8
    assert m["n_active"] == n_top + 1          # every slave node in contact
    assert m["max_abs_gap"] < 1e-12            # zero gap, coordinates O(1)
    assert _stress_error(setup, res) < 1e-8


@pytest.mark.parametrize("method", MORTAR)
def test_patch_contact_csv_is_the_multiplier_as_a_traction(method, tmp_path):
    """contact.csv: one row per slave node, pressure = the mortar multiplier (a
    traction, force per length) = q; and the force it represents, integrated
    with the mortar matrix D, is q times the width (the load), to round-off."""
    s, res, setup = run_scene("patch", params={"n_top": 7, "n_bottom": 10, "element": "tri1"},
                              method=method, out=tmp_path, return_result=True)
    with open(tmp_path / "contact.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["x", "y", "gap", "pressure", "has_master"]
    p = np.array([float(r["pressure"]) for r in rows])
    pair = setup.model.item("contact")
    lam = res.z[pair.dofs]
    assert p.size == pair.slave.n_nodes == 8
    np.testing.assert_allclose(p, lam, rtol=1e-12, atol=0)   # the csv holds lam itself
    np.testing.assert_allclose(p, Q, rtol=1e-8)             # ... which is the traction q
    D = pair.evaluate(res.z, tangent=False).info["D"]
    # sum_A,B D_AB lam_B = int lam_h dGamma: the resultant of the traction field
    assert float((D @ lam).sum()) == pytest.approx(Q * 1.0, rel=1e-8)


# --------------------------------------------------------------- 2. offset / overlap patch
OFFSETS = [
    pytest.param(0.13, 1.0, id="shifted-right"),      # slave end beyond master at x = 1
    pytest.param(-0.13, 1.0, id="shifted-left"),      # slave end beyond master at x = 0
    pytest.param(-0.17, 1.4, id="slave-longer"),      # slave overhangs both master ends
    pytest.param(0.05, 0.8, id="master-longer"),      # master elements cut by slave ends
]


@pytest.mark.parametrize("method", MORTAR)
@pytest.mark.parametrize("offset, top_width", OFFSETS)
@pytest.mark.parametrize("n_top, n_bottom", [(7, 10), (10, 7)])
def test_offset_patch_uniform_pressure_on_the_overlap(method, offset, top_width, n_top,
                                                      n_bottom):
    """Offset / overlapping blocks (see the patch scene doc: the uncovered parts of
    the interface carry q directly, so the uniform state stays exact).  Mortar
    (standard and dual): pressure q at every slave node of the overlapped part,
    the outer node of a partially overlapped slave element also carries q (its
    multiplier shape function is part of the partition of unity there), slave
    nodes facing nothing carry nothing, and sigma_yy = -q in every element.
    Measured: <= 2e-13 on the overlap, <= 2e-11 at the outer nodes; 1e-8 as above."""
    s, res, setup = _patch(method, n_top=n_top, n_bottom=n_bottom, element="tri1",
                           offset=offset, top_width=top_width)
    m = s["metrics"]
    assert m["pressure_error"] < 1e-8
    assert m["unsupported_pressure"] == 0.0
    pair = setup.model.item("contact")
    ev = pair.evaluate(res.z, tangent=False, with_lam=False)
    lam = res.z[pair.dofs]
    # the nodes with a multiplier: those on the overlap and the outer node of each
    # slave element cut by a master end (none when the master is the longer one)
    xs = np.sort(pair.slave.X[0])
    lo, hi = max(0.0, offset), min(1.0, offset + top_width)
    n_cut = sum(int(np.any((xs[:-1] < e) & (xs[1:] > e))) for e in (lo, hi))
    assert ev.mask.sum() == m["n_overlap"] + n_cut
    np.testing.assert_allclose(lam[ev.mask], Q, rtol=1e-8)
    assert np.all(pair.active == ev.mask)
    assert _stress_error(setup, res) < 1e-8


@pytest.mark.parametrize("method", MORTAR)
def test_offset_patch_step_segmentation(method):
    """``segmentation=step``: one load step from the zero-gap start, and with
    nu = 0 nothing slides, so the frozen segments are the converged ones and the
    patch test passes to round-off as well (measured <= 2e-13)."""
    s, res, setup = _patch(method, n_top=7, n_bottom=10, element="tri1", offset=-0.13,
                           segmentation="step")
    assert s["metrics"]["pressure_error"] < 1e-8
    assert _stress_error(setup, res) < 1e-8


def test_offset_patch_nts_error_is_reported():
    """Single-pass NTS on the shifted patch: O(1) error (measured 0.27 for 10
    against 7 tri1 elements shifted by 0.13; 0.08 without the shift), reported by
    the metric, not hidden: only a lower bound is asserted."""
    m = run_scene("patch", params={"n_top": 10, "n_bottom": 7, "element": "tri1",
                                   "offset": 0.13}, method="nts")["metrics"]
    assert m["pressure_error"] > 0.05


@pytest.mark.parametrize("method", MORTAR)
def test_offset_patch_sliver_is_exact_above_the_mask_threshold(method):
    """A slave end element that overlaps the master by 1 % of its length: its
    outer node's support is 0.5e-4 of its tributary length (above the mask
    threshold mask_tolerance(space, 1) = 1e-6 of multiplier_spaces.py); the patch test still passes to
    round-off (measured 2e-14 on the overlap, 6e-10 at the outer node, whose
    dual/standard coefficients amplify round-off by ~1/f^2)."""
    h = 1.0 / 7
    s, res, setup = _patch(method, n_top=7, n_bottom=10, element="tri1",
                           offset=-(h - 0.01 * h))
    assert s["metrics"]["pressure_error"] < 1e-8
    assert _stress_error(setup, res) < 1e-8


@pytest.mark.parametrize("method", MORTAR)
def test_offset_patch_sliver_below_the_mask_threshold(method):
    """Covered fraction f = 5e-4 of a slave end element: the outer node's support
    (f^2 / 2 of the element, 2.5e-7 of its tributary length) is below MASK_TOL, the
    node is masked out and merged into its neighbour like a crosspoint (Phi_B = 1
    on the element), so the sliver's traction is kept.  Before the merge the
    pressure error was 4.5e-7 (standard and dual, ~1.8 f^2); at f = 1e-3 (on the
    threshold) the mask flipped between Newton iterations and the dual run needed
    the active-set cycling guard."""
    h = 1.0 / 7
    s, res, setup = _patch(method, n_top=7, n_bottom=10, element="tri1",
                           offset=-(h - 5e-4 * h))
    assert s["metrics"]["pressure_error"] < 1e-8


def test_patch_offset_parameters_are_validated():
    with pytest.raises(ValueError, match="offset"):
        run_scene("patch", params={"offset": 1.5})
    with pytest.raises(ValueError, match="top_width"):
        run_scene("patch", params={"top_width": 0.0})
    with pytest.raises(ValueError, match="offset"):   # no overlap left
        run_scene("patch", params={"offset": -0.5, "top_width": 0.5})


# ------------------------------------------------------------------------------ 3. Hertz
_HERTZ: dict = {}


def _hertz(method, base, refine, **params):
    """Summary and contact data (x, pressure, sorted by x) of a hertz run, cached."""
    key = (method, base, refine, tuple(sorted(params.items())))
    if key not in _HERTZ:
        s, res, setup = run_scene("hertz", params={"base": base, "refine": refine, **params},
                                  method=method, return_result=True)
        assert s["converged"]
        d = setup.contact(res.z)
        o = np.argsort(d["x"])
        _HERTZ[key] = (s, d["x"][o], d["pressure"][o])
    return _HERTZ[key]


def _edge_element(x, a):
    """Largest slave element (node spacing) within 1.2 a of the axis."""
    xs = x[x <= 1.2 * a]
    return float(np.diff(xs).max())


@pytest.mark.parametrize("method", MORTAR)
@pytest.mark.parametrize("base", ["rigid", "elastic"])   # elastic: 12-15 s each
def test_hertz_default_refinement(method, base):
    """Default mesh (h0 = a/30 in the contact zone): peak pressure within 2 % of
    Hertz p0 and the half-width within one element.

    Measured peak errors: rigid 1.45 % (mortar) / 1.30 % (dual), elastic 1.21 % /
    1.04 %.  About 1.0 % of it is not discretization: the finite-strain model
    deviates from linear Hertz theory by O(a/R) (see the load-scaling test); the
    rest is O(h).  The standard mortar pressure has no oscillation beyond one
    node (measured excess variation 0.003 p0 rigid, 0.019 p0 elastic; dual 0)."""
    s, x, p = _hertz(method, base, 0)
    m = s["metrics"]
    a = m["half_width_exact"]
    assert m["peak_pressure_error"] < 0.02
    assert abs(m["half_width"] - a) < _edge_element(x, a)
    assert m["pressure_oscillation"] < (0.03 if method == "mortar" else 1e-3)


def test_hertz_remaining_error_is_the_finite_strain_deviation():
    """The FE pressure lies ~1 % above Hertz's p(x) at the interior nodes
    (0.2 a < x < 0.5 a) on every mesh (0.8 % at h = a/7.5 .. a/60), and that
    offset scales with a/R, the strain level: measured 0.79 % at the default load
    (a/R = 0.048), 0.43 % at a quarter of it (a/R = 0.024), 0.24 % at 1/16; with
    h = a/30 in all three.  A discretization error at fixed h/a would not change
    with the load; a small-strain deviation O(a/R) halves with a/R.  Asserted:
    the quarter-load offset is below 0.65 of the full-load one (0.5 expected,
    0.54 measured), so the target peak error cannot go below ~1 % by refining."""
    def offset(load):
        s, x, p = _hertz("mortar-dual", "rigid", 0, load=load)
        a, p0 = s["metrics"]["half_width_exact"], s["metrics"]["peak_pressure_exact"]
        k = (x > 0.2 * a) & (x < 0.5 * a)
        return float(np.mean(p[k] / (p0 * np.sqrt(1 - (x[k] / a) ** 2)) - 1))
    full, quarter = offset(3.2032), offset(3.2032 / 4)
    assert 0.0 < quarter < 0.65 * full


@pytest.mark.slow
@pytest.mark.parametrize("method", MORTAR)
def test_hertz_rigid_convergence_rate_and_bounded_oscillation(method):
    """Rigid base, h0 = a/7.5, a/15, a/30, a/60 (refine -2 .. 1).

    Peak errors measured: mortar 3.08, 1.88, 1.45, 1.22 %; dual 2.18, 1.62, 1.30,
    1.15 %: they approach the ~1 % finite-strain offset, so the rate is measured
    on the differences between successive meshes (self-convergence, no reference
    needed): orders 1.5, 0.9 (mortar) and 0.8, 1.1 (dual), O(h) as expected from
    the nodal-force error of the mesh patch at the peak; asserted > 0.5.
    Oscillation (excess variation / p0): mortar 0.034, 0, 0.003, 0.039 -- one
    overshoot of the outermost active node at the contact edge (the standard
    multiplier's linear drop to zero over the last element), not a growing
    wave; bounded by 0.06.  Dual: 0 on every mesh."""
    runs = [_hertz(method, "rigid", r) for r in (-2, -1, 0, 1)]
    peaks = np.array([s["metrics"]["peak_pressure"] for s, _, _ in runs])
    errs = [s["metrics"]["peak_pressure_error"] for s, _, _ in runs]
    d = np.abs(np.diff(peaks))
    orders = np.log2(d[:-1] / d[1:])
    assert np.all(orders > 0.5), orders
    assert errs[-1] < errs[0] and errs[-1] < 0.015
    osc = [s["metrics"]["pressure_oscillation"] for s, _, _ in runs]
    assert max(osc) < (0.06 if method == "mortar" else 1e-3), osc


# -------------------------------------------------------------------------- 4. cable_flat
from skfem_mortar.scenes.cable_flat import flat_exact  # noqa: E402

FLAT = flat_exact(1.0, 2.0, 100.0, 20.0, 0.5, "linear")


def _flat(method, n, **params):
    s, res, setup = run_scene("cable_flat", params={"n_elements": n, **params}, method=method,
                              return_result=True)
    assert s["converged"]
    d = setup.contact(res.z)
    o = np.argsort(d["x"])
    return s, d["x"][o], d["pressure"][o], setup.model.item("contact").active[o]


@pytest.mark.parametrize("method", MORTAR)
def test_cable_flat_error_envelope(method):
    """Contact force and tension within 1e-3 at n = 200 (measured 1.8e-5 / 2.5e-5
    mortar, 1.0e-5 / 2.0e-5 dual), and below C h = h / c on n = 50, 100, 200, 400
    (not asserted monotone: the contact edges cross nodes).  C h: each edge of the
    contact zone is misplaced by at most one element h = L0 / n, which changes the
    force 2 c p by at most 2 p h, a relative error h / c; the tension follows from
    the same geometry.  Measured errors are 100-10000 times below it."""
    for n in (50, 100, 200, 400):
        m = _flat(method, n)[0]["metrics"]
        bound = (2.0 / n) / FLAT["contact_half_width"]
        if n == 200:
            bound = min(bound, 1e-3)
        assert m["contact_force_error"] < bound, n
        assert m["tension_error"] < bound, n


def test_cable_flat_edge_pressure_standard_multipliers():
    """Standard multipliers at the contact edge (n = 200, 29 active nodes): the
    discrete cable kinks at the outermost contact node, and the point load of
    that kink is spread by the consistent mortar matrix D (lam = D^-1 f) into an
    alternating tail.  Measured p / 20 - 1 from the outermost active node
    inwards: -0.46, +0.32, -0.14, +0.051, -0.018, +0.0057, -0.0018, +5.5e-4, ...:
    alternating signs, the ratio of successive deviations 0.43, 0.37, 0.34, 0.33,
    ... 0.29, approaching 2 - sqrt(3) = 0.27, the decay of the inverse of the
    tridiagonal D.  The tails of both edges meet in the middle at 2e-7 (14 nodes
    from each edge).  The contact force is still within 2e-5 of 2 c p: the tail
    is self-equilibrated."""
    s, x, p, act = _flat("mortar", 200)
    right = np.flatnonzero(act & (x > 0))[-1]
    dev = p[right - 6:right + 1][::-1] / 20.0 - 1.0      # outermost first
    assert np.all(np.sign(dev[:-1]) == -np.sign(dev[1:]))  # alternating
    ratios = np.abs(dev[1:] / dev[:-1])[1:]                # from the 2nd node on
    assert np.all((ratios > 0.2) & (ratios < 0.5)), ratios
    mid = np.argmin(np.abs(x))
    assert p[mid] == pytest.approx(20.0, rel=1e-6)         # 0.3^13 of the edge's 0.32
    assert s["metrics"]["contact_force_error"] < 1e-4


def test_cable_flat_edge_pressure_dual_multipliers():
    """Dual multipliers at the contact edge (n = 200): no tail.  The outermost
    active node carries a partial value (measured 0.755 p: the edge lies inside
    its tributary length), its inner neighbour p (1 - 8e-7), every other active
    node p to round-off (measured 7e-13).  NTS on the same plane gives the same
    numbers except the 8e-7: the dual weighted gap of a flat master is the nodal
    gap times int N_A, but the dual gap and its contact force follow the averaged
    slave normal, which at the kinked outermost node is tilted by half the kink
    angle (~0.005 rad); NTS uses the plane's normal."""
    s, x, p, act = _flat("mortar-dual", 200)
    idx = np.flatnonzero(act)
    np.testing.assert_allclose(p[idx[2:-2]], 20.0, rtol=1e-10)
    np.testing.assert_allclose(p[idx[[1, -2]]], 20.0, rtol=1e-5)
    assert 0.0 < p[idx[-1]] < 20.0 and 0.0 < p[idx[0]] < 20.0
    _, _, p_nts, act_nts = _flat("nts", 200)
    assert np.array_equal(act, act_nts)
    np.testing.assert_allclose(p, p_nts, rtol=1e-5, atol=1e-10)


# ------------------------------------------------------------------ 5. linear momentum
@pytest.mark.parametrize("method", MORTAR)
def test_linear_momentum_solid_solid_hertz(method):
    """Hertz on an elastic base (solid against solid): the contact forces G^T lam on
    the slave and master nodes sum to zero to round-off (both come from the same
    weighted gap, which is invariant under a translation of both surfaces;
    measured 1e-16 .. 1e-15 relative to the contact force P/2)."""
    setup, params, _ = build_scene("hertz", params={"refine": -2, "base": "elastic"},
                                   method=method)
    res = solve(setup.model, 4)
    f_s, f_m = setup.model.item("contact").forces(res.z)
    total = np.linalg.norm(f_s.sum(axis=1))
    # vertical equilibrium of the half model to the Newton tolerance (the horizontal
    # part is balanced by the symmetry supports: the deformed interface is curved)
    assert f_s[1].sum() == pytest.approx(params["load"] / 2, rel=1e-8)
    assert np.linalg.norm(f_s.sum(axis=1) + f_m.sum(axis=1)) < 1e-12 * total


@pytest.mark.parametrize("method", MORTAR)
def test_linear_momentum_cable_solid_seed(method):
    """The seed scene (cable sliding into the cushion): action = reaction to
    round-off (measured ~1e-16 relative), and each body in equilibrium to the
    Newton tolerance."""
    s = run_scene("seed", {"n_cable": 24, "refine_cushion": 1}, method=method)
    m = s["metrics"]
    assert m["action_reaction_error"] < 1e-12
    assert m["cable_equilibrium_error"] < 1e-8 and m["cushion_equilibrium_error"] < 1e-8


# --------------------------------------------------------- 6. Newton and segmentation
P_HALF = 3.2032 / 2   # hertz: the contact force of the half model, the force scale


def _quadratic_pairs(norms, scale, floor=1e-11):
    """(rho_k, rho_k+1) of the normalized residuals in the asymptotic range: rho_k below
    0.05 and rho_k+1 above the round-off floor (the last residual of a step sits at
    ~4e-13 of the scale, where no rate can be read)."""
    rho = np.asarray(norms) / scale
    return [(r0, r1) for r0, r1 in zip(rho[:-1], rho[1:]) if r0 < 0.05 and r1 > floor]


@pytest.mark.parametrize("method", MORTAR)
@pytest.mark.parametrize("policy", ["iteration", "step"])
def test_hertz_elastic_newton_is_quadratic(method, policy):
    """Hertz on an elastic base (refine -2, 4 load steps): the contact zone grows
    and the mortar segment end points (the master nodes projected onto the slave
    elements) move in every step.  With ``segmentation=iteration`` the tangent is
    the exact derivative of the re-segmented weighted gaps, with ``step`` of the
    frozen ones; either way, once the active set is fixed (the last iterations
    of a step), rho_k+1 <= K rho_k^2 with rho = |R| / (P/2).  Measured K = 0.002
    .. 0.08 and order log(rho_k+1) / log(rho_k) = 2.3 .. 3.4; asserted K < 10 and
    order > 1.8 (a tangent with a relative error e converges linearly at rate ~e:
    K = e / rho_k would exceed 10 for any e > 1e-3 at rho_k ~ 1e-4).  Both policies
    take the same iteration counts ([3, 6, 4, 5] mortar, [4, 4, 4, 4] dual)."""
    s, res, setup = run_scene("hertz", params={"refine": -2, "base": "elastic",
                                               "segmentation": policy},
                              method=method, return_result=True)
    assert s["converged"]
    # the segment end points move during the last step (segmentations of its start
    # and of its converged state)
    pair = setup.model.item("contact")
    sg0, sg1 = (segment(pair.slave.x(z), pair.slave.segments, pair.master.x(z),
                        pair.master.segments) for z in res.states[-2:])
    if sg0.n == sg1.n and np.array_equal(sg0.e_s, sg1.e_s) and np.array_equal(sg0.e_m, sg1.e_m):
        assert np.abs(sg1.xi - sg0.xi).max() > 1e-4
    checked = 0
    for st in s["steps"]:
        pairs = _quadratic_pairs(st["residual_norms"], P_HALF)
        assert pairs, st["residual_norms"]
        for r0, r1 in pairs:
            assert r1 <= 10 * r0 ** 2, (r0, r1)
            assert math.log(r1) / math.log(r0) > 1.8, (r0, r1)
            checked += 1
    assert checked >= len(s["steps"])


@pytest.mark.parametrize("method", MORTAR)
def test_step_segmentation_error_shrinks_with_the_step_size(method):
    """``segmentation=step`` freezes the segments of the last converged state for
    the whole load step, so the converged state of a step solves a slightly
    different problem (segment end points of the step's start): the difference to
    ``iteration`` is first order in the load increment.  Hertz on an elastic
    base (refine -2): max |u_step - u_iter| / max |u_iter| measured 1.1e-6, 5.3e-7,
    2.8e-7 (mortar) and 9.8e-7, 4.9e-7, 2.4e-7 (dual) with 2, 4, 8 steps.
    Asserted: 4 times fewer steps' increments (2 -> 8 steps) at least halve it
    (first order would quarter it)."""
    def diff(n):
        z = {}
        for policy in ("iteration", "step"):
            s, res, setup = run_scene("hertz", params={"refine": -2, "base": "elastic",
                                                       "segmentation": policy},
                                      method=method, steps=n, return_result=True)
            assert s["converged"]
            z[policy] = res.z
        all_dofs = np.arange(z["step"].size)
        u_dofs = np.setdiff1d(all_dofs, all_dofs[setup.model.item("contact").dofs])
        du = np.abs(z["step"][u_dofs] - z["iteration"][u_dofs]).max()
        return du / np.abs(z["iteration"][u_dofs]).max()
    d2, d8 = diff(2), diff(8)
    assert 0.0 < d8 < 0.5 * d2
    assert d2 < 1e-5   # small: the segments move little within a step here


# ------------------------------------------------------------ Hertz mesh and master parts
def test_hertz_split_corner_and_segmented_plane():
    """The corner node at the origin gets two triangles (split_corner) and the mesh
    keeps its area; the rigid plane is a chain of collinear segments on y = 0
    with outward normal +y, covering |x| <= 3 a."""
    from skfem_mortar.scenes.hertz import graded_quarter_disk, rigid_plane
    from skfem_mortar.contact.surfaces import segment_normals
    R, a = 8.0, 0.3853
    m = graded_quarter_disk(R, a / 30, 1.2 * a)
    o = np.argmin(np.hypot(m.p[0], m.p[1] - 0.0))
    assert np.count_nonzero((m.t == o).any(axis=0)) == 2
    e = m.p[:, m.t]
    area = 0.5 * np.abs((e[0, 1] - e[0, 0]) * (e[1, 2] - e[1, 0])
                        - (e[0, 2] - e[0, 0]) * (e[1, 1] - e[1, 0]))
    assert area.min() > 0
    # the quarter disk minus the circular segments cut off by the arc's chords
    # (nodes on the circle): R^2 / 2 (theta - sin theta), theta = 2 asin(l / 2R)
    arc = m.facets[:, m.boundaries["arc"]]
    chord = np.hypot(*(m.p[:, arc[1]] - m.p[:, arc[0]]))
    theta = 2 * np.arcsin(chord / (2 * R))
    exact = math.pi * R * R / 4 - np.sum(R * R / 2 * (theta - np.sin(theta)))
    assert area.sum() == pytest.approx(exact, rel=1e-12)
    plane = rigid_plane(3 * a, a / 30)
    nrm, length = segment_normals(plane.X, plane.segments)
    np.testing.assert_allclose(nrm, np.array([[0.0], [1.0]]) * np.ones(length.size), atol=1e-15)
    assert plane.X[1].max() == 0.0 == plane.X[1].min()
    assert plane.X[0].min() == pytest.approx(-3 * a) and plane.X[0].max() == pytest.approx(3 * a)


def test_long_master_segment_against_a_kinked_slave():
    """Five slave nodes 0.004 apart with the middle one 1.2e-4 below its
    neighbours (as in the converged standard-mortar Hertz run at h = a/60, where
    it happened with the plane as one segment of length 4 R = 32): against a
    flat master segment of length 0.1 .. 4 all four slave elements get their
    mortar segment; against one of length 32 the far master nodes have no
    projection onto the two kinked elements along their turning normal field
    (no real root): they are clipped at the slave end on their side instead of
    dropping the pair (before: no segment, the middle node masked, penetrating)."""
    xs = np.array([[-0.004, 0.0, 0.004, 0.008, 0.012], [0.0, 0.0, -1.2e-4, 0.0, 0.0]])
    ss = np.array([[0, 1], [1, 2], [2, 3], [3, 4]])
    xm = np.array([[16.0, -16.0], [0.0, 0.0]])
    sm = np.array([[0, 1]])
    sg = segment(xs, ss, xm, sm)
    assert sorted(set(sg.e_s.tolist())) == [0, 1, 2, 3]


@pytest.mark.parametrize("method", MORTAR)
def test_cable_flat_step_segmentation_does_not_penetrate(method):
    """cable_flat, n = 200, 8 steps, ``segmentation=step``, the plane one segment of
    length 100.  Before the far master nodes were clipped by side (see
    test_long_master_segment_against_a_kinked_slave) the curved cable elements
    next to the contact zone had no frozen segment, the nodes reaching the plane
    during the last step stayed masked and penetrated (3.7e-4, force error
    3.8e-3).  Now step and iteration give the same answer: force errors 1.8e-5
    (mortar) / 1.0e-5 (dual); no penetration with dual multipliers, and with
    standard ones only the intrinsic one at the contact edge (the weighted gap
    of the last active node averages its penetration against the rising free
    arc: 1.06e-5, also with ``iteration``; 1.2e-6 at n = 400)."""
    s, res, setup = run_scene("cable_flat", params={"n_elements": 200, "segmentation": "step"},
                              method=method, return_result=True)
    y = setup.model.item("cable").x(res.z)[1]
    assert y.max() - 0.5 < (1e-8 if method == "mortar-dual" else 2e-5)
    assert s["metrics"]["contact_force_error"] < 1e-4


@pytest.mark.slow
@pytest.mark.parametrize("method", MORTAR)
def test_hertz_elastic_refinement(method):
    """Elastic base, h0 = a/7.5, a/15, a/30 (refine -2 .. 0).  Peak errors
    measured: mortar 2.14, 1.53, 1.21 % (1.00 % at a/60); dual 0.97, 1.17, 1.04 %
    (0.92 % at a/60) -- the dual errors sit in the ~1 % finite-strain band from
    the coarsest mesh on, the O(h) part changing sign.  Asserted on the
    differences between successive meshes: they shrink (mortar: order 0.93
    measured, > 0.5 asserted; dual: 0.0020 p0 then 0.0013 p0, asserted to shrink);
    the oscillation of the standard multipliers stays bounded (0.109, 0, 0.019;
    0.0015 at a/60), dual 0."""
    runs = [_hertz(method, "elastic", r) for r in (-2, -1, 0)]
    peaks = np.array([s["metrics"]["peak_pressure"] for s, _, _ in runs])
    d = np.abs(np.diff(peaks))
    if method == "mortar":
        assert math.log2(d[0] / d[1]) > 0.5, d
    else:
        assert d[1] < d[0], d
    assert all(s["metrics"]["peak_pressure_error"] < 0.025 for s, _, _ in runs)
    osc = [s["metrics"]["pressure_oscillation"] for s, _, _ in runs]
    assert max(osc) < (0.15 if method == "mortar" else 1e-3), osc


@pytest.mark.parametrize("method", MORTAR)
def test_step_start_active_set_stays_in_mask(method):
    """The first iteration of a step reuses the last converged active set; nodes
    no longer in ``mask`` (with ``segmentation=step`` the segments are rebuilt at
    the step start) must leave it, else their multiplier row is zero and the
    tangent singular (cable_flat, n = 400, step: 'Matrix is exactly singular' at
    iteration 0 of step 9 before the segmentation fix).  Here every node is
    declared active while the plane (length 0.5) supports only the middle ones."""
    from skfem import MeshTri

    from skfem_mortar.contact.pair import ContactPair
    from skfem_mortar.bodies.materials import NeoHooke
    from skfem_mortar.bodies.solid import Solid
    from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane
    m = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5)).with_defaults()
    b = Solid(m, NeoHooke(E=100.0, nu=0.0), name="block")
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"),
                       RigidPlane((0.5, 0.0), (0.0, 1.0), length=0.5), method, name="c",
                       segmentation="step")
    from skfem_mortar.core.model import Model
    model = Model([b, pair])
    z = np.zeros(model.n)
    pair.begin_step(z, 1.0)                     # initial set, then pretend all were active
    pair.state.converged = np.ones(pair.n_dofs, bool)
    pair.begin_step(z, 1.0)
    ev = pair.evaluate(z, tangent=False, with_lam=False)
    assert not ev.mask.all()
    c = pair.assemble(z, 1.0)
    assert np.array_equal(pair.active, ev.mask)
    K = np.zeros((model.n, model.n))
    np.add.at(K, (c.k_rows, c.k_cols), c.k_vals)
    rows = K[pair.offset:pair.offset + pair.n_dofs]
    assert np.all(np.abs(rows).max(axis=1) > 0)   # no zero multiplier row
