"""The contact discretization protocol and the method registry.

A toy method defined here, outside the package (node to rigid line: the gap of
slave node A is ``g_A = n . (x_A - p)``, so ``G`` has the rows ``n`` and
``H = 0``), is registered and solves a block pressed on a rigid line through
``ContactPair(..., method="toy")``; no package file knows it.
"""
import numpy as np
import pytest
import scipy.sparse as sp
from skfem import MeshTri

from skfem_mortar.contact.pair import METHODS, ContactPair
from skfem_mortar.contact.contact_eval import ContactEval
from skfem_mortar.contact.discretization import (ContactDiscretization, make_method, register_method,
                                         registered_methods, unregister_method)
from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.solver.stepping import solve
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane, tributary_lengths

E = 100.0
BUILT_IN = ("nts", "mortar", "mortar-dual")


class NodeToLine:
    """Slave nodes against the rigid line of a :class:`RigidPlane` master: every
    hook of the protocol written out (no base class)."""

    method = "toy"
    multiplier_kind = "force"
    multipliers_per_node = 1
    symmetric = True
    has_history = True  # counts its evaluations across steps (to test the checkpoint)

    def __init__(self, slave, master, pair_name="contact", **options):
        if set(options) - {"scale"}:
            raise ValueError(f"unknown option(s) {sorted(set(options) - {'scale'})} for 'toy'")
        self.slave, self.master, self.options = slave, master, dict(options)
        self.pinned = None
        self.calls = {"begin": 0, "after": 0, "end": 0}
        self.evaluations = 0

    def set_pinned(self, pinned):
        self.pinned = pinned

    def set_reference(self, xs0, xm0):
        pass

    def begin_step(self, xs, xm, first):
        self.calls["begin"] += 1

    def evaluate(self, xs, xm, lam, tangent):
        self.evaluations += 1
        n, p = self.master.normal, self.master.point
        ns, nm = xs.shape[1], xm.shape[1]
        g = n @ (xs - p[:, None])
        mask = np.ones(ns, dtype=bool)
        if self.pinned is not None:
            mask &= ~self.pinned
        G = H = None
        if tangent:
            rows = np.repeat(np.arange(ns), 2)
            cols = np.column_stack([2 * np.arange(ns), 2 * np.arange(ns) + 1]).ravel()
            G = sp.csr_matrix((np.tile(n, ns), (rows, cols)), shape=(ns, 2 * ns + 2 * nm))
            if lam is not None:
                H = sp.csr_matrix((2 * ns + 2 * nm,) * 2)
        return ContactEval(g=g, G=G, H=H, area=tributary_lengths(xs, self.slave.segments),
                           mask=mask)

    def after_iteration(self, ev):
        self.calls["after"] += 1

    def tail_signal(self, lam, ev):
        return lam, False

    def end_step(self, xs, xm):
        self.calls["end"] += 1

    def step_info(self):
        return {"toy_evaluations": self.evaluations}

    def failure_hint(self):
        return ""

    def state_dict(self):
        return {"toy_evaluations": np.array(self.evaluations)}

    def load_state_dict(self, state):
        a = np.asarray(state["toy_evaluations"])
        if a.shape != () or a < 0:
            raise ValueError("contact: checkpoint entry 'toy_evaluations' must be a count >= 0")
        self.evaluations = int(a)


@pytest.fixture
def toy():
    register_method("toy", NodeToLine)
    yield
    unregister_method("toy")


def _block_on_line(method, dy=-0.02, **kw):
    """Unit block (4 x 4) on the rigid line y = 0, top pushed down by dy, bottom the slave."""
    m = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5)).with_defaults()
    b = Solid(m, NeoHooke(E=E, nu=0.0), name="block")
    plane = RigidPlane((0.5, 0.0), (0.0, 1.0), length=10.0)
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), plane, method, name="c", **kw)
    model = Model([b, Dirichlet(b, b.dofs_on("top", "y"), dy),
                   Dirichlet(b, b.dofs_on("left", "x"), 0.0), pair])
    return pair, model


