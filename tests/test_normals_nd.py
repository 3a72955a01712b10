"""Averaged nodal normals of any dimension (contact/normals.py).

* Convergence to the exact normal of a sphere, at order 2: on a closed cube-sphere of
  quad4 cells (every node), and on a triangulated spherical cap (its inner nodes: a
  boundary node's cells lie on one side, an O(h) error that is no fault of the
  average).  The ratio of errors per halving of h must exceed 3.5 (order 2 gives 4; a
  first-order error gives 2).  On a closed geodesic or cube-split triangulation the
  error is O(h) at the nodes near its irregular vertices and along the base polyhedron's
  edges, where the mesh itself kinks: measured 1.9x per halving there, so those meshes
  are not used to show the order.
* First and second derivatives against central differences, tri3, quad4, line2, line3.
  Step 1e-6: truncation h^2 |f'''| ~ 1e-12 times the mesh's curvature scale, rounding
  eps/h ~ 1e-10; derivatives here are O(1 / cell size) ~ 10 and second O(100), so
  atol 1e-6 (first) and 1e-5 (second, differences of first derivatives).
* 2D: the same normals, derivatives and Hessians as the mortar kernels' own
  (mortar_segmentation.nodal_normals jets; mortar_quadratic_segmentation.nodal_normals
  values), to 1e-13 (both are a few flops from the same coordinates).
"""
import numpy as np
import pytest

from skfem_mortar.contact.normals import nodal_normals

RNG = np.random.default_rng(34)


def cap(n, a=0.5):
    """A spherical cap: the square [-a, a]^2 at z = 1, n x n cells split along one
    diagonal, projected onto the unit sphere; and which nodes are inside."""
    s = np.linspace(-a, a, n + 1)
    U, V = np.meshgrid(s, s, indexing="ij")
    x = np.vstack([U.ravel(), V.ravel(), np.ones(U.size)])
    x /= np.linalg.norm(x, axis=0)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    inner = ((np.abs(U) < a - 1e-12) & (np.abs(V) < a - 1e-12)).ravel()
    return x, q, np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]), inner


def cube_sphere(n):
    """The six faces of the cube [-1, 1]^3, n x n quad4 cells each, projected onto the
    unit sphere, counter-clockwise seen from outside."""
    s = np.linspace(-1.0, 1.0, n + 1)
    A, B = np.meshgrid(s, s, indexing="ij")
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    P, C, e = [], [], np.eye(3)
    for ax in range(3):
        for sign in (1.0, -1.0):
            P.append(sign * e[ax][:, None] + A.ravel() * e[(ax + 1) % 3][:, None]
                     + B.ravel() * e[(ax + 2) % 3][:, None])
            C.append(q + ax * 2 * idx.size + (sign < 0) * idx.size)
    P, C = np.hstack(P), np.vstack(C)
    P /= np.linalg.norm(P, axis=0)
    _, first, inv = np.unique(np.round(P * 1e9).astype(np.int64), axis=1, return_index=True,
                              return_inverse=True)
    x, C = P[:, first], inv.ravel()[C]
    v = np.cross(x[:, C[:, 2]] - x[:, C[:, 0]], x[:, C[:, 3]] - x[:, C[:, 1]], axis=0)
    flip = np.sum(v * x[:, C].mean(axis=2), axis=0) < 0
    C[flip] = C[flip][:, [0, 3, 2, 1]]
    return x, C


def test_sphere_quad4_second_order_at_every_node():
    errors = []
    for n in (4, 8, 16):
        x, C = cube_sphere(n)
        nn = nodal_normals(x, C, "quad4", order=0)
        errors.append(np.linalg.norm(nn.n - x, axis=0).max())
    ratios = np.array(errors[:-1]) / errors[1:]
    assert np.all(ratios > 3.5), (errors, ratios)       # measured 3.67, 3.91


def test_sphere_cap_tri3_second_order_at_inner_nodes():
    errors = []
    for n in (8, 16, 32):
        x, _, T, inner = cap(n)
        nn = nodal_normals(x, T, "tri3", order=0)
        errors.append(np.linalg.norm(nn.n - x, axis=0)[inner].max())
    ratios = np.array(errors[:-1]) / errors[1:]
    assert np.all(ratios > 3.5), (errors, ratios)       # measured 3.92, 3.99
    assert errors[-1] < 5e-4                              # measured 2.7e-4


def _normals_flat(x, conn, cell):
    return nodal_normals(x, conn, cell, order=0).n


def _full(nn, n_nodes):
    """The neighbourhood derivatives scattered to (d, n, n_nodes, d) and the second (if
    any) to (d, n, n_nodes, d, n_nodes, d)."""
    d, n = nn.n.shape
    K = nn.nodes.shape[1]
    J = np.zeros((d, n, n_nodes, d))
    H = np.zeros((d, n, n_nodes, d, n_nodes, d))
    for A in range(n):
        for j in range(K):
            b = nn.nodes[A, j]
            if b < 0:
                continue
            J[:, A, b] += nn.dn[:, A, j]
            for l in range(K):
                c = nn.nodes[A, l]
                if c >= 0 and nn.d2n is not None:
                    H[:, A, b, :, c] += nn.d2n[:, A, j, :, l]
    return J, H


