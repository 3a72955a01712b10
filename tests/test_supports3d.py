"""Supports and dead loads of 3D bodies: Dirichlet by boundary tag, by dof mask,
by nodes and per component (x, y, z); dead tractions on 3D faces; point loads."""
import numpy as np
import pytest
import skfem

from skfem_mortar.bodies.material import LinearElastic
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.loads.traction import PointLoad, Traction


def _body(element="hex1"):
    g = np.linspace(0.0, 1.0, 3)
    if element.startswith("hex"):
        mesh = skfem.MeshHex1.init_tensor(g, g, 2 * g)
        mesh = skfem.MeshHex2.from_mesh(mesh) if element == "hex2" else mesh
    else:
        mesh = skfem.MeshTet1.init_tensor(g, g, 2 * g)
        mesh = skfem.MeshTet2.from_mesh(mesh) if element == "tet2" else mesh
    return Solid(mesh.with_defaults(), LinearElastic(E=1.0, nu=0.3), element=element,
                 name="body")


@pytest.mark.parametrize("element", ["tet1", "tet2", "hex1", "hex2"])
@pytest.mark.parametrize("component", [None, 0, 1, 2, "x", "y", "z"])
def test_dirichlet_by_boundary_tag_and_component(element, component):
    body = _body(element)
    d = Dirichlet(body, boundary="front", component=component, value=0.25)
    want = body.dofs_on("front", component)
    np.testing.assert_array_equal(d.local_dofs, np.unique(want))
    comp = body.dof_component[d.local_dofs]
    if component is None:
        assert set(comp) == {0, 1, 2}
    else:
        assert set(comp) == {{"x": 0, "y": 1, "z": 2}.get(component, component)}
    # every node of the face z = 0 (vertices, and edge and face nodes of quadratic
    # elements), none elsewhere
    assert np.all(body.basis.doflocs[2, d.local_dofs] == 0.0)
    on_face = np.flatnonzero(body.basis.doflocs[2] == 0.0)      # every component's
    assert d.local_dofs.size == (on_face.size if component is None else on_face.size // 3)
    dofs, vals = d.prescribed(0.5)
    assert np.all(vals == 0.125) and np.all(dofs == body.offset + d.local_dofs)


def test_dirichlet_by_dof_mask_and_by_nodes_in_3d():
    body = _body("hex1")
    mask = np.zeros(body.n_dofs, dtype=bool)
    mask[body.dofs_on("back", "z")] = True
    np.testing.assert_array_equal(Dirichlet(body, mask).local_dofs, np.flatnonzero(mask))
    nodes = np.flatnonzero(np.isclose(body.X[2], 2.0))
    # per node values as (components, nodes): the z row lands on the z dofs
    value = np.vstack([np.zeros(nodes.size), np.zeros(nodes.size), 0.1 + body.X[0, nodes]])
    d = Dirichlet(body, nodes=nodes, value=value)
    dofs, vals = d.prescribed(1.0)
    local = dofs - body.offset
    z = body.dof_component[local] == 2
    np.testing.assert_array_equal(np.sort(local[z]), np.sort(body.node_dofs[2, nodes]))
    want = np.zeros(body.n_dofs)
    want[body.node_dofs[2, nodes]] = 0.1 + body.X[0, nodes]
    np.testing.assert_array_equal(vals, want[local])
    assert np.all(vals[~z] == 0.0)
    dz = Dirichlet(body, nodes=nodes, component="z", value=0.3)
    np.testing.assert_array_equal(dz.local_dofs, np.sort(body.node_dofs[2, nodes]))


def test_dirichlet_refusals_in_3d_name_the_argument():
    body = _body("tet1")
    with pytest.raises(ValueError, match=r"component must be None \(all 3\), 0, 1, 2, 'x', "
                                         r"'y' or 'z', got 3"):
        Dirichlet(body, nodes=[0], component=3)
    with pytest.raises(ValueError, match="component must be"):
        Dirichlet(body, boundary="left", component="w")
    with pytest.raises(ValueError, match="not both"):
        Dirichlet(body, [0, 1, 2], boundary="left")
    with pytest.raises(ValueError, match="unknown boundary 'nowhere'"):
        Dirichlet(body, boundary="nowhere")
    with pytest.raises(ValueError, match="goes with nodes= or boundary="):
        Dirichlet(body, [0, 1, 2], component="z")
    # the vertex numbers of a face passed as dofs: refused, they look like node numbers
    # (where they can be told apart: those of "front", 0 .. 8, are also every dof of
    # vertices 0, 1, 2, a support too)
    face = np.unique(body.mesh.facets[:, body.mesh.boundaries["bottom"]])
    with pytest.raises(ValueError, match="look like node numbers"):
        Dirichlet(body, face)
    with pytest.raises(ValueError, match="value given per node must have shape"):
        Dirichlet(body, nodes=face, value=np.zeros((face.size, 3)))
    flat = Solid(skfem.MeshTri1().with_defaults(), LinearElastic(E=1.0, nu=0.3))
    with pytest.raises(ValueError, match=r"component must be None \(both\), 0, 1, 'x' or "
                                         r"'y', got 'z'"):
        Dirichlet(flat, nodes=[0], component="z")


@pytest.mark.parametrize("element", ["tet1", "tet2", "hex1", "hex2"])
def test_a_dead_traction_on_a_3d_face_carries_t_times_its_area(element):
    body = _body(element)
    t = np.array([0.5, -1.0, 2.0])
    f = Traction(body, "top", t).force           # the face y = 1: area 1 x 2
    comp = body.dof_component
    # exact integration of constant tractions: the resultant to round-off
    np.testing.assert_allclose([f[comp == c].sum() for c in range(3)], 2.0 * t, atol=1e-13)
    # off the face: the round-off of shape functions that vanish on it (1e-17 seen)
    off = ~np.isin(np.arange(body.n_dofs), body.dofs_on("top"))
    assert np.max(np.abs(f[off])) < 1e-15 * np.abs(t).max()
    # a traction varying over the face, T = (0, 0, z): int z dA = 2 over [0, 1] x [0, 2]
    g = Traction(body, "top", lambda x: np.array([0 * x[0], 0 * x[0], x[2]])).force
    np.testing.assert_allclose(g[comp == 2].sum(), 2.0, atol=1e-13)
    with pytest.raises(ValueError, match="traction must be a 3-vector"):
        Traction(body, "top", [1.0, 2.0])
    with pytest.raises(ValueError, match=r"traction\(x\) must return"):
        Traction(body, "top", lambda x: np.zeros(3))


def test_a_point_load_on_a_3d_node():
    body = _body("hex1")
    corner = int(np.flatnonzero(np.all(body.X == [[1.0], [1.0], [2.0]], axis=0))[0])
    load = PointLoad(body, body.dofs_at_nodes([corner]), [0.0, 0.0, -3.0])
    c = load.assemble(np.zeros(body.n_dofs), 0.5)
    np.testing.assert_array_equal(c.r_index, body.node_dofs[:, corner])
    np.testing.assert_array_equal(c.r_value, [0.0, 0.0, 1.5])
