"""The one mortar kernel's rules read from the cell table, its chunks and its hooks
(contact/mortar_kernel.py, contact/mortar_support.py).

* One merge rule for every cell (``mortar_support.merge_nodes``, from the row's edges):
  bit for bit the lines' rule (``mortar_support.merge_matrix``) on every merged
  pattern of line2, line3 and the registered-style piecewise line2x2, and on tri3 and
  quad4 the faces' masking rule written out here independently (to the other kept
  corners of a triangle; to a quad corner's kept edge neighbours, else across).
* Chunks of whole slave cells (``chunk_entries``) give the unchunked call's ``g``, ``G``,
  ``H``, ``D``, ``M``, mask and supports to 1e-14 of their largest entry (only the order
  of the triplets' sums changes: round-off ~1e-16), with masked and merged nodes, and
  with a chunk bound so small that every slave cell is its own chunk.
* With ``H`` asked, the slave cells whose nodes all have a zero multiplier go first
  order (``mortar_kernel.passes``): the all-Hessian call's results to 1e-14 (2D lines
  and 3D faces, in one chunk and in chunks).
* A slave cell whose Hessian jets would exceed ``GROUP_ENTRIES`` raises ContactSizeError,
  a failed Newton iteration.
* ``integrand=``: the weighted gap written as an integrand equals the default bit for
  bit; another integrand (a slip-like ``int N_A (x_m - x_s) . e_1 dGamma``) has ``G`` and
  ``H`` that agree with central differences of the whole pipeline to 1e-7 of their
  scale (step 1e-6: truncation ~1e-10, round-off ~1e-10; a missing chain term is O(1)).
* ``mirror=``: a slave node on the mirror line takes the mirror normal (its weighted
  gap changes) and ``G``, ``H`` stay exact (central differences as above); given with an
  axisymmetric measure's axis, the same line twice changes nothing (bit for bit).
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.integration_points import LocalLayout
from skfem_mortar.contact.measures import AXISYMMETRIC, PLANE
from skfem_mortar.contact.mortar_cells import combine, dot, shape_jets, slave_geometry
from skfem_mortar.contact.mortar_support import merge_matrix
from skfem_mortar.contact.mortar_support import edge_distances, merge_nodes

LINE2, LINE3, TRI3, QUAD4 = (cell_type(c) for c in ("line2", "line3", "tri3", "quad4"))


def _patterns(k):
    return np.array(list(itertools.product([False, True], repeat=k)))


@pytest.mark.parametrize("cell", [LINE2, LINE3])
def test_merge_rule_is_the_lines_rule_bit_for_bit(cell):
    merged = _patterns(cell.n_nodes)
    assert np.array_equal(merge_nodes(merged, cell), merge_matrix(merged, cell))


def test_merge_rule_on_a_piecewise_line():
    """line2x2-like (start, middle, end on one edge): the lines' rule, bit for bit."""
    from skfem_mortar.contact.cells import CellType
    base = LINE3
    cell = CellType("line2x2_rule", 1, 3, (0, 2), ((0, 1, 2),), np.array([[-1.0, 0.0, 1.0]]),
                    base.shape, base.dshape, base.d2shape, base.quadrature, 1)
    merged = _patterns(3)
    assert np.array_equal(merge_nodes(merged, cell), merge_matrix(merged, cell))


def _faces_rule(merged, cell):
    """The faces' masking rule written out: tri3 to the other kept corners; quad4 to the
    kept edge neighbours of a corner, else to the opposite corner; equal shares."""
    k = cell.n_nodes
    T = np.diag((~merged).astype(float))
    for b in np.flatnonzero(merged):
        if k == 3:
            to = [a for a in range(3) if a != b and not merged[a]]
        else:
            to = [a for a in ((b + 1) % 4, (b + 3) % 4) if not merged[a]]
            if not to and not merged[(b + 2) % 4]:
                to = [(b + 2) % 4]
        for a in to:
            T[a, b] += 1.0 / len(to)
    return T


