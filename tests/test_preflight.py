"""Preflight checks (issue 13): models that cannot work are refused before the
first load step, with a ValueError naming the item and the fix; the same models
the right way round, and every scene, pass.

The models are written as a new user would write them from the README.  No
test solves: ``model.preflight`` is called on the initial state exactly as
``solve`` calls it (``_preflight`` below), so the file runs in a few seconds.
"""
import warnings

import numpy as np
import pytest
import skfem

from skfem_mortar import (Cable, ContactPair, Dirichlet, FollowerPressure, Model, NeoHooke,
                          Solid, Traction)
from skfem_mortar.contact.pair import METHODS  # the method names: nts, mortar, mortar-dual
from skfem_mortar.core.item import Contribution, Item
from skfem_mortar.contact.preflight import PreflightWarning
from skfem_mortar.app.runner import build_scene
from skfem_mortar.scenes import get_scene, list_scenes
from skfem_mortar.contact.surfaces import ContactSurface, RigidCircle, RigidPlane


def _preflight(model, load_factor=0.0):
    """What ``solve`` does before its first step: prescribed values into z, then preflight."""
    z = model.zeros()
    fixed, values = model.prescribed(load_factor)
    z[fixed] = values
    model.preflight(z, load_factor, fixed)


# --------------------------------------------------------------------------- models
def _disk(y0=0.0, nref=2, name="disk"):
    """A unit disk whose lowest node is at (0, y0), rim and top tagged."""
    mesh = skfem.MeshTri.init_circle(nref).translated((0.0, 1.0 + y0))
    mesh = mesh.with_boundaries({"rim": lambda x: np.ones(x.shape[1], bool),
                                 "top": lambda x: x[1] > 1.9 + y0})
    return Solid(mesh, NeoHooke(E=10.0, nu=0.3), element="tri1", name=name)


def _axis(disk):
    """Dirichlet on the x-dofs of the disk's nodes on its symmetry axis x = 0."""
    nodes = np.flatnonzero(np.isclose(disk.X[0], 0.0))
    return Dirichlet(disk, disk.dofs_at_nodes(nodes, component=0), name="axis")


def _on(disk, master, method="nts", support=True, **kw):
    pair = ContactPair(ContactSurface.from_solid(disk, "rim"), master, method=method, **kw)
    items = [disk, pair, Traction(disk, "top", (0.0, -0.5))]
    if master.body is not None:
        items.append(master.body)
    return Model(items + ([_axis(disk)] if support else []))


def _block(name="block", top=0.0, x=(-2.0, 2.0), n=16):
    mesh = skfem.MeshTri.init_tensor(np.linspace(*x, n + 1), np.linspace(top - 1.0, top, 5))
    mesh = mesh.with_boundaries({"top": lambda p: np.isclose(p[1], top),
                                 "bottom": lambda p: np.isclose(p[1], top - 1.0)})
    return Solid(mesh, NeoHooke(E=10.0, nu=0.3), element="tri1", name=name)


def _disk_on_block(method, support, **kw):
    """/work/scratch/disk_block.py's model: the disk (3 refinements) pressed on a clamped block."""
    disk, block = _disk(nref=3), _block()
    pair = ContactPair(ContactSurface.from_solid(disk, "rim"),
                       ContactSurface.from_solid(block, "top"), method=method, **kw)
    items = [disk, block, pair, Traction(disk, "top", (0.0, -0.5)),
             Dirichlet(block, block.dofs_on("bottom"), name="clamp")]
    return Model(items + ([_axis(disk)] if support else []))


def _cable(side, plane_normal=(0.0, -1.0)):
    """cable_flat's set-up: a cable pinned at both ends, bulging up to 0.1, inflated
    towards the rigid plane y = 0.25 (its contact zone begins open)."""
    cable = Cable.between((-1.0, 0.0), (1.0, 0.0), 2.0, 40, bulge="left", EA=100.0,
                          law="linear", name="cable")
    pair = ContactPair(ContactSurface.from_cable(cable, side=side),
                       RigidPlane((0.0, 0.25), plane_normal, length=4.0), "nts")
    return Model([cable, FollowerPressure(cable, 20.0, side="left"),
                  Dirichlet(cable, cable.support_dofs(), name="supports"), pair])


