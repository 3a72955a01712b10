"""Inexact Newton with kept factors as the preconditioner of FGMRES (``linear="krylov"``).

The answers are those of the direct path to the Newton tolerance, Newton stays
quadratic once the active set has settled, the kept factors are reused and a
failing Krylov solve falls back to a factorization.  Run with either backend
(``SKFEM_MORTAR_SOLVER=superlu`` forces SuperLU on the whole suite).
"""
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

from skfem_mortar.app.runner import build_scene
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.solver import krylov, linsolve, stepping
from skfem_mortar.solver.krylov import KrylovSolver, fgmres, forcing
from skfem_mortar.solver.linsolve import available_backends, factorize
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve
from test_linsolve_paths import contact_system

PATHS = ["superlu"] + (["pardiso-unsymmetric", "pardiso-symmetric", "pardiso-single"]
                       if "pardiso" in available_backends() else [])


def _path(path, monkeypatch):
    monkeypatch.setenv("SKFEM_MORTAR_SOLVER", path.split("-")[0])
    monkeypatch.setattr(linsolve, "SYMMETRIC", path != "pardiso-unsymmetric")
    # single-precision symmetric factors at every size on their path, never elsewhere
    monkeypatch.setattr(linsolve, "SINGLE_ABOVE", 0 if path == "pardiso-single" else 10**12)


# -- options -------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs,name", [({"linear": "gmres"}, "linear"),
                                         ({"linear": None}, "linear"),
                                         ({"forcing_max": 1.0}, "forcing_max"),
                                         ({"forcing_max": float("nan")}, "forcing_max"),
                                         ({"forcing_max": 0.0}, "forcing_max"),
                                         ({"krylov_max_iter": 0}, "krylov_max_iter"),
                                         ({"krylov_max_iter": 2.5}, "krylov_max_iter")])
def test_bad_linear_options_are_refused(kwargs, name):
    with pytest.raises(ValueError, match=name):
        NewtonOptions(**kwargs)


def test_auto_chooses_by_the_size():
    assert krylov.choose_linear("direct", 10 ** 9) == "direct"
    assert krylov.choose_linear("krylov", 1) == "krylov"
    assert krylov.choose_linear("auto", 1) == "direct"
    above = krylov.AUTO_KRYLOV_ABOVE
    assert krylov.choose_linear("auto", above if above else 10 ** 9) == (
        "krylov" if above else "direct")


# -- the pieces ------------------------------------------------------------------------
@pytest.mark.parametrize("path", PATHS)
def test_kept_factors_apply_the_inverse_of_their_matrix(path, monkeypatch):
    """``KeptFactors.solve`` is ``K0^-1`` also for a right-hand side other than the
    factored one (the symmetric path: ``S0^-1 T0(r)``), with inactive and active
    multiplier rows; a second system with other values on the same pattern
    leaves the first one's factors applying ``K0^-1`` (SuperLU) or marks them
    dead (PARDISO replaced them in its instance)."""
    _path(path, monkeypatch)
    A, b, mult = contact_system(inactive=(2, 5))
    x, kept = factorize(A, b, multipliers=mult)
    assert kept is not None and kept.kind == {"pardiso-single": "pardiso-symmetric-single",
                                              "pardiso-unsymmetric": "pardiso"}.get(path, path)
    r = np.random.default_rng(1).standard_normal(b.size)
    ref = np.linalg.solve(A.toarray(), r)
    if path == "pardiso-single":
        # unrefined single-precision factors: condition ~1e5 times float32's 6e-8
        # bounds the error by ~1e-2; above double's round-off (they are single)
        err = np.abs(kept.solve(r) - ref).max() / np.abs(ref).max()
        assert 1e-12 < err < 1e-2
    else:
        # direct solves of a system of condition ~1e5: 1e-9 relative is round-off
        np.testing.assert_allclose(kept.solve(r), ref, atol=1e-9 * np.abs(ref).max())
    np.testing.assert_allclose(x, np.linalg.solve(A.toarray(), b),
                               atol=1e-9 * np.abs(ref).max())
    assert kept.same_pattern(A) and not kept.same_pattern(A[:-1, :-1])
    A2, b2, _ = contact_system(inactive=(1,), seed=0)
    factorize(A2 * 1.5, b2, multipliers=mult)
    if path == "superlu":
        np.testing.assert_allclose(kept.solve(r), ref, atol=1e-9 * np.abs(ref).max())
    else:
        assert not kept.alive()
        with pytest.raises(RuntimeError):
            kept.solve(r)


