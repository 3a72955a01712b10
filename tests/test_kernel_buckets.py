"""A dual space's groups split by their slave cell's number of integration cells
(``mortar_kernel._buckets``): one slave cell under many master cells no longer widens
every group's jets.

A slave chain whose cells hold 4 to 23 integration cells (a fine master under
part of a coarse slave) gives several buckets; the call equals the one-bucket call
(``BUCKET_SLOTS`` above every count) to 1e-14 of each output's largest entry: only the
order in which the groups' triplets and gaps are summed changes (a few ulps; a lost or
doubled group is of the order of the entries).  A call whose slave cells all hold at
most ``BUCKET_SLOTS`` cells takes one bucket and is the same to the bit.
"""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel


def _chain(xv, f):
    return np.array([xv, f(xv)]), np.array([[i, i + 1] for i in range(xv.size - 1)])


def _call(xm_nodes, space, crosspoints=None):
    xs, ss = _chain(np.r_[np.linspace(-0.3, 0.0, 4), np.linspace(0.02, 0.3, 15)],
                    lambda x: 0.999 - np.sqrt(1.0 - x * x))
    xm, sm = _chain(xm_nodes, lambda x: 0.02 * np.sin(5 * x))
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    return mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space=space,
                                  crosspoints=crosspoints)


FINE = np.linspace(0.45, -0.45, 181)          # 20 master cells under a 0.1 slave cell


def _outputs(ev):
    return (ev.g, ev.G.toarray(), ev.H.toarray(), ev.info["D"].toarray(),
            ev.info["M"].toarray())


@pytest.mark.parametrize("crosspoints", [None, [2]])
def test_buckets_equal_one_bucket(crosspoints, monkeypatch):
    asked = []
    buckets = mortar_kernel._buckets

    def spy(e_s):
        out = buckets(e_s)
        asked.append(len(out))
        return out
    monkeypatch.setattr(mortar_kernel, "_buckets", spy)
    a = _call(FINE, "dual", crosspoints)
    assert asked == [3]              # slave cells of 4, 5-6 and 22-23 integration cells
    monkeypatch.setattr(mortar_kernel, "BUCKET_SLOTS", 10**9)
    b = _call(FINE, "dual", crosspoints)
    assert (a.mask == b.mask).all()
    for u, v in zip(_outputs(a), _outputs(b)):
        assert np.abs(u - v).max() <= 1e-14 * np.abs(v).max()


def test_few_cells_a_slave_cell_take_one_bucket(monkeypatch):
    coarse = np.linspace(0.45, -0.45, 10)         # 1 to 3 integration cells a slave cell
    a = _call(coarse, "dual")
    monkeypatch.setattr(mortar_kernel, "BUCKET_SLOTS", 10**9)
    b = _call(coarse, "dual")
    for u, v in zip(_outputs(a), _outputs(b)):
        assert np.array_equal(u, v)
