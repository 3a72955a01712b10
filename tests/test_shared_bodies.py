"""Bodies shared by two models (issue 32): one model per contact method on the
same bodies, each solve giving that model's own answer whatever was built or
solved in between; a contact pair (an item with a history) belongs to the
model built last with it."""
import numpy as np
import pytest
import skfem

import readme_scene
from skfem_mortar import Dirichlet, Model, NeoHooke, Solid, solve


def _block(name, x0, n):
    mesh = (skfem.MeshTri.init_tensor(np.linspace(x0, x0 + 1, n), np.linspace(0, 1, n))
            .with_boundaries({"left": lambda x: np.isclose(x[0], x0)}))
    return Solid(mesh, NeoHooke(E=10.0, nu=0.3), element="tri1", name=name)


def _bodies():
    """The README scene's cable and cushion, and two blocks ``c`` and ``d``
    (2 x 2 and 4 x 4 vertices) that touch nothing, each clamped on its left."""
    return {"cable": readme_scene.cable(), "cushion": readme_scene.cushion(),
            "c": _block("c", 3, 2), "d": _block("d", 5, 4)}


def _items(bodies, method, order):
    """The items of one model: the bodies named in ``order`` (in that order),
    its own pair, loads and supports."""
    rest, pair = readme_scene.items(bodies["cable"], bodies["cushion"], method)
    own = [bodies[name] for name in order.split()]
    held = [Dirichlet(b, b.dofs_on("left"), name=f"{b.name}_clamp") for b in own
            if b.name in ("c", "d")]
    return own + rest + held, pair


#: the two models of each case: (method, bodies) of m1 and m2.  On main m1's
#: solve after m2 was built read m2's offsets: "index": m2 puts a body m1 lacks
#: before the shared ones (m1 read past its unknowns: IndexError); "overlap":
#: m1 has a body m2 lacks before the shared ones (m1's blocks overlapped: a
#: singular tangent); "rigid": d's block moved into c's (the preflight: "rigid
#: modes held by nothing ... moving together with 'd'")
CASES = {"index": (("mortar", "cable cushion"), ("nts", "d cable cushion")),
         "overlap": (("mortar", "c cable cushion"), ("nts", "cushion cable")),
         "rigid": (("mortar", "cable cushion c d"), ("nts", "cable cushion d"))}


def _answer(model, pair):
    r = solve(model, 4)
    return r.z, [s.newton_iterations for s in r.steps], pair.contact_data(r.z)["pressure"]


def _alone(spec, solves):
    """The answers of ``solves`` solves of one model built on bodies of its own."""
    model_items, pair = _items(_bodies(), *spec)
    model = Model(model_items)
    return [_answer(model, pair) for _ in range(solves)]


def _same(a, b):
    # bitwise: the same model solved from the same state sums the same numbers in
    # the same order (the layout is the model's own), so nothing may differ
    za, ia, pa = a
    zb, ib, pb = b
    assert ia == ib
    assert np.array_equal(za, zb)
    assert np.array_equal(pa, pb)


