"""The one mortar kernel in 3D: the same code as in 2D, fed tri3 integration points.

A test-only segmentation (the contract of contact/integration_points.py): each slave
tri3 face is one integration cell against one large master tri3 face under the whole
slave surface; its Gauss points are the triangle rule in the slave parameter plane
(``w`` = rule weight, the reference triangle's Jacobian 1), and ``xi_m`` is the
projection of ``x_s(xi_s)`` along the interpolated normal ``n~(xi_s)`` onto the affine
master face, ``x_0 + E eta = x_s + alpha n~``, by Cramer's rule in jets (exact).  The 3D
segmentation proper (clipping, H10's) plugs in the same way.

* Flat slave a gap ``g0`` above a flat master: ``sum D = sum M = area``,
  ``sum_A g_A = g0 area`` (to 1e-14 of the area: round-off), rows of ``M`` summing to
  the rows of ``D`` (partition of unity on the master).
* Slave faces tri3 and quad4 (bilinear, warped: the dual's ``k = 4`` inverse by
  Gauss-Jordan in jets).
* A warped slave over a tilted master, standard and dual: ``G`` and
  ``H`` with the nodal normals chained in against central differences of the whole
  pipeline to 1e-7 of their scale (step 1e-6: truncation ~1e-10, round-off ~1e-10).
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.integration_points import IntegrationCells, IntegrationPoints
from skfem_mortar.contact.jets import Jet

TRI3 = cell_type("tri3")


def _det(a, b, c):
    """``a . (b x c)`` of three 3-vectors (lists of jets or arrays)."""
    return (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))


class FaceOnBigFace:
    """Every slave face (tri3 or quad4) against master face 0 (tri3), integrated whole
    (module docstring)."""

    def __init__(self, slave=TRI3, degree: int = 4):
        self.cells = (slave, TRI3)
        self.rule = slave.quadrature(degree)

    def integration_cells(self, xs, conn_s, xm, conn_m, normals):
        n = len(conn_s)
        return IntegrationCells(np.arange(n), np.zeros(n, dtype=np.int64))

    def integration_points(self, cells, local):
        pts, w = self.rule
        like = local.x_s[0][0]
        nv, second = like.g.shape[0], like.h is not None
        n = cells.e_s.size
        xi = tuple(Jet.constant(np.broadcast_to(pts[r], (n, pts.shape[1])).copy(), nv, second)
                   for r in range(2))
        cs = self.cells[0]
        N = cs.shape(pts)                                      # (k, nq)
        p = [sum(local.x_s[a][i].expand() * N[a] for a in range(cs.n_nodes)) for i in range(3)]
        nt = [sum(local.n_s[a][i].expand() * N[a] for a in range(cs.n_nodes)) for i in range(3)]
        x0 = [c.expand() for c in local.x_m[0]]
        e1 = [local.x_m[1][i].expand() - x0[i] for i in range(3)]
        e2 = [local.x_m[2][i].expand() - x0[i] for i in range(3)]
        r = [p[i] - x0[i] for i in range(3)]
        mn = [-c for c in nt]
        inv = _det(e1, e2, mn).inv()
        eta = (_det(r, e2, mn) * inv, _det(e1, r, mn) * inv)
        weight = Jet.constant(np.broadcast_to(w, (n, w.size)).copy(), nv, second)
        return IntegrationPoints(cells.e_s, cells.e_m, xi, eta, weight)


def _surfaces(warp: float, tilt: float, gap: float, slave=TRI3):
    """A 2 x 2 square of 8 slave tri3 faces or 4 quad4 faces (outward normal -z: clockwise
    seen from above) at height ``gap`` (+ a warp), over one master face (normal +z)
    tilted by ``tilt``."""
    g = np.linspace(0.0, 1.0, 3)
    X, Y = np.meshgrid(g, g, indexing="ij")
    rng = np.random.default_rng(2)
    xs = np.vstack([X.ravel(), Y.ravel(), gap + warp * rng.random(9)])
    conn = []
    for i in range(2):
        for j in range(2):
            a, b, c, d = 3 * i + j, 3 * (i + 1) + j, 3 * (i + 1) + j + 1, 3 * i + j + 1
            conn += ([[a, c, b], [a, d, c]] if slave is TRI3      # clockwise from above
                     else [[a, d, c, b]])
    xm = np.array([[-1.0, 3.0, -1.0], [-1.0, -1.0, 3.0], [0.0, tilt, -tilt]])
    return xs, np.array(conn), xm, np.array([[0, 1, 2]])


def _run(xs, ss, xm, sm, lam=None, space="standard", slave=TRI3):
    return mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space=space, cells=(slave, TRI3),
                                  points=FaceOnBigFace(slave))


QUAD4 = cell_type("quad4")
CASES = [(c, s) for c in (TRI3, QUAD4) for s in ("standard", "dual")]


@pytest.mark.parametrize("slave, space", CASES)
def test_flat_faces_integrate_area_and_gap(slave, space):
    xs, ss, xm, sm = _surfaces(0.0, 0.0, 0.05, slave)
    ev = _run(xs, ss, xm, sm, space=space, slave=slave)
    D, M = ev.info["D"].toarray(), ev.info["M"].toarray()
    assert ev.mask.all()
    assert abs(D.sum() - 1.0) <= 1e-14 and abs(M.sum() - 1.0) <= 1e-14
    np.testing.assert_allclose(M.sum(1), D.sum(1), atol=1e-15)
    assert abs(ev.g.sum() - 0.05) <= 1e-14
    if space == "dual":     # D is diagonal
        assert np.abs(D - np.diag(np.diag(D))).max() <= 1e-15


@pytest.mark.parametrize("slave, space", CASES)
def test_chained_derivatives_in_3d_against_finite_differences(slave, space):
    xs, ss, xm, sm = _surfaces(0.03, 0.1, 0.05, slave)
    lam = np.random.default_rng(3).random(xs.shape[1])
    ns, nm = xs.shape[1], xm.shape[1]
    x = np.concatenate([xs.T.ravel(), xm.T.ravel()])

    def at(z):
        return z[:3 * ns].reshape(ns, 3).T, ss, z[3 * ns:].reshape(nm, 3).T, sm

    A = _run(*at(x), lam, space, slave)
    h = 1e-6
    runs = [_run(*at(x + s * h * e), space=space, slave=slave) for e in np.eye(x.size)
            for s in (1, -1)]
    G = np.array([(runs[2 * i].g - runs[2 * i + 1].g) / (2 * h) for i in range(x.size)]).T
    H = np.array([(runs[2 * i].G.T @ lam - runs[2 * i + 1].G.T @ lam) / (2 * h)
                  for i in range(x.size)])
    for a, b in ((A.G.toarray(), G), (A.H.toarray(), H)):
        assert np.abs(a - b).max() <= 1e-7 * np.abs(b).max()