def test_a_method_registered_outside_the_package_solves_the_block_on_a_line(toy):
    """nu = 0 neo-Hooke, frictionless line: uniform P_yy = mu (ly - 1/ly), all
    five bottom nodes in contact, gaps zero to round-off."""
    assert "toy" in METHODS and registered_methods()[:3] == BUILT_IN
    pair, model = _block_on_line("toy", scale=1.0)
    assert isinstance(pair.discretization, NodeToLine)
    assert pair.options == {"scale": 1.0} and pair.multiplier_kind == "force"
    res = solve(model, 2)
    assert res.steps[-1].info["toy_evaluations"] == pair.discretization.evaluations
    ly = 0.98
    p_exact = -E / 2 * (ly - 1 / ly)
    d = pair.contact_data(res.z)
    np.testing.assert_allclose(d["pressure"], p_exact, rtol=1e-8)
    np.testing.assert_allclose(d["gap"], 0.0, atol=1e-12)
    np.testing.assert_allclose(pair.total_force(res.z), [0.0, p_exact], atol=1e-8 * p_exact)
    assert res.steps[-1].n_active == 5
    assert pair.violation(res.z, E) == ""
    calls = pair.discretization.calls
    assert calls["end"] == 2 and calls["begin"] >= 2 and calls["after"] >= 2
    assert res.steps[-1].info["segment_locks"] == 0   # the record's keys stay the same

    # the method's state rides in the pair's checkpoint, beside the pair's own
    state = pair.state_dict()
    assert int(state["toy_evaluations"]) == pair.discretization.evaluations
    again, _ = _block_on_line("toy")
    again.load_state_dict(state)
    assert again.discretization.evaluations == pair.discretization.evaluations
    np.testing.assert_array_equal(again.state.converged, pair.state.converged)
    with pytest.raises(ValueError, match="'toy_evaluations'"):
        again.load_state_dict({**state, "toy_evaluations": np.array(-1)})


def test_the_toy_agrees_with_nts_on_the_line(toy):
    """On a straight rigid line the NTS gap is the toy's: the same solution."""
    zs = [solve(model, 2).z[pair.dofs] for pair, model in
          (_block_on_line(m) for m in ("toy", "nts"))]
    np.testing.assert_allclose(zs[0], zs[1], rtol=1e-9)


@pytest.mark.parametrize("method", BUILT_IN)
def test_the_built_ins_implement_the_protocol(method):
    pair, _ = _block_on_line(method)
    d = pair.discretization
    assert isinstance(d, ContactDiscretization)
    assert d.method == method and d.multipliers_per_node == 1 and d.symmetric
    assert d.multiplier_kind == ("force" if method == "nts" else "traction")
    assert d.has_history  # nts: segment preferences, locks; all: the reserved pattern
    assert isinstance(make_method(method, pair.slave, pair.master), type(d))


def test_an_unknown_method_is_refused_naming_the_registered_ones(toy):
    pair, _ = _block_on_line("nts")
    with pytest.raises(ValueError, match="method must be one of nts, mortar, mortar-dual, toy, "
                                         "got 'penalty'"):
        ContactPair(pair.slave, pair.master, "penalty")
    with pytest.raises(ValueError, match="method must be one of nts, mortar, mortar-dual, toy"):
        make_method("penalty", pair.slave, pair.master)


def test_the_registry_refuses_what_does_not_fit(toy):
    pair, _ = _block_on_line("nts")
    with pytest.raises(ValueError, match="'toy' is registered already"):
        register_method("toy", NodeToLine)
    register_method("not-a-method", lambda slave, master, **kw: object())
    try:
        with pytest.raises(TypeError, match="lacks hooks of ContactDiscretization"):
            ContactPair(pair.slave, pair.master, "not-a-method")
    finally:
        unregister_method("not-a-method")
    assert "not-a-method" not in METHODS


def test_options_are_the_methods_and_checked_when_built():
    pair, _ = _block_on_line("nts")
    with pytest.raises(ValueError, match="unknown option 'n_gauss' for method 'nts'"):
        ContactPair(pair.slave, pair.master, "nts", n_gauss=2)
    # a pair keyword that does not apply is said so (not "unknown ... did you mean" itself)
    with pytest.raises(ValueError, match=r"^segmentation='step' does not apply to method 'nts'"):
        ContactPair(pair.slave, pair.master, "nts", segmentation="step")
    with pytest.raises(ValueError, match="unknown option 'stick' for method 'mortar-dual'"):
        ContactPair(pair.slave, pair.master, "mortar-dual", stick=0.1)
    step = ContactPair(pair.slave, pair.master, "mortar", segmentation="step", n_gauss=3)
    assert step.discretization.segmentation == "step" and step.options == {"n_gauss": 3}


def test_a_checkpoint_entry_of_the_method_is_checked_by_the_method():
    pair, model = _block_on_line("nts")
    solve(model, 1)
    state = pair.state_dict()
    assert {"prefer", "lock", "active", "x0_slave"} <= set(state)
    bad = {**state, "prefer": np.full(pair.slave.n_nodes, 7)}
    with pytest.raises(ValueError, match="checkpoint entry 'prefer' indexes no master segment"):
        pair.load_state_dict(bad)
    with pytest.raises(ValueError, match="expected"):
        pair.load_state_dict({k: v for k, v in state.items() if k != "lock"})
    pair.load_state_dict(state)
