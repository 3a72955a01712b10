"""Every solver path gives the same answers; the analysis is kept while the pattern repeats.

Paths: SciPy's SuperLU, PARDISO unsymmetric (``mtype`` 11), PARDISO symmetric
indefinite (``mtype`` -2) of the symmetrized system
(:func:`~skfem_mortar.solver.linsolve.symmetrize`).  The PARDISO cases skip
without the extra ``fast`` (a failure in CI's second step).
"""
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from skfem_mortar.app.runner import build_scene
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.solver import linsolve, pardiso
from skfem_mortar.solver.linsolve import available_backends, symmetrize
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve

HAS_PARDISO = "pardiso" in available_backends()
needs_pardiso = pytest.mark.skipif(not HAS_PARDISO, reason="pypardiso not installed (a default dependency on x86-64 Linux and Windows)")


def contact_system(n=40, m=6, seed=0, inactive=(4, 5)):
    """``[K -B^T; c B 0]`` with K symmetric positive definite, the multiplier rows
    ``c_r B_r`` (a different c per row, as row scales give) and some inactive rows
    ``s lam_r`` (their row and column kept as explicit zeros, as over a reserved
    pattern)."""
    rng = np.random.default_rng(seed)
    K = sp.diags([-np.ones(n - 1), 2.0 + rng.random(n), -np.ones(n - 1)], [-1, 0, 1]).toarray()
    B = np.zeros((m, n))
    for r in range(m):
        B[r, rng.choice(n, 4, replace=False)] = rng.standard_normal(4)
    A = np.zeros((n + m, n + m))
    A[:n, :n] = K
    A[:n, n:] = -B.T
    c = 10.0 ** rng.uniform(-2, 3, m)
    A[n:, :n] = c[:, None] * B
    struct = A != 0
    for r in inactive:
        A[n + r, :n] = 0.0
        A[n + r, n + r] = 0.7
    struct[n:, n:] |= np.eye(m, dtype=bool)
    rows, cols = np.nonzero(struct | struct.T)
    M = sp.csr_matrix((A[rows, cols], (rows, cols)), shape=A.shape)  # explicit zeros kept
    mult = np.arange(n + m) >= n
    return M, rng.standard_normal(n + m), mult


def _stored(A):
    S = A.copy()
    S.data[:] = 1.0
    return S.toarray() != 0


def _full(U):
    return (U + U.T - sp.diags(U.diagonal())).tocsr()


def test_symmetrize_gives_a_symmetric_system_with_the_same_answer():
    A, b, mult = contact_system()
    U, bs, transform, _ = symmetrize(A, b, mult)
    assert sp.tril(U, -1).nnz == 0
    S = _full(U)
    x = spla.spsolve(S.tocsc(), bs)
    x_ref = np.linalg.solve(A.toarray(), b)
    # both direct solves of systems with condition ~1e5: 1e-10 relative is round-off
    np.testing.assert_allclose(x, x_ref, rtol=1e-10, atol=1e-10 * np.abs(x_ref).max())
    np.testing.assert_allclose(transform(b), bs, rtol=0, atol=0)


def test_symmetrize_keeps_the_pattern_over_active_set_changes():
    """Another active set on the same pattern: the same upper-triangle structure."""
    A1, b, mult = contact_system(inactive=(4, 5))
    A2, _, _ = contact_system(inactive=(1,))
    rows, cols = np.nonzero(_stored(A1) | _stored(A2))  # the union of both patterns

    def on_union(A):  # explicit zeros kept (coo -> csr keeps them)
        return sp.coo_matrix((A.toarray()[rows, cols], (rows, cols)), shape=A.shape).tocsr()
    A1, A2 = on_union(A1), on_union(A2)
    U1, U2 = symmetrize(A1, b, mult)[0], symmetrize(A2, b, mult)[0]
    assert np.array_equal(U1.indptr, U2.indptr) and np.array_equal(U1.indices, U2.indices)


