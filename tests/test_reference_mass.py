"""A dual space on slave cells covered whole takes the reference cell's mass.

When the line segmentation reports every slave cell covered whole by its integration
cells (``LineSegmentation.whole_cells``: affine, both ends slave vertices, no gap and no
overlap) and the measure is the plane's, ``A_e = D_e M_e^-1`` is the reference cell's and
constant, so the kernel skips the mass jets (``mortar_kernel._reference_mass``).  The call
equals the jets' path (``whole_cells`` answering None) to 1e-13 of each output's largest
entry (measured 5e-16 on g, 1.8e-15 on H: the same sums of O(1) terms in another order;
a wrong basis or a dropped derivative of ``A_e`` is of the order of the entries), with
the mask the same; crosspoints merge a node's function first (the same ``T``).
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import line_points, mortar_kernel


def _chains():
    def chain(n, f, x0, x1):
        xv = np.linspace(x0, x1, n + 1)
        return np.array([xv, f(xv)]), np.array([[i, i + 1] for i in range(n)])
    xs, ss = chain(25, lambda x: 0.999 - np.sqrt(1.0 - x * x), -0.3, 0.3)
    xm, sm = chain(33, lambda x: 0.02 * np.sin(5 * x), 0.45, -0.45)
    return xs, ss, xm, sm


@pytest.mark.parametrize("crosspoints", [None, [0], [3]])
def test_reference_mass_equals_the_jets(crosspoints, monkeypatch):
    xs, ss, xm, sm = _chains()
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    asked = []
    whole = line_points.LineSegmentation.whole_cells

    def spy(self, cells):
        out = whole(self, cells)
        asked.append(out)
        return out
    monkeypatch.setattr(line_points.LineSegmentation, "whole_cells", spy)
    a = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space="dual", crosspoints=crosspoints)
    assert len(asked) == 1 and asked[0].all()           # the reference path was taken
    monkeypatch.setattr(line_points.LineSegmentation, "whole_cells", lambda self, c: None)
    b = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space="dual", crosspoints=crosspoints)
    assert (a.mask == b.mask).all()
    for u, v in ((a.g, b.g), (a.G, b.G), (a.H, b.H), (a.info["D"], b.info["D"]),
                 (a.info["M"], b.info["M"])):
        u = u.toarray() if hasattr(u, "toarray") else u
        v = v.toarray() if hasattr(v, "toarray") else v
        assert np.abs(u - v).max() <= 1e-13 * np.abs(v).max()


def test_a_cell_partly_covered_takes_the_jets(monkeypatch):
    """The master shorter than the slave: its end cells are partly covered, so the
    kernel asks for the mass jets (the reference basis would be wrong there)."""
    xs, ss, xm, sm = _chains()
    xm = xm * np.array([[0.5], [1.0]])
    masses = []
    integrals = mortar_kernel._Surfaces.integrals

    def spy(self, points, ic, second, mass, integrand=None):
        masses.append(mass)
        return integrals(self, points, ic, second, mass, integrand)
    monkeypatch.setattr(mortar_kernel._Surfaces, "integrals", spy)
    mortar_kernel.evaluate(xs, ss, xm, sm, lam=np.ones(xs.shape[1]), space="dual")
    assert masses == [True]