# --------------------------------------------------------------------------- orientation
def test_rigid_plane_with_the_wrong_normal_is_refused():
    """A disk resting on y = 0 with the plane's normal pointing down (into the disk's
    side, away from it): refused, naming the pair and the flipped normal."""
    model = _on(_disk(), RigidPlane((0.0, 0.0), (0.0, -1.0)))
    with pytest.raises(ValueError, match=r"'contact'.*point the same way.*flip the plane's "
                                         r"normal, RigidPlane\(point, normal=\(0, 1\)\)"):
        _preflight(model)


def test_rigid_plane_with_the_right_normal_passes():
    _preflight(_on(_disk(), RigidPlane((0.0, 0.0), (0.0, 1.0))))


def test_rigid_circle_from_outside():
    """The disk resting on top of a rigid cylinder: its default normal (away from the
    centre) faces the disk; inside=True is refused and the message says to drop it."""
    _preflight(_on(_disk(), RigidCircle((0.0, -1.0), 1.0)))
    with pytest.raises(ValueError, match="drop inside=True"):
        _preflight(_on(_disk(), RigidCircle((0.0, -1.0), 1.0, inside=True)))


def test_rigid_circle_from_inside():
    """The disk in a circular hole of radius 2, touching its bottom: inside=True faces
    the disk; the default (normal away from the centre) is refused, naming inside=True."""
    _preflight(_on(_disk(), RigidCircle((0.0, 2.0), 2.0, inside=True)))
    with pytest.raises(ValueError, match=r"RigidCircle\(\.\.\., inside=True\)"):
        _preflight(_on(_disk(), RigidCircle((0.0, 2.0), 2.0)))


def test_cable_on_the_wrong_side_is_refused():
    """The cable's right side (its normal down) against a plane above it: refused,
    the fix names side='left'.  The plane's normal points at the cable (the
    slave lies on its side), so the cable is the one to turn."""
    with pytest.raises(ValueError, match=r"to turn the slave 'cable_right'.*side='left'\) "
                                         r"instead of side='right'"):
        _preflight(_cable("right"))
    _preflight(_cable("left"))  # the right way round; pinned at both ends: held


def test_rigid_plane_wrong_under_a_cable_is_refused():
    """The cable's left side against a plane whose normal points up (away from the
    cable below it): the plane is the one to turn."""
    with pytest.raises(ValueError, match=r"to turn the master 'plane'.*normal=\(0, -1\)"):
        _preflight(_cable("left", plane_normal=(0.0, 1.0)))


def _reversed(surface, name):
    """The same surface built by hand with every segment reversed (traced clockwise)."""
    return ContactSurface(surface.body, surface.nodes, surface.segments[:, ::-1], name=name)


@pytest.mark.parametrize("which", ["slave", "master"])
def test_solid_boundary_traced_the_other_way_is_refused(which):
    """A hand-made surface of a solid traced clockwise (normals into the body), as
    slave or as master: refused, naming the surface, the body and the fix."""
    disk, block = _disk(), _block()
    slave = ContactSurface.from_solid(disk, "rim")
    master = ContactSurface.from_solid(block, "top")
    if which == "slave":
        slave = _reversed(slave, "rim_by_hand")
    else:
        master = _reversed(master, "top_by_hand")
    pair = ContactPair(slave, master, "nts")
    model = Model([disk, block, pair, _axis(disk),
                   Dirichlet(block, block.dofs_on("bottom"), name="clamp")])
    body = "disk" if which == "slave" else "block"
    with pytest.raises(ValueError, match=rf"'{'rim' if which == 'slave' else 'top'}_by_hand' "
                                         rf"of body '{body}'.*point into the body.*reverse its "
                                         rf"segments"):
        _preflight(model)


def test_solid_faces_turned_away_are_refused():
    """Both surfaces outward but the wrong face of the slave (the block's top against
    the lower block's top): refused, the slave named as the face turned away."""
    lower, upper = _block("lower"), _block("upper", top=1.0, x=(-1.0, 1.0), n=8)
    pair = ContactPair(ContactSurface.from_solid(upper, "top"),
                       ContactSurface.from_solid(lower, "top"), "nts")
    model = Model([lower, upper, pair, Dirichlet(lower, lower.dofs_on("bottom")),
                   Dirichlet(upper, upper.dofs_on("bottom"))])
    with pytest.raises(ValueError, match=r"the slave 'upper_top' is the face turned away"):
        _preflight(model)


