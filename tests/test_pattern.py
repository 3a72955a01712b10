"""The reserved contact pattern (ContactDiscretization's optional ``pattern`` hook).

(a) superset: over whole solves, every nonzero of ``G`` and ``H`` at every
Newton iteration lies inside the pattern the method returned at the same
positions; (b) it changes rarely; (c) the pair's triplets over it (explicit
zeros) sum to the same tangent as the triplets of ``G`` and ``H`` alone; (d) a
method without the hook still works.
"""
import copy
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

from skfem_mortar.app.runner import build_scene
from skfem_mortar.contact.discretization import (ContactDiscretization, PatternedDiscretization,
                                                  register_method, unregister_method)
from skfem_mortar.contact.nts import NTS
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.solver.stepping import solve

METHODS = ("nts", "mortar", "mortar-dual")
#: small versions of the scenes with a deformable master (the pattern matters there)
SCENES = [("hertz", {"base": "elastic", "refine": -1}), ("patch", {}), ("seed", {})]


def _nonzeros(M: sp.spmatrix) -> set:
    C = M.tocoo()
    nz = C.data != 0
    return set(zip(C.row[nz].tolist(), C.col[nz].tolist()))


class Recorder:
    """Wraps a pair's discretization: every pattern call is checked against the
    tangent evaluation just before it (same positions)."""

    def __init__(self, d):
        self.d, self.last, self.patterns, self.calls, self.bad = d, None, [], 0, []
        real_eval, real_pattern = d.evaluate, d.pattern

        def evaluate(xs, xm, lam, tangent):
            ev = real_eval(xs, xm, lam, tangent)
            if tangent and lam is not None:
                self.last = (xs.copy(), xm.copy(), ev)
            return ev

        def pattern(xs, xm):
            P = real_pattern(xs, xm)
            self.calls += 1
            if not self.patterns or self.patterns[-1] is not P:
                self.patterns.append(P)
            xs0, xm0, ev = self.last
            assert np.array_equal(xs0, xs) and np.array_equal(xm0, xm)
            held = _nonzeros(P)
            S = _nonzeros(P.T @ P)
            miss_g = _nonzeros(ev.G) - held
            miss_h = set() if ev.H is None else _nonzeros(ev.H) - S
            if miss_g or miss_h:
                self.bad.append((len(miss_g), len(miss_h)))
            return P

        d.evaluate, d.pattern = evaluate, pattern


def _solve(scene, params, method):
    setup = build_scene(scene, params, method)[0]
    pairs = [it for it in setup.model.items if isinstance(it, ContactPair)]
    recs = [Recorder(p.discretization) for p in pairs]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the preflight's NTS warning on hertz
        res = solve(setup.model, setup.n_steps or 10, **setup.solve_options)
    return res, pairs, recs


@pytest.fixture(scope="module", params=[(s, p, m) for s, p in SCENES for m in METHODS],
                ids=lambda v: f"{v[0]}-{v[2]}")
def solved(request):
    return request.param, _solve(*request.param)


def test_pattern_holds_every_nonzero_of_G_and_H(solved):
    (scene, _, method), (res, pairs, recs) = solved
    iterations = sum(s.newton_iterations for s in res.steps)
    for pair, rec in zip(pairs, recs):
        # one pattern call per tangent evaluation: at least one per iteration
        assert rec.calls >= iterations
        assert rec.bad == [], f"{scene}/{method}: entries outside the pattern {rec.bad[:3]}"
        assert pair.pattern_misses == 0


def test_pattern_changes_rarely(solved):
    """A reservation is kept over iterations and steps until the search leaves
    it: measured 1 or 2 per solve here (ironing, a die slid over 40 steps: 8 to
    18), against 20 to 55 iterations; at most one per four load steps (plus the
    first) still fails a pattern that follows G (a new one at most iterations)."""
    (scene, _, method), (res, pairs, recs) = solved
    iterations = sum(s.newton_iterations for s in res.steps)
    for rec in recs:
        assert 1 <= len(rec.patterns) <= 1 + len(res.steps) // 4, \
            (scene, method, len(rec.patterns), iterations, len(res.steps))


def _triplet_tangent(pair, z, n):
    """The pair's tangent summed from G and H alone (no reservation)."""
    c = pair.assemble(z, 1.0, tangent=True)
    return sp.coo_matrix((c.k_vals, (c.k_rows, c.k_cols)), shape=(n, n)).tocsr(), c.k_vals.size


