"""Node numbers are not dofs (issue 32): ``Dirichlet(body, nodes=...)`` takes
node numbers, and ``Dirichlet(body, dofs)`` refuses the node numbers a user
takes from the mesh (``mesh.boundary_nodes()``, ``mesh.nodes_satisfying``)
instead of solving another model."""
import numpy as np
import pytest

import readme_scene
import skfem

from skfem_mortar import Dirichlet, LinearElastic, Model, Solid, solve


_cushion = readme_scene.cushion


def _top(mesh):
    return mesh.nodes_satisfying(lambda x: np.isclose(x[1], 1.4))


def _left(mesh):
    return mesh.nodes_satisfying(lambda x: np.isclose(x[0], -1.5))


@pytest.mark.parametrize("nodes", ["boundary_nodes", "top", "left"])
def test_node_numbers_given_as_dofs_are_refused(nodes):
    cushion = _cushion(ny=5)
    mesh = cushion.mesh
    given = {"boundary_nodes": mesh.boundary_nodes(), "top": _top(mesh),
             # the left edge's 5 nodes read as dofs lie on the left edge too:
             # refused as exactly the vertices of the named boundary "left"
             # (read as dofs: both components of vertices 0 and 1, x of vertex 2)
             "left": _left(mesh)}[nodes]
    with pytest.raises(ValueError, match="dofs of body 'cushion' look like node numbers.*"
                                         "Dirichlet\\(body, nodes=\\.\\.\\."):
        Dirichlet(cushion, given)


def test_node_numbers_that_are_also_whole_vertices_dofs_are_taken_as_dofs():
    """The limit of the check: an edge of 4 nodes numbered 0..3 is also both
    components of vertices 0 and 1 (a support), so it is taken as dofs."""
    cushion = _cushion(ny=4)
    assert np.array_equal(_left(cushion.mesh), [0, 1, 2, 3])
    assert np.array_equal(Dirichlet(cushion, _left(cushion.mesh)).local_dofs,
                          cushion.dofs_at_nodes([0, 1]))


@pytest.mark.parametrize("element", ["tri1", "tri2"])
def test_dofs_from_the_body_are_never_taken_for_node_numbers(element):
    """Every boundary's dofs, each component's, each single vertex's, and both
    components of any two vertices (numbers small enough to be vertex numbers,
    of interior vertices too) are accepted."""
    for nx, ny in [(3, 2), (4, 3), (13, 4)]:
        body = _cushion(element, nx, ny)
        for name in body.mesh.boundaries:
            for component in (None, "x", "y"):
                Dirichlet(body, body.dofs_on(name, component))
        for k in range(body.n_nodes):
            for component in (None, "x", "y"):
                Dirichlet(body, body.dofs_at_nodes([k], component))
            # point supports inside: both components of two vertices
            Dirichlet(body, body.dofs_at_nodes([k, (k + 1) % body.n_nodes]))
        Dirichlet(body, body.dofs_on(lambda x: np.ones(x.shape[1], dtype=bool)))


def test_nodes_give_the_dofs_of_the_nodes():
    cushion = _cushion()
    top = _top(cushion.mesh)
    assert np.array_equal(Dirichlet(cushion, nodes=top).local_dofs, cushion.dofs_on("top"))
    mask = np.isin(np.arange(cushion.n_nodes), top)
    assert np.array_equal(Dirichlet(cushion, nodes=mask).local_dofs, cushion.dofs_on("top"))
    assert np.array_equal(Dirichlet(cushion, nodes=top, component="y").local_dofs,
                          cushion.dofs_on("top", "y"))
    # values: every x value, then every y value (a (2, n) array reads so too)
    ux, uy = np.arange(top.size) * 0.01, -np.arange(top.size) * 0.02
    for value in (np.concatenate([ux, uy]), np.vstack([ux, uy])):
        d = Dirichlet(cushion, nodes=top, value=value, ramp=False)
        dofs, vals = d.prescribed(1.0)
        at = dict(zip(dofs.tolist(), vals.tolist()))
        nd = cushion.node_dofs
        assert [at[d] for d in nd[0, top]] == ux.tolist()
        assert [at[d] for d in nd[1, top]] == uy.tolist()
    path = Dirichlet(cushion, nodes=top, value=lambda t: t * np.vstack([ux, uy]))
    dofs, vals = path.prescribed(0.5)
    assert dict(zip(dofs.tolist(), vals.tolist()))[nd[1, top[3]]] == 0.5 * uy[3]


