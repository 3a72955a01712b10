"""The declared item protocol and the output protocol (issue 15, item 1)."""
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import MeshQuad, MeshTri

from skfem_mortar.output.contact_output import ContactOutput
from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.bodies.mixed import MixedSolid
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.item import ContactTable, Contribution, Item, ItemProtocol, Output
from skfem_mortar.core.model import Model
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.app.runner import run_scene
from skfem_mortar.bodies.sri import SRISolid
from skfem_mortar.solver.stepping import solve
from skfem_mortar.loads.traction import PointLoad

from toy_items import Spring

#: the hooks the solver calls on an item (ItemProtocol, Item)
HOOKS = ("assemble", "prescribed", "referenced_bodies", "set_fixed", "begin_step",
         "end_step", "settled", "step_info", "violation", "failure_hint", "state_dict",
         "load_state_dict", "outputs")

#: what each built-in item class declares: (symmetric tangent, carries history)
DECLARED = {"Solid": (True, False), "MixedSolid": (True, False), "SRISolid": (True, False),
            "Cable": (True, False), "FollowerPressure": (False, False),
            "Traction": (True, False), "PointLoad": (True, False),
            "Dirichlet": (True, False), "ContactPair": (False, True)}


def _solved(scene, method=None):
    _, result, setup = run_scene(scene, {}, method=method, steps=2, return_result=True)
    return result, setup.model


@pytest.fixture(scope="module")
def solved_models():
    """Solved models holding every built-in item class, with a state to assemble at."""
    out = [_solved("patch", "mortar"), _solved("seed", "nts"), _solved("hertz")]
    mixed = MixedSolid(MeshTri.init_symmetric(), NeoHooke(mu=1.0, lmbda=10.0), name="mixed")
    sri = SRISolid(MeshQuad(), NeoHooke(mu=1.0, lmbda=10.0), name="sri")
    extra = Model([mixed, sri, PointLoad(sri, [2, 3], 0.01, name="tip"),
                   Dirichlet(mixed, mixed.dofs_at_nodes([0, 1])), Dirichlet(sri, [0, 1, 6, 7])])
    z = extra.zeros()
    z[sri.dofs] = 0.01 * np.sin(np.arange(sri.n_dofs))
    out.append((type("R", (), {"z": z})(), extra))
    return out


def _items(solved_models):
    return [(it, result.z, model) for result, model in solved_models for it in model.items]


def test_every_built_in_item_class_is_covered(solved_models):
    assert {type(it).__name__ for it, _, _ in _items(solved_models)} == set(DECLARED)


def test_built_in_items_satisfy_the_item_protocol(solved_models):
    for it, z, model in _items(solved_models):
        assert isinstance(it, Item)
        for hook in HOOKS:
            assert callable(getattr(it, hook)), (type(it).__name__, hook)
        for name in ItemProtocol.__annotations__:
            assert hasattr(it, name), (type(it).__name__, name)
        assert isinstance(it.symmetric, bool) and isinstance(it.has_history, bool)
        assert isinstance(it.failure_hint(), str)
        assert isinstance(it.step_info(), dict)
        # history is what a checkpoint keeps
        assert it.has_history == bool(it.state_dict()), type(it).__name__
        for o in it.outputs():
            assert isinstance(o, Output)


@pytest.mark.parametrize("cls", sorted(DECLARED))
@pytest.mark.parametrize("what", ["symmetric", "has_history"])
def test_declarations(solved_models, cls, what):
    k = ("symmetric", "has_history").index(what)
    found = [it for it, _, _ in _items(solved_models) if type(it).__name__ == cls]
    assert found and all(getattr(it, what) is DECLARED[cls][k] for it in found)


def test_the_symmetric_declarations_are_true_of_the_tangents(solved_models):
    """A class declared symmetric assembles a symmetric tangent (to round-off); a
    class declared unsymmetric assembles an unsymmetric one somewhere (a follower
    pressure on a closed ring happens to be symmetric)."""
    asym: dict[str, list[float]] = {}
    for it, z, model in _items(solved_models):
        c = it.assemble(z, 1.0, True)
        if not c.k_vals.size:
            continue
        K = sp.coo_matrix((c.k_vals, (c.k_rows, c.k_cols)), shape=(model.n, model.n)).tocsr()
        asym.setdefault(type(it).__name__, []).append(abs(K - K.T).max() / abs(K).max())
    for cls, values in asym.items():
        if DECLARED[cls][0]:
            assert max(values) < 1e-12, (cls, values)
        else:
            assert max(values) > 1e-3, (cls, values)


