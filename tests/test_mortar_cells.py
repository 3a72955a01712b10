"""The one mortar kernel (contact/mortar_cells.py) fed by the line segmentation's
integration points (contact/line_points.py, the contract of
contact/integration_points.py).

* On line2 its closed forms (the affine cells' end points and master points) equal the
  general path (Newton in the cells' coordinates, ``LineSegmentation(fast=False)``):
  ``g``, ``G = dg/dx``, ``H = sum lam_A d2g_A/dx2``, ``D`` and ``M``, plane and
  axisymmetric, to 1e-13 of their largest entry (the same points by two routes:
  round-off is ~1e-16 of it; a wrong closed form shows at 1e-3 and more).  The values
  against a brute-force reference and the derivatives against finite differences:
  ``test_mortar.py``.
* ``G`` and ``H`` with the nodal normals chained in at assembly agree with central
  differences of the whole pipeline (segmentation, normals, kernel) to 1e-7 of their
  scale (the truncation error of a step of 1e-6 is ~1e-10 here, round-off 1e-10).
* The dual basis ``A_e = D_e M_e^-1``, summed over each slave cell's integration cells,
  equals the curved kernel's (an element rule over the projectable part) when both
  rules are exact, and the linear kernel's (closed forms) always.
* The contract is checked: wrong shapes raise ValueError naming the field.
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.integration_points import (IntegrationPoints, LocalLayout,
                                                     LocalVariables, check_points)
from skfem_mortar.contact.line_points import LineSegmentation
from skfem_mortar.contact.measures import AXISYMMETRIC, PLANE

LINE2, LINE3 = cell_type("line2"), cell_type("line3")


def run(xs, ss, xm, sm, cells, lam=None, n_gauss=2, measure=PLANE, space="standard"):
    """The one kernel: segmentation -> local variables -> points -> integrals -> assembly."""
    return mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space=space, n_gauss=n_gauss,
                                  measure=measure, cells=cells)


def _curve(x0, x1, n, f, k, rng, noise=0.005):
    """``n`` cells of ``k`` nodes along ``y = f(x)`` (line3 order: start, end, mid)."""
    t = np.linspace(x0, x1, (k - 1) * n + 1)
    X = np.vstack([t, f(t) + noise * rng.random(t.size)])
    if k == 2:
        return X, np.array([[i, i + 1] for i in range(n)])
    return X, np.array([[2 * i, 2 * i + 2, 2 * i + 1] for i in range(n)])


def _pair(ks, km, seed=0, shift=0.0):
    """A curved slave over a curved master (shift 0.3: inside its reach; 0.8: its far end
    sticks out, so nodes there are masked and merged)."""
    rng = np.random.default_rng(seed)
    xs, ss = _curve(0.05 + shift, 0.95 + shift, 4 if ks == 2 else 3,
                    lambda t: 0.02 + 0.1 * (t - shift) ** 2, ks, rng)
    xm, sm = _curve(1.3, -0.2, 5 if km == 2 else 4, lambda t: -0.05 * t ** 2, km, rng)
    return xs, ss, xm, sm


def _close(a, b, tol=1e-13):
    a = a.toarray() if hasattr(a, "toarray") else np.asarray(a)
    b = b.toarray() if hasattr(b, "toarray") else np.asarray(b)
    assert np.abs(a - b).max() <= tol * max(np.abs(b).max(), 1e-300)


@pytest.mark.parametrize("shift", [0.3, 0.8])
@pytest.mark.parametrize("space", ["standard", "dual"])
@pytest.mark.parametrize("measure", [PLANE, AXISYMMETRIC])
def test_line2_closed_forms_equal_the_general_path(shift, space, measure):
    xs, ss, xm, sm = _pair(2, 2, shift=shift)
    lam = np.random.default_rng(5).random(xs.shape[1])
    A = run(xs, ss, xm, sm, (LINE2, LINE2), lam, measure=measure, space=space)
    assert all(LineSegmentation((LINE2, LINE2)).fast)
    general = LineSegmentation((LINE2, LINE2), 2, fast=False, pairs=None, margin=None, reach=0.0,
                               frozen=False, **({"mirror": ((np.array([1.0, 0.0]), 0.0),)}
                                                if measure.axis is not None else {}))
    E = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, measure=measure, space=space,
                               cells=(LINE2, LINE2), points=general)
    assert (A.mask == E.mask).all() and E.mask.all() == (shift < 0.5)
    for a, b in ((A.g, E.g), (A.G, E.G), (A.H, E.H), (A.info["D"], E.info["D"]),
                 (A.info["M"], E.info["M"]), (A.area, E.area)):
        _close(a, b)


def _at(split, x, ss, sm):
    xs, xm = split(x)
    return xs, ss, xm, sm


def _fd(ks, km, measure, space):
    xs, ss, xm, sm = _pair(ks, km, seed=3, shift=0.8)
    cells = (cell_type(f"line{ks}"), cell_type(f"line{km}"))
    lam = np.random.default_rng(7).random(xs.shape[1])
    ns, nm = xs.shape[1], xm.shape[1]

    def split(x):
        return x[:2 * ns].reshape(ns, 2).T, x[2 * ns:].reshape(nm, 2).T

    x = np.concatenate([xs.T.ravel(), xm.T.ravel()])
    A = run(xs, ss, xm, sm, cells, lam, measure=measure, space=space)
    h = 1e-6
    E = np.eye(x.size)
    runs = [run(*_at(split, x + s * h * e, ss, sm), cells, measure=measure, space=space)
            for e in E for s in (1, -1)]
    G = np.array([(runs[2 * i].g - runs[2 * i + 1].g) / (2 * h) for i in range(x.size)]).T
    q = [r.G.T @ lam for r in runs]
    H = np.array([(q[2 * i] - q[2 * i + 1]) / (2 * h) for i in range(x.size)])
    return A, G, H


@pytest.mark.parametrize("ks, km, space", [(2, 2, "dual"), (3, 3, "standard"),
                                           (3, 2, "dual")])
def test_chained_derivatives_against_finite_differences(ks, km, space):
    """Partly covered slaves (masked, merged nodes), the dual basis included."""
    A, G, H = _fd(ks, km, AXISYMMETRIC if ks == 3 else PLANE, space)
    _close(A.G, G, 1e-7)
    _close(A.H, H, 1e-7)


def test_contract_checks_name_the_field():
    loc = LocalVariables.of(np.zeros((2, 2, 2)), np.zeros((2, 2, 2)), np.ones((2, 2, 2)))
    assert loc.layout == LocalLayout(2, 2, 2) and loc.layout.n_loc == 12
    ok = loc.x_s[0][0].expand()
    pts = IntegrationPoints(np.zeros(2, int), np.zeros(2, int), (ok,), (ok,), ok)
    check_points(pts, loc)
    with pytest.raises(ValueError, match="xi_m"):
        check_points(pts._replace(xi_m=(ok, ok)), loc)
    with pytest.raises(ValueError, match="points.w"):
        check_points(pts._replace(w=loc.x_s[0][0]), loc)
    with pytest.raises(ValueError, match="ns"):
        LocalVariables.of(np.zeros((2, 2, 2)), np.zeros((2, 2, 2)), np.ones((2, 3, 2)))
    with pytest.raises(ValueError, match="n_gauss"):
        LineSegmentation((LINE2, LINE2), 0)


@pytest.mark.parametrize("space", ["standard", "dual"])
@pytest.mark.parametrize("km", [2, 3])
def test_fast_path_equals_the_general_path(space, km):
    """The closed forms on affine cells (line_points.affine: a line2 slave's end points,
    a line2 master's coordinates) give the general path's points (Newton in jets): g, G
    and H within 1e-13 of the largest entry (round-off; a missing implicit-function term
    would show in H at 1e-2)."""
    xs, ss, xm, sm = _pair(2, km, seed=4, shift=0.8)
    cells = (LINE2, cell_type(f"line{km}"))
    lam = np.random.default_rng(8).random(xs.shape[1])
    out = [mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space=space, cells=cells,
                                  points=LineSegmentation(cells, 2, fast=fast, frozen=False))
           for fast in (True, False)]
    assert LineSegmentation(cells).fast == (True, km == 2)
    for a, b in ((out[0].g, out[1].g), (out[0].G, out[1].G), (out[0].H, out[1].H)):
        _close(a, b)