@pytest.mark.parametrize("cell", [TRI3, QUAD4])
def test_merge_rule_is_the_faces_rule(cell):
    merged = _patterns(cell.n_nodes)
    T = merge_nodes(merged, cell)
    for m, t in zip(merged, T):
        assert np.array_equal(t, _faces_rule(m, cell)), m
    assert np.array_equal(edge_distances(QUAD4), [[0, 1, 2, 1], [1, 0, 1, 2], [2, 1, 0, 1],
                                                  [1, 2, 1, 0]])


def test_merge_rule_names_its_parameter():
    with pytest.raises(ValueError, match="merged must have the columns of the cell line3"):
        merge_nodes(np.zeros((1, 2), dtype=bool), LINE3)


def _curve(x0, x1, n, f, k):
    t = np.linspace(x0, x1, (k - 1) * n + 1)
    X = np.vstack([t, f(t)])
    if k == 2:
        return X, np.array([[i, i + 1] for i in range(n)])
    return X, np.array([[2 * i, 2 * i + 2, 2 * i + 1] for i in range(n)])


def _pair(k, shift=0.8):
    """A curved slave whose far end hangs off the master (masked, merged nodes)."""
    xs, ss = _curve(0.05 + shift, 0.95 + shift, 5 if k == 2 else 3,
                    lambda t: 0.02 + 0.1 * (t - shift) ** 2, k)
    xm, sm = _curve(1.3, -0.2, 6 if k == 2 else 4, lambda t: -0.05 * t ** 2, k)
    return xs, ss, xm, sm


def _rel(a, b):
    a = a.toarray() if hasattr(a, "toarray") else np.asarray(a)
    b = b.toarray() if hasattr(b, "toarray") else np.asarray(b)
    return np.abs(a - b).max() / max(np.abs(a).max(), 1e-300)


@pytest.mark.parametrize("k, space", [(2, "dual"), (3, "standard"), (3, "dual")])
@pytest.mark.parametrize("per", [1, 2])
def test_chunks_give_the_unchunked_call(k, space, per):
    """``per`` integration cells a chunk (``per nv^2`` entries)."""
    xs, ss, xm, sm = _pair(k)
    nv = 12 if k == 2 else 18
    entries = per * nv * nv
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    kw = dict(lam=lam, space=space, cells=(cell_type(f"line{k}"),) * 2)
    one = mortar_kernel.evaluate(xs, ss, xm, sm, **kw)
    parts = mortar_kernel.chunks(one.info["segmentation"].e_s, nv, True, entries)
    assert len(parts) > 1
    cut = mortar_kernel.evaluate(xs, ss, xm, sm, chunk_entries=entries, **kw)
    assert not one.mask.all() and np.array_equal(one.mask, cut.mask)
    assert _rel(one.area, cut.area) <= 1e-15      # the support pass: values, other sum order
    for a, b in ((one.g, cut.g), (one.G, cut.G), (one.H, cut.H), (one.info["D"], cut.info["D"]),
                 (one.info["M"], cut.info["M"])):
        assert _rel(a, b) <= 1e-14


def _all_second_order(monkeypatch):
    """The kernel with every cell in the Hessian pass (the reference of the split)."""
    real = mortar_kernel.passes
    monkeypatch.setattr(mortar_kernel, "passes", lambda e_s, seg_s, lam, nv, entries=None: real(
        e_s, seg_s, None if lam is None else np.ones_like(lam), nv, entries))