@pytest.mark.parametrize("method", METHODS)
def test_initial_penetration_and_touching_blocks_pass(method):
    """An upper block overlapping the lower one by 0.01 (4 % of an element) and one
    exactly on it, pressed down, its corner held in x: legitimate, both pass."""
    for top in (1.0 - 0.01, 1.0):
        lower, upper = _block("lower", top=0.0, x=(0.0, 1.0), n=4), \
            _block("upper", top=top, x=(0.0, 1.0), n=5)
        corner = int(np.argmin(np.hypot(upper.X[0], upper.X[1] - top)))
        pair = ContactPair(ContactSurface.from_solid(upper, "bottom"),
                           ContactSurface.from_solid(lower, "top"), method)
        _preflight(Model([lower, upper, pair, Traction(upper, "top", (0.0, -1.0)),
                          Dirichlet(upper, upper.dofs_at_nodes([corner], "x")),
                          Dirichlet(lower, lower.dofs_on("bottom"))]))


# --------------------------------------------------------------------------- rigid modes
@pytest.mark.parametrize("method", ["nts", "mortar-dual"])
def test_disk_on_a_block_without_axis_support_is_refused(method):
    """Frictionless contact at the disk's lowest node holds only its vertical motion:
    the x-translation and the rotation are held by nothing (today's 'converged'
    drift); the message names both and the axis support."""
    with pytest.raises(ValueError, match=r"body 'disk': translation in x and rotation are "
                                         r"held by nothing.*touches at 1 node.*x-dofs of the "
                                         r"nodes on a symmetry axis \(e.g. x = 0\)"):
        _preflight(_disk_on_block(method, support=False))
    _preflight(_disk_on_block(method, support=True))


def test_contact_that_touches_nowhere_is_refused_with_the_fix():
    """A disk resting on the block touches it: every method passes (standard
    mortar too, whose weighted gap at the lowest node, 0.0064, is above the
    touch tolerance: the initial set also holds the nodes the master touches).
    Lifted 0.05 above the block and pushed by a load, nothing holds the disk's
    vertical motion until it lands: refused, naming the gap and the fix."""
    for method in ("nts", "mortar", "mortar-dual"):
        _preflight(_disk_on_block(method, support=True))
    disk, block = _disk(y0=0.05, nref=3), _block()
    pair = ContactPair(ContactSurface.from_solid(disk, "rim"),
                       ContactSurface.from_solid(block, "top"), method="mortar")
    model = Model([disk, block, pair, Traction(disk, "top", (0.0, -0.5)), _axis(disk),
                   Dirichlet(block, block.dofs_on("bottom"), name="clamp")])
    with pytest.raises(ValueError, match=r"translation in y is held by nothing.*touches at "
                                         r"no node.*close the gap"):
        _preflight(model)


class GroundSpring(Item):
    """Springs of stiffness ``k`` from the given global dofs to the ground (a user's item)."""

    def __init__(self, body, dofs, k):
        self.body, self.local, self.k, self.name = body, np.asarray(dofs), k, "spring"

    def assemble(self, z, load_factor, tangent=True):
        g = self.body.offset + self.local
        c = Contribution(g, self.k * np.asarray(z)[g])
        if tangent:
            c.k_rows, c.k_cols, c.k_vals = g, g, np.full(g.size, self.k)
        return c


def test_soft_springs_hold_the_modes_they_see():
    """Springs 1e-6 of E on the x-dofs of the disk's top node hold the x-translation
    and the rotation about the contact node, not the rotation about the top node
    (which the contact normal does not see either); a second spring at the lowest
    node holds that too."""
    disk, block = _disk(nref=3), _block()
    top = int(np.argmax(disk.X[1]))
    bottom = int(np.argmin(disk.X[1]))
    pair = ContactPair(ContactSurface.from_solid(disk, "rim"),
                       ContactSurface.from_solid(block, "top"), "nts")
    base = [disk, block, pair, Dirichlet(block, block.dofs_on("bottom"))]
    one = GroundSpring(disk, disk.dofs_at_nodes([top], component=0), 1e-5)
    with pytest.raises(ValueError, match=r"rotation about \(0, 2\) is held by nothing"):
        _preflight(Model(base + [one]))
    both = GroundSpring(disk, disk.dofs_at_nodes([top, bottom], component=0), 1e-5)
    _preflight(Model(base + [both]))


