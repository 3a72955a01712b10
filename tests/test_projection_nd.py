"""Closest-point projection onto cells of any type (contact/projection.py).

Tolerances: Newton stops at steps below 1e-12 in reference coordinates; at the solution
the residual T.(x - p) is then ~1e-12 times |T|^2 (cells of size ~1 here): 1e-10.  The
closed form and Newton on line2 differ by rounding only (one exact step): 1e-13.
Central differences of xi with step 1e-6: truncation ~1e-12 |xi'''|, rounding ~1e-10
(xi converged to 1e-12 at each side: its error divided by 2h is 1e-6 at worst, so Newton
runs to tol 1e-14 there): atol 1e-6.
"""
import time

import numpy as np
import pytest

from skfem_mortar.contact.cells import CELLS
from skfem_mortar.contact.projection import inside_reference, project, project_line2

RNG = np.random.default_rng(7)


def _warped_quads(m):
    """``m`` quad4 cells in 3D: a unit square with corners lifted out of plane by up to
    0.3 (a hyperbolic paraboloid patch), rotated and shifted at random."""
    base = np.array([[0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0], [0.0, 0.0, 0.0, 0.0]])
    cells = []
    for _ in range(m):
        c = base + RNG.uniform(-0.15, 0.15, (3, 4)) + [[0], [0], [0]]
        c[2] += RNG.uniform(-0.3, 0.3) * np.array([1, -1, 1, -1])
        Q, _ = np.linalg.qr(RNG.standard_normal((3, 3)))
        cells.append(Q @ c + RNG.standard_normal((3, 1)))
    x = np.hstack(cells)
    return x, np.arange(4 * m).reshape(m, 4)


def _points_near(x, conn, cell, m, spread=0.3):
    xi = np.asarray(CELLS[cell].ref_nodes)[:, list(CELLS[cell].corners)].mean(axis=1)
    xi = xi[:, None] + RNG.uniform(-0.6, 0.6, (CELLS[cell].dim, m))
    pts = np.einsum("dmk,km->dm", x[:, conn], CELLS[cell].shape(xi))
    return pts + spread * RNG.standard_normal(pts.shape)


def _residual(pr, x, conn, cell, p):
    T = np.einsum("dmk,kjm->djm", x[:, conn], CELLS[cell].dshape(pr.xi))
    return np.einsum("djm,dm->jm", T, pr.x - p)


def test_tri3_against_the_normal_equations():
    m = 200
    x = RNG.standard_normal((3, 3 * m))
    conn = np.arange(3 * m).reshape(m, 3)
    p = _points_near(x, conn, "tri3", m)
    pr = project(p, x, conn, "tri3", np.arange(m), derivatives=True)
    a, b, c = (x[:, conn[:, k]] for k in range(3))
    for i in range(m):   # least squares: p - a = [b - a, c - a] xi
        A = np.column_stack([b[:, i] - a[:, i], c[:, i] - a[:, i]])
        xi = np.linalg.lstsq(A, p[:, i] - a[:, i], rcond=None)[0]
        assert np.allclose(pr.xi[:, i], xi, atol=1e-10, rtol=0)
    assert pr.converged.all()
    inside = (pr.xi >= 0).all(axis=0) & (pr.xi.sum(axis=0) <= 1)
    assert np.array_equal(inside_reference("tri3", pr.xi), inside)


def test_warped_quad4_is_a_closest_point():
    x, conn = _warped_quads(100)
    p = _points_near(x, conn, "quad4", 100, spread=0.2)
    pr = project(p, x, conn, "quad4", np.arange(100))
    assert pr.converged.all()
    assert np.abs(_residual(pr, x, conn, "quad4", p)).max() < 1e-10
    # a local minimum: no point of the cell within 0.05 in xi is nearer
    offsets = 0.05 * np.array([[1, -1, 0, 0, 1, -1], [0, 0, 1, -1, 1, -1]])
    for o in offsets.T:
        xi = pr.xi + o[:, None]
        q = np.einsum("dmk,km->dm", x[:, conn], CELLS["quad4"].shape(xi))
        assert np.all(np.linalg.norm(q - p, axis=0) >= pr.distance - 1e-14)


def test_line2_closed_form_equals_newton_and_is_faster():
    m = 20000
    x = RNG.standard_normal((2, 2 * m))
    conn = np.arange(2 * m).reshape(m, 2)
    p = RNG.standard_normal((2, m))
    a, b = x[:, conn[:, 0]], x[:, conn[:, 1]]
    closed = project_line2(p, a, b)
    newton = project(p, x, conn, "line2", np.arange(m))
    assert np.allclose(newton.xi[0], closed, atol=1e-13 * np.abs(closed).max(), rtol=0)

    def best(f):
        t = []
        for _ in range(5):
            t0 = time.perf_counter()
            f()
            t.append(time.perf_counter() - t0)
        return min(t)
    # the closed form builds no shape-function arrays: measured ~20x faster here;
    # asserted only 2x (timings on a shared machine)
    assert best(lambda: project_line2(p, a, b)) * 2 < best(
        lambda: project(p, x, conn, "line2", np.arange(m)))


@pytest.mark.parametrize("cell", ["line3", "quad4", "tri3"])
def test_derivatives_against_central_differences(cell):
    if cell == "quad4":
        x, conn = _warped_quads(3)
    elif cell == "tri3":
        x, conn = RNG.standard_normal((3, 9)), np.arange(9).reshape(3, 3)
    else:
        t = np.linspace(0, 3, 9)
        x = np.vstack([t, 0.3 * np.sin(2 * t)])
        conn = np.column_stack([np.arange(0, 8, 3)[:3], np.arange(2, 9, 3)[:3],
                                np.arange(1, 8, 3)[:3]])
    m = conn.shape[0]
    p = _points_near(x, conn, cell, m, spread=0.1)
    e_ = np.arange(m)
    pr = project(p, x, conn, cell, e_, derivatives=True, tol=1e-14)
    h = 1e-6
    for c in range(x.shape[0]):
        dp = np.zeros_like(p)
        dp[c] = h
        fd = (project(p + dp, x, conn, cell, e_, tol=1e-14).xi
              - project(p - dp, x, conn, cell, e_, tol=1e-14).xi) / (2 * h)
        assert np.allclose(pr.dxi_dp[:, :, c], fd, atol=1e-6, rtol=0)
        for b in range(conn.shape[1]):
            dx = np.zeros_like(x)
            dx[c, conn[:, b]] = h
            fd = (project(p, x + dx, conn, cell, e_, tol=1e-14).xi
                  - project(p, x - dx, conn, cell, e_, tol=1e-14).xi) / (2 * h)
            assert np.allclose(pr.dxi_dX[:, :, b, c], fd, atol=1e-6, rtol=0)


def test_inside_reference_of_every_row():
    assert list(inside_reference("line2", np.array([[-1.0, 0.0, 1.0, 1.1]]))) == [1, 1, 1, 0]
    assert list(inside_reference("quad4", np.array([[0.9, 1.1], [-0.9, 0]]))) == [1, 0]
    assert list(inside_reference("tri3", np.array([[0.5, 0.6, -0.01], [0.5, 0.5, 0.3]]),
                                 tol=0.0)) == [1, 0, 0]


def test_bad_input_is_refused():
    x = np.zeros((3, 3))
    with pytest.raises(ValueError, match="p must have shape"):
        project(np.zeros((2, 1)), x, [[0, 1, 2]], "tri3", [0])
    with pytest.raises(ValueError, match="tol"):
        project(np.zeros((3, 1)), x, [[0, 1, 2]], "tri3", [0], tol=0.0)
