"""Inexact Newton solves: a kept factorization as the preconditioner of FGMRES.

``NewtonOptions(linear="krylov")`` solves the Newton system ``K_k dz = -R_k``
of iteration ``k`` to the relative tolerance ``eta_k`` (the *forcing term*)

    || K_k dz + R_k || <= eta_k || R_k ||

with flexible GMRES (:func:`fgmres`), right-preconditioned by the factors of an
earlier tangent ``K_j`` (``j < k``, :class:`~skfem_mortar.solver.linsolve.KeptFactors`:
``M^-1 = K_j^-1``, one PARDISO phase 33 or SuperLU triangular solve per Krylov
iteration, against a factorization).  The current matrix is factored afresh
(:func:`~skfem_mortar.solver.linsolve.factorize`, whose direct answer is taken
as it is, no Krylov iteration) when there are no factors yet, the sparsity
pattern changed (a new contact reservation) or the factors were replaced,
when the active set is not settled (an item changed its set in the last
iteration), and when FGMRES did not reach ``eta_k`` within ``max_iter``
iterations or failed (breakdown, a non-finite vector): a *fallback*.  A
converged Newton step is therefore as right as with direct solves: the
convergence test of :func:`~skfem_mortar.solver.newton.newton` is unchanged.

Why the active set decides: the factors of another active set differ from the
current matrix in every changed multiplier row and its column (a perturbation
of the rank of the changes), and FGMRES needed 20 to 40 iterations to reach
``eta = 1e-2`` with them on hertz in one step (mortar, ``refine`` 1 to 3),
while a factorization costs about 15 preconditioner solves at ``refine=2``
(one core: phase 23 0.34 s, phase 33 0.022 s) and 6 at ``refine=3`` (1.2 s,
0.2 s: PARDISO refines twice after its 8 perturbed pivots).  With the factors
of the current active set (the settled iterations at the end of a step) it
took 1 to 8.  So the kept factors pay only in the settled iterations: on
hertz in one step 1 of 7 solves at ``refine=1``, 2 of 7 at 2, 2 of 8 at 3.

Forcing term (Eisenstat and Walker's choice 2, ``gamma = 0.9``, exponent 2),
with ``r_k = ||R_k||``, the step's force scale ``S`` and the Newton tolerance
``tol``:

    eta_k = min(eta_max, max(gamma (r_k / r_{k-1})^2, gamma eta_{k-1}^2 if > 0.1))
    eta_k = min(eta_k, c_q r_k / S)             (quadratic convergence kept)
    eta_k = max(eta_k, 0.1 tol / r_k, ETA_MIN)  (no oversolving), then <= eta_max

The second line keeps the linear error ``eta_k r_k <= c_q r_k^2 / S``
(``c_q`` = :data:`ETA_QUADRATIC`) below Newton's own quadratic term, so the
iteration stays quadratic once the active set has settled; the third stops at a linear residual a tenth of the
Newton tolerance (enough for the convergence test) and above round-off.

FGMRES (our own, not ``scipy.sparse.linalg.gmres``): scipy's GMRES applies the
preconditioner as a fixed linear map and tests the residual of its
restarted cycles, while PARDISO's phase 33 refines adaptively after perturbed
pivots (not exactly linear) and the test here is the true residual within one
cycle of at most ``max_iter`` iterations.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp

from ..core.validate import count
from .linsolve import KeptFactors, factorize

__all__ = ["LINEAR", "KrylovSolver", "KrylovCounts", "fgmres", "forcing",
           "choose_linear", "KRYLOV_MAX_ITER", "FORCING_MAX", "AUTO_KRYLOV_ABOVE"]

log = logging.getLogger(__name__)

#: the choices of ``NewtonOptions.linear``
LINEAR = ("direct", "krylov", "auto")
#: FGMRES iterations with the kept factors before they are given up (refactored)
KRYLOV_MAX_ITER = 12
#: largest forcing term eta_max (``NewtonOptions.forcing_max``)
FORCING_MAX = 1e-2
#: Eisenstat-Walker's gamma of choice 2
FORCING_GAMMA = 0.9
#: c_q of the quadratic bound ``eta_k <= c_q r_k / S``: with 1 (the linear error
#: as large as a quadratic term ``r_k^2 / S``) seed (mortar-dual, 10 steps)
#: ended one step at 1.1e-10 S against the tolerance 1e-10 S (direct: 9.8e-11)
#: and took an extra Newton iteration; 0.01 adds at most a hundredth of it
ETA_QUADRATIC = 1e-2
#: smallest forcing term (a relative residual FGMRES in double precision
#: reaches with good factors; the bound 0.1 tol / r_k is above it on every
#: scene of the tests)
ETA_MIN = 1e-12
#: ``linear="auto"`` takes "krylov" from this many free unknowns on (None: never).
#: hertz one step, one core, medians of 3: solve time per iteration 0.297 s
#: against 0.345 s at 4.7e4 unknowns, 1.40 s against 1.59 s at 1.7e5 (2 of
#: 7 or 8 factorizations saved, the same Newton iterations); at 1.5e4 no gain
AUTO_KRYLOV_ABOVE: int | None = 40000


def choose_linear(linear: str, n: int) -> str:
    """``"direct"`` or ``"krylov"`` for ``linear`` on a system of ``n`` unknowns
    (``"auto"``: "krylov" from :data:`AUTO_KRYLOV_ABOVE` unknowns on)."""
    if linear == "auto":
        return "krylov" if AUTO_KRYLOV_ABOVE is not None and n >= AUTO_KRYLOV_ABOVE \
            else "direct"
    return linear


def forcing(norms: list[float], eta_prev: float | None, scale: float, tol: float,
            eta_max: float = FORCING_MAX) -> float:
    """The forcing term ``eta_k`` of the module docstring.

    Parameters
    ----------
    norms : list of float
        Residual norms ``r_0 .. r_k`` of the step so far (``r_k`` the current).
    eta_prev : float or None
        The forcing term of the last iteration (None in the first one).
    scale : float
        The step's force scale ``S`` (> 0; ``inf`` or 0 drops the quadratic bound).
    tol : float
        The Newton tolerance on the residual norm.
    eta_max : float
        Upper bound, in (0, 1).
    """
    r = norms[-1]
    if len(norms) < 2 or eta_prev is None or not norms[-2] > 0.0:
        eta = eta_max
    else:
        eta = FORCING_GAMMA * (r / norms[-2]) ** 2
        guard = FORCING_GAMMA * eta_prev ** 2
        if guard > 0.1:  # EW's safeguard against a sudden drop of eta
            eta = max(eta, guard)
        eta = min(eta, eta_max)
    if 0.0 < scale < np.inf:
        eta = min(eta, ETA_QUADRATIC * r / scale)
    if r > 0.0:
        eta = max(eta, 0.1 * tol / r)
    return float(min(max(eta, ETA_MIN), eta_max))


class FgmresResult(NamedTuple):
    """What :func:`fgmres` did: the answer, its iterations, its true relative
    residual ``||b - A x|| / ||b||``, whether it reached ``rtol``, and why not."""

    x: np.ndarray
    iterations: int
    residual: float
    converged: bool
    reason: str


def fgmres(A: sp.spmatrix, b: np.ndarray, psolve: Callable[[np.ndarray], np.ndarray],
           rtol: float, max_iter: int) -> FgmresResult:
    """Flexible GMRES from ``x0 = 0``, right-preconditioned, one cycle.

    Arnoldi on ``A M_j^-1`` with ``z_j = M_j^-1 v_j`` (``psolve``) kept, so that the
    preconditioner may change between iterations (Saad 1993):
    ``A Z_m = V_{m+1} H_m``, ``x = Z_m y`` with ``y`` minimizing
    ``|| beta e_1 - H_m y ||`` (Givens rotations; the minimum is the residual
    ``||b - A x||`` in exact arithmetic), classical Gram-Schmidt twice for the
    orthogonalization (matrix-vector products, no loop over rows).  Stops
    when the estimate is below ``rtol ||b|| / 2`` (slack for the true residual,
    computed at the end with one product), on a breakdown or after ``max_iter``
    iterations.  A non-finite vector stops it unconverged.
    """
    n = b.size
    beta = float(np.linalg.norm(b))
    if beta == 0.0:
        return FgmresResult(np.zeros(n), 0, 0.0, True, "")
    if not np.isfinite(beta):
        return FgmresResult(np.zeros(n), 0, np.inf, False, "non-finite right-hand side")
    V = np.empty((max_iter + 1, n))
    Z = np.empty((max_iter, n))
    H = np.zeros((max_iter + 1, max_iter))
    cs, sn = np.zeros(max_iter), np.zeros(max_iter)
    g = np.zeros(max_iter + 1)
    V[0] = b / beta
    g[0] = beta
    target = 0.5 * rtol * beta
    k, reason = 0, ""
    for j in range(max_iter):
        z = psolve(V[j])
        w = A @ z
        if not (np.all(np.isfinite(z)) and np.all(np.isfinite(w))):
            reason = "non-finite preconditioned vector"
            break
        Z[j] = z
        Vj = V[:j + 1]
        h = Vj @ w
        w -= h @ Vj
        h2 = Vj @ w  # second pass: orthogonal to round-off
        w -= h2 @ Vj
        h += h2
        hn = float(np.linalg.norm(w))
        col = np.append(h, hn)
        for i in range(j):  # the earlier rotations (j scalars, not rows)
            col[i], col[i + 1] = cs[i] * col[i] + sn[i] * col[i + 1], \
                -sn[i] * col[i] + cs[i] * col[i + 1]
        d = float(np.hypot(col[j], col[j + 1]))
        if d == 0.0:
            reason = "breakdown"
            break
        cs[j], sn[j] = col[j] / d, col[j + 1] / d
        col[j], col[j + 1] = d, 0.0
        H[:j + 2, j] = col
        g[j + 1], g[j] = -sn[j] * g[j], cs[j] * g[j]
        k = j + 1
        if abs(g[j + 1]) <= target or hn <= 1e-14 * beta:  # converged, or an invariant space
            break
        V[j + 1] = w / hn
    if k == 0:
        return FgmresResult(np.zeros(n), 0, 1.0, False, reason or "no iteration")
    y = la.solve_triangular(H[:k, :k], g[:k])
    x = y @ Z[:k]
    res = float(np.linalg.norm(b - A @ x)) / beta
    ok = bool(np.isfinite(res) and res <= rtol and np.all(np.isfinite(x)))
    if not ok and not reason:
        reason = (f"relative residual {res:.2e} above {rtol:.2e} after {k} iterations"
                  if np.isfinite(res) else "non-finite answer")
    return FgmresResult(x, k, res, ok, reason)


@dataclass
class KrylovCounts:
    """What the linear solves of a Newton step did.

    ``factorizations``: fresh factorizations (direct answers); ``krylov_solves``:
    solves answered by FGMRES with kept factors; ``krylov_iterations``: FGMRES
    iterations in all (those of the fallbacks included); ``fallbacks``: FGMRES
    runs that did not reach their tolerance (followed by a factorization)."""

    factorizations: int = 0
    krylov_solves: int = 0
    krylov_iterations: int = 0
    fallbacks: int = 0


class KrylovSolver:
    """The linear solves of one Newton step with kept factors (module docstring).

    Parameters
    ----------
    backend : {"superlu", "pardiso"}, optional
        The direct solver (default :func:`~skfem_mortar.solver.linsolve.default_backend`).
    max_iter : int
        FGMRES iterations before the factors are given up (>= 1).
    """

    def __init__(self, backend: str | None = None, max_iter: int = KRYLOV_MAX_ITER):
        self.backend, self.max_iter = backend, count("max_iter", max_iter, 1)
        self.kept: KeptFactors | None = None
        self.counts = KrylovCounts()

    def solve(self, K: sp.spmatrix, b: np.ndarray, eta: float,
              multipliers: np.ndarray | None = None, reuse: bool = True,
              hint=None) -> np.ndarray:
        """``x`` with ``||K x - b|| <= eta ||b||``: FGMRES preconditioned by the kept
        factors when they are there for ``K``'s pattern and ``reuse`` is true,
        else (or when it fails) the direct answer of a fresh factorization of
        ``K``, whose factors are kept.  Newton passes ``reuse`` = the active set
        is settled (no item changed its set in the last iteration): as it
        refactors every unsettled iteration, the kept factors are then of the
        current active set (with factors of another active set FGMRES needed
        20 to 40 iterations to reach 1e-2 on hertz, more than a factorization
        costs; module docstring).  ``hint``: as for
        :func:`~skfem_mortar.solver.linsolve.solve_linear`.

        Raises
        ------
        InversionError
            As :func:`~skfem_mortar.solver.linsolve.solve_linear` (the direct solve).
        """
        kept = self.kept
        if reuse and kept is not None and kept.alive() and kept.same_pattern(K):
            try:
                out = fgmres(K, b, kept.solve, eta, self.max_iter)
            except Exception as exc:  # noqa: BLE001 (the factors' solve failed): refactor
                out = FgmresResult(np.zeros(b.size), 0, np.inf, False, str(exc))
            self.counts.krylov_iterations += out.iterations
            if out.converged:
                self.counts.krylov_solves += 1
                return out.x
            self.counts.fallbacks += 1
            log.debug("fgmres with kept factors: %s; refactoring", out.reason)
        self.kept = None  # (freed before the new factors are made)
        x, self.kept = factorize(K, b, self.backend, multipliers, hint)
        self.counts.factorizations += 1
        return x
