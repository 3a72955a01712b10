"""NTS written once over the cell table: any line cell, the closed form only a shortcut.

* A master of ``line2x2`` cells (start, middle, end; piecewise linear, registered
  from tests/test_cell_registration.py) gives the gaps, ``G`` and ``H`` of the same
  master cut into its line2 halves: the general kernel reads the cell's shape
  functions, nothing reads its three columns as line3 (which would put a parabola
  through the wrong nodes, a gap off by the sag, ~1e-2 here).
* The general kernel (Newton in the cell's coordinate, jets) on line2 cells
  declared curved (a copy of line2 of declared degree 2, so not affine) against the
  closed form: gaps, ``G``, ``H`` and the NTS slip with its derivatives agree to
  1e-12 of their largest entries (both exact; round-off of a few dozen operations
  on unit-size numbers is ~1e-15, a wrong or missing term is O(1)).
* Tributary weights and chain order of a line2x2 chain: ``int N_A`` = L/4, L/2, L/4.
"""
from __future__ import annotations

import types

import numpy as np
import pytest

from skfem_mortar.contact import nts
from skfem_mortar.contact.active_set import chain_order
from skfem_mortar.contact.cells import CELLS, CellType, cell_type, register_cell
from skfem_mortar.contact.curves import cell_lengths, is_affine, tributary_weights
from skfem_mortar.contact.methods import make_method
from skfem_mortar.contact.slip import nts_slip

from test_cell_registration import line2x2  # noqa: F401  (the fixture)

#: both sides exact: agreement to round-off (module doc)
RTOL = 1e-12


@pytest.fixture
def line2_curve():
    """line2's shape functions declared of degree 2: the general kernel on line2."""
    c = cell_type("line2")
    cell = CellType("line2_curve", 1, 2, c.corners, c.edges, c.ref_nodes, c.shape, c.dshape,
                    c.d2shape, c.quadrature, 2)
    register_cell(cell)
    yield cell
    CELLS.pop("line2_curve")


def _close(a, b):
    a, b = np.asarray(a), np.asarray(b)
    assert np.abs(a - b).max() <= RTOL * max(np.abs(a).max(), np.abs(b).max(), 1.0)


def _dense(M):
    return M.toarray()


def _bent_master():
    """A master chain right to left (normal +y), its middle nodes off the chords."""
    xv = np.linspace(1.2, -0.2, 5)
    X = np.zeros((2, 9))
    X[0, 0::2], X[0, 1::2] = xv, 0.5 * (xv[:-1] + xv[1:]) + [0.03, -0.02, 0.01, 0.02]
    X[1] = 0.2 * (X[0] - 0.5) ** 2
    X[1, 1::2] += [0.02, -0.015, 0.01, 0.02]
    seg = np.array([[2 * i, 2 * i + 1, 2 * i + 2] for i in range(4)])
    return X, seg


def _slave(n=7, seed=1):
    rng = np.random.default_rng(seed)
    x = np.linspace(0.05, 0.95, n) + 0.01 * rng.standard_normal(n)
    return np.vstack([x, 0.2 * (x - 0.5) ** 2 + 0.02 * rng.standard_normal(n)]), \
        np.c_[0:n - 1, 1:n]