@pytest.mark.parametrize("k, space", [(2, "dual"), (3, "standard"), (3, "dual")])
@pytest.mark.parametrize("entries", [None, 2 * 18 * 18])   # one chunk; two line3 cells a chunk
def test_cells_without_multipliers_skip_the_hessian_pass(k, space, entries, monkeypatch):
    """With the multipliers zero at some slave nodes, the slave cells with all their
    nodes at zero go first order (:func:`~skfem_mortar.contact.mortar_kernel.passes`):
    ``g``, ``G``, ``H``, ``D``, ``M`` are the all-Hessian call's to 1e-14 of their largest
    entry (only the order of the triplets' sums changes: round-off ~1e-16), supports and
    mask to the last bit, in one chunk and in chunks; with every multiplier zero, ``H``
    holds no nonzero entry and no cell carries a Hessian."""
    xs, ss, xm, sm = _pair(k)
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    lam[ss[0]] = 0.0                                # the first slave cell's nodes
    lam[ss[1, 1]] = 0.0                             # and one of the second's
    kw = dict(space=space, cells=(cell_type(f"line{k}"),) * 2, chunk_entries=entries)
    nv = LocalLayout.of(kw["cells"]).n_loc
    split = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, **kw)
    e_s = split.info["segmentation"].e_s
    plan, _ = mortar_kernel.passes(e_s, ss, lam, nv, entries)
    assert {second for _, second in plan} == {True, False}
    assert np.isin(e_s, 0).any() and np.isin(e_s, 1).any()   # cold cells and hot in the call
    nothing = mortar_kernel.evaluate(xs, ss, xm, sm, lam=0.0 * lam, **kw)
    assert nothing.H.count_nonzero() == 0 and nothing.H.shape == split.H.shape
    assert not any(second for _, second in mortar_kernel.passes(e_s, ss, 0.0 * lam, nv, None)[0])
    _all_second_order(monkeypatch)
    ref = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, **kw)
    assert np.array_equal(ref.area, split.area) and np.array_equal(ref.mask, split.mask)
    assert not ref.mask.all()                       # masked, merged nodes among them
    for a, b in ((ref.g, split.g), (ref.G, split.G), (ref.H, split.H),
                 (ref.info["D"], split.info["D"]), (ref.info["M"], split.info["M"])):
        assert _rel(a, b) <= 1e-14
    zero = mortar_kernel.evaluate(xs, ss, xm, sm, lam=0.0 * lam, **kw)
    assert _rel(zero.G, nothing.G) <= 1e-14 and abs(zero.H).max() == 0.0


@pytest.mark.parametrize("space", ["standard", "dual"])
def test_faces_without_multipliers_skip_the_hessian_pass(space, monkeypatch):
    """The same on tri3/quad4 faces (a master sliding off a corner): ``G`` and ``H``
    the all-Hessian call's to 1e-14 of their largest entry."""
    from test_mortar3d_pair import _case, _method
    rng = np.random.default_rng(7)
    xs, fs, xm, fm = _case("sliding", ("tri3", "quad4"), rng)
    method = _method(space, xs, fs, "tri3", xm, fm, "quad4")
    lam = rng.uniform(0.5, 1.5, xs.shape[1])
    lam[fs[:3].ravel()] = 0.0
    split = method.evaluate(xs, xm, lam, True)
    assert 0 < np.count_nonzero(lam) < lam.size
    _all_second_order(monkeypatch)
    method._last = None
    ref = method.evaluate(xs, xm, lam, True)
    for a, b in ((ref.g, split.g), (ref.G, split.G), (ref.H, split.H)):
        assert _rel(a, b) <= 1e-14


def test_chunks_are_whole_slave_cells_under_the_bound():
    e_s = np.array([3, 0, 0, 1, 2, 2, 2, 1, 4])
    parts = mortar_kernel.chunks(e_s, 2, False, 6)          # 3 cells a chunk
    assert np.array_equal(np.sort(np.concatenate(parts)), np.arange(e_s.size))
    for p in parts:
        assert np.all(np.diff(p) > 0)                      # the rows' own order
        assert all(np.isin(np.flatnonzero(e_s == e), p).all() for e in np.unique(e_s[p]))
        assert p.size <= 3 or np.unique(e_s[p]).size == 1
    assert mortar_kernel.chunks(e_s, 2, False, 100) == [None]


def _weighted_gap(points, local, cells, measure):
    d = local.layout.d
    N, xs, dG = slave_geometry(points, local, cells[0], measure)
    xm = combine(shape_jets(cells[1], points.xi_m), local.x_m, d)
    nt = combine(N, local.n_s, d)
    gn = dot(nt, [q - p for p, q in zip(xs, xm)]) * dot(nt, nt).sqrt().inv()
    return [(N[a] * gn * dG).sum() for a in range(cells[0].n_nodes)]


