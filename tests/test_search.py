"""Tests of the contact search against a brute-force reference."""

import numpy as np
import pytest

from skfem_mortar.search import box_pairs, node_segment_pairs, segment_boxes, segment_pairs


def _brute(lo_a, hi_a, lo_b, hi_b, margin):
    ok = np.all((lo_a[:, :, None] - margin <= hi_b[:, None, :])
                & (lo_b[:, None, :] <= hi_a[:, :, None] + margin), axis=0)
    return np.nonzero(ok)


def _chain(rng, n, scale):
    x = np.cumsum(rng.normal(scale=scale, size=(2, n)), axis=1)
    return x, np.column_stack([np.arange(n - 1), np.arange(1, n)])


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("margin", [0.0, 0.05, 0.3])
def test_segment_pairs_equal_brute_force(seed, margin):
    rng = np.random.default_rng(seed)
    xs, ss = _chain(rng, 60, 0.1)
    xm, sm = _chain(rng, 45, 0.15)
    xm += xs[:, 30:31] - xm[:, 20:21]  # make the chains cross
    # one very long master segment (a rigid plane) among short ones
    xm[:, -1] = [40.0, -3.0]
    i, j = segment_pairs(xs, ss, xm, sm, margin)
    bi, bj = _brute(*segment_boxes(xs, ss), *segment_boxes(xm, sm), margin)
    np.testing.assert_array_equal(i, bi)
    np.testing.assert_array_equal(j, bj)
    assert len(i) > 0


@pytest.mark.parametrize("seed", range(3))
def test_node_segment_pairs_equal_brute_force(seed):
    rng = np.random.default_rng(seed)
    xn = rng.uniform(-1, 1, (2, 80))
    xm, sm = _chain(rng, 50, 0.2)
    i, j = node_segment_pairs(xn, xm, sm, 0.1)
    bi, bj = _brute(xn, xn, *segment_boxes(xm, sm), 0.1)
    np.testing.assert_array_equal(i, bi)
    np.testing.assert_array_equal(j, bj)


def test_search_examines_linearly_many_candidates(monkeypatch):
    # two flat matching chains: each slave segment overlaps 3 master ones. Count
    # the candidate pairs the search tests exactly (not wall time, which a loaded
    # machine makes noisy): all pairs would be n^2, a spatial index O(n).
    from skfem_mortar import search

    examined = []
    real = search._overlap

    def counting(lo_a, hi_a, lo_b, hi_b, ia, ib, margin):
        examined.append(len(ia))
        return real(lo_a, hi_a, lo_b, hi_b, ia, ib, margin)

    monkeypatch.setattr(search, "_overlap", counting)

    def run(n):
        t = np.linspace(0, 1, n)
        x = np.vstack([t, 0 * t])
        s = np.column_stack([np.arange(n - 1), np.arange(1, n)])
        examined.clear()
        i, j = segment_pairs(x, s, x.copy(), s, 0.0)
        assert len(i) == 3 * (n - 1) - 2
        return sum(examined)

    c1, c2 = run(5000), run(40000)
    # 8x the segments: a linear number of candidates grows ~8x (all pairs: 64x)
    assert c2 / c1 < 10, (c1, c2)
    assert c2 < 20 * 40000  # a bounded number of candidates per segment


def test_bad_margin():
    with pytest.raises(ValueError, match="margin"):
        box_pairs(np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)), -1.0)
