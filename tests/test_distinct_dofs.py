"""The kernel's scatter sums each group's repeated dofs before it keeps the triplets
(``mortar_kernel._distinct``, ``_on_distinct``).

A line2 group's extended variables repeat its slave nodes (in ``x_s`` and in the normal
stencils of both ends), so the Hessian block of a line2 integration cell goes out as
12 x 12 triplets instead of 20 x 20; a quad4 face's as far fewer than its extended
variables squared.

* The deduplicated call equals the call that keeps every extended variable
  (``_distinct`` replaced by the identity) to 1e-14 of each output's largest entry:
  only the order in which the repeated entries are summed changes (measured 2.5e-16
  of ``G``, 3.8e-16 of ``H`` on line2, a few ulps; a lost or doubled entry is of the
  order of the entries themselves).  ``g`` and ``D``, ``M`` do not go through it and
  are equal to the bit.
* It keeps ``u^2`` H triplets a group, ``u`` the most distinct dofs of a group (12 for a
  line2 integration cell with standard multipliers: the slave nodes p, a, b, n of the two
  normal stencils and the master nodes c, d), fewer than the extended variables.
The derivatives themselves are tested by the kernel's finite-difference tests
(test_mortar, test_kernel_faces), which run through this scatter.
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.points3d import FacePoints

from test_segmentation3d import _quad_square


def _identity(ext):
    return ext, np.broadcast_to(np.arange(ext.shape[1]), ext.shape)


def _lines():
    def chain(n, f, x0, x1):
        xv = np.linspace(x0, x1, n + 1)
        return np.array([xv, f(xv)]), np.array([[i, i + 1] for i in range(n)])
    xs, ss = chain(25, lambda x: 0.999 - np.sqrt(1.0 - x * x), -0.3, 0.3)
    xm, sm = chain(33, lambda x: 0.02 * np.sin(5 * x), 0.45, -0.45)
    return (xs, ss, xm, sm), {}


def _faces():
    rng = np.random.default_rng(3)
    xs, ss = _quad_square(2, rng)
    xs[2] += 0.03 * rng.uniform(-1.0, 1.0, xs.shape[1])
    xm, sm = _quad_square(3, rng, z=0.02, up=False)
    xm[:2] = xm[:2] * 1.2 - 0.1
    cells = ("quad4", "quad4")
    return (xs, ss, xm, sm), {"cells": cells, "points": FacePoints(cells)}


def _call(case, space, crosspoints):
    args, kw = case()
    lam = np.linspace(0.5, 1.5, args[0].shape[1])
    return mortar_kernel.evaluate(*args, lam=lam, space=space, crosspoints=crosspoints, **kw)


@pytest.mark.parametrize("case", [_lines, _faces])
@pytest.mark.parametrize("space, crosspoints", [("standard", None), ("dual", None),
                                                ("dual", [3])])
def test_distinct_dofs_equal_every_extended_variable(case, space, crosspoints,
                                                      monkeypatch):
    a = _call(case, space, crosspoints)
    monkeypatch.setattr(mortar_kernel, "_distinct", _identity)
    b = _call(case, space, crosspoints)
    assert (a.mask == b.mask).all()
    assert np.array_equal(a.g, b.g)
    for key in ("D", "M"):
        assert (a.info[key] != b.info[key]).nnz == 0
    for u, v in ((a.G, b.G), (a.H, b.H)):
        u, v = u.toarray(), v.toarray()
        assert np.abs(u - v).max() <= 1e-14 * np.abs(v).max()


@pytest.mark.parametrize("case, space, u", [(_lines, "standard", 12), (_lines, "dual", None),
                                            (_faces, "dual", None)])
def test_fewer_triplets_are_kept(case, space, u, monkeypatch):
    kept = []                                   # (groups, dofs a group) of each H block
    block = mortar_kernel.Triplets.block

    def count(self, dofs, hess):
        kept.append(dofs.shape)
        block(self, dofs, hess)
    monkeypatch.setattr(mortar_kernel.Triplets, "block", count)
    _call(case, space, None)
    distinct = list(kept)
    monkeypatch.setattr(mortar_kernel, "_distinct", _identity)
    _call(case, space, None)
    extended = kept[len(distinct):]
    assert sum(n * w * w for n, w in distinct) < sum(n * w * w for n, w in extended)
    if u is not None:
        assert [w for _, w in distinct] == [u]
