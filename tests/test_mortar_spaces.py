"""The mortar kernels and :class:`~skfem_mortar.contact.mortar_method.Mortar` take their
multipliers from a multiplier space and never from a flag: a space with
``coefficients(D_e, M_e)`` gets the biorthogonal functions, any other traction space
``Phi_A = N_A``, a force space is refused (:func:`~skfem_mortar.contact.mortar.biorthogonal`).

Each comparison is exact (``array_equal``): the same kernel path runs whether the space
comes by name or as an object, so nothing may differ in the last bit.
"""
from __future__ import annotations

import types

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.mortar import biorthogonal
from skfem_mortar.contact.mortar_method import Mortar
from skfem_mortar.contact.multiplier_spaces import (DualSpace, StandardSpace, make_space,
                                                    register_space, unregister_space)


class _Biorthogonal(StandardSpace):
    """A space of another name with the dual space's ``coefficients`` (arrays, and
    ``cell_coefficients`` on jets, which the one kernel asks on line3)."""

    name = "test-biorthogonal"
    coefficients = staticmethod(DualSpace.coefficients)
    cell_coefficients = staticmethod(DualSpace.cell_coefficients)


@pytest.fixture
def other_space():
    register_space(_Biorthogonal())
    yield "test-biorthogonal"
    unregister_space("test-biorthogonal")


def _pair(k):
    """A flat slave of 4 cells over a wider master of 5 (k = 2: line2, 3: line3)."""
    def chain(x0, x1, y, n):
        xv = np.linspace(x0, x1, n + 1)
        X, seg = [list(xv), [y] * (n + 1)], []
        for i in range(n):
            if k == 3:
                X[0].append(0.5 * (xv[i] + xv[i + 1]))
                X[1].append(y)
            seg.append([i, i + 1, n + 1 + i][:k])
        return np.array(X, float), np.array(seg)
    xs, ss = chain(0.0, 1.0, 0.01, 4)
    xm, sm = chain(1.1, -0.1, 0.0, 5)
    xm[1] += 0.002 * np.sin(3.0 * xm[0])          # a wavy master: G, H not trivial
    return xs, ss, xm, sm


@pytest.mark.parametrize("k", [2, 3])
def test_the_kernel_asks_the_space_not_its_name(other_space, k):
    """By name, as the object, and as another space with the same coefficients: one result."""
    kernel = mortar_kernel.evaluate
    xs, ss, xm, sm = _pair(k)
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    ref = kernel(xs, ss, xm, sm, lam=lam, space="dual")
    for space in (make_space("dual"), other_space, make_space(other_space)):
        ev = kernel(xs, ss, xm, sm, lam=lam, space=space)
        assert np.array_equal(ev.g, ref.g)
        assert np.array_equal(ev.G.toarray(), ref.G.toarray())
        assert np.array_equal(ev.H.toarray(), ref.H.toarray())
    std = kernel(xs, ss, xm, sm, lam=lam, space="standard")
    assert not np.allclose(std.info["D"].toarray(), ref.info["D"].toarray())   # it matters


def test_biorthogonal_reads_the_space():
    assert biorthogonal("dual") and biorthogonal(DualSpace())
    assert not biorthogonal("standard") and not biorthogonal(StandardSpace())


@pytest.mark.parametrize("space, match", [("nodal", "traction"), ("no-such-space", "one of")])
def test_a_space_the_kernels_cannot_use_is_refused(space, match):
    xs, ss, xm, sm = _pair(2)
    with pytest.raises(ValueError, match=match):
        mortar_kernel.evaluate(xs, ss, xm, sm, space=space)
    with pytest.raises(ValueError, match=match):
        Mortar(*_surfaces(xs, ss, xm, sm), multiplier_space=space)


def _surfaces(xs, ss, xm, sm):
    return (types.SimpleNamespace(segments=ss, n_nodes=xs.shape[1], cell="line2", X=xs),
            types.SimpleNamespace(segments=sm, n_nodes=xm.shape[1], cell="line2", X=xm))


def test_the_method_names_its_space(other_space):
    """``multiplier_space`` picks the kernel's functions and names the method."""
    xs, ss, xm, sm = _pair(2)
    s, m = _surfaces(xs, ss, xm, sm)
    assert Mortar(s, m).method == "mortar"
    assert Mortar(s, m, multiplier_space="dual").method == "mortar-dual"
    meth = Mortar(s, m, multiplier_space=other_space)
    assert meth.method == f"mortar-{other_space}"
    ev = meth.evaluate(xs, xm, None, True)
    ref = mortar_kernel.evaluate(xs, ss, xm, sm, space="dual")
    assert np.array_equal(ev.g, ref.g) and np.array_equal(ev.G.toarray(), ref.G.toarray())
