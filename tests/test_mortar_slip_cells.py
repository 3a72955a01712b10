"""The mortar slip on the one kernel (contact/mortar_slip_cells.py, contact/slip.py).

* ``r_A`` of :func:`tangential_evaluate` is ``tau_A . (M x_m - D x_s)`` with the ``D``, ``M``
  of the same call, and ``D``, ``M`` and the mask are those of the weighted gap's call;
* the whole :func:`mortar_slip` (history part included): ``G`` and ``H`` against central
  differences on line2, line3, mixed and line2x2 cells, standard and dual, plane and
  axisymmetric, with a slave overhanging the master (a masked, merged node);
* the tangent's chained derivatives (:func:`tangent_jets`) against differences of the
  nodal normals, and the 3D refusal.
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.measures import AXISYMMETRIC, PLANE
from skfem_mortar.contact.mortar_slip_cells import (tangent_basis, tangent_jets,
                                                    tangential_evaluate)
from skfem_mortar.contact.normals import nodal_normals
from skfem_mortar.contact.slip import mortar_history, mortar_slip
from test_cell_registration import line2x2  # noqa: F401  (the fixture)
from test_slip import fd_jacobian, pack, unpack

# Central differences with h = 1e-6 on unit-size geometry: truncation ~h^2 |u'''| ~ 1e-12
# and round-off ~eps |u| / h ~ 1e-10, times the entries' scale (2 pi r ~ 10 with the
# axisymmetric weight), so exact derivatives agree to ~1e-9 of the largest entry; a
# missing chain-rule term is off by O(1e-3..1).
FD_H = 1e-6
FD_TOL = 2e-8
N_DIRECTIONS = 4
# Sums of the same products in another order: round-off of |D| |x| ~ 1 (x 2 pi r).
ROUND = 1e-13


def _cells(kind: str, n: int) -> np.ndarray:
    """``n`` cells of ``kind`` along a chain of nodes (line3: start, end, mid)."""
    i = np.arange(n)
    if kind == "line2":
        return np.c_[i, i + 1]
    if kind == "line3":
        return np.c_[2 * i, 2 * i + 2, 2 * i + 1]
    return np.c_[2 * i, 2 * i + 1, 2 * i + 2]                    # line2x2


def surfaces(ks: str, km: str, off: float = 0.0, ns: int = 4, nm: int = 4):
    """A curved slave (above, along +x: outward normal down) over a curved master (along
    -x), slightly apart, at radius >= 0.7; ``off`` shifts the slave along x (-0.6: its
    first cell lies beyond the master's end, so its first node is masked and merged)."""
    nn = lambda k, n: n + 1 if k == "line2" else 2 * n + 1      # noqa: E731
    X = np.linspace(1.3, 2.3, nn(ks, ns)) + off
    xs = np.array([X, 0.5 + 0.3 * (X - 1.8) ** 2])
    Xm = np.linspace(2.6, 1.0, nn(km, nm))
    xm = np.array([Xm, 0.48 - 0.1 * (Xm - 1.7) ** 2])
    return xs, _cells(ks, ns), xm, _cells(km, nm)


def directional(f, z, V, h=FD_H):
    """Central differences of ``f`` along the columns of ``V``."""
    return np.stack([(f(z + h * v) - f(z - h * v)) / (2 * h) for v in V.T], 1)


CASES = [("line2", "line2"), ("line3", "line3"), ("line2", "line3"), ("line3", "line2"),
         ("line2x2", "line2"), ("line2x2", "line2x2")]


@pytest.mark.parametrize("ks, km", CASES)
@pytest.mark.parametrize("space", ["standard", "dual"])
@pytest.mark.parametrize("measure", [PLANE, AXISYMMETRIC])
def test_offset_is_the_mortar_identity_with_the_gaps_integrals(ks, km, space, measure, request):
    """``r_A = tau_A . (M x_m - D x_s)`` with the call's own ``D``, ``M``; those and the mask
    are the weighted gap's (the same kernel call with the default integrand)."""
    if "line2x2" in (ks, km):
        request.getfixturevalue("line2x2")
    xs, ss, xm, sm = surfaces(ks, km, off=-0.6)
    cells = (ks, km)
    t = tangential_evaluate(xs, ss, xm, sm, tangent=False, cells=cells, space=space,
                            measure=measure)
    v = t.info["M"] @ xm.T - t.info["D"] @ xs.T
    scale = abs(t.info["D"]).sum(axis=1).max()
    np.testing.assert_allclose(t.g, np.sum(t.info["tangent"].T * v, axis=1), rtol=0,
                               atol=ROUND * scale)
    assert np.abs(t.g[t.mask]).max() > 1e-4 * scale         # curved: not trivially zero
    assert not t.mask.all()                                  # the overhanging node
    g = mortar_kernel.evaluate(xs, ss, xm, sm, tangent=False, cells=cells, space=space,
                               measure=measure, n_gauss=3 if "line3" in cells else 2)
    for name in ("D", "M"):
        assert abs(t.info[name] - g.info[name]).max() == 0.0
    np.testing.assert_array_equal(t.mask, g.mask)


def _sliding(ks: str, km: str, opts: dict):
    """The slip as a function of the packed positions on a state slid by 0.05 from the
    converged one (the history) and perturbed, its positions and multipliers."""
    xs0, ss, xm0, sm = surfaces(ks, km, off=-0.6)
    hist = mortar_history(xs0, ss, xm0, sm, **opts)
    rng = np.random.default_rng(3)
    xs = xs0 + [[0.05], [0.0]] + 0.01 * rng.standard_normal(xs0.shape)
    xm = xm0 + 0.01 * rng.standard_normal(xm0.shape)

    def ev(q, **kw):
        a, b = unpack(q, xs.shape[1])
        return mortar_slip(a, ss, b, sm, hist["D_prev"], hist["M_prev"], **opts, **kw)
    return ev, pack(xs, xm), rng.standard_normal(xs.shape[1])


# every cell pairing with both spaces and both measures, in 12 runs (not 24: a case costs a
# second of differences)
FD_CASES = [(ks, km, space, measure) for i, (ks, km) in enumerate(CASES)
            for space, measure in ((("standard", PLANE), ("dual", AXISYMMETRIC)),
                                   (("dual", PLANE), ("standard", AXISYMMETRIC)))[i % 2]]


@pytest.mark.parametrize("ks, km, space, measure", FD_CASES)
def test_mortar_slip_derivatives_against_finite_differences(ks, km, space, measure, request):
    """The whole slip ``u = r + tau . w`` on a sliding, perturbed state with an overhanging
    slave: ``G`` and ``H`` against central differences of ``u`` and ``G^T lam``."""
    if "line2x2" in (ks, km):
        request.getfixturevalue("line2x2")
    ev, z, lam = _sliding(ks, km, dict(cells=(ks, km), space=space, measure=measure))
    e = ev(z, lam_t=lam)
    assert np.abs(e.u[e.mask]).max() > 1e-3 and not e.mask.all()
    G, H = e.G.toarray(), e.H.toarray()
    # differences along random directions (every dof moves, so a missing term shows);
    # tolerances relative to the largest entry (the axisymmetric weight 2 pi r ~ 10)
    V = np.random.default_rng(4).standard_normal((z.size, N_DIRECTIONS))
    V /= np.linalg.norm(V, axis=0)                  # unit steps: truncation ~h^2, as per dof
    np.testing.assert_allclose(G @ V, directional(lambda q: ev(q, tangent=False).u, z, V),
                               atol=FD_TOL * max(1.0, abs(G).max()), rtol=0)
    np.testing.assert_allclose(H @ V, directional(lambda q: ev(q).G.T @ lam, z, V),
                               atol=FD_TOL * max(1.0, abs(H).max()), rtol=0)
    np.testing.assert_allclose(H, H.T, atol=1e-14 * max(1.0, abs(H).max()))


@pytest.mark.parametrize("cell", ["line2", "line3"])
def test_tangent_jets_are_the_turned_normals_derivatives(cell):
    """``tau = (n_y, -n_x)`` and its first and second derivatives over each node's
    neighbourhood against central differences of the nodal normals."""
    xs, ss, _, _ = surfaces(cell, "line2")
    nn = nodal_normals(xs, ss, cell, order=2)
    tau, dtau, d2tau = tangent_jets(nn)
    np.testing.assert_array_equal(tau, np.stack([nn.n[1], -nn.n[0]]))
    z = xs.T.ravel()
    taus = lambda q: np.stack(tangent_basis(nodal_normals(q.reshape(-1, 2).T, ss,  # noqa: E731
                                                          cell, order=0).n)[0]).ravel()
    J = fd_jacobian(taus, z).reshape(2, -1, z.size)               # d tau_i(A) / dz
    nodes = np.where(nn.nodes >= 0, nn.nodes, 0)
    for A in range(xs.shape[1]):
        for j in np.flatnonzero(nn.nodes[A] >= 0):
            np.testing.assert_allclose(dtau[:, A, j], J[:, A, 2 * nodes[A, j]:2 * nodes[A, j] + 2],
                                       atol=1e-8, rtol=0)
    # second derivatives: differences of dtau
    A, j = 1, 1
    c = 2 * nodes[A, j]
    for comp in range(2):
        e = np.zeros(z.size)
        e[c + comp] = FD_H
        dp = tangent_jets(nodal_normals((z + e).reshape(-1, 2).T, ss, cell, order=1), False)[1]
        dm = tangent_jets(nodal_normals((z - e).reshape(-1, 2).T, ss, cell, order=1), False)[1]
        np.testing.assert_allclose(d2tau[:, A, :, :, j, comp], (dp[:, A] - dm[:, A]) / (2 * FD_H),
                                   atol=1e-7, rtol=0)


def test_tangent_basis_refuses_a_3d_normal():
    assert tangent_basis([np.array([0.6]), np.array([0.8])]) == [[0.8, -0.6]]
    with pytest.raises(ValueError, match="n must have 2 components"):
        tangent_basis([np.zeros(1)] * 3)


def test_mortar_slip_refuses_face_cells():
    """Tangential quantities of 3D contact are not built: face cells are refused by name."""
    tri = np.array([[0, 1, 2]])
    with pytest.raises(ValueError, match="line cells .* got slave tri3"):
        mortar_slip(np.zeros((3, 3)), tri, np.zeros((3, 3)), tri, np.zeros((3, 3)),
                    np.zeros((3, 3)), cells=("tri3", "tri3"))