def test_nts_on_a_line2x2_master_is_nts_on_its_halves(line2x2):
    xm, seg = _bent_master()
    xs, seg_s = _slave()
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    halves = np.stack([seg[:, [0, 1]], seg[:, [1, 2]]], 1).reshape(-1, 2)
    a = nts.evaluate(xs, seg_s, xm, seg, lam=lam, cells=("line2", "line2x2"))
    b = nts.evaluate(xs, seg_s, xm, halves, lam=lam, cells=("line2", "line2"))
    assert a.mask.all() and b.mask.all()
    _close(a.g, b.g)
    _close(_dense(a.G), _dense(b.G))
    _close(_dense(a.H), _dense(b.H))
    np.testing.assert_array_equal(a.info["segment"], b.info["segment"] // 2)
    # as line3 (the columns' count) the gap would differ by the parabola's sag
    c = nts.evaluate(xs, seg_s, xm, seg, cells=("line2", "line3"), tangent=False)
    assert np.abs(c.g - b.g).max() > 1e-3


def test_the_general_kernel_is_the_closed_form_on_line2(line2_curve):
    assert is_affine("line2") and not is_affine(line2_curve)
    xm, seg = _bent_master()
    halves = np.stack([seg[:, [0, 1]], seg[:, [1, 2]]], 1).reshape(-1, 2)
    xs, seg_s = _slave()
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    a = nts.evaluate(xs, seg_s, xm, halves, lam=lam, cells=("line2", "line2"))
    b = nts.evaluate(xs, seg_s, xm, halves, lam=lam, cells=("line2", line2_curve))
    np.testing.assert_array_equal(a.info["segment"], b.info["segment"])
    _close(a.g, b.g)
    _close(a.info["xi"], b.info["xi"])
    _close(_dense(a.G), _dense(b.G))
    _close(_dense(a.H), _dense(b.H))
    # the slip from a previous state two segments back: the lengths crossed
    prev = np.maximum(a.info["segment"] - 2, 0)
    xi_prev = np.full(xs.shape[1], 0.3)
    sa = nts_slip(xs, xm, halves, xi_prev, prev, a.info["segment"], lam, cell="line2")
    sb = nts_slip(xs, xm, halves, xi_prev, prev, a.info["segment"], lam, cell=line2_curve)
    _close(sa.u, sb.u)
    _close(sa.tangent, sb.tangent)
    _close(_dense(sa.G), _dense(sb.G))
    _close(_dense(sa.H), _dense(sb.H))


def test_line2x2_weights_lengths_and_chain_order(line2x2):
    x = np.vstack([np.linspace(0.0, 2.0, 5), np.zeros(5)])
    seg = np.array([[0, 1, 2], [2, 3, 4]])
    np.testing.assert_allclose(tributary_weights(x, seg, "line2x2"),
                               [0.25, 0.5, 0.5, 0.5, 0.25], rtol=1e-14)
    np.testing.assert_allclose(cell_lengths(x, seg, "line2x2"), [1.0, 1.0], rtol=1e-14)
    np.testing.assert_array_equal(chain_order(seg, False, 5, "line2x2"), [0, 1, 2, 3, 4])
    # line3's column order (start, end, mid) would give 0, 2, 2, 4, 3: not a chain
    assert chain_order(seg, False, 5, "line3") is None


def test_the_nts_method_takes_a_line2x2_slave(line2x2):
    """The method accepts a registered line cell and evaluates through the same kernel:
    a flat line2x2 slave 0.01 above a flat line2 master, gap 0.01 at every node,
    forces balancing (the rows of G sum to zero over the x and y dofs)."""
    xs = np.vstack([np.linspace(0.0, 1.0, 9), np.full(9, 0.01)])
    ss = np.array([[2 * i, 2 * i + 1, 2 * i + 2] for i in range(4)])
    xm = np.vstack([np.linspace(1.1, -0.1, 6), np.zeros(6)])
    sm = np.array([[i, i + 1] for i in range(5)])
    s = types.SimpleNamespace(segments=ss, n_nodes=9, cell="line2x2", X=xs, body=None)
    m = types.SimpleNamespace(segments=sm, n_nodes=6, cell="line2", X=xm, body=None)
    method = make_method("nts", s, m)
    ev = method.evaluate(xs, xm, np.ones(9), True)
    np.testing.assert_allclose(ev.g, 0.01, rtol=1e-12)
    np.testing.assert_allclose(ev.area, [0.0625] + [0.125] * 7 + [0.0625], rtol=1e-12)
    G = _dense(ev.G)
    assert np.abs(G[:, 0::2].sum(1)).max() < 1e-14 and np.abs(G[:, 1::2].sum(1)).max() < 1e-14