def test_bodies_free_together_are_named_together():
    """A block on a second block that nothing holds: the lower one is free, and the
    upper one moves with it (contact couples their vertical motions)."""
    lower, upper = _block("lower", x=(0.0, 1.0), n=4), _block("upper", top=1.0, x=(0.0, 1.0), n=4)
    corner = int(np.argmin(np.hypot(upper.X[0], upper.X[1] - 1.0)))
    pair = ContactPair(ContactSurface.from_solid(upper, "bottom"),
                       ContactSurface.from_solid(lower, "top"), "nts")
    model = Model([lower, upper, pair, Dirichlet(upper, upper.dofs_at_nodes([corner], "x"))])
    with pytest.raises(ValueError, match=r"body 'lower': translations in x and y and rotation "
                                         r"are held by nothing, moving together with 'upper'"):
        _preflight(model)


def test_cable_pinned_at_both_ends_passes():
    _preflight(_cable("left"))


# --------------------------------------------------------------------------- methods
def test_nts_with_a_coarse_slave_warns_before_the_solve():
    """patch 2 on 20 (slave 10x coarser, pressure error 2.5 when solved): a
    PreflightWarning naming the fix; mortar gets none."""
    setup, _, _ = build_scene("patch", {"n_top": 2, "n_bottom": 20}, "nts")
    with pytest.warns(PreflightWarning, match="coarser than the master.*make the finer "
                                              "surface the slave"):
        _preflight(setup.model)
    setup, _, _ = build_scene("patch", {"n_top": 2, "n_bottom": 20}, "mortar")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PreflightWarning)
        _preflight(setup.model)


@pytest.mark.parametrize("params, warns", [
    ({"n_top": 5, "n_bottom": 4}, True),                      # pressure error 0.062 solved
    ({"n_top": 10, "n_bottom": 7, "element": "quad2"}, True),  # 0.072
    ({"n_top": 5, "n_bottom": 5, "offset": 0.1}, True),       # 0.11
    ({"n_top": 6, "n_bottom": 6}, False),                     # 9e-16: matching
    ({"n_top": 20, "n_bottom": 2}, False),                    # 4e-14: the slave refines the master
    ({"n_top": 10, "n_bottom": 5, "element": "quad2"}, False),  # 1e-13
])
def test_nts_on_non_matching_meshes_warns_how_far_off_the_patch_test(params, warns):
    """A deformable pair whose master nodes do not all coincide with slave nodes
    where they meet: NTS is off the patch test (the pressure errors in the
    comments, measured with ``skfem-mortar run patch --method nts``); the warning
    says by how much and names method="mortar-dual"."""
    setup, _, _ = build_scene("patch", params, "nts")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _preflight(setup.model)
    texts = [str(w.message) for w in caught if issubclass(w.category, PreflightWarning)]
    patch = [t for t in texts if "fails the contact patch test" in t]
    assert bool(patch) == warns
    if warns:
        assert "6 % to 47 % off" in patch[0] and 'method="mortar-dual" (the default)' in patch[0]


# --------------------------------------------------------------------------- scenes
def _smallest(scene):
    """Every integer size parameter of the scene at its lower bound (meshes, elements)."""
    return {p.name: p.low for p in scene.params
            if p.kind is int and p.low is not None and p.name != "n_steps"}


@pytest.mark.parametrize("name", [s.name for s in list_scenes()])
def test_every_scene_passes_for_every_method(name):
    """Every scene at its defaults and at its smallest sizes, for every method it
    takes: no refusal (warnings allowed: hertz on an elastic base with NTS has a
    coarser slave where the surfaces meet)."""
    scene = get_scene(name)
    variants = [{}, _smallest(scene)]
    if name == "hertz":
        variants += [{"base": "elastic", "refine": -3}, {"element": "mini", "refine": -3}]
    if name == "ironing":
        variants.append({"slave": "die"})
    for params in variants:
        for method in scene.methods:
            setup, _, _ = build_scene(name, params, method)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", PreflightWarning)
                _preflight(setup.model)