def _slip_like(points, local, cells, measure):
    N, xs, dG = slave_geometry(points, local, cells[0], measure)
    xm = combine(shape_jets(cells[1], points.xi_m), local.x_m, local.layout.d)
    return [(N[a] * (xm[0] - xs[0]) * dG).sum() for a in range(cells[0].n_nodes)]


@pytest.mark.parametrize("k, space", [(2, "standard"), (3, "dual")])
def test_integrand_hook_default_is_the_weighted_gap(k, space):
    xs, ss, xm, sm = _pair(k)
    kw = dict(lam=np.linspace(0.5, 1.5, xs.shape[1]), space=space,
              cells=(cell_type(f"line{k}"),) * 2, measure=AXISYMMETRIC)
    a = mortar_kernel.evaluate(xs, ss, xm, sm, **kw)
    b = mortar_kernel.evaluate(xs, ss, xm, sm, integrand=_weighted_gap, **kw)
    assert np.array_equal(a.g, b.g)
    assert (a.G != b.G).nnz == 0 and (a.H != b.H).nnz == 0


def _fd(xs, ss, xm, sm, lam, h=1e-6, held=(), **kw):
    """Largest errors of ``G`` and ``H`` against central differences along random
    directions (``held`` dofs not moved), relative to their largest entries."""
    ev = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, **kw)
    G, H = ev.G.toarray(), ev.H.toarray()
    x = np.r_[xs.T.ravel(), xm.T.ravel()]
    d, n = xs.shape[0], xs.size

    def at(y):
        return mortar_kernel.evaluate(y[:n].reshape(-1, d).T, ss, y[n:].reshape(-1, d).T, sm,
                                      lam=lam, **kw)
    eg = eh = 0.0
    for v in np.random.default_rng(1).normal(size=(3, x.size)):
        v[list(held)] = 0.0
        p, m = at(x + h * v), at(x - h * v)
        assert np.array_equal(p.mask, ev.mask) and np.array_equal(m.mask, ev.mask)
        eg = max(eg, np.abs((p.g - m.g) / (2 * h) - G @ v).max() / np.abs(G).max())
        eh = max(eh, np.abs((p.G.T @ lam - m.G.T @ lam) / (2 * h) - H @ v).max()
                 / np.abs(H).max())
    return ev, eg, eh


@pytest.mark.parametrize("k, space", [(2, "dual"), (3, "standard")])
def test_integrand_hook_derivatives_against_finite_differences(k, space):
    xs, ss, xm, sm = _pair(k)
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    ev, eg, eh = _fd(xs, ss, xm, sm, lam, space=space, cells=(cell_type(f"line{k}"),) * 2,
                     integrand=_slip_like)
    assert not ev.mask.all()
    assert eg <= 1e-7 and eh <= 1e-7


def test_integrand_must_give_one_jet_per_slave_node():
    xs, ss, xm, sm = _pair(2)
    with pytest.raises(ValueError, match="integrand must return 2 jets"):
        mortar_kernel.evaluate(xs, ss, xm, sm, cells=(LINE2, LINE2),
                               integrand=lambda *a: _slip_like(*a)[:1])


def test_mirror_normal_exact_and_combined_with_the_axis():
    xs, ss, xm, sm = _pair(2, shift=0.0)
    xs = xs - np.array([[xs[0, 0]], [0.0]])                 # slave node 0 on x = 0
    xs[1] += 0.2 * xs[0]                                    # its normal tilted
    xm = xm + np.array([[0.05], [0.0]])
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    kw = dict(space="dual", cells=(LINE2, LINE2))
    mirror = ((np.array([1.0, 0.0]), 0.0),)
    plain = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, **kw)
    # node 0's x dof held: a step off the line leaves the mirror normal's regime
    ev, eg, eh = _fd(xs, ss, xm, sm, lam, mirror=mirror, held=(0,), **kw)
    assert abs(ev.g[0] - plain.g[0]) > 1e-3 * abs(plain.g[0])
    assert eg <= 1e-7 and eh <= 1e-7
    axi = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, measure=AXISYMMETRIC, **kw)
    both = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, measure=AXISYMMETRIC,
                                  mirror=mirror, **kw)
    assert np.array_equal(axi.g, both.g) and (axi.H != both.H).nnz == 0
    assert PLANE.unit




