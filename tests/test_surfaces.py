"""Tests of contact surfaces: orientation, chaining, rigid surfaces, bad input."""
import numpy as np
import pytest
from skfem import MeshQuad, MeshTri

from skfem_mortar.bodies.materials import NeoHooke
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.contact.surfaces import ContactSurface, RigidCircle, RigidPlane, chain_segments


def _solid(mesh_cls=MeshTri):
    m = mesh_cls.init_tensor(np.linspace(0, 2, 6), np.linspace(0, 1, 4)).with_defaults()
    return Solid(m, NeoHooke(E=1.0, nu=0.3), element="tri1" if mesh_cls is MeshTri else "quad1")


@pytest.mark.parametrize("mesh_cls", [MeshTri, MeshQuad])
@pytest.mark.parametrize("tag,normal", [("top", (0, 1)), ("bottom", (0, -1)),
                                        ("left", (-1, 0)), ("right", (1, 0))])
def test_solid_surface_outward_and_chained(mesh_cls, tag, normal):
    s = _solid(mesh_cls)
    S = ContactSurface.from_solid(s, tag)
    z = np.zeros(s.n_dofs)
    n, l = S.normals(z)
    np.testing.assert_allclose(n, np.array(normal, float)[:, None] * np.ones(len(l)), atol=1e-15)
    seg = S.segments
    np.testing.assert_array_equal(seg[1:, 0], seg[:-1, 1])  # chain order
    assert not S.closed
    # dofs map to the body's unknowns: moving them moves x(z)
    z[S.dofs()[1]] = 0.25
    np.testing.assert_allclose(S.x(z)[1], S.X[1] + 0.25)


def test_closed_boundary_is_counter_clockwise():
    s = _solid()
    f = np.concatenate([s.mesh.boundaries[t] for t in ("top", "left", "bottom", "right")])
    S = ContactSurface.from_solid(s, f)
    assert S.closed
    x = S.X[:, S.segments[:, 0]]
    area = 0.5 * np.sum(x[0] * np.roll(x[1], -1) - np.roll(x[0], -1) * x[1])
    assert area == pytest.approx(2.0, rel=1e-14)  # positive: counter-clockwise


def test_rigid_surfaces():
    p = RigidPlane((0.0, 0.5), (0.0, -2.0), length=10.0)
    n, l = p.normals(None)
    np.testing.assert_allclose(n[:, 0], [0, -1], atol=1e-15)
    assert l[0] == pytest.approx(10.0) and p.dofs() is None
    c = RigidCircle((1.0, 2.0), 3.0, 64)
    n, l = c.normals(None)
    mid = 0.5 * (c.X[:, c.segments[:, 0]] + c.X[:, c.segments[:, 1]]) - np.array([[1.0], [2.0]])
    assert np.all(np.sum(n * mid, axis=0) > 0)  # pointing away from the centre
    assert c.closed


def test_not_a_chain():
    with pytest.raises(ValueError, match="simple chain"):
        chain_segments(np.array([[0, 1], [2, 1]]))  # inconsistent orientation
    with pytest.raises(ValueError, match="pieces"):
        chain_segments(np.array([[0, 1], [2, 3]]))
    with pytest.raises(ValueError, match="simple chain"):
        chain_segments(np.array([[0, 1], [1, 2], [1, 3]]))  # branch
    order, closed = chain_segments(np.array([[3, 4], [1, 2], [0, 1], [2, 3]]))
    np.testing.assert_array_equal(order, [2, 1, 3, 0])
    assert not closed


def test_bad_parameters():
    with pytest.raises(ValueError, match="radius"):
        RigidCircle((0, 0), -1.0)
    with pytest.raises(ValueError, match="normal"):
        RigidPlane((0, 0), (0, 0))
    with pytest.raises(ValueError, match="boundary"):
        ContactSurface.from_solid(_solid(), "nope")


def test_quadratic_elements_give_three_node_segments():
    # (their geometry: tests/test_quadratic_surfaces.py)
    m = MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 3)).with_defaults()
    s = Solid(m, NeoHooke(E=1.0, nu=0.3), element="tri2")
    surface = ContactSurface.from_solid(s, "top")
    assert surface.order == 2 and surface.segments.shape == (2, 3)
