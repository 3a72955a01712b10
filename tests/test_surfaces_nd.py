"""Contact surfaces of any dimension: the cell type carried explicitly, boundaries of 3D
meshes oriented outward from their elements (contact/boundary_cells.py), surfaces of
tri3 and quad4 cells.

The outward test is the divergence theorem: for a closed boundary, ``sum_f c_f . v_f / 3``
(``v_f`` a facet's area vector, ``c_f`` its centroid; exact for flat facets) is the
volume, positive only if every facet points out; a facet turned over changes it by
twice its term, far above round-off (1e-14 of the volume).
"""
from types import SimpleNamespace

import numpy as np
import pytest
from skfem import MeshHex, MeshQuad, MeshTet, MeshTri

from skfem_mortar.contact.boundary_cells import boundary_cells, closed_surface
from skfem_mortar.contact.cell_map import area_vectors, cell_tangents, reversal
from skfem_mortar.contact.cells import CELLS
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane

RNG = np.random.default_rng(35)


def _volume(x, conn, cell):
    """``sum_f c_f . v_f / 3`` at the facets' centres (flat facets: their area vectors)."""
    centre = np.asarray(cell.ref_nodes)[:, list(cell.corners)].mean(axis=1, keepdims=True)
    v = area_vectors(cell_tangents(x, conn, cell, centre))[..., 0]
    w = 4.0 if cell.name == "quad4" else 0.5            # reference areas
    return float(np.sum(x[:, conn].mean(axis=2) * v) * w / 3.0)


@pytest.mark.parametrize("mesh_cls,cell", [(MeshTet, "tri3"), (MeshHex, "quad4")])
def test_3d_boundary_cells_point_out(mesh_cls, cell):
    m = mesh_cls.init_tensor(np.linspace(0, 2, 4), np.linspace(0, 1, 3),
                             np.linspace(0, 1.5, 4))
    facets = m.boundary_facets()
    conn, c = boundary_cells(m, facets)
    assert c is CELLS[cell] and conn.shape == (facets.size, c.n_nodes)
    assert closed_surface(conn, c, m.p.shape[1])
    assert _volume(m.p, conn, c) == pytest.approx(3.0, rel=1e-14)
    # every facet's normal points away from its element's centroid
    centre = np.asarray(c.ref_nodes)[:, list(c.corners)].mean(axis=1, keepdims=True)
    v = area_vectors(cell_tangents(m.p, conn, c, centre))[..., 0]
    elem = m.f2t[0, facets]
    away = m.p[:, conn].mean(axis=2) - m.p[:, m.t[:, elem]].mean(axis=1)
    assert np.all(np.sum(v * away, axis=0) > 0)
    # one facet turned over: no longer consistently oriented
    bad = conn.copy()
    bad[0] = bad[0][list(reversal(c))]
    with pytest.raises(ValueError, match="consistently oriented"):
        closed_surface(bad, c, m.p.shape[1])


def test_2d_boundary_cells_as_before():
    """In 2D the outward rows are what the chain was built from before: (start, end)
    with the right-hand normal pointing out, for triangles and quadrilaterals."""
    for mesh_cls in (MeshTri, MeshQuad):
        m = mesh_cls.init_tensor(np.linspace(0, 2, 5), np.linspace(0, 1, 3))
        conn, c = boundary_cells(m, m.boundary_facets())
        assert c is CELLS["line2"]
        t = m.p[:, conn[:, 1]] - m.p[:, conn[:, 0]]
        mid = m.p[:, conn].mean(axis=2) - np.array([[1.0], [0.5]])
        assert np.all(t[1] * mid[0] - t[0] * mid[1] > 0)      # (t_y, -t_x) . mid > 0


@pytest.mark.parametrize("element,mesh_cls,cell", [("tet1", MeshTet, "tri3"),
                                                  ("hex1", MeshHex, "quad4")])
def test_surface_of_a_3d_solid(element, mesh_cls, cell):
    """``from_solid`` of a (duck-typed) 3D solid: tri3 / quad4 cells, outward, the
    body's dofs; a surface of surface cells is not chained."""
    m = mesh_cls.init_tensor(np.linspace(0, 2, 4), np.linspace(0, 1, 3),
                             np.linspace(0, 1.5, 3)).with_defaults()
    n = m.p.shape[1]
    solid = SimpleNamespace(mesh=m, X=m.p, node_dofs=np.arange(3 * n).reshape(n, 3).T,
                            element=element, name="block", n_nodes=n, n_dofs=3 * n, offset=0,
                            x=lambda z: m.p + z[np.arange(3 * n).reshape(n, 3).T])
    S = ContactSurface.from_solid(solid, "back")   # z = 1.5 (skfem: top is y = 1)
    assert S.cell is CELLS[cell] and S.dim == 3 and S.order == 1 and not S.closed
    nrm, area = S.normals(np.zeros(3 * n))
    np.testing.assert_allclose(nrm, np.array([[0.0], [0.0], [1.0]]) * np.ones(area.size),
                               atol=1e-15)
    assert area.sum() == pytest.approx(2.0, rel=1e-14)
    assert np.all(S.X[2] == 1.5) and S.dofs().shape == (3, S.n_nodes)
    R = S.reversed()
    assert np.allclose(R.normals(np.zeros(3 * n))[0][2], -1.0)
    blocks = S.output_cells()
    assert blocks[0][0] == ("triangle" if cell == "tri3" else "quad")


def test_the_cell_is_explicit():
    """The default is read from the argument once (two columns: line2, three: line3);
    a given cell type is kept however many columns it has; in 3D it is required."""
    X = np.array([[0.0, 1.0, 2.0, 3.0], [0.0, 0.0, 0.0, 0.0]])
    assert ContactSurface(None, None, [[0, 1], [1, 2]], X=X).cell is CELLS["line2"]
    assert ContactSurface(None, None, [0, 1, 1, 2], X=X).cell is CELLS["line2"]
    s3 = ContactSurface(None, None, [[0, 2, 1]], X=X)
    assert s3.cell is CELLS["line3"] and s3.order == 2
    with pytest.raises(ValueError, match="connectivity of line2 cells"):
        ContactSurface(None, None, [[0, 2, 1]], X=X, cell="line2")
    with pytest.raises(ValueError, match="cell is required"):
        ContactSurface(None, None, [[0, 1, 2]], X=np.eye(3))
    with pytest.raises(ValueError, match="does not bound a body in 2 dimensions"):
        ContactSurface(None, None, [[0, 1, 2]], X=X, cell="tri3")
    with pytest.raises(ValueError, match="registered cell types"):
        ContactSurface(None, None, [[0, 1]], X=X, cell="line4")
    assert RigidPlane((0, 0), (0, 1)).cell is CELLS["line2"]


def test_rigid_3d_surface_and_zero_area():
    X = np.array([[0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0], [0.0, 0.0, 0.0, 0.0]])
    S = ContactSurface(None, None, [[0, 1, 2, 3]], X=X, cell="quad4")
    assert S.closed is False and S.normals(None)[1][0] == pytest.approx(1.0)
    with pytest.raises(ValueError, match="zero area"):
        ContactSurface(None, None, [[0, 1, 1]], X=X, cell="tri3")