@pytest.mark.parametrize("method", METHODS)
def test_reserved_triplets_sum_to_the_same_tangent(method, monkeypatch):
    """Over the reservation the triplets carry explicit zeros, and the sum is
    the tangent of G and H (the path of a method without the hook) to the
    last bit: each entry is one value of G or H, scattered, not a new sum."""
    setup = build_scene("hertz", {"base": "elastic", "refine": -2}, method)[0]
    model = setup.model
    pair = next(it for it in model.items if isinstance(it, ContactPair))
    z = model.zeros()
    for it in model.items:
        it.begin_step(z, 0.3)
    rng = np.random.default_rng(0)
    z[: model.n_u] += 1e-4 * rng.standard_normal(model.n_u)
    z[pair.dofs] = np.abs(rng.standard_normal(pair.n_dofs))  # a mix of active and inactive
    state = copy.deepcopy(pair.state)  # the active set: each call with a tangent updates it
    K_res, n_triplets = _triplet_tangent(pair, z, model.n)
    pair.state = state
    monkeypatch.setattr(ContactPair, "_reservation", lambda self, z, gd: None)
    K_plain, _ = _triplet_tangent(pair, z, model.n)
    assert 0 < pair.active.sum() < pair.n_dofs
    assert abs(K_res - K_plain).max() == 0.0
    assert n_triplets > K_plain.nnz  # the explicit zeros are there


class NoHook(ContactDiscretization):
    """NTS behind the protocol, without the optional hook."""

    method = "nts-no-hook"
    multiplier_kind = "force"
    multipliers_per_node = 1
    symmetric = True
    has_history = True

    def __init__(self, slave, master, pair_name="contact", **options):
        self.inner = NTS(slave, master, pair_name=pair_name, **options)
        self.options = self.inner.options

    def __getattribute__(self, name):
        if name in ("set_pinned", "set_reference", "begin_step", "evaluate", "after_iteration",
                    "end_step", "step_info", "failure_hint", "state_dict", "load_state_dict",
                    "tail_signal"):
            return getattr(object.__getattribute__(self, "inner"), name)
        return object.__getattribute__(self, name)


def test_a_method_without_the_hook_gives_the_same_answer():
    assert isinstance(NTS.__new__(NTS), PatternedDiscretization)
    assert not isinstance(NoHook.__new__(NoHook), PatternedDiscretization)
    register_method("nts-no-hook", NoHook)
    try:
        out = {}
        for method in ("nts", "nts-no-hook"):
            setup = build_scene("patch", {}, "nts")[0]
            pair = next(it for it in setup.model.items if isinstance(it, ContactPair))
            model_items = [ContactPair(pair.slave, pair.master, method=method, name=pair.name)
                           if it is pair else it for it in setup.model.items]
            model = type(setup.model)(model_items)
            res = solve(model, setup.n_steps or 1, **setup.solve_options)
            out[method] = (res.z, [s.newton_iterations for s in res.steps])
        assert out["nts"][1] == out["nts-no-hook"][1]
        # the same Newton steps; the explicit zeros change only SuperLU's ordering,
        # so the answers agree to round-off of the displacements (1e-15 relative)
        z1, z2 = out["nts"][0], out["nts-no-hook"][0]
        assert np.max(np.abs(z1 - z2)) <= 1e-12 * np.max(np.abs(z1))
    finally:
        unregister_method("nts-no-hook")


@pytest.mark.parametrize("method", METHODS)
def test_the_reservation_goes_into_checkpoints(method):
    """A resumed run starts from the uninterrupted run's reservation (the same
    explicit zeros, so the same solver orderings); a bad entry is refused."""
    res, pairs, _ = _solve("patch", {}, method)
    d = pairs[0].discretization
    state = d.state_dict()
    assert state["reserved"].size > 0
    fresh = build_scene("patch", {}, method)[0]
    d2 = next(it for it in fresh.model.items if isinstance(it, ContactPair)).discretization
    d2.load_state_dict(state)
    assert abs(d2.pattern(*_positions(pairs[0], res.z)) - d._reserved[1]).nnz == 0
    for bad in (state["reserved"][::-1], state["reserved"] + 10**9, state["reserved"] * 0.5):
        with pytest.raises(ValueError, match="'reserved' must be sorted unique integers"):
            d2.load_state_dict({**state, "reserved": bad})