@pytest.mark.parametrize("kw, match", [
    ({}, "give either dofs .* or nodes=.*not neither"),
    ({"dofs": [0, 1], "nodes": [0]}, "not both"),
    ({"dofs": [0, 1], "component": "x"}, "component='x' goes with nodes="),
    ({"nodes": [0], "component": 2}, "component must be None \\(both\\), 0, 1, 'x' or 'y'"),
    ({"nodes": [0], "component": True}, "component must be None"),
    ({"nodes": [10**6]}, "nodes of body 'cushion' must lie in \\[0, 52\\)"),
    ({"nodes": [0.5]}, "nodes of body 'cushion' must be integers"),
    ({"nodes": np.ones(5, dtype=bool)}, "nodes of body 'cushion': a boolean mask must have "
                                        "shape \\(52,\\)"),
])
def test_dofs_or_nodes_not_both_nor_neither(kw, match):
    with pytest.raises(ValueError, match=match):
        Dirichlet(_cushion(), **kw)


def test_a_model_clamped_by_nodes_solves_as_the_one_clamped_by_dofs():
    """The README model: clamped by the top nodes or by the top dofs, the same
    model (bitwise: the same dofs, values and order)."""
    def peak(clamp):
        cushion, cable = _cushion(), readme_scene.cable()
        rest, pair = readme_scene.items(cable, cushion, "mortar", clamp)
        r = solve(Model([cable, cushion] + rest), 4)
        return pair.contact_data(r.z)["pressure"]
    by_dofs = peak(lambda b: Dirichlet(b, b.dofs_on("top"), name="clamp"))
    by_nodes = peak(lambda b: Dirichlet(b, nodes=_top(b.mesh), name="clamp"))
    assert np.array_equal(by_dofs, by_nodes) and by_dofs.max() > 0


def test_an_edge_support_with_an_interior_pin_is_not_taken_for_node_numbers():
    """y held on the left edge plus an x pin at an interior vertex (dofs the body
    gave): on a 4 x 3 quad mesh they are [1, 3, 5, 8], all of them also boundary
    vertex numbers, but as vertices they do not run along the boundary, so they
    are read as the dofs they are (the first version of the check refused them)."""
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0, 1, 4), np.linspace(0, 1, 3)).with_defaults()
    body = Solid(mesh, LinearElastic(E=1.0, nu=0.3), element="quad1", name="b")
    inner = np.setdiff1d(np.arange(mesh.p.shape[1]), mesh.boundary_nodes())
    dofs = np.concatenate([body.dofs_on("left", "y"), body.dofs_at_nodes(inner[:1], "x")])
    assert np.array_equal(Dirichlet(body, dofs).local_dofs, np.unique(dofs))
    # the mistake the check is for is still refused on the same mesh
    top = mesh.nodes_satisfying(lambda x: np.isclose(x[1], 1.0))
    with pytest.raises(ValueError, match="look like node numbers"):
        Dirichlet(body, top)


def test_node_values_in_the_node_major_layout_are_refused():
    """Per-node values as (nodes, components) would interleave x and y: refused,
    naming the shape wanted; (components, nodes) pairs each node's x and y."""
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0, 1, 4), np.linspace(0, 1, 3)).with_defaults()
    body = Solid(mesh, LinearElastic(E=1.0, nu=0.3), element="quad1", name="b")
    top = mesh.nodes_satisfying(lambda x: np.isclose(x[1], 1.0))
    ux = np.arange(1.0, top.size + 1)
    with pytest.raises(ValueError, match=r"value given per node must have shape \(2, 4\)"):
        Dirichlet(body, nodes=top, value=np.column_stack([ux, -ux]))
    d = Dirichlet(body, nodes=top, value=np.vstack([ux, -ux]))
    dofs, vals = d.prescribed(1.0)
    nd = body.node_dofs[:, top]
    lookup = dict(zip(dofs - body.offset, vals))
    assert [lookup[k] for k in nd[0]] == list(ux) and [lookup[k] for k in nd[1]] == list(-ux)


def test_a_boundary_tag_given_as_dofs_names_boundary_keyword():
    """A newcomer's ``Dirichlet(block, "bottom")`` (the tag where dofs go) is refused with
    the keyword that takes a tag, not a dtype complaint."""
    import skfem
    from skfem_mortar import Dirichlet, LinearElastic, Solid

    mesh = skfem.MeshQuad.init_tensor([0.0, 1.0], [0.0, 1.0])
    block = Solid(mesh, LinearElastic(E=1.0, nu=0.3), element="quad1", name="block")
    with pytest.raises(ValueError, match=r"boundary='bottom'"):
        Dirichlet(block, "bottom")
