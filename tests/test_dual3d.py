"""Dual multipliers on tri3 and quad4 faces (contact/dual3d.py): the cofactor inverse up
to 4 x 4 on jets, Phi = 4 N - 1 on a fully projected tri3, the masking rule (sums to
one, the line2 basis along a covered edge), partly projected faces over strips of
relative width 1e-1 to 1e-7 with and without masking, tributary weights.  D_e and M_e
come from the 3D integration points (contact/points3d.py) and a small integrator here
that stands in for the kernel."""
import numpy as np
import pytest

from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.dual3d import (edge_distances, face_tributary_weights,
                                         merge_faces, sym_inverse)
from skfem_mortar.contact.jets import Jet
from skfem_mortar.contact.points3d import integration_points
from skfem_mortar.contact.segmentation3d import segment_faces
from test_points3d import _jacobian

SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]).T
TRIANGLE = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]).T


def _full(M: dict, k: int) -> np.ndarray:
    return np.array([[M[min(a, b), max(a, b)] for b in range(k)] for a in range(k)])


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_sym_inverse_is_numpy_inverse(k):
    """Random symmetric positive definite matrices: the cofactor inverse equals
    numpy's to 1e-12 relative (condition numbers below 1e2 here)."""
    rng = np.random.default_rng(k)
    A = rng.normal(size=(50, k, k))
    S = A @ np.swapaxes(A, 1, 2) + k * np.eye(k)
    inv = sym_inverse({(a, b): S[:, a, b] for a in range(k) for b in range(a, k)}, k)
    ref = np.linalg.inv(S)
    got = np.moveaxis(_full(inv, k), -1, 0)
    assert np.abs(got - ref).max() < 1e-12 * np.abs(ref).max()


def test_sym_inverse_derivatives_on_jets():
    """k = 4 on jets of 10 variables (the upper triangle): the gradient and Hessian of
    each entry against central differences of the values (step 1e-5: 1e-8)."""
    rng = np.random.default_rng(7)
    A = rng.normal(size=(4, 4))
    S = A @ A.T + 4 * np.eye(4)
    keys = [(a, b) for a in range(4) for b in range(a, 4)]
    J = {key: Jet.variable(np.array([S[key]]), i, 10, True) for i, key in enumerate(keys)}
    inv = sym_inverse(J, 4)
    h = 1e-5
    for i, key in enumerate(keys):
        def at(t):
            M = {kk: np.array([S[kk] + (t if kk == key else 0.0)]) for kk in keys}
            return sym_inverse(M, 4)
        p, m = at(h), at(-h)
        for kk in keys:
            assert abs((p[kk] - m[kk])[0] / (2 * h) - inv[kk].g[i, 0]) < 1e-8
    # the Hessian: differences of the jets' gradients
    for i, key in enumerate(keys):
        def grad(t):
            Jt = {kk: Jet.variable(np.array([S[kk] + (t if kk == key else 0.0)]), j, 10, True)
                  for j, kk in enumerate(keys)}
            return sym_inverse(Jt, 4)
        p, m = grad(h), grad(-h)
        for kk in keys:
            assert np.abs((p[kk].g - m[kk].g)[:, 0] / (2 * h) - inv[kk].hessian()[i, :, 0]).max() < 1e-7
    with pytest.raises(ValueError, match="k must be 1, 2, 3 or 4"):
        sym_inverse({}, 5)


def _face_matrices(xs, Ss, cs, xm, Sm, cm, T=None):
    """D_e (k,), M_e (k, k) over the face's projected part (the integration cells),
    of N~ = T N when T is given: the test's integrator."""
    seg = segment_faces(xs, Ss, xm, Sm, (cs.name, cm.name), pairs=([0], [0]))
    ip = integration_points(xs, Ss, xm, Sm, (cs.name, cm.name), seg, second=False)
    xi = np.stack([ip.xi_s[0].v, ip.xi_s[1].v])
    X = np.transpose(xs[:, Ss[ip.e_s]], (1, 2, 0))
    dG = (ip.w.v * _jacobian(cs, X, xi)).ravel()
    N = cs.shape(xi).reshape(cs.n_nodes, -1)
    if T is not None:
        N = T @ N
    return N @ dG, (N * dG) @ N.T, N


def _coefficients(D, M, T=None):
    """A~ = D~ M~^-1 (dead rows: identity in M~, zero in D~) and C = A~ T."""
    dead = ~np.any(M, axis=1) if T is None else ~T.any(axis=1)
    M = M + np.diag(dead * 1.0)
    A = np.diag(D) @ np.linalg.inv(M)
    return A if T is None else A @ T


def test_fully_projected_tri3_and_quad4():
    """A flat tri3 fully projected: A_e = 4 I - 1 (Phi_A = 4 N_A - 1); a parallelogram
    quad4: 4 on the diagonal, -2 to the edge neighbours, 1 across (the tensor product of
    line2's [[2, -1], [-1, 2]]); to 1e-12 (the points' round-off through M^-1)."""
    big = np.array([[-1, -1, 0.1], [2, -1, 0.1], [2, 2, 0.1], [-1, 2, 0.1]]).T
    Sm = np.array([[0, 3, 2, 1]])
    tri, quad = cell_type("tri3"), cell_type("quad4")
    D, M, _ = _face_matrices(TRIANGLE, np.array([[0, 1, 2]]), tri, big, Sm, quad)
    assert np.abs(_coefficients(D, M) - (4 * np.eye(3) - 1)).max() < 1e-12
    P = SQUARE.copy()
    P[0] += 0.3 * P[1]                                          # a parallelogram
    D, M, _ = _face_matrices(P, np.array([[0, 1, 2, 3]]), quad, big, Sm, quad)
    line = np.array([[2.0, -1.0], [-1.0, 2.0]])
    ref = np.kron(line, line)[np.ix_([0, 2, 3, 1], [0, 2, 3, 1])]
    assert np.abs(_coefficients(D, M) - ref).max() < 1e-12


