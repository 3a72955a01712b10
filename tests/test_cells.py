"""The facet cell table (contact/cells.py): every row's shape functions, derivatives and
quadrature, and the registry's checks.

Tolerances: the shape functions are polynomials evaluated in double precision, so
identities (partition of unity, Kronecker property) hold to a few ulps: 1e-14.  Central
differences with step h have truncation error h^2/6 |f'''| (zero for polynomials of
degree <= 2 -- all rows here) plus rounding eps/h ~ 1e-16/1e-5 = 1e-11: tolerance 1e-8.
A quadrature rule exact to degree p integrates a monomial of degree <= p to rounding
(1e-13 relative); one degree above, the error of the rules used here is at least
~1e-3 of the integral, so "not exact" is asserted at 1e-8.
"""
from math import factorial

import numpy as np
import pytest

from skfem_mortar.contact.cells import (CELLS, CellType, cell_type, line_quadrature,
                                        register_cell)

ROWS = ("line2", "line3", "tri3", "quad4")
RNG = np.random.default_rng(3)


def _inside(cell, n=7):
    """``n`` random points inside the reference cell (dim, n)."""
    if cell.name.startswith("tri"):
        a = RNG.uniform(0.0, 1.0, (2, n))
        flip = a.sum(axis=0) > 1
        a[:, flip] = 1.0 - a[:, flip]
        return a
    return RNG.uniform(-0.9, 0.9, (cell.dim, n))


def _exact(cell, powers):
    """Exact integral of ``prod xi_k^p_k`` over the reference cell."""
    if cell.name.startswith("tri"):
        a, b = powers
        return factorial(a) * factorial(b) / factorial(a + b + 2)
    return np.prod([(1.0 - (-1.0) ** (p + 1)) / (p + 1) for p in powers])


def _monomials(dim, degree):
    if dim == 1:
        return [(degree,)]
    return [(a, degree - a) for a in range(degree + 1)]


@pytest.mark.parametrize("name", ROWS)
def test_partition_of_unity_and_kronecker(name):
    cell = CELLS[name]
    xi = _inside(cell)
    assert np.allclose(cell.shape(xi).sum(axis=0), 1.0, atol=1e-14, rtol=0)
    assert np.allclose(cell.dshape(xi).sum(axis=0), 0.0, atol=1e-14, rtol=0)
    assert np.allclose(cell.d2shape(xi).sum(axis=0), 0.0, atol=1e-14, rtol=0)
    assert np.allclose(cell.shape(cell.ref_nodes), np.eye(cell.n_nodes), atol=1e-14, rtol=0)
    # the corners are where the reference cell's vertices are, the edges' ends corners
    for e in cell.edges:
        assert e[0] in cell.corners and e[-1] in cell.corners


@pytest.mark.parametrize("name", ROWS)
def test_derivatives_against_central_differences(name):
    cell = CELLS[name]
    xi, h = _inside(cell), 1e-5
    dN, d2N = cell.dshape(xi), cell.d2shape(xi)
    assert dN.shape == (cell.n_nodes, cell.dim, xi.shape[1])
    assert d2N.shape == (cell.n_nodes, cell.dim, cell.dim, xi.shape[1])
    for k in range(cell.dim):
        e = np.zeros((cell.dim, 1))
        e[k] = h
        fd = (cell.shape(xi + e) - cell.shape(xi - e)) / (2 * h)
        assert np.allclose(dN[:, k], fd, atol=1e-8, rtol=0)
        fd2 = (cell.dshape(xi + e) - cell.dshape(xi - e)) / (2 * h)
        assert np.allclose(d2N[:, :, k], fd2, atol=1e-8, rtol=0)


