"""A cell type and a segmentation registered from a test file: ``line2x2``.

``line2x2`` has three nodes (start, middle, end) and piecewise-linear geometry
through the middle node: line3's column count, and not line3.  A kernel that read
the cell type from the connectivity's columns would integrate it as a parabola
(with line3's node order, start, end, mid, even through the wrong nodes).

What holds now: the cell and its segmentation register; the segmentation's
integration cells are the line2 ones of its halves; the mortar kernels' values-only
parts read its row (tributary weights and supports by its shape functions and
composite rule, the crosspoint merge along its edge); the curved kernel's
monomials, read from the rows, refuse it (it is no polynomial on [-1, 1]); and
every contact method refuses a ``line2x2`` surface at construction, naming the
cell, instead of integrating it as line3.  The mortar and NTS kernels evaluate
line2 and line3 only (their geometry is monomial coefficients per cell, now derived
from the cell table); the patch test through them waits for the kernels to
integrate a cell piece by piece (the dual coefficients over the projectable part
cross line2x2's kink at the middle node).
"""
from __future__ import annotations

import types

import numpy as np
import pytest

from skfem_mortar.contact import segmentation as sgm
from skfem_mortar.contact.cells import CELLS, CellType, cell_type, line_quadrature, register_cell
from skfem_mortar.contact.methods import make_method
from skfem_mortar.contact.mortar_quadratic import merge_matrix
from skfem_mortar.contact.mortar_support import multiplier_support, tributary_weights
from skfem_mortar.contact.mortar_quadratic_segmentation import monomials, segment_lines


def _shape(xi):
    x = np.asarray(xi, dtype=float)[0]
    left, right = np.minimum(x, 0.0), np.maximum(x, 0.0)
    return np.stack([-left, 1.0 + left - right, right])


def _dshape(xi):
    x = np.asarray(xi, dtype=float)[0]
    neg = (x < 0.0) * 1.0
    return np.stack([-neg, 2.0 * neg - 1.0, 1.0 - neg])[:, None]


def _d2shape(xi):
    x = np.asarray(xi, dtype=float)[0]
    return np.zeros((3, 1, 1) + x.shape)


def _quadrature(degree):
    """Gauss on each half of [-1, 1] (the shape functions are linear on each)."""
    x, w = line_quadrature(degree)
    return np.hstack([(x - 1.0) * 0.5, (x + 1.0) * 0.5]), np.hstack([w, w]) * 0.5


LINE2X2 = CellType("line2x2", 1, 3, (0, 2), ((0, 1, 2),),
                   np.array([[-1.0, 0.0, 1.0]]), _shape, _dshape, _d2shape, _quadrature, 1)


def segment_line2x2(xs, seg_s, xm, seg_m, cells, pairs=None, margin=None, frozen=True,
                    reach=0.0):
    """The line2 segmentation of the halves (start, middle), (middle, end), mapped back:
    ``xi = (xi_half - 1)/2`` on the first half, ``(xi_half + 1)/2`` on the second."""
    halves = np.stack([seg_s[:, [0, 1]], seg_s[:, [1, 2]]], 1).reshape(-1, 2)
    line2 = cell_type("line2")
    sg = segment_lines(xs, halves, xm, seg_m, (line2, line2), margin=margin, frozen=frozen,
                       reach=reach)
    second = sg.e_s % 2
    e_s = sg.e_s // 2
    xi = (sg.xi + np.where(second, 1.0, -1.0)[:, None]) * 0.5
    n = len(seg_s)
    elem_xi = np.tile([1.0, -1.0], (n, 1))
    np.minimum.at(elem_xi[:, 0], e_s, xi[:, 0])
    np.maximum.at(elem_xi[:, 1], e_s, xi[:, 1])
    return sgm.Segmentation(e_s=e_s, e_m=sg.e_m, xi=xi, src=sg.src, elem_xi=elem_xi,
                            elem_node=np.full((n, 2), -1), frozen=frozen, xi_m=sg.xi_m)


@pytest.fixture
def line2x2(monkeypatch):
    """``line2x2`` and its segmentation registered for one test, then removed."""
    register_cell(LINE2X2)
    monkeypatch.setitem(sgm.SEGMENTATIONS, "line2x2", segment_line2x2)
    yield LINE2X2
    CELLS.pop("line2x2")


