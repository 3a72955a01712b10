"""Mirror normals (contact/normals.py, ``mirror=``): a node on a symmetry line or plane
averages its normal with its mirror image, so its normal lies in the plane.

* A symmetric quad4 cap cut in half at x = 0: the half's mirrored normals at the cut
  equal the whole cap's normals there (the whole mesh is symmetric, so its average
  is the mirrored one), to round-off.
* First and second derivatives against central differences (tri3, quad4 half caps,
  a line2 and a line3 chain from the axis r = 0), step 1e-6 with the tolerances of
  test_normals_nd (atol 1e-6 first, 1e-5 second); the e-component of a node on the
  plane is not varied (a model holds it there: it is a symmetry condition, and the
  node would leave the plane).  In 2D the mirror normal of a node on the line is
  ``(0, +-1)``-like: constant, all its derivatives zero.
"""
import numpy as np
import pytest

from skfem_mortar.contact.normals import mirror_nodes, mirror_of_axis, nodal_normals
from test_normals_nd import RNG, _full, cap

X_PLANE = ((np.array([1.0, 0.0, 0.0]), 0.0),)


def half_cap(n: int, cell: str, jitter: float = 0.0):
    """The cap of test_normals_nd (n even) restricted to x >= 0, nodes on x = 0 exactly;
    ``jitter`` moves every node but keeps those nodes' x at 0.  Returns the nodes,
    the cells, which nodes are on x = 0 and the kept nodes' numbers in the cap."""
    x, q, T, _ = cap(n)
    conn = q if cell == "quad4" else T
    keep = np.all(x[0, conn] >= -1e-15, axis=1)
    conn = conn[keep]
    used = np.unique(conn)
    new = np.full(x.shape[1], -1)
    new[used] = np.arange(used.size)
    x = x[:, used].copy()
    on = np.abs(x[0]) < 1e-15
    x[0, on] = 0.0
    if jitter:
        dx = jitter * RNG.standard_normal(x.shape)
        dx[0, on] = 0.0
        x += dx
    return x, new[conn], on, used


def test_mirrored_half_equals_the_symmetric_whole():
    x, q, _, _ = cap(4)
    whole = nodal_normals(x, q, "quad4", order=0).n
    xh, qh, on, used = half_cap(4, "quad4")
    half = nodal_normals(xh, qh, "quad4", order=0, mirror=X_PLANE).n
    plain = nodal_normals(xh, qh, "quad4", order=0).n
    np.testing.assert_allclose(half[:, on], whole[:, used[on]], atol=1e-14)
    np.testing.assert_array_equal(half[:, ~on], plain[:, ~on])
    assert np.abs(half[0, on]).max() < 1e-15
    assert np.abs(plain[0, on]).min() > 1e-2     # without the mirror they tilt off x = 0


def _fd(x, conn, cell, mirror, frozen):
    """The derivatives of nodal_normals against central differences, every coordinate
    but those in ``frozen`` (bool (d, n))."""
    n_nodes, d = x.shape[1], x.shape[0]
    nn = nodal_normals(x, conn, cell, mirror=mirror)
    J, H = _full(nn, n_nodes)
    h = 1e-6

    def flat(y, order=0):
        return nodal_normals(y, conn, cell, order=order, mirror=mirror)
    for b in range(n_nodes):
        for c in range(d):
            if frozen[c, b]:
                continue
            e = np.zeros_like(x)
            e[c, b] = h
            fd = (flat(x + e).n - flat(x - e).n) / (2 * h)
            assert np.allclose(J[:, :, b, c], fd, atol=1e-6, rtol=0), (b, c)
            dp, dm = _full(flat(x + e, 1), n_nodes)[0], _full(flat(x - e, 1), n_nodes)[0]
            assert np.allclose(H[:, :, :, :, b, c], (dp - dm) / (2 * h), atol=1e-5, rtol=0)
    assert np.allclose(H, np.transpose(H, (0, 1, 4, 5, 2, 3)), atol=1e-12)
    return nn, J


@pytest.mark.parametrize("cell", ["tri3", "quad4"])
def test_3d_mirror_derivatives(cell):
    x, conn, on, _ = half_cap(2, cell, jitter=0.02)
    frozen = np.zeros_like(x, dtype=bool)
    frozen[0, on] = True
    nn, J = _fd(x, conn, cell, X_PLANE, frozen)
    assert on.sum() >= 3 and np.abs(nn.n[0, on]).max() < 1e-15
    assert np.abs(J[:, on]).max() > 1e-2      # in 3D they still move with the mesh


@pytest.mark.parametrize("cell", ["line2", "line3"])
def test_axis_mirror_in_2d(cell):
    """A chain from the axis r = 0: the axis node's normal is axial, (0, -1) here, with
    zero derivatives; the other nodes are unchanged, and so are their derivatives."""
    t = np.linspace(0.0, 1.0, 7)
    x = np.vstack([t, 0.3 * t * t]) + 0.01 * RNG.standard_normal((2, 7))
    x[0, 0] = 0.0
    conn = (np.column_stack([np.arange(6), np.arange(1, 7)]) if cell == "line2" else
            np.column_stack([np.arange(0, 6, 2), np.arange(2, 8, 2), np.arange(1, 7, 2)]))
    mirror = mirror_of_axis(0)
    frozen = np.zeros_like(x, dtype=bool)
    frozen[0, 0] = True
    nn, J = _fd(x, conn, cell, mirror, frozen)
    np.testing.assert_array_equal(nn.n[:, 0], [0.0, -1.0])
    # zero to round-off: (P s) / |P s| of s = (0, s_y) differentiated (exact zero
    # for the first derivatives, 1e-16 of the second)
    assert np.abs(nn.dn[:, 0]).max() < 1e-15 and np.abs(nn.d2n[:, 0]).max() < 1e-12
    plain = nodal_normals(x, conn, cell)
    np.testing.assert_array_equal(nn.n[:, 1:], plain.n[:, 1:])
    np.testing.assert_array_equal(nn.dn[:, 1:], plain.dn[:, 1:])


def test_mirror_input_is_checked():
    x = np.zeros((2, 3))
    with pytest.raises(ValueError, match="mirror"):
        mirror_nodes(x, [(np.zeros(2), 0.0)])
    with pytest.raises(ValueError, match="mirror"):
        mirror_nodes(x, [(np.ones(3), 0.0)])
    with pytest.raises(ValueError, match="mirror"):
        mirror_nodes(x, [np.ones(2)])
    assert mirror_of_axis(None) == ()