@pytest.mark.parametrize("name", ROWS)
def test_shapes_broadcast_over_trailing_axes(name):
    """``xi (dim, a, b)`` gives ``N (n_nodes, a, b)``: the kernels pass (dim, n, n_gauss)."""
    cell = CELLS[name]
    xi = _inside(cell, 12).reshape(cell.dim, 3, 4)
    flat = _inside(cell, 0)
    assert cell.shape(xi).shape == (cell.n_nodes, 3, 4)
    assert np.array_equal(cell.shape(xi).reshape(cell.n_nodes, 12),
                          cell.shape(xi.reshape(cell.dim, 12)))
    assert cell.dshape(xi).shape == (cell.n_nodes, cell.dim, 3, 4)
    assert cell.d2shape(xi).shape == (cell.n_nodes, cell.dim, cell.dim, 3, 4)
    assert cell.shape(flat).shape == (cell.n_nodes, 0)


@pytest.mark.parametrize("name", ROWS)
@pytest.mark.parametrize("degree", range(0, 8))
def test_quadrature_exact_to_its_degree(name, degree):
    cell = CELLS[name]
    pts, w = cell.quadrature(degree)
    assert pts.shape == (cell.dim, w.size) and np.all(w > 0)
    for p in range(degree + 1):
        for powers in _monomials(cell.dim, p):
            f = np.prod([pts[k] ** powers[k] for k in range(cell.dim)], axis=0)
            assert abs(f @ w - _exact(cell, powers)) <= 1e-13 * max(1.0, abs(_exact(cell, powers)))


@pytest.mark.parametrize("name", ROWS)
@pytest.mark.parametrize("degree", (1, 3, 5, 7))
def test_quadrature_not_exact_one_degree_above(name, degree):
    """The rules are exact to odd degrees 2n - 1; at 2n some monomial is missed (else the
    exactness test above could not fail for a rule that is too large)."""
    cell = CELLS[name]
    pts, w = cell.quadrature(degree)
    errors = [abs(np.prod([pts[k] ** q[k] for k in range(cell.dim)], axis=0) @ w
                  - _exact(cell, q)) for q in _monomials(cell.dim, degree + 1)]
    assert max(errors) > 1e-8


def test_quadrature_point_counts():
    assert line_quadrature(3)[1].size == 2 and line_quadrature(4)[1].size == 3
    assert CELLS["quad4"].quadrature(3)[1].size == 4
    assert CELLS["tri3"].quadrature(3)[1].size == 4
    pts, _ = CELLS["tri3"].quadrature(5)
    assert np.all(pts >= 0) and np.all(pts.sum(axis=0) <= 1)


def test_node_orders_as_the_package_uses_them():
    """line3 is (start, end, mid) as in core.chain; tri3 and quad4 counter-clockwise."""
    from skfem_mortar.core.chain import curve_points
    x = np.array([[0.0, 2.0, 1.0], [0.0, 0.0, 0.5]])
    xi = np.array([-0.3, 0.4])
    ours = np.einsum("dk,kq->dq", x, CELLS["line3"].shape(xi[None]))
    assert np.allclose(ours, curve_points(x, np.array([[0, 1, 2]]), xi)[:, 0], atol=1e-15)
    for name in ("tri3", "quad4"):
        r = CELLS[name].ref_nodes
        area = 0.5 * np.sum(r[0] * np.roll(r[1], -1) - np.roll(r[0], -1) * r[1])
        assert area > 0