def test_symmetrize_refuses_an_unsymmetric_multiplier_row():
    A, b, mult = contact_system()
    A = A.tolil()
    n = A.shape[0] - 6
    r = n
    cols = A.rows[r]
    A[r, cols[0]] = A[r, cols[0]] * 1.5  # no longer a multiple of its column
    assert symmetrize(A.tocsr(), b, mult) is None


@needs_pardiso
def test_symmetric_pardiso_refines_only_after_perturbed_pivots(monkeypatch):
    """PARDISO refines its answer only when it perturbed pivots (``iparm(8) = 0``;
    with ``iparm(8) = 2`` it refined every answer twice, 60 % of a solve with the
    factors at 1.7e5 unknowns): here none are perturbed, no step is taken, and
    the answer still passes the residual check."""
    monkeypatch.setattr(linsolve, "SYMMETRIC", True)
    pardiso._pardiso_solvers.clear()
    A, b, mult = contact_system(inactive=(2,))
    x = linsolve.solve_linear(A, b, backend="pardiso", multipliers=mult)
    s = pardiso._pardiso_solvers[-2]
    assert s.perturbed == 0 and s.solver.get_iparm(7) == 0  # iparm(7): steps taken
    assert s.factorizations == s.solves == 1
    assert np.linalg.norm(A @ x - b) <= pardiso.PARDISO_RTOL * np.linalg.norm(b)


def test_single_precision_factors_are_refined_to_the_residual_check(monkeypatch):
    """The single-precision symmetric path (iparm(28) = 1): its factors answer
    to about single precision (a relative residual far above double's 1e-16,
    here > 1e-12), and the refinement in double brings every answer under
    :data:`PARDISO_RTOL` with at most :data:`REFINE_STEPS_SINGLE` steps."""
    if not HAS_PARDISO:
        pytest.skip("pypardiso not installed")
    monkeypatch.setattr(linsolve, "SYMMETRIC", True)
    monkeypatch.setattr(linsolve, "SINGLE_ABOVE", 0)
    pardiso._pardiso_solvers.clear()
    A, b, mult = contact_system(n=400, m=30, inactive=(2, 7))
    x = linsolve.solve_linear(A, b, backend="pardiso", multipliers=mult)
    s = pardiso._pardiso_solvers[(-2, "single")]
    assert -2 not in pardiso._pardiso_solvers  # no fallback to double precision
    assert s.solver.get_iparm(28) == 1 and s.single
    assert np.linalg.norm(A @ x - b) <= pardiso.PARDISO_RTOL * np.linalg.norm(b)
    assert s.factorizations == 1 and 1 <= s.solves - 1 <= pardiso.REFINE_STEPS_SINGLE
    sym = symmetrize(A.tocsr(), b, mult)
    y = s._run(sym.U, sym.b, 33)  # the factors' own answer, unrefined
    assert np.linalg.norm(A @ y - b) > 1e-12 * np.linalg.norm(b)


# -- the paths on scenes ----------------------------------------------------------
CASES = [("hertz", {"base": "elastic", "refine": -1}, "nts"),
         ("hertz", {"base": "elastic", "refine": -1}, "mortar"),
         ("hertz", {"refine": -1}, "mortar-dual"),
         ("patch", {}, "nts"), ("patch", {}, "mortar"), ("patch", {}, "mortar-dual"),
         ("seed", {}, "mortar-dual")]
PATHS = ("superlu", "pardiso-unsymmetric", "pardiso-symmetric", "pardiso-single")


def _run(scene, params, method, path, rtol, monkeypatch):
    monkeypatch.setenv("SKFEM_MORTAR_SOLVER", path.split("-")[0])
    monkeypatch.setattr(linsolve, "SYMMETRIC", path in ("pardiso-symmetric", "pardiso-single"))
    # single precision at every size on its path (by default from 5e4 unknowns), never elsewhere
    monkeypatch.setattr(linsolve, "SINGLE_ABOVE", 0 if path == "pardiso-single" else 10**12)
    pardiso._pardiso_solvers.clear()  # fresh counters
    setup = build_scene(scene, params, method)[0]
    opts = dict(setup.solve_options)
    opts["newton"] = NewtonOptions(rtol=rtol)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the preflight's NTS warning
        res = solve(setup.model, setup.n_steps or 10, **opts)
    pair = next(it for it in setup.model.items if isinstance(it, ContactPair))
    counts = {m: (s.analyses, s.factorizations) for m, s in pardiso._pardiso_solvers.items()}
    return setup.model, res, pair.active.copy(), counts