def test_merge_rule():
    """tri3 with corner 2 masked: halves to 0 and 1; quad4 with corners 2, 3 masked: the
    line2 functions along edge 0-1 (3 to 0, 2 to 1); quad4 with corner 2 masked: halves
    to its neighbours 1 and 3; quad4 with 1, 2, 3 masked: all to 0; every column sums
    to one unless the whole face is masked (then zero)."""
    tri, quad = cell_type("tri3"), cell_type("quad4")
    assert np.array_equal(edge_distances(quad), [[0, 1, 2, 1], [1, 0, 1, 2], [2, 1, 0, 1],
                                                 [1, 2, 1, 0]])
    T = merge_faces(np.array([[False, False, True], [True, True, True]]), tri)
    assert np.array_equal(T[0], [[1, 0, 0.5], [0, 1, 0.5], [0, 0, 0]]) and not T[1].any()
    T = merge_faces(np.array([[False, False, True, True], [False, False, True, False],
                              [False, True, True, True]]), quad)
    assert np.array_equal(T[0], [[1, 0, 0, 1], [0, 1, 1, 0], [0, 0, 0, 0], [0, 0, 0, 0]])
    assert np.array_equal(T[1], [[1, 0, 0, 0], [0, 1, 0.5, 0], [0, 0, 0, 0], [0, 0, 0.5, 1]])
    assert np.array_equal(T[2, 0], [1, 1, 1, 1]) and not T[2, 1:].any()
    with pytest.raises(ValueError, match="merged must have the columns of the face cell"):
        merge_faces(np.zeros((1, 3), dtype=bool), quad)


def _strip(eps):
    """A master quad4 covering y < eps of the unit slave faces (facing down)."""
    xm = np.array([[-1, -1, 0.01], [-1, eps, 0.01], [2, eps, 0.01], [2, -1, 0.01]]).T
    return xm, np.array([[0, 1, 2, 3]])


@pytest.mark.parametrize("slave", ["tri3", "quad4"])
def test_partly_projected_faces_over_strips(slave):
    """A face covered over a strip of relative width eps along its edge 0-1, eps = 1e-1
    to 1e-7.  Unmasked, A_e grows like 6 / eps on the tri3 (593 at 0.01, the issue's
    figure) and 12 / eps on the quad4 (1188 at 0.01), and stays finite; masked by the rule (the far
    nodes merged), the coefficients are those of line2's dual basis along the edge
    (2 and -1, to 2 eps: the strip of a tri3 narrows along it, 0.16 at eps = 0.1),
    the multipliers sum
    to one at every Gauss point, and they are biorthogonal to N~ (1e-12 relative)."""
    cs, quad = cell_type(slave), cell_type("quad4")
    xs = TRIANGLE if slave == "tri3" else SQUARE
    Ss = np.arange(cs.n_nodes)[None]
    far = np.array([False, False, True] if slave == "tri3" else [False, False, True, True])
    T = merge_faces(far[None], cs)[0]
    grow = []
    for eps in 10.0 ** -np.arange(1, 8):
        xm, Sm = _strip(eps)
        D, M, _ = _face_matrices(xs, Ss, cs, xm, Sm, quad)
        A = _coefficients(D, M)
        assert np.all(np.isfinite(A))
        grow.append(np.abs(A).max())
        Dt, Mt, _ = _face_matrices(xs, Ss, cs, xm, Sm, quad, T)
        C = _coefficients(Dt, Mt, T)
        assert np.all(np.isfinite(C)) and np.abs(C).max() < 2.0 + 2 * eps
        kept = ~far
        assert np.abs(C[kept][:, kept] - [[2, -1], [-1, 2]]).max() < 2 * eps
        assert not C[far].any()
        # biorthogonal to N~ over the strip; sum_A C_AB = 1: sum_A Phi_A = 1
        At = np.diag(Dt) @ np.linalg.inv(Mt + np.diag(far * 1.0))
        assert np.abs((At @ Mt)[np.ix_(kept, kept)] - np.diag(Dt[kept])).max() < 1e-12 * Dt.max()
        assert np.abs(C.sum(axis=0) - 1.0).max() < 1e-9
    if slave == "tri3":
        assert abs(grow[1] - 593) < 1 and 5.9 / 1e-3 < grow[2] < 6.1 / 1e-3
    else:
        assert abs(grow[1] - 1188) < 1 and 11.9 / 1e-3 < grow[2] < 12.1 / 1e-3
    assert all(a < b for a, b in zip(grow[:4], grow[1:5]))      # growing while resolved


def test_tributary_weights():
    """A flat tri3 of area A: A/3 per corner; a parallelogram quad4: A/4; two faces
    sharing an edge add up; ``absolute`` equals the signed weights for these
    nonnegative functions."""
    w = face_tributary_weights(TRIANGLE, np.array([[0, 1, 2]]), "tri3")
    assert np.abs(w - 1 / 6).max() < 1e-15
    P = SQUARE.copy()
    P[0] += 0.3 * P[1]
    w = face_tributary_weights(P, np.array([[0, 1, 2, 3]]), "quad4")
    assert np.abs(w - 0.25).max() < 1e-15
    x = np.c_[SQUARE, [2, 0, 0], [2, 1, 0]]
    w = face_tributary_weights(x, np.array([[0, 1, 2, 3], [1, 4, 5, 2]]), "quad4",
                               absolute=True)
    assert np.allclose(w, [0.25, 0.5, 0.5, 0.25, 0.25, 0.25], rtol=0, atol=1e-15)
