"""The linear solve backends: same answers on saddle-point systems, clean failures."""
import numpy as np
import pytest
import scipy.sparse as sp

from skfem_mortar.solver import linsolve, pardiso
from skfem_mortar.core.errors import InversionError
from skfem_mortar.solver.linsolve import available_backends, default_backend, solve_linear

HAS_PARDISO = "pardiso" in available_backends()
BACKENDS = ["superlu"] + (["pardiso"] if HAS_PARDISO else [])


def saddle_point(n=60, m=7, seed=0):
    """[K B^T; B 0] with K an SPD 1D Laplacian plus noise and B a random full-rank block,
    and one inactive multiplier row set to the identity (as the contact pair does)."""
    rng = np.random.default_rng(seed)
    K = sp.diags([-np.ones(n - 1), 2.0 + rng.random(n), -np.ones(n - 1)], [-1, 0, 1])
    B = sp.random(m, n, density=0.2, random_state=seed) + sp.eye(m, n, k=3)
    B = B.tolil()
    B[m - 1, :] = 0.0
    C = sp.csr_matrix((m, m))
    C = C.tolil()
    C[m - 1, m - 1] = 1.0
    A = sp.bmat([[K, B.T], [B, C]]).tocsr()
    return A, rng.standard_normal(n + m)


@pytest.mark.parametrize("backend", BACKENDS)
def test_solves_saddle_point(backend):
    A, b = saddle_point()
    x = solve_linear(A, b, backend=backend)
    np.testing.assert_allclose(A @ x, b, atol=1e-10 * np.linalg.norm(b))
    x_dense = np.linalg.solve(A.toarray(), b)
    np.testing.assert_allclose(x, x_dense, rtol=1e-9, atol=1e-12)


@pytest.mark.skipif(not HAS_PARDISO, reason="pypardiso not installed (a default dependency on x86-64 Linux and Windows)")
def test_backends_agree_on_a_model_tangent():
    """The block Newton system of a real contact scene, both backends."""
    from skfem_mortar.app.runner import build_scene

    setup = build_scene("seed", {"n_cable": 24, "refine_cushion": 1})[0]
    model = setup.model
    z = model.zeros()
    for it in model.items:
        it.begin_step(z, 0.5)
    R, K, _ = model.assemble(z, 0.5)
    fixed, _ = model.prescribed(0.5)
    free = np.setdiff1d(np.arange(model.n), fixed)
    Kf, rf = K[free][:, free], -R[free]
    x1 = solve_linear(Kf, rf, backend="superlu")
    x2 = solve_linear(Kf, rf, backend="pardiso")
    np.testing.assert_allclose(x2, x1, rtol=1e-8, atol=1e-10 * np.abs(x1).max())


@pytest.mark.parametrize("backend", BACKENDS)
def test_singular_raises_inversion_error(backend):
    A = sp.csr_matrix(np.array([[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 1.0]]))
    with pytest.raises(InversionError):
        solve_linear(A, np.ones(3), backend=backend)


@pytest.mark.parametrize("backend", BACKENDS)
def test_empty_system(backend):
    assert solve_linear(sp.csr_matrix((0, 0)), np.zeros(0), backend=backend).shape == (0,)


def test_default_backend_and_override(monkeypatch):
    monkeypatch.delenv("SKFEM_MORTAR_SOLVER", raising=False)
    assert default_backend() == ("pardiso" if HAS_PARDISO else "superlu")
    monkeypatch.setenv("SKFEM_MORTAR_SOLVER", "superlu")
    assert default_backend() == "superlu"
    monkeypatch.setenv("SKFEM_MORTAR_SOLVER", "umfpack")
    with pytest.raises(ValueError, match="SKFEM_MORTAR_SOLVER"):
        default_backend()


def test_unknown_backend():
    with pytest.raises(ValueError, match="backend"):
        solve_linear(sp.eye(2, format="csr"), np.ones(2), backend="lapack")


@pytest.mark.skipif(not HAS_PARDISO, reason="pypardiso not installed (a default dependency on x86-64 Linux and Windows)")
def test_pardiso_falls_back_when_its_answer_is_bad(monkeypatch):
    """A PARDISO answer with a large residual is replaced by SuperLU's."""
    A, b = saddle_point(seed=2)
    monkeypatch.setattr(pardiso, "PARDISO_RTOL", -1.0)  # no answer passes the check
    x = solve_linear(A, b, backend="pardiso")
    np.testing.assert_allclose(A @ x, b, atol=1e-10 * np.linalg.norm(b))


def test_superlu_does_not_change_the_input():
    A, b = saddle_point(seed=3)
    A0, b0 = A.copy(), b.copy()
    for backend in BACKENDS:
        solve_linear(A, b, backend=backend)
    assert (A != A0).nnz == 0 and np.array_equal(b, b0)


@pytest.mark.skipif(not HAS_PARDISO, reason="pypardiso not installed (a default dependency on x86-64 Linux and Windows)")
def test_pardiso_reuses_the_analysis_of_a_repeated_pattern():
    """Same pattern, new values (a Newton iteration without active set change): the
    analysis is reused and the answer is still right; a new pattern starts afresh."""
    A, b = saddle_point(seed=4)
    solve_linear(A, b, backend="pardiso")
    kept = linsolve.pardiso_solver().pattern
    assert kept is not None
    A2 = A.copy()
    A2.data = A2.data * (1.0 + 0.3 * np.random.default_rng(5).random(A2.nnz))
    x = solve_linear(A2, b, backend="pardiso")
    assert linsolve.pardiso_solver().pattern is kept  # no new analysis
    np.testing.assert_allclose(x, np.linalg.solve(A2.toarray(), b), rtol=1e-9, atol=1e-12)
    A3, b3 = saddle_point(n=50, seed=6)
    x3 = solve_linear(A3, b3, backend="pardiso")
    assert linsolve.pardiso_solver().pattern is not kept
    np.testing.assert_allclose(x3, np.linalg.solve(A3.toarray(), b3), rtol=1e-9, atol=1e-12)
