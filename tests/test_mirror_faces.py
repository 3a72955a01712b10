"""Mortar between faces at symmetry planes (issue 38, item 2): the kernel on the master
extended by its mirror images (:mod:`skfem_mortar.contact.mirror_faces`) gives a
quarter model the half's weighted gaps, G and H.

The sphere faces of ``hertz3d`` below z = 0.02 (refine -3), moved by a displacement
field that is mirror-symmetric about ``X = 0``, on the rigid plane's quad4 faces: the
quarter (planes ``X = 0``, ``Y = 0``) against the half (``Y = 0``), by the one kernel
with both multiplier spaces (the plane: quad4 faces 0.06 a side over 0.6 x 0.6 in the
quarter, and their mirror images in the half).  A node on ``X = 0`` carries half the half's weighted
gap in the quarter (its support is cut in two), every other node all of it; and for
a symmetric ``v`` and ``lam``, ``G v`` and ``v^T H v`` follow the same shares.
"""
import numpy as np
import pytest
from scipy.spatial import cKDTree

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.mirror_faces import evaluate_mirrored, mirrored_master
from skfem_mortar.contact.points3d import FacePoints
from skfem_mortar.contact.surfaces import ContactSurface
from skfem_mortar.scenes._contact3d import plane_grid
from skfem_mortar.scenes._hertz3d import PARAMS, build_bodies

CELLS = ("tri3", "quad4")
EX, EY = (np.array([1.0, 0.0, 0.0]), 0.0), (np.array([0.0, 1.0, 0.0]), 0.0)
MIRROR = np.array([[-1.0], [1.0], [1.0]])

#: quarter against half: the same integrals over mirror-image cells, summed in another
#: order (measured 6e-14 in g, 3e-11 in G v, relative to the largest); without the
#: mirror images the quarter misses strips of its faces on X = 0 (7e-5 in g, 4e-4 in
#: G v)
TOL = {"g": 1e-11, "G": 1e-9, "H": 1e-9}


def _model(model: str):
    """The sphere's faces below z = 0.02, and the quarter's rigid plane faces (the
    half: those and their mirror images, the nodes on X = 0 shared)."""
    params = {**{p.name: p.default for p in PARAMS}, "refine": -3, "base": "rigid",
              "model": model, "element": "tet1"}                      # tri3 faces
    parts = build_bodies(params)
    s = ContactSurface.from_solid(*parts.slave, name="sphere_face")
    seg = s.segments[np.all(s.X[2, s.segments] < 0.02, axis=1)]
    used = np.unique(seg)
    loc = np.full(s.X.shape[1], -1)
    loc[used] = np.arange(used.size)
    xm, fm = plane_grid((0.0, 0.6), (0.0, 0.6), 0.0, 0.06)
    if model == "half":
        on = np.flatnonzero(xm[0] == 0.0)
        off = np.flatnonzero(xm[0] != 0.0)
        image = np.arange(xm.shape[1])
        image[off] = xm.shape[1] + np.arange(off.size)
        fm = np.vstack([fm, image[fm][:, ::-1]])
        xm = np.hstack([xm, MIRROR * xm[:, off]])
        assert on.size > 0
    return s.X[:, used], loc[seg], xm, fm


def _field(X, a, b):
    """A displacement mirror-symmetric about X = 0 (u_x odd, u_y and u_z even in x)."""
    return np.vstack([a * X[0] * np.cos(3 * X[1]), a * X[1] * (1 + X[0] ** 2),
                      -0.003 + 0.02 * (X[0] ** 2 + X[1] ** 2) + b * np.cos(5 * X[1])])


@pytest.fixture(scope="module")
def models():
    return _model("quarter"), _model("half")


def _flat(xs, xm):
    return np.concatenate([xs.T.ravel(), xm.T.ravel()])


@pytest.mark.parametrize("space", ["standard", "dual"])
def test_a_quarter_with_mirror_images_is_the_half(models, space):
    (Xq, sq, xmq, fmq), (Xh, sh, xmh, fmh) = models
    iq = cKDTree(Xh.T).query(Xq.T)[1]
    jq = cKDTree(xmh.T).query(xmq.T)[1]
    assert np.abs(Xh[:, iq] - Xq).max() == 0.0 and np.abs(xmh[:, jq] - xmq).max() == 0.0
    share = np.where(np.abs(Xq[0]) < 1e-12, 0.5, 1.0)
    lam_h = 1.0 + np.cos(4 * Xh[1]) * (1 + Xh[0] ** 2)        # symmetric multipliers
    opts = {"space": space, "cells": CELLS, "tangent": True}
    eh = mortar_kernel.evaluate(Xh + _field(Xh, 0.01, 0.001), sh, xmh, fmh, lam=lam_h,
                                points=FacePoints(CELLS, 5), mirror=[EY], **opts)
    xs_q = Xq + _field(Xq, 0.01, 0.001)
    kw = {"lam": lam_h[iq], "points": FacePoints(CELLS, 5), "mirror": [EX, EY], **opts}
    eq = evaluate_mirrored(mortar_kernel.evaluate, xs_q, sq, xmq, fmq, [EX], 0.2, **kw)
    bare = mortar_kernel.evaluate(xs_q, sq, xmq, fmq, **{**kw, "lam": None, "tangent": False})
    assert np.array_equal(eq.mask, eh.mask[iq]) and eq.mask.sum() > 20
    act = eq.mask
    ref = share * eh.g[iq]
    err = lambda e: np.abs(e.g - ref)[act].max() / np.abs(ref).max()   # noqa: E731
    assert err(eq) <= TOL["g"] and err(bare) > 1e3 * TOL["g"]
    # G and H along a symmetric perturbation of both surfaces
    vh = _flat(_field(Xh, 1.0, 0.3), _field(xmh, 0.5, 0.2))
    vq = _flat(_field(Xq, 1.0, 0.3), _field(xmq, 0.5, 0.2))
    dh, dq = eh.G @ vh, eq.G @ vq
    refd = share * dh[iq]
    assert np.abs(dq - refd)[act].max() <= TOL["G"] * np.abs(refd).max()
    # sum_A lam_A g_A over the half is twice the quarter's (H restricted to rows in mask)
    hh, hq = vh @ (eh.H @ vh), vq @ (eq.H @ vq)
    assert hq == pytest.approx(0.5 * hh, rel=TOL["H"])


def test_mirror_images_are_reflected_and_reversed():
    """The ghost faces are the reflections of the faces within reach, orientation
    reversed, and each ghost node names its real node."""
    xm = np.array([[0.0, 1.0, 1.0, 0.0, 2.0, 2.0], [0.0, 0.0, 1.0, 1.0, 0.0, 1.0],
                   [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]])
    faces = np.array([[0, 1, 2, 3], [1, 4, 5, 2]])        # the second off the plane x = 0
    X, F, node, R = mirrored_master(xm, faces, [EX], 0.5)
    assert F.shape == (3, 4) and X.shape == (3, 10)
    np.testing.assert_array_equal(node[6:], [0, 1, 2, 3])
    np.testing.assert_allclose(X[:, 6:], MIRROR * xm[:, :4])
    np.testing.assert_array_equal(F[2], [9, 8, 7, 6])
    assert len(R) == 4 and np.allclose(R[0], np.diag([-1.0, 1.0, 1.0]))
    n = lambda P: np.cross(P[:, 1] - P[:, 0], P[:, 3] - P[:, 0])   # noqa: E731
    assert n(X[:, F[0]])[2] > 0 and n(X[:, F[2]])[2] > 0       # both face up
