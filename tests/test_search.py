"""Tests of the contact search against a brute-force reference."""

import numpy as np
import pytest

from skfem_mortar.contact.search import box_pairs, node_segment_pairs, segment_boxes, segment_pairs


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


@pytest.mark.parametrize("seed", range(5))
def test_per_segment_margins_equal_brute_force(seed):
    """Local margins (each box inflated by its own amount, e.g. its element
    length, plus a global reach) against all pairs tested directly."""
    rng = np.random.default_rng(seed)
    xs, ss = _chain(rng, 60, 0.1)
    xm, sm = _chain(rng, 45, 0.15)
    xm += xs[:, 30:31] - xm[:, 20:21]
    xm[:, -1] = [40.0, -3.0]
    ms = rng.uniform(0.0, 0.2, len(ss))
    mm = rng.uniform(0.0, 0.2, len(sm))
    i, j = segment_pairs(xs, ss, xm, sm, 0.02, ms, mm)
    lo_s, hi_s = segment_boxes(xs, ss)
    lo_m, hi_m = segment_boxes(xm, sm)
    bi, bj = _brute(lo_s - ms, hi_s + ms, lo_m - mm, hi_m + mm, 0.02)
    np.testing.assert_array_equal(i, bi)
    np.testing.assert_array_equal(j, bj)
    with pytest.raises(ValueError, match="margin_s"):
        segment_pairs(xs, ss, xm, sm, 0.0, -ms, mm)


def test_local_mortar_margin_keeps_the_segments_of_a_global_one():
    """Hertz's graded cylinder on its rigid plane: the mortar segments (pairs
    whose projections overlap) found with the local margin (the two element
    lengths) equal those of a margin of the largest element length, from far
    fewer candidates (the global margin pairs every fine slave element with
    every master element within the largest arc element, ~2.4)."""
    from skfem_mortar.contact.mortar_segmentation import segment
    from skfem_mortar.scenes import get_scene
    import skfem_mortar.contact.search as search
    sc = get_scene("hertz")
    setup = sc.build({p.name: p.default for p in sc.params}, "mortar")
    pair = [it for it in setup.model.items if hasattr(it, "slave")][0]
    z = np.zeros(setup.model.n)
    xs, xm = pair.slave.x(z), pair.master.x(z)
    xs = xs - [[0.0], [0.002]]  # pressed in a little: some slave elements penetrate
    counts = []
    real = search.box_pairs

    def counting(*a, **k):
        out = real(*a, **k)
        counts.append(len(out[0]))
        return out
    search.box_pairs = counting
    try:
        local = segment(xs, pair.slave.segments, xm, pair.master.segments)
        big = max(np.hypot(*np.diff(xs[:, pair.slave.segments], axis=2)[:, :, 0]).max(), 1.0)
        wide = segment(xs, pair.slave.segments, xm, pair.master.segments, margin=big)
    finally:
        search.box_pairs = real
    np.testing.assert_array_equal(local.e_s, wide.e_s)
    np.testing.assert_array_equal(local.e_m, wide.e_m)
    np.testing.assert_array_equal(local.xi, wide.xi)
    assert local.e_s.size > 10
    assert counts[0] * 10 < counts[1]


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
    from skfem_mortar.contact import search

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


def test_mortar_search_reaches_a_node_that_penetrated_deeply_within_the_step():
    """The local margin is the two element lengths plus the motion since
    the last converged state (``ContactPair._reach``): a slave pushed 3 element
    lengths into the master within one step is still paired (in ``mask``, with
    a negative weighted gap), so the active set catches it; without the motion
    term it would have no master partner and stay inactive."""
    from skfem_mortar.scenes import get_scene
    sc = get_scene("patch")
    setup = sc.build({p.name: p.default for p in sc.params}, "mortar")
    pair = [it for it in setup.model.items if hasattr(it, "slave")][0]
    z = np.zeros(setup.model.n)
    pair.begin_step(z, 0.0)
    xs = pair.slave.x(z)
    seg = pair.slave.segments
    t = xs[:, seg[:, 1]] - xs[:, seg[:, 0]]
    n = np.array([t[1].sum(), -t[0].sum()])
    n /= np.linalg.norm(n)                                 # mean outward slave normal
    h = np.hypot(*t).max()
    ds = pair.slave.dofs()                                 # (2, n) global dofs
    z[ds[0]] += 3.0 * h * n[0]                             # into the master
    z[ds[1]] += 3.0 * h * n[1]
    ev = pair.evaluate(z, tangent=False, with_lam=False)
    assert ev.mask.sum() >= ev.mask.size - 2 and np.all(ev.g[ev.mask] < 0)
    pair._x0 = (pair.slave.x(z), pair.master.x(z))       # as if it had started there
    ev0 = pair.evaluate(z, tangent=False, with_lam=False)
    assert ev0.mask.sum() < ev.mask.sum()


