"""Which slave cells the line segmentation reports covered whole
(:meth:`~skfem_mortar.contact.line_points.LineSegmentation.whole_cells`): the cells whose
dual basis is the reference cell's (both ends slave vertices, no gap, no overlap, an
affine slave cell); the kernel may then skip the mass jets."""
from __future__ import annotations

import numpy as np

from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.line_points import LineSegmentation

LINE2, LINE3 = cell_type("line2"), cell_type("line3")


def _flat(xs_x, xm_x, d=0.01):
    xs_x, xm_x = np.asarray(xs_x, float)[::-1], np.asarray(xm_x, float)
    xs = np.vstack([xs_x, np.zeros_like(xs_x)])
    xm = np.vstack([xm_x, np.full_like(xm_x, d)])
    chain = lambda n: np.c_[np.arange(n - 1), np.arange(1, n)]  # noqa: E731
    return xs, chain(xs.shape[1]), xm, chain(xm.shape[1])


def test_whole_cells_are_the_fully_covered_ones():
    """Slave cells [0, .25], ..., [.75, 1] (numbered from x = 1) under a master from 0.1
    to 0.9 with a node at 0.6: the two middle cells are covered whole (one of them by
    two pieces), the end cells only in part."""
    xs, ss, xm, sm = _flat(np.linspace(0, 1, 5), [0.1, 0.6, 0.9])
    pts = LineSegmentation((LINE2, LINE2))
    ic = pts.integration_cells(xs, ss, xm, sm)
    whole = pts.whole_cells(ic)
    by_cell = {int(e): bool(w) for e, w in zip(ic.e_s, whole)}
    assert by_cell == {0: False, 1: True, 2: True, 3: False}
    assert np.sum(ic.e_s == 1) == 2 or np.sum(ic.e_s == 2) == 2      # one cell in two pieces


def test_a_gap_in_the_master_is_not_whole():
    """A master with a hole inside one slave cell: the hull of its pieces is the whole
    cell but their lengths sum to less than 2: not whole."""
    xs, ss, _, _ = _flat(np.linspace(0, 1, 3), [0.0])
    xm = np.array([[-0.1, 0.7, 0.8, 1.1], [0.01] * 4])
    sm = np.array([[0, 1], [2, 3]])
    pts = LineSegmentation((LINE2, LINE2))
    ic = pts.integration_cells(xs, ss, xm, sm)
    whole = pts.whole_cells(ic)
    assert not whole[ic.e_s == 0].any() and whole[ic.e_s == 1].all()


def test_curved_cells_report_nothing():
    """line3 slave cells: their Jacobian is not constant, no reference basis (None)."""
    t = np.linspace(0.0, 1.0, 5)
    xs = np.vstack([t[::-1], 0.0 * t])
    ss = np.array([[0, 2, 1], [2, 4, 3]])
    pts = LineSegmentation((LINE3, LINE2))
    xm = np.array([[-0.2, 1.2], [0.01, 0.01]])
    ic = pts.integration_cells(xs, ss, xm, np.array([[0, 1]]))
    assert pts.whole_cells(ic) is None