@needs_pardiso
@pytest.mark.parametrize("rtol,tol", [(1e-10, 1e-8), (1e-13, 1e-10)], ids=["default", "tight"])
@pytest.mark.parametrize("scene,params,method", CASES, ids=lambda v: str(v))
def test_every_solver_path_gives_the_same_answer(scene, params, method, rtol, tol, monkeypatch):
    """Displacements and multipliers agree to 1e-8 relative at the default rtol
    (Newton stops within 1e-10 of the force scale, the linear solves differ in
    round-off only) and to 1e-10 at rtol 1e-13; the final active sets are the same."""
    out = {p: _run(scene, params, method, p, rtol, monkeypatch) for p in PATHS}
    model, ref, act_ref, _ = out["superlu"]
    nu = model.n_u
    for p in PATHS[1:]:
        _, res, act, counts = out[p]
        assert res.converged
        assert np.array_equal(act, act_ref), p
        for blk in (slice(0, nu), slice(nu, None)):
            scale = np.abs(ref.z[blk]).max()
            assert np.abs(res.z[blk] - ref.z[blk]).max() <= tol * scale, (p, blk)
    # the symmetric path is taken where every item but the pair is symmetric
    sym_counts = out["pardiso-symmetric"][3]
    assert (-2 in sym_counts) == model.symmetrizable
    # ... and on its path in single precision, every answer from the single factors
    single_counts = out["pardiso-single"][3]
    assert ((-2, "single") in single_counts) == model.symmetrizable
    assert -2 not in single_counts  # no fallback to double precision
    assert model.symmetrizable == (scene == "hertz")  # patch, seed: a follower pressure


@needs_pardiso
@pytest.mark.parametrize("path", PATHS[1:])
def test_pardiso_keeps_its_analysis_over_a_settled_solve(path, monkeypatch):
    """hertz (elastic base, mortar, 10 steps): the contact reservation is made
    once, so the model's pattern is built once and PARDISO analyses it once per
    load step (it forgets its analysis at the start of a step, so a resumed run
    repeats the step's solves: measured 10 analyses for 46 factorizations); a
    fresh analysis at every pattern change would be one per iteration."""
    model, res, _, counts = _run("hertz", {"base": "elastic", "refine": -1}, "mortar", path,
                                 1e-10, monkeypatch)
    iterations = sum(s.newton_iterations for s in res.steps)
    key = {"pardiso-unsymmetric": 11, "pardiso-symmetric": -2, "pardiso-single": (-2, "single")}
    analyses, factorizations = counts[key[path]]
    assert factorizations >= iterations
    attempts = len(res.steps) + sum(s.cuts for s in res.steps)
    assert analyses <= attempts + model.pattern_builds and analyses < iterations // 3


