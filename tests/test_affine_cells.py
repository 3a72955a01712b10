"""Straight lines are a property of the cell row (``CellType.affine``: order 1 with
``dim + 1`` nodes), not of the name ``line2``: the mortar method's search
(``Mortar.curved``) and the lines' segmentation (``segment_lines``) read it.

A copy of line2's row registered under another name takes line2's path: the method
searches as for line2, and its evaluation is line2's to the bit (the same closed forms,
the same operations in the same order); the bilinear quad4 and the piecewise line2x2
(order 1, three nodes) are not affine.
"""
from __future__ import annotations

import dataclasses
import types

import numpy as np
import pytest

from skfem_mortar.contact.cells import CELLS, cell_type, register_cell
from skfem_mortar.contact.methods import make_method

from test_cell_registration import LINE2X2


@pytest.mark.parametrize("name, affine", [("line2", True), ("line3", False), ("tri3", True),
                                          ("quad4", False)])
def test_the_rows_say_whether_they_are_affine(name, affine):
    assert cell_type(name).affine is affine


def test_a_piecewise_line_is_not_affine():
    assert LINE2X2.order == 1 and not LINE2X2.affine


@pytest.fixture
def straight2():
    register_cell(dataclasses.replace(cell_type("line2"), name="straight2"))
    yield
    CELLS.pop("straight2")


def _surfaces(cell):
    def chain(n, f, x0, x1):
        xv = np.linspace(x0, x1, n + 1)
        seg = np.array([[i, i + 1] for i in range(n)])
        return np.array([xv, f(xv)]), types.SimpleNamespace(
            segments=seg, n_nodes=n + 1, order=1, cell=cell)
    xs, s = chain(25, lambda x: 0.999 - np.sqrt(1.0 - x * x), -0.3, 0.3)
    xm, m = chain(33, lambda x: 0.02 * np.sin(5 * x), 0.45, -0.45)
    return xs, s, xm, m


@pytest.mark.parametrize("method", ["mortar", "mortar-dual"])
def test_a_renamed_line2_takes_line2s_path(straight2, method):
    evs = []
    for cell in ("line2", "straight2"):
        xs, s, xm, m = _surfaces(cell)
        meth = make_method(method, s, m)
        assert not meth.curved
        evs.append(meth.evaluate(xs, xm, np.linspace(0.5, 1.5, xs.shape[1]), True))
    a, b = evs
    assert np.array_equal(a.g, b.g) and np.array_equal(a.mask, b.mask)
    for u, v in ((a.G, b.G), (a.H, b.H)):
        assert (u != v).nnz == 0
