"""The one mortar kernel on tri3 and quad4 faces with the 3D segmentation's points
(``mortar_kernel.evaluate(..., cells=(cs, cm), points=FacePoints((cs, cm)))``).

* Flat non-matching meshes of the unit square, the master larger than the slave, each
  pairing: ``sum D = sum M = 1`` (the slave area) and ``g_A = gap sum_B D_AB`` (the
  weighted gap of a constant gap), to 1e-14 (round-off of ~100 cells' sums; a wrong
  weight, Jacobian or normal shows at 1e-3 and more).  The dual ``D`` is diagonal.
* A warped slave partly covered by a shifted master, so that nodes are masked and merged
  by the one merge rule (the faces' masking rule, from the cell's edges): ``G`` and ``H``
  of the whole pipeline (segmentation, nodal normals chained in, kernel) against central
  differences along random directions to 1e-7 of their scale (step 1e-6: truncation
  ~1e-10 of the scale, round-off ~1e-10; the measured errors are 1e-11 to 1e-9).
* In chunks of one slave face each, the call equals the unchunked one to 1e-13 of each
  output's largest entry: the triplets are summed in another order (~1e-16), and the
  points' Newton in values stops when the largest step of its chunk is converged, so a
  cell's last step depends on its chunk (round-off of the points; measured 3e-14 of
  ``H``, 0 to 3e-17 of the rest).
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.points3d import FacePoints

from test_segmentation3d import _quad_square, _tri_square

MAKE = {"tri3": _tri_square, "quad4": _quad_square}


def _flat(cells, rng):
    xs, ss = MAKE[cells[0]](2, rng)
    xm, sm = MAKE[cells[1]](3, rng, z=0.01, up=False)
    xm[:2] = xm[:2] * 1.2 - 0.1            # master larger: every slave face covered
    return xs, ss, xm, sm


@pytest.mark.parametrize("cells, space", [(("tri3", "tri3"), "standard"),
                                          (("quad4", "quad4"), "dual"),
                                          (("tri3", "quad4"), "dual"),
                                          (("quad4", "tri3"), "standard")])
def test_flat_faces_integrate_area_and_gap(cells, space):
    xs, ss, xm, sm = _flat(cells, np.random.default_rng(0))
    ev = mortar_kernel.evaluate(xs, ss, xm, sm, tangent=False, space=space, cells=cells,
                                points=FacePoints(cells))
    D, M = ev.info["D"].toarray(), ev.info["M"].toarray()
    assert ev.mask.all()
    assert abs(D.sum() - 1.0) <= 1e-14 and abs(M.sum() - 1.0) <= 1e-14
    np.testing.assert_allclose(ev.g, 0.01 * D.sum(1), rtol=0, atol=1e-14)
    if space == "dual":
        assert np.abs(D - np.diag(np.diag(D))).max() <= 1e-14


def _partial(cells, shift):
    rng = np.random.default_rng(3)
    xs, ss = MAKE[cells[0]](2, rng)
    xs[2] += 0.03 * rng.uniform(-1.0, 1.0, xs.shape[1])
    xm, sm = MAKE[cells[1]](2, rng, z=0.02, up=False)
    xm[0] += shift[0]
    xm[1] += shift[1]
    return xs, ss, xm, sm, rng.uniform(0.5, 1.5, xs.shape[1])


@pytest.mark.parametrize("cells, space, shift", [(("tri3", "quad4"), "standard", (0.37, 0.21)),
                                                 (("quad4", "tri3"), "dual", (0.55, 0.3))])
def test_chained_derivatives_against_finite_differences(cells, space, shift):
    xs, ss, xm, sm, lam = _partial(cells, shift)
    pts = FacePoints(cells)

    def at(x):
        n = xs.size
        return mortar_kernel.evaluate(x[:n].reshape(-1, 3).T, ss, x[n:].reshape(-1, 3).T, sm,
                                      lam=lam, space=space, cells=cells, points=pts)
    x = np.r_[xs.T.ravel(), xm.T.ravel()]
    ev = at(x)
    assert 0 < (~ev.mask).sum() < ev.mask.size            # masked and merged nodes
    G, H = ev.G.toarray(), ev.H.toarray()
    h = 1e-6
    for v in np.random.default_rng(1).normal(size=(2, x.size)):
        p, m = at(x + h * v), at(x - h * v)
        assert np.array_equal(p.mask, ev.mask) and np.array_equal(m.mask, ev.mask)
        assert np.abs((p.g - m.g) / (2 * h) - G @ v).max() <= 1e-7 * np.abs(G).max()
        assert (np.abs((p.G.T @ lam - m.G.T @ lam) / (2 * h) - H @ v).max()
                <= 1e-7 * np.abs(H).max())


def test_chunks_of_one_face_give_the_unchunked_call():
    cells = ("quad4", "quad4")
    xs, ss, xm, sm, lam = _partial(cells, (0.55, 0.3))
    kw = dict(lam=lam, space="dual", cells=cells, points=FacePoints(cells))
    one = mortar_kernel.evaluate(xs, ss, xm, sm, **kw)
    cut = mortar_kernel.evaluate(xs, ss, xm, sm, chunk_entries=1, **kw)
    assert not one.mask.all() and np.array_equal(one.mask, cut.mask)
    for a, b in ((one.g, cut.g), (one.G, cut.G), (one.H, cut.H), (one.info["D"], cut.info["D"]),
                 (one.info["M"], cut.info["M"])):
        a = a.toarray() if hasattr(a, "toarray") else a
        b = b.toarray() if hasattr(b, "toarray") else b
        assert np.abs(a - b).max() <= 1e-13 * np.abs(a).max()
