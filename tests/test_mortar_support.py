"""The slave nodes' mortar supports and tributary weights read from the cell table
(:mod:`skfem_mortar.contact.mortar_support`), shared by the linear and curved kernels,
and the crosspoint merge along the cell's edge (:func:`~skfem_mortar.contact.
mortar_support.merge_matrix`).

Tolerances: the closed forms below and the Gauss sums agree to round-off of sums of a
few terms of size ~1 (rtol 1e-14); where the integrand is not a polynomial (a curved
line3 cell: ``|dx/dxi|`` is a square root) the rules are compared with each other
only through the kernels' own tests.
"""
from __future__ import annotations

import numpy as np

from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.mortar_support import multiplier_support, tributary_weights
from skfem_mortar.contact.segmentation import Segmentation


def _line2_support(xs, seg, xi, e):
    """The linear kernel's former closed form: on ``[xi_a, xi_b]`` of a cell of length
    ``l``, ``int N_1,2 = l/2 ((xi_b - xi_a) -+ (xi_b^2 - xi_a^2)/2)/2``."""
    lo, hi = xi[:, 0], xi[:, 1]
    half = 0.5 * np.hypot(*(xs[:, seg[e, 1]] - xs[:, seg[e, 0]]))
    out = np.zeros(xs.shape[1])
    np.add.at(out, seg[e, 0], half * ((hi - lo) - 0.5 * (hi * hi - lo * lo)) * 0.5)
    np.add.at(out, seg[e, 1], half * ((hi - lo) + 0.5 * (hi * hi - lo * lo)) * 0.5)
    return out


def test_line2_support_and_weights_are_the_closed_forms():
    rng = np.random.default_rng(3)
    xs = np.vstack([np.linspace(0.0, 1.0, 6), 0.1 * rng.random(6)])
    seg = np.array([[i, i + 1] for i in range(5)])
    e = np.array([0, 1, 1, 3, 4])
    xi = np.sort(rng.uniform(-1.0, 1.0, (5, 2)), axis=1)
    sg = Segmentation(e_s=e, e_m=np.zeros(5, int), xi=xi, src=np.full((5, 2), -1),
                      elem_xi=np.tile([1.0, -1.0], (5, 1)), elem_node=np.full((5, 2), -1))
    line2 = cell_type("line2")
    np.testing.assert_allclose(multiplier_support(xs, seg, sg, line2, 1),
                               _line2_support(xs, seg, xi, e), rtol=1e-14, atol=1e-17)
    ls = np.hypot(*np.diff(xs, axis=1))
    np.testing.assert_allclose(tributary_weights(xs, seg, line2, 1),
                               0.5 * (np.r_[ls, 0.0] + np.r_[0.0, ls]), rtol=1e-14)
