"""The one NTS gap (:mod:`skfem_mortar.contact.nts_gap`) on every cell NTS takes.

``g = n(xi) . (x_s - x(xi))`` at the closest point: its ``dg/dq`` and ``d2g/dq2``
from the jets against central differences of the gap recomputed from scratch (a
fresh closest-point projection by :func:`~skfem_mortar.contact.projection.project`
and the normal written out per dimension here: ``(t_y, -t_x)`` on a line, ``T_1 x
T_2`` on a face), on curved and warped cells, at points inside and slightly
outside the cell (the extended map).  Tolerances: the step ``h = 1e-6`` of the
central differences leaves ``O(h^2)`` ~ 1e-12 of truncation and ``eps / h`` ~
1e-10 of round-off in the gradient, and the Hessian is the difference of two
gradients, ``eps / h`` ~ 1e-10 relative; 1e-7 and 1e-6 leave room for the
conditioning of the Newton solve and still catch any missing term (dropping the
implicit derivative of ``xi`` moves H by O(1), see the last test).
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact.cells import CellType, cell_type
from skfem_mortar.contact.nts_gap import CLOSED_FORMS, gap_jets, gap_rows
from skfem_mortar.contact.projection import project

RNG = np.random.default_rng(7)
H_STEP = 1e-6


def _cells():
    """Each cell NTS takes, its nodes (d, k) bent or warped, and a slave point."""
    out = []
    line3 = np.array([[0.0, 1.0, 0.5], [0.0, 0.1, 0.12]])          # (start, end, mid)
    out.append(("line3", line3, np.array([0.3, 0.4])))
    out.append(("line3", line3, np.array([1.08, -0.2])))           # beyond the end
    out.append(("line2", np.array([[0.0, 1.2], [0.1, -0.2]]), np.array([0.4, 0.5])))
    tri = np.array([[0.0, 1.0, 0.1], [0.0, 0.2, 1.0], [0.0, 0.1, -0.05]])
    out.append(("tri3", tri, np.array([0.3, 0.3, 0.4])))
    out.append(("tri3", tri, np.array([-0.05, 0.5, -0.3])))         # outside an edge
    quad = np.array([[-1.0, 1.0, 1.1, -0.9], [-1.0, -0.9, 1.0, 1.1],
                     [0.0, 0.2, -0.1, 0.25]])                       # warped
    out.append(("quad4", quad, np.array([0.2, -0.3, 0.5])))
    out.append(("quad4", quad, np.array([1.15, 0.2, -0.4])))        # outside
    return out


def _gap(cell: CellType, q: np.ndarray, xi0: np.ndarray) -> float:
    """The gap from scratch: ``q = [x_s, x_1, ..., x_k]``."""
    d = cell.dim + 1
    xs, P = q[:d], q[d:].reshape(cell.n_nodes, d).T
    pr = project(xs[:, None], P, np.arange(cell.n_nodes)[None], cell, np.zeros(1),
                 xi0=xi0[:, None], tol=1e-15, max_iter=60)
    xi = pr.xi
    T = np.einsum("dk,kj->dj", P, cell.dshape(xi)[:, :, 0])
    c = np.array([T[1, 0], -T[0, 0]]) if d == 2 else np.cross(T[:, 0], T[:, 1])
    return float(np.dot(c / np.linalg.norm(c), xs - P @ cell.shape(xi)[:, 0]))


def _jets(cell: CellType, q: np.ndarray, xi0: np.ndarray):
    d = cell.dim + 1
    xs, P = q[:d], q[d:].reshape(cell.n_nodes, d).T
    pr = project(xs[:, None], P, np.arange(cell.n_nodes)[None], cell, np.zeros(1),
                 xi0=xi0[:, None], tol=1e-15, max_iter=60)
    gj = gap_jets(cell, xs[:, None], P[:, None, :], pr.xi, True)
    return gj.v[0], gj.g[:, 0], gj.hessian()[:, :, 0]


@pytest.mark.parametrize("case", range(len(_cells())))
def test_gap_derivatives_against_central_differences(case):
    name, P, xs = _cells()[case]
    cell = cell_type(name)
    xi0 = np.asarray(cell.ref_nodes, dtype=float)[:, list(cell.corners)].mean(axis=1)
    q = np.concatenate([xs, P.T.ravel()])
    g, G, H = _jets(cell, q, xi0)
    assert abs(g - _gap(cell, q, xi0)) <= 1e-14
    G_fd, H_fd = np.zeros_like(G), np.zeros_like(H)
    for i in range(q.size):
        e = np.zeros(q.size)
        e[i] = H_STEP
        G_fd[i] = (_gap(cell, q + e, xi0) - _gap(cell, q - e, xi0)) / (2 * H_STEP)
        H_fd[:, i] = (_jets(cell, q + e, xi0)[1] - _jets(cell, q - e, xi0)[1]) / (2 * H_STEP)
    assert np.abs(G - G_fd).max() <= 1e-7 * np.abs(G).max()
    assert np.abs(H - H_fd).max() <= 1e-6 * np.abs(H).max()
    assert np.abs(H - H.T).max() == 0.0


def test_the_closed_form_is_the_jets_on_line2():
    """:data:`CLOSED_FORMS` ``line2`` against :func:`gap_rows` (the jets) on the same
    rows: equal to round-off (1e-14 of the largest entry)."""
    cell = cell_type("line2")
    xm = RNG.standard_normal((2, 6))
    seg = np.c_[0:5, 1:6]
    k = np.arange(5)
    xs = 0.5 * (xm[:, :-1] + xm[:, 1:]) + 0.1 * RNG.standard_normal((2, 5))
    x1, x2 = xm[:, seg[:, 0]], xm[:, seg[:, 1]]
    t = x2 - x1
    l = np.hypot(*t)
    u = np.sum((xs - x1) * t, axis=0) / l**2
    n = np.vstack([t[1], -t[0]]) / l
    pr = {"n": n, "e": t / l, "xi": u, "l": l, "g": np.sum((xs - x1) * n, axis=0)}
    a = CLOSED_FORMS["line2"](xs, xm, k, seg, pr, True)
    b = gap_rows(cell, xs, xm, k, seg, (2 * u - 1)[None], True)
    for x, y in zip(a, b):
        assert np.abs(x - y).max() <= 1e-14 * max(np.abs(y).max(), 1.0)


def test_the_implicit_derivative_of_xi_matters():
    """The test above can fail: with ``xi`` held fixed (no Newton step in jets) the
    gap's Hessian on a curved cell moves by O(1) of its size."""
    cell = cell_type("line3")
    name, P, xs = _cells()[0]
    pr = project(xs[:, None], P, np.arange(3)[None], cell, np.zeros(1), tol=1e-15)
    full = gap_jets(cell, xs[:, None], P[:, None, :], pr.xi, True)
    from skfem_mortar.contact import nts_gap
    from skfem_mortar.contact.jets import Jet
    nv = 8
    var = [Jet.variable(v, i, nv, True) for i, v in enumerate(
        [xs[0:1], xs[1:2]] + [P[c, a:a + 1] for a in range(3) for c in range(2)])]
    JP = [var[2 + 2 * a: 4 + 2 * a] for a in range(3)]
    zero = Jet.constant(np.zeros(1), nv, True)
    x, T, _ = nts_gap._taylor(cell, JP, pr.xi, [zero])
    fixed = ((var[0] - x[0]) * T[0][1] - (var[1] - x[1]) * T[0][0]) * (
        (T[0][0] * T[0][0] + T[0][1] * T[0][1]).sqrt().inv())
    assert abs(fixed.v[0] - full.v[0]) <= 1e-14
    assert np.abs(fixed.hessian() - full.hessian()).max() > 1e-2 * np.abs(full.hessian()).max()
