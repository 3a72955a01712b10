"""The readings of the 3D refinement series (``scenes/_tied3d.py``): the oscillation
measure is 0 for a linear field on a uniform grid and O(1) for a checkerboard, the
lumped L2 error is 0 against the multipliers' own values and the stated ratio against a
scaled field, so the series' falling errors and bounded oscillations measure the
multipliers and not the readings."""
from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshTri

from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.mortar_support import tributary_weights
from skfem_mortar.scenes._tied3d import oscillation, traction_error

TRI3 = cell_type("tri3")


def _plane(n: int = 9):
    """A uniform tri3 grid on the plane ``X = 0.5`` (axis 0), ``(y, z)`` in ``[0, 1]^2``,
    and its nodes as 3D points."""
    mesh = MeshTri.init_tensor(np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, n))
    X = np.vstack([np.full(mesh.p.shape[1], 0.5), mesh.p])
    return X, mesh.t.T.copy()


def test_oscillation_is_zero_for_a_linear_field_and_order_one_for_a_checkerboard():
    """Interior nodes of the uniform grid have their six neighbours in opposite pairs,
    so a linear field equals their mean (round-off: 1e-15 of the field's size); the
    checkerboard ``(-1)^(i + j)`` departs from the mean of its neighbours (two of the
    same sign, four of the other) by ``1 - (2 - 4) / 6 = 4/3`` of its size."""
    X, conn = _plane()
    tied = np.ones(X.shape[1], dtype=bool)
    linear = np.vstack([1.0 + X[1] + 2.0 * X[2], X[2], -X[1]])
    assert oscillation(linear, conn, TRI3, tied) < 1e-13
    ij = np.round(X[1:] * 8).astype(int)
    checker = np.vstack([(-1.0) ** ij.sum(axis=0), np.zeros((2, X.shape[1]))])
    assert oscillation(checker, conn, TRI3, tied) == pytest.approx(4.0 / 3.0, rel=1e-12)


def test_oscillation_leaves_out_untied_nodes_and_their_neighbours():
    """A spike of 5 on a field of 1 reads ``(5 - 1) / 5`` when tied; on an untied
    node it is not read, nor are its neighbours (those nodes are the merged ones of
    the tie, or outside the contact's window)."""
    X, conn = _plane()
    field = np.vstack([np.ones(X.shape[1]), np.zeros((2, X.shape[1]))])
    centre = int(np.argmin(np.sum((X[1:] - 0.5) ** 2, axis=0)))
    field[0, centre] = 5.0
    tied = np.ones(X.shape[1], dtype=bool)
    assert oscillation(field, conn, TRI3, tied) == pytest.approx(0.8, rel=1e-12)  # 4 / 5
    tied[centre] = False
    assert oscillation(field, conn, TRI3, tied) == 0.0


def test_traction_error_is_the_lumped_relative_l2_norm():
    """Against its own nodal values the error is 0 (round-off); against a field ``1 +
    eps`` times the reference it is ``eps`` (the weights cancel); a node of weight 0
    is left out."""
    X, conn = _plane()
    w = tributary_weights(X, conn, TRI3, 2)
    t = np.vstack([np.sin(3 * X[1]) + 2.0, X[2] * X[1], np.cos(X[2])])
    assert traction_error(X, t, w, X, t, 0) < 1e-14
    assert traction_error(X, 1.25 * t, w, X, t, 0) == pytest.approx(0.25, rel=1e-12)
    spoiled = t.copy()
    spoiled[:, 0] += 100.0
    w0 = w.copy()
    w0[0] = 0.0
    assert traction_error(X, spoiled, w0, X, t, 0) < 1e-14