def _meshes():
    x, q, T, _ = cap(3)
    yield "tri3", x + 0.02 * RNG.standard_normal(x.shape), T
    yield "quad4", x + 0.02 * RNG.standard_normal(x.shape), q
    t = np.linspace(0.0, 2.0, 7)
    curve = np.vstack([t, 0.3 * np.sin(t)]) + 0.01 * RNG.standard_normal((2, 7))
    yield "line2", curve, np.column_stack([np.arange(6), np.arange(1, 7)])
    ends = np.column_stack([np.arange(0, 6, 2), np.arange(2, 8, 2), np.arange(1, 7, 2)])
    yield "line3", curve, ends


@pytest.mark.parametrize("case", list(_meshes()), ids=lambda c: c[0])
def test_derivatives_against_central_differences(case):
    cell, x, conn = case
    n_nodes, d = x.shape[1], x.shape[0]
    nn = nodal_normals(x, conn, cell)
    J, H = _full(nn, n_nodes)
    h = 1e-6
    for b in range(n_nodes):
        for c in range(d):
            e = np.zeros_like(x)
            e[c, b] = h
            fd = (_normals_flat(x + e, conn, cell) - _normals_flat(x - e, conn, cell)) / (2 * h)
            assert np.allclose(J[:, :, b, c], fd, atol=1e-6, rtol=0), (b, c)
            dp = _full(nodal_normals(x + e, conn, cell, order=1), n_nodes)[0]
            dm = _full(nodal_normals(x - e, conn, cell, order=1), n_nodes)[0]
            assert np.allclose(H[:, :, :, :, b, c], (dp - dm) / (2 * h), atol=1e-5, rtol=0)
    # the Hessian is symmetric in its two variable pairs
    assert np.allclose(H, np.transpose(H, (0, 1, 4, 5, 2, 3)), atol=1e-12)


def test_2d_linear_normals_are_the_mortar_kernels():
    from skfem_mortar.contact.mortar_segmentation import nodal_normals as kernel
    t = np.linspace(0.0, 3.0, 9)
    x = np.vstack([t, 0.4 * np.sin(t)]) + 0.02 * RNG.standard_normal((2, 9))
    seg = np.column_stack([np.arange(8), np.arange(1, 9)])
    (nx, ny), pnode, nnode = kernel(x, seg, second=True, nv=6)
    nn = nodal_normals(x, seg, "line2")
    assert np.allclose(nn.n, np.vstack([nx.v, ny.v]), atol=1e-14, rtol=0)
    for A in range(9):
        slots = [list(nn.nodes[A]).index(b) for b in (pnode[A], A, nnode[A])]
        for i, jet in enumerate((nx, ny)):
            g = jet.g[:, A].reshape(3, 2)
            Hk = jet.hessian()[:, :, A].reshape(3, 2, 3, 2)
            ours = nn.dn[i, A][slots]
            ours2 = nn.d2n[i, A][slots][:, :, slots]
            ends = [k for k, b in enumerate((pnode[A], A, nnode[A])) if b != A or k == 1]
            assert np.allclose(ours[ends], g[ends], atol=1e-13, rtol=0)
            assert np.allclose(ours2[ends][:, :, ends], Hk[ends][:, :, ends], atol=1e-12, rtol=0)


def test_2d_curved_normals_are_the_quadratic_kernels():
    from skfem_mortar.contact.mortar_quadratic_segmentation import nodal_normals as kernel
    t = np.linspace(0.0, 3.0, 9)
    x = np.vstack([t, 0.4 * np.sin(t)]) + 0.02 * RNG.standard_normal((2, 9))
    seg = np.column_stack([np.arange(0, 8, 2), np.arange(2, 10, 2), np.arange(1, 9, 2)])
    assert np.allclose(nodal_normals(x, seg, "line3", order=0).n, kernel(x, seg),
                       atol=1e-14, rtol=0)


def test_any_number_of_neighbours_and_degenerate_cells():
    """A fan of 7 triangles around a node (K = 8) and a node on one degenerate cell
    only (zero normal)."""
    ang = np.linspace(0, 2 * np.pi, 8)[:-1]
    x = np.vstack([np.r_[0.0, np.cos(ang), 5.0], np.r_[0.0, np.sin(ang), 5.0],
                   np.r_[0.3, np.zeros(7), 5.0]])
    T = np.column_stack([np.zeros(7, int), 1 + np.arange(7), 1 + (np.arange(7) + 1) % 7])
    T = np.vstack([T, [8, 8, 8]])
    nn = nodal_normals(x, T, "tri3")
    assert nn.nodes.shape[1] == 8 and set(nn.nodes[0]) == set(range(8))
    assert np.allclose(nn.n[:, 0], [0, 0, 1], atol=1e-15)
    assert np.all(nn.n[:, 8] == 0) and np.all(nn.dn[:, 8] == 0)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="x must have shape"):
        nodal_normals(np.zeros((2, 3)), [[0, 1, 2]], "tri3")
    with pytest.raises(ValueError, match="connectivity of tri3"):
        nodal_normals(np.zeros((3, 4)), [[0, 1, 2, 3]], "tri3")
    with pytest.raises(ValueError, match="order"):
        nodal_normals(np.zeros((3, 3)), [[0, 1, 2]], "tri3", order=3)