def test_fgmres_reaches_its_tolerance_and_reports_failure():
    """An exact preconditioner answers in one iteration; no preconditioner on a
    system of condition 1e4 does not reach 1e-10 in 3 iterations (reported,
    with the true residual); a non-finite preconditioner stops it unconverged."""
    rng = np.random.default_rng(0)
    n = 60
    A = sp.csr_matrix(np.diag(np.logspace(0, 4, n)) + 0.1 * rng.standard_normal((n, n)))
    b = rng.standard_normal(n)
    Ad = A.toarray()
    out = fgmres(A, b, lambda v: np.linalg.solve(Ad, v), 1e-10, 10)
    assert out.converged and out.iterations == 1
    # the true relative residual, checked here against its own computation
    assert np.linalg.norm(A @ out.x - b) <= 1e-10 * np.linalg.norm(b)
    out = fgmres(A, b, lambda v: v, 1e-10, 3)
    assert not out.converged and out.iterations == 3 and out.residual > 1e-10
    assert out.residual == pytest.approx(np.linalg.norm(A @ out.x - b) / np.linalg.norm(b))
    out = fgmres(A, b, lambda v: v * np.nan, 1e-10, 3)
    assert not out.converged and "non-finite" in out.reason


def test_forcing_term_bounds():
    """Choice 2 (0.9 (r_k/r_{k-1})^2) between its bounds: eta_max first, the
    quadratic bound 0.01 r_k/S, no oversolving below 0.1 tol/r_k."""
    S, tol = 1.0, 1e-10
    assert forcing([1.0], None, S, tol, 0.01) == 0.01
    assert forcing([1.0, 0.5], 0.01, np.inf, tol, 0.5) == pytest.approx(0.9 * 0.25)
    assert forcing([1.0, 0.5], 0.01, S, tol, 0.5) == pytest.approx(0.01 * 0.5)
    assert forcing([1.0, 0.1], 0.5, np.inf, tol, 0.5) == pytest.approx(0.9 * 0.25)  # EW's guard
    assert forcing([1e-2, 1e-4], 1e-2, S, tol, 0.5) == pytest.approx(1e-6)  # 0.01 r/S
    assert forcing([1e-6, 1e-9], 1e-2, S, tol, 0.5) == pytest.approx(1e-2)  # 0.1 tol / r
    assert forcing([1e-6, 1e-9], 1e-2, np.inf, tol, 0.5) == pytest.approx(1e-2)


# -- scenes ----------------------------------------------------------------------------
CASES = [("hertz", {"refine": -1}, "mortar", 1),
         ("hertz", {"base": "elastic", "refine": -1}, "nts", 1),
         ("patch", {}, "mortar", None),
         ("seed", {}, "mortar-dual", None)]


def _solve(scene, params, method, n_steps, linear, **extra):
    """Solve a scene; returns the model, the result, the final active set and
    the Newton reports of the converged steps."""
    setup = build_scene(scene, params, method)[0]
    opts = dict(setup.solve_options)
    opts["newton"] = NewtonOptions(linear=linear, **extra)
    reports = []
    real = stepping.newton_step

    def step(*args, **kwargs):
        rep = real(*args, **kwargs)
        reports.append(rep)
        return rep
    stepping.newton_step = step
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the preflight's NTS warning
            res = solve(setup.model, n_steps or setup.n_steps or 10, **opts)
    finally:
        stepping.newton_step = real
    pair = next(it for it in setup.model.items if isinstance(it, ContactPair))
    return setup.model, res, pair.active.copy(), [r for r in reports if r.converged]


def _same_answer(model, ref, res, tol):
    for blk in (slice(0, model.n_u), slice(model.n_u, None)):
        scale = np.abs(ref.z[blk]).max()
        assert np.abs(res.z[blk] - ref.z[blk]).max() <= tol * scale, blk


#: patch and seed carry a follower pressure: no symmetric path (pardiso-symmetric
#: would repeat the unsymmetric solves)
SCENE_PATHS = [(*case, path) for case in CASES for path in PATHS
               if path not in ("pardiso-symmetric", "pardiso-single") or case[0] == "hertz"]


@pytest.mark.parametrize("scene,params,method,n_steps,path", SCENE_PATHS, ids=lambda v: str(v))
def test_krylov_gives_the_direct_answer(scene, params, method, n_steps, path, monkeypatch):
    """Displacements and multipliers agree to 1e-8 relative (Newton stops both
    within 1e-10 of the force scale; the linear solves of the last iteration
    are to 0.1 of that tolerance), the final active sets are the same, and
    inexact solves cost no extra Newton iteration or step cut on these scenes."""
    _path(path, monkeypatch)
    model, ref, act_ref, reps_ref = _solve(scene, params, method, n_steps, "direct")
    _, res, act, reps = _solve(scene, params, method, n_steps, "krylov")
    assert res.converged and np.array_equal(act, act_ref)
    _same_answer(model, ref, res, 1e-8)
    assert [s.newton_iterations for s in res.steps] == [s.newton_iterations for s in ref.steps]
    assert all(r.linear == "krylov" for r in reps)
    assert all(r.factorizations == r.iterations for r in reps_ref)  # direct: one per solve