def test_cell_type_lookup_and_errors():
    assert cell_type("tri3") is CELLS["tri3"]
    assert cell_type(CELLS["line2"]) is CELLS["line2"]
    with pytest.raises(ValueError, match="registered cell types.*line2"):
        cell_type("tri6")
    with pytest.raises(ValueError, match="already registered"):
        register_cell(CELLS["line2"])
    with pytest.raises(ValueError, match="CellType"):
        register_cell("line2")
    bad = CellType("bad", 1, 2, (0, 1), ((0, 1),), np.array([[-1.0, 1.0]]),
                   lambda xi: np.stack([np.ones_like(xi[0]), np.zeros_like(xi[0])]),
                   CELLS["line2"].dshape, CELLS["line2"].d2shape, line_quadrature)
    with pytest.raises(ValueError, match="identity"):
        register_cell(bad)
    bad = CellType("bad", 1, 2, (0, 5), ((0, 1),), np.array([[-1.0, 1.0]]),
                   *(getattr(CELLS["line2"], a) for a in ("shape", "dshape", "d2shape")),
                   line_quadrature)
    with pytest.raises(ValueError, match="local node"):
        register_cell(bad)
    bad = CellType("bad", 1, 2, (0, 1), ((0, 1),), np.array([[-1.0, 0.0, 1.0]]),
                   *(getattr(CELLS["line2"], a) for a in ("shape", "dshape", "d2shape")),
                   line_quadrature)
    with pytest.raises(ValueError, match="ref_nodes"):
        register_cell(bad)
    assert "bad" not in CELLS
    with pytest.raises(ValueError, match="degree"):
        line_quadrature(-1)


def test_a_piecewise_cell_registers_with_its_own_rule():
    """A test-style ``line2x2`` (start, middle, end; piecewise linear) is a row like any
    other: three columns, and not line3."""
    def shape(xi):
        x = np.asarray(xi, dtype=float)[0]
        return np.stack([np.maximum(-x, 0), np.maximum(x, 0), 1 - np.abs(x)])[[0, 2, 1]]

    def dshape(xi):
        x = np.asarray(xi, dtype=float)[0]
        s = np.where(x < 0, -1.0, 1.0)
        return np.stack([np.where(x < 0, -1.0, 0.0), -s, np.where(x < 0, 0.0, 1.0)])[:, None]

    def rule(degree):
        p, w = line_quadrature(degree)
        return np.hstack([0.5 * (p - 1), 0.5 * (p + 1)]), np.hstack([0.5 * w, 0.5 * w])

    cell = CellType("line2x2_cells_test", 1, 3, (0, 2), ((0, 1, 2),),
                    np.array([[-1.0, 0.0, 1.0]]), shape, dshape,
                    lambda xi: np.zeros((3, 1, 1) + np.shape(xi)[1:]), rule)
    register_cell(cell)
    try:
        assert cell_type("line2x2_cells_test") is cell and cell is not CELLS["line3"]
        pts, w = cell.quadrature(1)
        assert np.isclose(w.sum(), 2.0) and np.isclose(cell.shape(pts) @ w, [0.5, 1, 0.5]).all()
    finally:
        del CELLS["line2x2_cells_test"]


def test_output_cells():
    """Cells VTK knows are written as they are; another type as its edges' pieces."""
    from skfem_mortar.contact.cell_map import output_cells
    conn = np.array([[0, 1, 2], [2, 3, 4]])
    assert output_cells(conn, "line3")[0][0] == "line3"
    assert output_cells(conn, "tri3")[0][0] == "triangle"
    cell = CellType("pieces_cells_test", 1, 3, (0, 2), ((0, 1, 2),),
                    np.array([[-1.0, 0.0, 1.0]]), CELLS["line3"].shape, CELLS["line3"].dshape,
                    CELLS["line3"].d2shape, line_quadrature)
    kind, lines = output_cells(conn, cell)[0]
    assert kind == "line" and lines.tolist() == [[0, 1], [1, 2], [2, 3], [3, 4]]


def test_one_point_triangle_rule_is_scipys_without_importing_it():
    """The one-point triangle rule (what registering tri3 asks) is written out so that
    importing the package does not import scipy.special (25 ms): the same bits."""
    import subprocess
    import sys

    from scipy.special import roots_jacobi

    from skfem_mortar.contact.cells import tri_quadrature
    v, wv = roots_jacobi(1, 1.0, 0.0)
    y = 0.5 * (1.0 + v[0])
    X, w = tri_quadrature(1)
    assert np.array_equal(X, [[0.5 * (1.0 - y)], [y]]) and np.array_equal(w, [2.0 * 2.0 / 8.0])
    code = "import sys, skfem_mortar.app.runner; print('scipy.special' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