def test_output_protocol_of_built_in_items(solved_models):
    result, model = solved_models[0]  # patch: two solids and a contact pair
    pair = model.item("contact")
    assert isinstance(pair, ContactTable) and not isinstance(pair, Output)
    [o] = pair.outputs()
    assert isinstance(o, ContactOutput) and o.name == pair.name
    bodies = [it for it in model.items if isinstance(it, Output)]
    assert [b.outputs() for b in bodies] == [[b] for b in bodies]
    assert [o.name for o in model.outputs()] == [it.name for it in model.items
                                                 if it.outputs()]
    assert model.contact_tables() == [pair]
    assert [o.name for o in result.outputs()] == [b.name for b in bodies] + [pair.name]
    assert model.symmetric == all(it.symmetric for it in model.items)
    for it in model.items:
        if isinstance(it, Dirichlet):
            assert it.outputs() == []


class OnlyAssemble(Item):
    """A user item that defines nothing but assemble (a linear spring to ground)."""

    dof_kind = "u"
    n_dofs = 2
    name = "mine"

    def assemble(self, z, load_factor, tangent=True):
        u = z[self.dofs]
        r = 3.0 * u - load_factor * np.array([1.0, 2.0])
        return Contribution.from_local(self.offset, r, sp.identity(2) * 3.0 if tangent else None)


def test_a_user_item_with_only_assemble_works():
    it = OnlyAssemble()
    assert it.symmetric and not it.has_history and it.outputs() == []
    assert it.failure_hint() == "" and it.set_fixed(np.zeros(0, dtype=int)) is None
    model = Model([it])
    assert model.outputs() == [] and model.contact_tables() == [] and model.symmetric
    res = solve(model, 2)
    assert res.converged and np.allclose(res.z, [1 / 3, 2 / 3], rtol=0, atol=1e-12)
    assert res.outputs() == []


def test_an_item_declares_history_explicitly():
    class Remembers(OnlyAssemble):
        has_history = True

    assert Remembers().has_history and not OnlyAssemble().has_history


def test_newton_options_warns_and_still_works():
    def model():
        s = Spring(3, k=2.0, load=1.0)
        return Model([s, Dirichlet(s, [0])])

    opts = NewtonOptions(rtol=1e-12)
    with pytest.warns(DeprecationWarning, match="newton="):
        old = solve(model(), 2, newton_options=opts)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        new = solve(model(), 2, newton=opts)
    assert [s.residual_norms for s in old.steps] == [s.residual_norms for s in new.steps]
    assert np.array_equal(old.z, new.z)


def test_an_instance_may_declare_history():
    it = OnlyAssemble()
    it.has_history = True
    assert it.has_history and not OnlyAssemble().has_history


def test_the_loaded_declarations_are_true_of_the_residuals(solved_models):
    """An item declared not ``loaded`` assembles the same residual at any load
    factor (exactly: the load factor does not enter its arithmetic), and every
    load does change with it; ``Model.load_residual`` then sums the loads alone."""
    changed = set()
    for it, z, model in _items(solved_models):
        r0 = it.assemble(z, 0.25, tangent=False)
        r1 = it.assemble(z, 0.75, tangent=False)
        same = (np.array_equal(r0.r_index, r1.r_index)
                and np.array_equal(r0.r_value, r1.r_value))
        if not it.loaded:
            assert same, type(it).__name__
        elif not same:
            changed.add(type(it).__name__)
    assert {"FollowerPressure", "Traction", "PointLoad"} <= changed
    for result, model in solved_models:
        full = model.assemble(result.z, 0.75, tangent=False)[0] \
            - model.assemble(result.z, 0.25, tangent=False)[0]
        loads = model.load_residual(result.z, 0.75) - model.load_residual(result.z, 0.25)
        # the bodies' forces cancel in ``full`` only to their round-off
        scale = np.abs(model.assemble(result.z, 0.75, tangent=False)[0]).max() + 1e-300
        np.testing.assert_allclose(loads, full, rtol=0, atol=1e-13 * scale)


def test_the_body_protocol_of_built_in_bodies(solved_models):
    """Every built-in body gives its vertex positions (the Body protocol); a user
    body without them is a body all the same and lends no length to the floor."""
    from skfem_mortar.core.item import Body
    from skfem_mortar.solver.newton import ROUND_OFF, round_off_floor

    for it, z, model in _items(solved_models):
        if it.dof_kind == "u":
            assert isinstance(it, Body), type(it).__name__
            x = it.x(z)
            assert x.shape == it.X.shape and x.shape[0] == 2
    assert not isinstance(OnlyAssemble(), Body)
    result, model = solved_models[0]
    free = np.arange(model.n)
    K = model.assemble(result.z, 1.0)[1]
    floor = round_off_floor(model, result.z, K, free)
    # the floor is eps-sized and scales with the largest vertex coordinate L
    length = max(float(np.abs(b.x(result.z)).max()) for b in model.bodies)
    k_row = np.asarray(abs(K).max(axis=1).todense()).ravel()
    np.testing.assert_allclose(floor, ROUND_OFF * np.finfo(float).eps * length * k_row, rtol=1e-14)