def test_distance_to_polyline_equals_the_brute_force_minimum():
    """Against every point-segment distance (random polylines and points, some far
    outside every box): equal to round-off of coordinates O(10), so 1e-13."""
    from skfem_mortar.contact.search import distance_to_polyline
    rng = np.random.default_rng(7)
    for _ in range(10):
        m = int(rng.integers(2, 40))
        x = np.cumsum(rng.normal(size=(2, m)), axis=1)
        seg = np.column_stack([np.arange(m - 1), np.arange(1, m)])
        p = rng.normal(scale=6.0, size=(2, 600))
        a, d = x[:, seg[:, 0]], x[:, seg[:, 1]] - x[:, seg[:, 0]]
        q = p[:, :, None]
        t = np.clip(np.sum((q - a[:, None]) * d[:, None], axis=0) / np.sum(d * d, axis=0), 0, 1)
        brute = np.sqrt(np.min(np.sum((q - a[:, None] - t[None] * d[:, None]) ** 2, axis=0), 1))
        np.testing.assert_allclose(distance_to_polyline(p, x, seg), brute, rtol=1e-13, atol=1e-13)


# ------------------------------------------------------------- any dimension (3D)
def _sheet(rng, n, h, z0=0.0):
    """A wavy sheet of n x n quad4 cells of size h in 3D (and its tri3 split)."""
    s = np.arange(n + 1) * h
    X, Y = np.meshgrid(s, s, indexing="ij")
    x = np.vstack([X.ravel(), Y.ravel(), z0 + 0.3 * h * np.sin(X.ravel() + 2 * Y.ravel())])
    x += rng.normal(scale=0.1 * h, size=x.shape)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    return x, q, np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])


@pytest.mark.parametrize("grid_points", [10**9, 0])  # the grid; the k-d tree
@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("margin", [0.0, 0.05])
def test_3d_cell_pairs_equal_brute_force(monkeypatch, grid_points, seed, margin):
    """Surfaces of tri3 and quad4 cells, one rotated through the other, and a large
    cell: the grid over three coordinates (5 x 5 columns) and the tree find exactly
    the overlapping boxes."""
    from skfem_mortar.contact import search
    monkeypatch.setattr(search, "GRID_POINTS", grid_points)
    rng = np.random.default_rng(seed)
    xs, q, _ = _sheet(rng, 12, 0.1)
    xm, _, t = _sheet(rng, 15, 0.08)
    c, s = np.cos(0.4), np.sin(0.4)
    xm = np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ xm + [[0.1], [0.2], [-0.3]]
    xm = np.hstack([xm, [[-5.0, 5.0, 0.0], [-5.0, -5.0, 5.0], [0.0, 0.0, 0.0]]])
    t = np.vstack([t, [xm.shape[1] - 3, xm.shape[1] - 2, xm.shape[1] - 1]])
    i, j = segment_pairs(xs, q, xm, t, margin, cell_s="quad4", cell_m="tri3")
    bi, bj = _brute(*segment_boxes(xs, q, "quad4"), *segment_boxes(xm, t, "tri3"), margin)
    np.testing.assert_array_equal(i, bi)
    np.testing.assert_array_equal(j, bj)
    assert len(i) > 0 and np.any(j == t.shape[0] - 1)
    # nodes against cells
    i, j = node_segment_pairs(xs, xm, t, margin, cell="tri3")
    bi, bj = _brute(xs, xs, *segment_boxes(xm, t, "tri3"), margin)
    np.testing.assert_array_equal(i, bi)
    np.testing.assert_array_equal(j, bj)


@pytest.mark.parametrize("m", [5, 3000])
def test_3d_nearest_vertex_equals_brute_force(m):
    """Few vertices (every distance) and many (the grid, then the tree)."""
    from skfem_mortar.contact.search import nearest_vertex
    rng = np.random.default_rng(m)
    x = rng.uniform(0, 1, (3, m)) * [[1], [1], [0.05]]
    p = rng.uniform(-0.2, 1.2, (3, 700))
    d, k = nearest_vertex(x, p)
    all_d = np.sqrt(((p[:, :, None] - x[:, None, :]) ** 2).sum(axis=0))
    np.testing.assert_array_equal(k, np.argmin(all_d, axis=1))
    np.testing.assert_allclose(d, all_d.min(axis=1), rtol=1e-15, atol=0)


def test_cell_boxes_hold_the_cell():
    """The box of a cell holds every point of it: line3 (by its Bezier control point),
    a warped quad4 and a tri3 (by their nodes); a wrong column count is refused."""
    from skfem_mortar.contact.cells import CELLS
    rng = np.random.default_rng(1)
    for name, d in (("line3", 2), ("quad4", 3), ("tri3", 3)):
        cell = CELLS[name]
        x = rng.normal(size=(d, cell.n_nodes))
        lo, hi = segment_boxes(x, np.arange(cell.n_nodes)[None], name)
        xi, _ = cell.quadrature(20)
        pts = x @ cell.shape(xi)
        assert np.all(pts >= lo - 1e-15) and np.all(pts <= hi + 1e-15)
    with pytest.raises(ValueError, match="4 columns for quad4"):
        segment_boxes(np.zeros((3, 3)), [[0, 1, 2]], "quad4")