def _surfaces():
    """A flat slave of 4 line2x2 cells (9 nodes) above a flat line2 master (5 cells)."""
    xs = np.vstack([np.linspace(0.0, 1.0, 9), np.full(9, 0.01)])
    ss = np.array([[2 * i, 2 * i + 1, 2 * i + 2] for i in range(4)])
    xm = np.vstack([np.linspace(1.1, -0.1, 6), np.zeros(6)])
    sm = np.array([[i, i + 1] for i in range(5)])
    s = types.SimpleNamespace(segments=ss, n_nodes=9, cell="line2x2", X=xs)
    m = types.SimpleNamespace(segments=sm, n_nodes=6, cell="line2", X=xm)
    return s, m


def test_line2x2_registers_and_its_segmentation_covers_its_halves(line2x2):
    """The table takes the row (its checks: identity at the nodes, shapes); the
    registered segmentation is found for it, and its integration cells of a flat
    slave fully over a flat master cover every slave cell exactly once."""
    assert cell_type("line2x2") is line2x2 and line2x2.n_nodes == cell_type("line3").n_nodes
    seg = sgm.segmentation_for((line2x2, cell_type("line2")))
    assert seg is segment_line2x2
    s, m = _surfaces()
    sg = seg(s.X, s.segments, m.X, m.segments, (line2x2, cell_type("line2")))
    covered = np.bincount(sg.e_s, weights=sg.xi[:, 1] - sg.xi[:, 0], minlength=4)
    np.testing.assert_allclose(covered, 2.0, rtol=1e-14)   # the length of [-1, 1]


@pytest.mark.parametrize("method", ["mortar", "mortar-dual"])
def test_every_method_refuses_a_cell_it_does_not_evaluate(line2x2, method):
    """A line2x2 slave is refused by the mortar kernels naming the cell, not
    integrated as line3 (NTS evaluates it through the table:
    ``tests/test_nts_cells.py``)."""
    s, m = _surfaces()
    with pytest.raises(ValueError, match="line2x2"):
        make_method(method, s, m)


def test_line2x2_weights_and_supports_come_from_its_row(line2x2):
    """The mortar kernels' tributary weights and supports read the cell's shape
    functions and composite rule: the hat functions' integrals over each half,
    ``l_1/2, (l_1 + l_2)/2, l_2/2``, where a parabola through the nodes differs."""
    xs = np.array([[0.0, 0.3, 1.0], [0.0, 0.2, 0.0]])
    seg = np.array([[0, 1, 2]])
    l1, l2 = np.hypot(0.3, 0.2), np.hypot(0.7, 0.2)
    np.testing.assert_allclose(tributary_weights(xs, seg, line2x2, 1),
                               [l1 / 2, (l1 + l2) / 2, l2 / 2], rtol=1e-14)
    sg = sgm.Segmentation(e_s=np.array([0, 0]), e_m=np.array([0, 0]),
                          xi=np.array([[-1.0, 0.0], [0.0, 0.5]]), src=np.full((2, 2), -1),
                          elem_xi=np.array([[-1.0, 0.5]]), elem_node=np.full((1, 2), -1))
    # the first half whole, the second from xi = 0 to 0.5 (N_3 = xi there: l2 / 8)
    np.testing.assert_allclose(multiplier_support(xs, seg, sg, line2x2, 1),
                               [l1 / 2, l1 / 2 + l2 * 0.375, l2 * 0.125], rtol=1e-14)


def test_line2x2_merge_follows_its_edge(line2x2):
    """A merged start node goes to the middle node, column 1 (its neighbour along the
    edge), not to column 2 as the line3 layout (start, end, mid) would send it; a
    merged middle node in halves to both ends."""
    T = merge_matrix(np.array([[True, False, False], [False, True, False]]), line2x2)
    np.testing.assert_array_equal(T[0], [[0, 0, 0], [1, 1, 0], [0, 0, 1]])
    np.testing.assert_array_equal(T[1], [[1, 0.5, 0], [0, 0, 0], [0, 0.5, 1]])
    with pytest.raises(ValueError, match="merged"):
        merge_matrix(np.zeros((1, 2), bool), line2x2)


def test_the_curved_kernels_monomials_come_from_the_rows_and_refuse_line2x2(line2x2):
    """The curved mortar kernel writes its geometry in the monomials of the cell's row
    (exact for line2, line3: the Taylor coefficients at 0 are dyadic); line2x2 is no
    polynomial on [-1, 1] and is refused naming it, not integrated as a parabola."""
    np.testing.assert_array_equal(monomials(cell_type("line2")), [[0.5, -0.5, 0], [0.5, 0.5, 0]])
    np.testing.assert_array_equal(monomials(cell_type("line3")),
                                  [[0, -0.5, 0.5], [0, 0.5, 0.5], [1, 0, -1]])
    with pytest.raises(ValueError, match="line2x2"):
        monomials(line2x2)