def _positions(pair, z):
    return pair.slave.x(z), pair.master.x(z)


@pytest.mark.parametrize("m,n", [(0, 7), (1, 1), (1000, 40), (50000, 3000)])
def test_unique_keys_and_union_are_numpys(m, n):
    """The pattern's own sorts (scipy's row bucketing, a merge of sorted runs)
    give what ``np.unique`` gives: the sorted unique keys, each triplet's place
    among them, and each key array's place in the union."""
    from skfem_mortar.core.pattern import _union, _unique_keys
    rng = np.random.default_rng(m)
    rows, cols = rng.integers(0, n, m), rng.integers(0, n, m)
    keys, inv = _unique_keys(rows, cols, n)
    ref, ref_inv = np.unique(rows * n + cols, return_inverse=True)
    np.testing.assert_array_equal(keys, ref)
    np.testing.assert_array_equal(inv, ref_inv.ravel())
    other = np.unique(rng.integers(0, n * n, m // 3 + 1))
    union, places = _union([keys, other])
    np.testing.assert_array_equal(union, np.union1d(keys, other))
    for k, pl in zip((keys, other), places):
        np.testing.assert_array_equal(union[pl], k)


def test_pattern_sums_as_one_bincount_of_all_triplets():
    """The pattern adds the first item's values by ``bincount`` and the others'
    by ``np.add.at``, each in its order, and keeps the places per item: the
    sums are those of one ``bincount`` of all triplets in the items' order, to
    the last bit (no tolerance: the same additions in the same order), also
    after a rebuild for one item's new indices."""
    from skfem_mortar.core.item import Contribution
    from skfem_mortar.core.pattern import _Pattern
    rng = np.random.default_rng(3)
    n = 60

    def part(m, hi):
        return Contribution(np.zeros(0, dtype=np.int64), np.zeros(0), rng.integers(0, hi, m),
                            rng.integers(0, hi, m), rng.standard_normal(m))
    parts = [part(20, 5), part(5000, n), part(300, 8)]  # the largest not first
    previous = None
    for _ in range(2):
        pat = _Pattern((0, 1, 2), parts, n, previous)
        K = pat.matrix([p.k_vals for p in parts])
        keys = np.concatenate([p.k_rows * n + p.k_cols for p in parts])
        ref_keys, inv = np.unique(keys, return_inverse=True)
        ref = np.bincount(inv.ravel(), weights=np.concatenate([p.k_vals for p in parts]))
        np.testing.assert_array_equal(K.indptr, np.searchsorted(ref_keys // n, np.arange(n + 1)))
        np.testing.assert_array_equal(K.indices, ref_keys % n)
        np.testing.assert_array_equal(K.data, ref)
        previous, parts[2] = pat, part(300, n)  # a new reservation of the last item


@pytest.mark.parametrize("element", ["tri1", "tri2", "quad1"])
@pytest.mark.parametrize("offset", [0, 7])
def test_element_keys_are_the_triplets_keys(element, offset):
    """A Solid's pattern found per node (its vector dofs spread from the node
    pairs, :func:`_element_keys`) is the one of its triplets: the same keys and
    places exactly (integers); and a numbering that is not per node falls back."""
    from skfem import MeshQuad, MeshTri

    from skfem_mortar.bodies.materials import NeoHooke
    from skfem_mortar.bodies.solid import Solid
    from skfem_mortar.core.coo import element_coo
    from skfem_mortar.core.pattern import _element_keys, _unique_keys
    mesh = (MeshQuad() if element.startswith("quad") else MeshTri()).refined(2)
    s = Solid(mesh, NeoHooke(E=1.0, nu=0.3), element=element)
    n = offset + s.n_dofs + 3
    shuffled = np.random.default_rng(0).permutation(s.n_dofs)  # not per node
    for D in (offset + s._edofs, offset + shuffled[s._edofs]):
        keys, inv = _element_keys(D, n)
        ref_keys, ref_inv = _unique_keys(*element_coo(D, elements_last=True), n)
        np.testing.assert_array_equal(keys, ref_keys)
        np.testing.assert_array_equal(inv, ref_inv)
