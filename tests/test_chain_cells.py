"""core/chain.py takes the segments' cell: nothing there has to read line3 from three
columns.  With the cell given, a piecewise-linear ``line2x2`` cell (start, middle, end:
line3's column count) gets its own lengths, tributary lengths, chords, ends and
points; line2/line3 give what the column-count default gives (bit for bit: the same
code); a cell that does not fit the columns, or is not a line, is refused naming it."""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact.cells import cell_type
from skfem_mortar.core import chain
from test_cell_registration import LINE2X2

X = np.array([[0.0, 0.3, 1.0, 1.5, 1.2], [0.0, 0.2, 0.0, 0.1, 0.05]])
L1, L2 = np.hypot(0.3, 0.2), np.hypot(0.7, 0.2)


def test_line2x2_through_the_chain_functions():
    seg = np.array([[0, 1, 2]])
    np.testing.assert_allclose(chain.segment_lengths(X, seg, LINE2X2), [L1 + L2], rtol=1e-14)
    np.testing.assert_allclose(chain.tributary_lengths(X, seg, LINE2X2)[:3],
                               [L1 / 2, (L1 + L2) / 2, L2 / 2], rtol=1e-14)
    np.testing.assert_array_equal(chain.polyline(seg, LINE2X2), [[0, 1], [1, 2]])
    ending, starting = chain.segments_at_nodes(seg, 5, LINE2X2)
    assert ending[2] == 0 and starting[0] == 0 and ending[1] == starting[1] == -1
    n, length = chain.segment_normals(X, seg, LINE2X2)
    np.testing.assert_allclose(n[:, 0], [0.0, -1.0], atol=1e-15)   # the chord start -> end
    np.testing.assert_allclose(chain.curve_points(X, seg, np.array([-0.5, 0.5]), LINE2X2)[:, 0],
                               [[0.15, 0.65], [0.1, 0.1]], rtol=1e-14)


@pytest.mark.parametrize("name, seg", [("line2", [[0, 1], [1, 2]]),
                                       ("line3", [[0, 2, 1], [2, 3, 4]])])
def test_line2_line3_unchanged(name, seg):
    seg = np.array(seg)
    for f in (chain.segment_lengths, chain.tributary_lengths, chain.polyline):
        args = (seg,) if f is chain.polyline else (X, seg)
        np.testing.assert_array_equal(f(*args, cell_type(name)), f(*args))
        np.testing.assert_array_equal(f(*args, name), f(*args))


def test_refusals_name_the_cell():
    with pytest.raises(ValueError, match="line2"):
        chain.polyline(np.array([[0, 1, 2]]), "line2")
    with pytest.raises(ValueError, match="tri3"):
        chain.segment_lengths(X, np.array([[0, 1, 2]]), cell_type("tri3"))
    with pytest.raises(ValueError, match="cell must be"):
        chain.polyline(np.array([[0, 1]]), "quad4")
