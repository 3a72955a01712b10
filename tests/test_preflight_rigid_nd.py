"""Rigid modes of bodies of any dimension (contact/preflight_rigid.py): d (d + 1)/2
modes built from the body's coordinates, 3 in 2D and 6 in 3D.

A duck-typed 3D body (coordinates, node dofs, no stiffness of its own) stands in for a
3D solid: the preflight reads nothing else of it.  Rigidity is exact arithmetic on
O(1) numbers: (u(P) - u(Q)) . (P - Q) = 0 to 1e-14.
"""
from types import SimpleNamespace

import numpy as np
import pytest

from skfem_mortar.contact.preflight_rigid import _rigid_modes, check_rigid_modes

RNG = np.random.default_rng(36)


class _Body3D:
    """n nodes in 3D, dofs node-major (x, y, z), no stiffness (its energy is unknown
    to the preflight: it is held only by the Dirichlet data)."""

    dof_kind = "u"

    def __init__(self, n, offset=0, name="cube"):
        self.X = RNG.uniform(0.0, 1.0, (3, n))
        self.n_nodes, self.n_dofs, self.offset, self.name = n, 3 * n, offset, name
        self.node_dofs = np.arange(3 * n).reshape(n, 3).T

    def assemble(self, z, load_factor, tangent=True):
        e = np.zeros(0)
        return SimpleNamespace(k_vals=e, k_rows=e.astype(int), k_cols=e.astype(int))


def _model(body):
    return SimpleNamespace(items=[body], bodies=[body], n=body.n_dofs, n_u=body.n_dofs)


@pytest.mark.parametrize("d", [2, 3])
def test_modes_are_the_rigid_motions(d):
    n = 9
    X = RNG.uniform(0.0, 2.0, (d, n))
    body = SimpleNamespace(X=X, n_dofs=d * n, node_dofs=np.arange(d * n).reshape(n, d).T)
    bd = _rigid_modes(body)
    assert bd.n_modes == d * (d + 1) // 2
    assert np.linalg.matrix_rank(bd.modes) == bd.n_modes
    for j in range(bd.n_modes):
        u = bd.modes[body.node_dofs, j]                      # (d, n)
        dU = u[:, :, None] - u[:, None, :]
        dX = X[:, :, None] - X[:, None, :]
        assert np.abs(np.sum(dU * dX, axis=0)).max() < 1e-14
        size = np.hypot.reduce(u, axis=0).max()      # largest nodal motion: 1 (rotations
        assert size == 1.0 if j < d else size <= 1 + 1e-14   # about an axis: at most 1)


def test_3d_body_held_by_three_pinned_nodes_passes():
    body = _Body3D(8)
    fixed = body.node_dofs[:, :3].ravel()                    # three nodes, all components
    check_rigid_modes(_model(body), np.zeros(body.n_dofs), 0.0, fixed)


def test_3d_body_pinned_at_one_node_is_free_to_rotate():
    body = _Body3D(8)
    with pytest.raises(ValueError, match=r"3 of its 6 rigid modes \(0 translation\(s\), "
                                         r"3 rotation\(s\)\).*pin three nodes"):
        check_rigid_modes(_model(body), np.zeros(body.n_dofs), 0.0, body.node_dofs[:, 0])
    with pytest.raises(ValueError, match=r"6 of its 6 rigid modes \(3 translation\(s\), 3 rotation"):
        check_rigid_modes(_model(body), np.zeros(body.n_dofs), 0.0, np.zeros(0, int))


def test_a_body_of_another_dimension_is_refused():
    body = SimpleNamespace(X=np.zeros((4, 3)), n_dofs=12, node_dofs=np.zeros((4, 3), int),
                           name="b")
    with pytest.raises(ValueError, match="2 or 3 rows"):
        _rigid_modes(body)