@pytest.mark.parametrize("path", PATHS)
def test_kept_factors_are_reused_on_a_one_step_hertz(path, monkeypatch):
    """hertz (refine 0, mortar) in one step: the solves after the active set has
    settled are answered by FGMRES with the last factors (fewer factorizations
    than Newton iterations, a few Krylov iterations each), and the last
    residuals still fall quadratically: ``log(r_{k+1}/S) / log(r_k/S) >= 1.8``
    (exact Newton gives ~2; an eta fixed at 0.01 would give ~1, each step one
    factor 100 down) over the settled iterations above round-off (1e-11 S)."""
    _path(path, monkeypatch)
    _, res, _, reps = _solve("hertz", {"refine": 0}, "mortar", 1, "krylov")
    (rep,) = reps
    assert rep.factorizations < rep.iterations
    assert rep.krylov_solves == rep.iterations - rep.factorizations > 0
    assert 0 < rep.krylov_iterations <= 5 * rep.krylov_solves and rep.fallbacks == 0
    r = np.array(rep.residual_norms) / rep.scale
    tail = r[-(rep.krylov_solves + 1):]  # the residuals around the settled solves
    tail = tail[tail > 1e-11]
    assert tail.size >= 2
    ratios = np.log(tail[1:]) / np.log(tail[:-1])
    assert np.all(ratios >= 1.8), (tail, ratios)


def test_a_loose_forcing_term_is_not_quadratic(monkeypatch):
    """The quadratic test above can fail: with the forcing term fixed at 0.05
    (no quadratic bound, no choice 2) the settled residuals fall linearly."""
    monkeypatch.setattr(krylov, "forcing", lambda *a, **k: 0.05)
    import skfem_mortar.solver.newton as newton_mod
    monkeypatch.setattr(newton_mod, "forcing", lambda *a, **k: 0.05)
    _, res, _, reps = _solve("hertz", {"refine": 0}, "mortar", 1, "krylov")
    (rep,) = reps
    r = np.array(rep.residual_norms) / rep.scale
    tail = r[-(rep.krylov_solves + 1):]
    tail = tail[tail > 1e-11]
    assert np.any(np.log(tail[1:]) / np.log(tail[:-1]) < 1.8)


@pytest.mark.parametrize("path", PATHS)
def test_a_useless_preconditioner_falls_back_to_the_direct_answer(path, monkeypatch):
    """Kept factors that answer nothing (the identity, and NaN) make every FGMRES
    run fail: each solve falls back to a factorization, and the answer is the
    direct one (to the 1e-8 of the comparison above) in as many iterations."""
    _path(path, monkeypatch)
    model, ref, act_ref, _ = _solve("hertz", {"refine": -1}, "mortar", 1, "direct")
    for useless in (lambda self, r: np.asarray(r, dtype=float),
                    lambda self, r: np.full(np.shape(r), np.nan)):
        monkeypatch.setattr(linsolve.KeptFactors, "solve", useless)
        _, res, act, reps = _solve("hertz", {"refine": -1}, "mortar", 1, "krylov",
                                   krylov_max_iter=2)
        (rep,) = reps
        assert rep.fallbacks > 0 and rep.krylov_solves == 0
        assert rep.factorizations == rep.iterations
        assert np.array_equal(act, act_ref)
        _same_answer(model, ref, res, 1e-8)
        assert res.steps[0].newton_iterations == ref.steps[0].newton_iterations


def test_krylov_solver_refactors_on_a_new_pattern():
    """A matrix of another pattern is factored afresh, one of the same pattern
    reuses the factors (no new factorization, Krylov iterations)."""
    A, b, mult = contact_system(inactive=(2,))
    ks = KrylovSolver(backend="superlu")
    ks.solve(A, b, 1e-8)
    ks.solve(A * (1 + 1e-3), b, 1e-8)
    assert ks.counts.factorizations == 1 and ks.counts.krylov_solves == 1
    B = sp.csr_matrix(A.toarray() + np.eye(A.shape[0]) * 1e-3 + np.eye(A.shape[0], k=7))
    x = ks.solve(B, b, 1e-8)
    assert ks.counts.factorizations == 2
    # a direct answer of a system of condition ~1e5: 1e-9 relative
    assert np.linalg.norm(B @ x - b) <= 1e-9 * np.linalg.norm(b)
