"""What an axisymmetric model refuses of a contact pair, naming the constraint:
rigid masters off the axis (a tilted line, a line parallel to the axis at r <= 0, a
circle whose centre is off the axis, a rigid polygon reaching r < 0), a method
without the measure hook (``set_measure``), a pair moved to another geometry after
its first step, and contact in a 3D model; and what it accepts (a plate, a cylinder
about the axis, a sphere centred on it), with the measure told to the method at bind.
The preflight in (r, z): the one rigid mode of a body of revolution (the axial
translation) held by nothing, and surfaces that do not face each other."""
import numpy as np
import pytest
import skfem

from skfem_mortar import (ContactPair, ContactSurface, Dirichlet, Model, NeoHooke, RigidCircle,
                          RigidPlane, Solid, Traction, solve)
from skfem_mortar.contact.discretization import register_method, unregister_method
from skfem_mortar.contact.measures import AXISYMMETRIC, PLANE

from test_discretization import NodeToLine


def _disk():
    """A unit square body at 1 <= r <= 2 (no node on the axis), bottom at z = 0."""
    mesh = skfem.MeshTri.init_tensor(np.linspace(1.0, 2.0, 3), np.linspace(0.0, 1.0, 3))
    return Solid(mesh.with_defaults(), NeoHooke(E=1.0, nu=0.3), name="a")


def _model(master, method="nts", geometry="axisymmetric"):
    body = _disk()
    pair = ContactPair(ContactSurface.from_solid(body, "bottom"), master, method=method, name="c")
    return pair, Model([body, pair], geometry=geometry)


@pytest.mark.parametrize("master, constraint", [
    (RigidPlane((1.5, -0.1), (0.6, 0.8)), "normal to the axis"),
    (RigidPlane((0.0, -0.1), (1.0, 0.0)), "parallel to it at r > 0"),
    (RigidPlane((-0.5, -0.1), (-1.0, 0.0)), "parallel to it at r > 0"),
    (RigidCircle((0.3, -1.0), 1.0), "centre on the axis"),
    (ContactSurface(None, None, [[0, 1]], X=[[-1.0, 3.0], [-0.1, -0.1]], name="poly"),
     "lies in r >= 0"),
])
def test_rigid_masters_off_the_axis_constraint_are_refused_naming_it(master, constraint):
    with pytest.raises(ValueError, match=f"master .*{constraint}"):
        _model(master)
    _model(master, geometry="plane")     # the same master is fine in a plane model


@pytest.mark.parametrize("master", [
    RigidPlane((0.0, -0.1), (0.0, 1.0)),              # a plate z = -0.1 (crosses r = 0)
    RigidPlane((2.5, 0.5), (-1.0, 0.0)),              # a cylinder r = 2.5 about the axis
    RigidCircle((0.0, -1.0), 0.9),                    # a sphere centred on the axis
    ContactSurface(None, None, [[0, 1]], X=[[0.0, 3.0], [-0.1, -0.2]], name="cone"),
])
def test_masters_of_revolution_are_accepted_and_the_measure_told(master):
    pair, model = _model(master)
    assert pair.geometry == "axisymmetric" and pair.measure is AXISYMMETRIC
    assert pair.discretization.measure is AXISYMMETRIC


def test_a_plane_pair_tells_its_method_the_plane_measure():
    pair, _ = _model(RigidPlane((0.0, -0.1), (0.0, 1.0)), geometry="plane")
    assert pair.measure is PLANE and pair.discretization.measure is PLANE


def test_a_method_without_set_measure_is_refused_in_an_axisymmetric_model():
    register_method("toy", NodeToLine)
    try:
        plate = RigidPlane((0.0, -0.1), (0.0, 1.0))
        with pytest.raises(ValueError, match="method 'toy' has no set_measure hook.*'axisymmetric'"):
            _model(plate, method="toy")
        _model(plate, method="toy", geometry="plane")   # plane: no measure needed
    finally:
        unregister_method("toy")


def test_a_pair_that_took_steps_cannot_move_to_another_geometry():
    pair, _ = _model(RigidPlane((0.0, 0.0), (0.0, 1.0)), geometry="plane")
    pair._started = True          # as after its first load step
    with pytest.raises(ValueError, match="cannot move to a 'axisymmetric' one"):
        Model([pair.slave.body, pair], geometry="axisymmetric")


def test_a_3d_body_against_a_2d_rigid_line_is_refused():
    """Faces of a 3D body and a rigid line of the plane make no pair (3D contact
    takes faces on both sides; its rigid masters are its own)."""
    mesh = skfem.MeshTet.init_tensor(*(np.linspace(0.0, 1.0, 2),) * 3).with_defaults()
    body = Solid(mesh, NeoHooke(E=1.0, nu=0.3), element="tet1", name="b")
    slave = ContactSurface.from_solid(body, "bottom")
    with pytest.raises(ValueError, match="must both be faces or both be curves"):
        ContactPair(slave, RigidPlane((0.0, -0.1), (0.0, 1.0)), method="nts")


def _stacked(gap, slave_side="bottom"):
    """A cylinder r <= 1 above another (gap ``gap``), the lower one held axially; the
    upper one's ``slave_side`` the slave."""
    def body(n, z0, name):
        m = skfem.MeshTri.init_tensor(np.linspace(0, 1, n + 1), np.linspace(z0, z0 + 1, 3))
        return Solid(m.with_defaults(), NeoHooke(E=1.0, nu=0.3), name=name)

    low, up = body(3, 0.0, "low"), body(4, 1.0 + gap, "up")
    pair = ContactPair(ContactSurface.from_solid(up, slave_side),
                       ContactSurface.from_solid(low, "top"), method="nts", name="c")
    return Model([low, up, pair, Dirichlet(low, low.dofs_on("bottom", "y"), 0.0),
                  Traction(up, "top", [0.0, -1e-3])], geometry="axisymmetric")


def test_preflight_names_the_axial_translation_held_by_nothing():
    """A body of revolution has one rigid mode, the translation along the axis (the
    axis nodes hold u_r); an open gap holds nothing."""
    with pytest.raises(ValueError, match="body 'up': translation along the axis .z. is held "
                                         "by nothing .*hold the z-dofs of a node"):
        solve(_stacked(0.1))


def test_preflight_refuses_surfaces_that_do_not_face_each_other():
    """The upper cylinder's top (normal +z) as the slave on the lower one's top (+z)."""
    with pytest.raises(ValueError, match="point the same way"):
        solve(_stacked(0.0, slave_side="top"))