@needs_pardiso
@pytest.mark.parametrize("base", ["rigid", "elastic"])
def test_symmetric_analysis_survives_the_active_set_changes(base, monkeypatch):
    """hertz in one step (mortar): the symmetric path analyses once per pattern
    and answers every reused analysis at once, no refinement, no new analysis,
    although the active set changes over the solve (the analysis is run on the
    system with every coupled multiplier shown active, ``SymmetricSystem.analysis``;
    analysing the plain system answered the rigid base's reused solves with
    perturbed pivots: 1 refinement at this size, 2 new analyses at ``refine=3``).
    On the rigid base the pattern is built once (the reservation's slave part
    holds every slave element; the master's columns are not unknowns), so one
    analysis serves the whole solve: the rows the first search did not reach
    are shown active with the pairs' ``analysis_coupling`` (without it the
    reused analysis pivoted badly at ``refine=3``: a new analysis anyway)."""
    monkeypatch.setenv("SKFEM_MORTAR_SOLVER", "pardiso")
    monkeypatch.setattr(linsolve, "SYMMETRIC", True)
    pardiso._pardiso_solvers.clear()  # fresh counters
    setup = build_scene("hertz", {"base": base, "refine": -1}, "mortar")[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = solve(setup.model, 1, **setup.solve_options)
    assert res.converged and len(res.steps) == 1
    s = pardiso._pardiso_solvers[-2]
    iterations = res.steps[0].newton_iterations
    assert s.analyses == setup.model.pattern_builds < iterations
    assert s.factorizations == s.solves == iterations  # every answer the first one
    if base == "rigid":
        assert s.analyses == 1


def test_the_model_pattern_repeats_over_a_solve():
    """SuperLU or not: the fixed pattern is built once per contact reservation
    (here 1 or 2 over the solve) instead of a new sum's pattern every iteration,
    and the free block's index arrays are the same memory between builds."""
    setup = build_scene("hertz", {"base": "elastic", "refine": -2}, "mortar")[0]
    model = setup.model
    seen = []
    real = model.free_block

    def free_block(K, free):
        Kf = real(K, free)
        seen.append(Kf.indices.__array_interface__["data"][0])  # the memory, not the view
        return Kf
    model.free_block = free_block
    res = solve(model, 5)
    iterations = sum(s.newton_iterations for s in res.steps)
    assert not model._varying.any()
    assert 1 <= model.pattern_builds <= 2 < iterations
    distinct = len(set(seen))
    assert distinct <= model.pattern_builds + 1  # one per pattern (and per free set)


def test_the_analysis_shows_hinted_rows_active():
    """``SymmetricSystem.analysis``: an inactive row with no coupling values (a
    row the search has not reached) is shown active with the ``hint`` coupling
    at its transposed entries (diagonal 0); without a hint it stays an identity
    row; rows the hint does not name, and the values of ``U``, are unchanged."""
    A, b, mult = contact_system(inactive=(4, 5))
    n = 40
    coo = A.tocoo()
    coo.data[(coo.col == n + 5) & (coo.row < n)] = 0.0  # row 5 uncoupled: explicit zeros
    A = sp.csr_matrix((coo.data, (coo.row, coo.col)), shape=A.shape)
    cols = np.flatnonzero(_stored(A)[n + 5, :n])
    assert cols.size == 4
    hint = (np.full(cols.size, n + 5), cols, np.linspace(1.0, 2.0, cols.size))
    plain = symmetrize(A, b, mult)
    hinted = symmetrize(A, b, mult, lambda: hint)
    assert abs(plain.U - hinted.U).max() == 0.0
    P0, P1 = plain.analysis().toarray(), hinted.analysis().toarray()
    assert P0[n + 5, n + 5] != 0 and np.all(P0[cols, n + 5] == 0)   # identity row
    assert P1[n + 5, n + 5] == 0 and np.allclose(P1[cols, n + 5], hint[2])
    other = np.ones(P0.shape, bool)
    other[:, n + 5] = other[n + 5, :] = False
    assert np.array_equal(P0[other], P1[other])


@pytest.mark.parametrize("text", ["abc", "-3", "1e5"])
def test_a_bad_single_above_is_refused_naming_the_variable(text, monkeypatch):
    """``SKFEM_MORTAR_SINGLE_ABOVE`` takes an integer >= 0; anything else is a
    ValueError naming the variable, its range and the value given."""
    monkeypatch.setenv("SKFEM_MORTAR_SINGLE_ABOVE", text)
    with pytest.raises(ValueError, match=r"SKFEM_MORTAR_SINGLE_ABOVE must be an integer >= 0.*"
                                         + repr(text)):
        linsolve._single_above()
    monkeypatch.setenv("SKFEM_MORTAR_SINGLE_ABOVE", " 0 ")
    assert linsolve._single_above() == 0