@pytest.mark.parametrize("first", ["m1", "m2"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_a_model_solved_after_another_on_its_bodies_gives_its_own_answer(case, first):
    spec = dict(zip(("m1", "m2"), CASES[case]))
    other = "m2" if first == "m1" else "m1"
    bodies = _bodies()
    built = {}
    for name in ("m1", "m2"):  # both built before anything is solved
        model_items, pair = _items(bodies, *spec[name])
        built[name] = (Model(model_items), pair)
    got = [_answer(*built[first]), _answer(*built[other]), _answer(*built[first])]
    # a second solve of a model starts from its pair's converged state (its
    # history), so the third answer is that of a model solved twice alone
    want_first = _alone(spec[first], 2)
    _same(got[0], want_first[0])
    _same(got[1], _alone(spec[other], 1)[0])
    _same(got[2], want_first[1])


def test_switching_models_keeps_each_models_tangent_pattern():
    """The layout is written again only when another model was used, and the
    equal index arrays it gives keep the model's pattern (no rebuild)."""
    bodies = _bodies()
    cable, cushion = bodies["cable"], bodies["cushion"]
    m1_items, _ = _items(bodies, "mortar", "c cable cushion")
    m2_items, _ = _items(bodies, "nts", "cushion cable")
    m1 = Model(m1_items)
    z1 = m1.zeros()
    R, K, _ = m1.assemble(z1, 0.5)
    builds = m1.pattern_builds
    m2 = Model(m2_items)
    m2.assemble(m2.zeros(), 0.5)
    assert (cushion.offset, cable.offset) == (0, cushion.n_dofs)  # m2's layout
    R2, K2, _ = m1.assemble(z1, 0.5)
    assert m1.pattern_builds == builds
    assert np.array_equal(R, R2) and (K != K2).nnz == 0


def test_each_model_keeps_its_own_thickness():
    bodies = _bodies()
    cushion = bodies["cushion"]
    thin_items, _ = _items(bodies, "mortar", "cable cushion")
    thick_items, _ = _items(bodies, "mortar", "cable cushion")
    thin = Model(thin_items, thickness=1.0)
    z = thin.zeros()
    z[cushion.dofs] = 1e-3 * np.sin(np.arange(cushion.n_dofs))
    R_thin = thin.assemble(z, 0.5, tangent=False)[0]
    thick = Model(thick_items, thickness=2.0)
    assert cushion.thickness == 2.0
    # the thin model's thickness is written back when it is used: the same
    # numbers again, and the thick model's are exactly twice them (times a power of 2)
    assert np.array_equal(thin.assemble(z, 0.5, tangent=False)[0], R_thin)
    assert cushion.thickness == 1.0
    assert np.array_equal(thick.assemble(z, 0.5, tangent=False)[0], 2.0 * R_thin)


def test_a_pair_belongs_to_the_model_built_last_with_it():
    bodies = _bodies()
    model_items, pair = _items(bodies, "mortar", "cable cushion")
    first = Model(model_items)
    second = Model(model_items[::-1])  # the same items, another layout
    with pytest.raises(ValueError, match="item 'contact' \\(ContactPair\\) keeps a state .* "
                                         "was put in a model built after this one"):
        solve(first, 2)
    r = solve(second, 4)  # the pair is the second model's now
    assert pair.contact_data(r.z)["pressure"].max() > 0
    # bodies and conditions without history are shared freely: a third model
    # with its own pair uses them (and takes nothing from the second)
    third_items, _ = _items(bodies, "nts", "cushion cable")
    solve(Model(third_items), 2)
    solve(second, 1)


def test_rebind_gives_a_pair_its_models_layout_back():
    """A pair's own helpers read the layout of the model used last; rebind (what
    the pair's helpers can call) makes it its own model's again."""
    from skfem_mortar.core.binding import rebind
    bodies = _bodies()
    cable = bodies["cable"]
    m1_items, p1 = _items(bodies, "mortar", "cable cushion")
    m2_items, _ = _items(bodies, "nts", "c cable cushion")
    m1 = Model(m1_items)
    r1 = solve(m1, 4)
    want = p1.contact_data(r1.z)["pressure"]
    Model(m2_items)  # another layout of the same bodies (cable after c)
    assert cable.offset == bodies["c"].n_dofs
    rebind(p1)
    assert cable.offset == 0
    assert np.array_equal(p1.contact_data(r1.z)["pressure"], want)


def test_a_pairs_outputs_read_its_own_models_layout():
    """A user compares methods: m1 solved, m2 built (another layout) and solved,
    then m1's pair asked for its pressure and forces at m1's answer: they read
    m1's layout (without the pair's own rebind: an IndexError past m2's end)."""
    bodies = _bodies()
    items1, pair1 = _items(bodies, "mortar", "cable cushion")
    m1 = Model(items1)
    z1 = solve(m1, 4).z
    p1, f1 = pair1.contact_data(z1)["pressure"].copy(), pair1.total_force(z1).copy()
    items2, pair2 = _items(bodies, "nts", "d cable cushion")
    solve(Model(items2), 4)
    # the same evaluation at the same state and layout: bitwise the same numbers
    assert np.array_equal(pair1.contact_data(z1)["pressure"], p1)
    assert np.array_equal(pair1.total_force(z1), f1)