def test_d_and_m_are_made_when_first_read(monkeypatch):
    """A Newton step reads g, G and H only: the kernel leaves D and M (two of a small call's
    four sparse conversions) to the first reading of ``info``, copies included."""
    from skfem_mortar.contact import scatter
    from skfem_mortar.contact.contact_eval import LazyInfo
    calls = []
    real = scatter.Triplets.csr
    monkeypatch.setattr(scatter.Triplets, "csr", lambda self, shape: calls.append(shape)
                        or real(self, shape))
    xs, ss, xm, sm = _pair(2)
    lam = np.linspace(0.5, 1.5, xs.shape[1])
    ev = mortar_kernel.evaluate(xs, ss, xm, sm, lam=lam, space="dual")
    assert len(calls) == 2                        # G and H
    assert isinstance(ev.info, LazyInfo) and "D" in ev.info and "M" in ev.info
    twin = ev.info.copy()
    D = ev.info["D"]
    assert len(calls) == 3 and ev.info["D"] is D and len(calls) == 3   # made once
    assert ev.info.get("M") is ev.info["M"] and len(calls) == 4
    assert _rel(twin["D"], D) == 0.0 and len(calls) == 5              # the copy its own
    # D's row sums are the supports (the kernel's mask reads them): the same terms summed
    # in another order, so round-off of a few eps of the largest
    assert _rel(np.asarray(D.sum(axis=1)).ravel(), ev.area) <= 1e-14
    assert ev.info.get("nothing") is None
    with pytest.raises(KeyError):
        ev.info["nothing"]


def test_a_group_beyond_its_bound_is_a_failed_iteration(monkeypatch):
    """A slave cell under more master cells than :data:`GROUP_ENTRIES` allows its
    Hessian jets raises :class:`ContactSizeError` (an :class:`InversionError`: Newton
    takes the update back, else cuts the step) naming the count; without ``H`` (first
    order, ``nv`` entries) or with zero multipliers there (first-order pass) it
    evaluates; a solve that meets it at every attempt ends in a ConvergenceError that
    says why."""
    from skfem_mortar import ContactSizeError, ConvergenceError, InversionError
    from skfem_mortar.app.runner import run_scene
    assert issubclass(ContactSizeError, InversionError)
    xs, ss = _curve(0.0, 1.0, 2, lambda t: 0.01 + 0.0 * t, 2)      # two slave cells
    xm, sm = _curve(1.2, -0.2, 40, lambda t: 0.0 * t, 2)            # under 40 master cells
    cells = (LINE2, LINE2)
    # a slave cell (0.5 long) lies under about 15 master cells (0.035 long); the bound is
    # that of a group of 10: nv = d (2 k_s + m k_m) = 2 (2 * 2 + 10 * 2)
    bound = (2 * (2 * 2 + 10 * 2)) ** 2
    monkeypatch.setattr(mortar_kernel, "GROUP_ENTRIES", bound)
    with pytest.raises(ContactSizeError, match=r"under 1[4-6] master cells") as err:
        mortar_kernel.evaluate(xs, ss, xm, sm, lam=np.ones(3), space="dual", cells=cells)
    assert f"GROUP_ENTRIES = {bound}" in str(err.value)
    mortar_kernel.evaluate(xs, ss, xm, sm, space="dual", cells=cells)        # G only
    mortar_kernel.evaluate(xs, ss, xm, sm, lam=np.zeros(3), space="dual", cells=cells)
    monkeypatch.setattr(mortar_kernel, "GROUP_ENTRIES", 1)
    with pytest.raises(ConvergenceError, match="master cells"):
        run_scene("patch", {}, "mortar-dual", steps=1)
