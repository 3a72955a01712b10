"""The jets' fast paths give the general rules' answers.

* A product with an independent variable (:meth:`Jet.variable`) skips the outer
  product: it must equal the general product (the same operands with the variable's
  marker dropped) to the bit, the variable on either side, values of either shape.
* A jet of fewer variables (the leading ones) meets a wider one: the arithmetic pads
  it (:meth:`Jet.widen`), so the result must equal the one of the padded operand to
  the bit.
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact.jets import Jet


def _jet(rng, nv, shape):
    """A random jet of ``nv`` variables, values ``shape`` (a full, unsymmetric ``h``)."""
    return Jet(rng.standard_normal(shape), rng.standard_normal((nv,) + shape),
               rng.standard_normal((nv, nv) + shape))


def _plain(x: Jet) -> Jet:
    """``x`` without its variable marker: the general product's operand."""
    return Jet(x.v, x.g, x.h)


def _same(a: Jet, b: Jet) -> None:
    assert a.v.shape == b.v.shape and np.array_equal(a.v, b.v)
    assert np.array_equal(np.broadcast_to(a.g, b.g.shape), b.g)
    assert np.array_equal(np.broadcast_to(a.h, b.h.shape), b.h)


@pytest.mark.parametrize("shapes", [((5, 3), (5, 3)), ((5, 3), (5, 1)), ((5, 1), (5, 3))])
@pytest.mark.parametrize("left", [False, True])
def test_product_with_a_variable_is_the_general_product(shapes, left):
    rng = np.random.default_rng(3)
    nv = 7
    f = _jet(rng, nv, shapes[0])
    x = Jet.variable(rng.standard_normal(shapes[1]), 4, nv, True)
    fast = x * f if left else f * x
    general = _plain(x) * f if left else f * _plain(x)
    _same(fast, general)
    # and the Hessian is the product rule's: f'' x + f' e_j^T + e_j f'^T
    x4 = np.broadcast_to(x.v, fast.v.shape)
    e = np.zeros(nv)
    e[4] = 1.0
    fg = np.broadcast_to(f.g, (nv,) + fast.v.shape)
    sym = 0.5 * (f.h + np.swapaxes(f.h, 0, 1))
    want = (sym * x4 + fg[:, None] * e[None, :, None, None]
            + e[:, None, None, None] * fg[None])
    assert np.allclose(fast.hessian(), want, rtol=1e-14, atol=1e-14)  # two roundings


def test_product_with_a_variable_of_a_zero_hessian():
    """A linear ``f`` (zero Hessian view): the fast path writes the outer product only."""
    rng = np.random.default_rng(4)
    nv = 6
    a = Jet.variable(rng.standard_normal(4), 1, nv, True)
    f = a * 2.5 + 1.0                      # linear: a zero Hessian view
    x = Jet.variable(rng.standard_normal(4), 5, nv, True)
    _same(f * x, f * _plain(x))
    _same(x * f, _plain(x) * f)


@pytest.mark.parametrize("op", ["add", "sub", "mul", "where"])
def test_narrow_jets_pad_to_the_wider(op):
    rng = np.random.default_rng(5)
    a, b = _jet(rng, 4, (3, 2)), _jet(rng, 9, (3, 2))
    wide = a.widen(9)
    assert np.array_equal(wide.g[4:], 0 * wide.g[4:]) and not wide.h[4:].any()
    assert not wide.h[:, 4:].any()
    fn = {"add": lambda p, q: p + q, "sub": lambda p, q: p - q, "mul": lambda p, q: p * q,
          "where": lambda p, q: Jet.where(np.arange(6).reshape(3, 2) % 2 == 0, p, q)}[op]
    _same(fn(a, b), fn(wide, b))
    _same(fn(b, a), fn(b, wide))


def test_narrow_jet_times_a_variable_outside_it():
    """A variable beyond a narrow jet's variables widens it to the variable's count."""
    rng = np.random.default_rng(6)
    f = _jet(rng, 4, (3,))
    x = Jet.variable(rng.standard_normal(3), 7, 10, True)
    fast = f * x
    assert fast.g.shape[0] == 10
    _same(fast, f.widen(10) * _plain(x))


@pytest.mark.parametrize("q", range(1, 10))
@pytest.mark.parametrize("axis", [0, 1])
def test_sum_is_numpys_to_the_bit(q, axis):
    """Jet.sum adds fewer than 8 terms slice by slice, in numpy's order: the same bits
    (values over 16 decades, so a different order would show)."""
    from skfem_mortar.contact.jets import _sum
    rng = np.random.default_rng(q)
    shape = (4, 4, 7, q) if axis == 1 else (4, 4, q, 7)
    h = rng.standard_normal(shape) * 10.0 ** rng.integers(-8, 8, shape)
    j = Jet(h[0, 0], h[0], h)
    s = j.sum(axis)
    for got, a, ax in ((s.v, j.v, axis), (s.g, j.g, axis + 1), (s.h, j.h, axis + 2)):
        assert np.array_equal(got, a.sum(ax))
    assert np.array_equal(_sum(h, 3), h.sum(3)) and np.array_equal(_sum(h, 2), h.sum(2))
