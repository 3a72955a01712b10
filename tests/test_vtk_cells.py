"""Quadratic 3D elements written as VTK quadratic cells in VTK's node order
(output.vtk_cells), and a nodal field equal to x read back at every node."""
import numpy as np
import pytest
from skfem import (Basis, ElementHex1, ElementHex2, ElementQuad2, ElementTetP1, ElementTetP2,
                   ElementTriP2, ElementVector, MeshHex1, MeshHex2, MeshQuad1, MeshTet1,
                   MeshTet2, MeshTri1)

from skfem_mortar.output.io import SeriesWriter, read_series, vtu_text
from skfem_mortar.output.vtk_cells import VTK_ORDER, basis_cells, nodal_vectors

vtk = pytest.importorskip("vtk")

#: VTK's reference cells, whose parametric coordinates define its node order
VTK_CELL = {"tetra": "vtkTetra", "tetra10": "vtkQuadraticTetra", "hexahedron": "vtkHexahedron",
            "hexahedron27": "vtkTriQuadraticHexahedron", "triangle6": "vtkQuadraticTriangle",
            "quad9": "vtkBiQuadraticQuad"}

#: a shear and stretch with a positive determinant: the cells are affine images of
#: VTK's reference cell with a Jacobian that is not diagonal
A = np.array([[1.0, 0.3, -0.2], [0.1, 1.5, 0.25], [-0.15, 0.2, 0.8]])


def _grid(cls, n=3, sheared=True):
    """A tensor grid of the unit cube, mapped by ``A`` (a 2D mesh unmapped)."""
    g = np.linspace(0.0, 1.0, n)
    mesh = cls.init_tensor(g, g, g)
    return cls(A @ mesh.p, mesh.t) if sheared else mesh


CASES = [
    (lambda: _grid(MeshTet1), ElementTetP1, "tetra"),
    (lambda: _grid(MeshTet1), ElementTetP2, "tetra10"),
    (lambda: MeshTet2.from_mesh(_grid(MeshTet1)), ElementTetP2, "tetra10"),
    (lambda: _grid(MeshHex1), ElementHex1, "hexahedron"),
    (lambda: _grid(MeshHex1), ElementHex2, "hexahedron27"),
    (lambda: MeshHex2.from_mesh(_grid(MeshHex1)), ElementHex2, "hexahedron27"),
    (lambda: MeshTri1.init_symmetric(), ElementTriP2, "triangle6"),
    (lambda: MeshQuad1().refined(1), ElementQuad2, "quad9"),
]


def _reference(cell):
    c = getattr(vtk, VTK_CELL[cell])()
    n = c.GetNumberOfPoints()
    pc = c.GetParametricCoords()
    return np.array([pc[i] for i in range(3 * n)]).reshape(n, 3)


@pytest.mark.parametrize("make, elem, cell", CASES)
def test_every_cell_is_vtks_reference_cell_mapped_affinely_with_positive_jacobian(make, elem,
                                                                               cell):
    mesh = make()
    basis = Basis(mesh, ElementVector(elem()))
    points, cells = basis_cells(basis)
    assert [c for c, _ in cells] == [cell]
    conn = cells[0][1]
    xi = _reference(cell)
    d = mesh.p.shape[0]
    xi = xi[:, :d]
    # fit x = x0 + J xi per cell by least squares: exact (round-off) and det J > 0
    M = np.column_stack([np.ones(len(xi)), xi])                    # (n_loc, 1 + d)
    X = points[conn][:, :, :d]                                      # (n_el, n_loc, d)
    coef = np.linalg.lstsq(M, X.transpose(1, 0, 2).reshape(len(xi), -1), rcond=None)[0]
    coef = coef.reshape(1 + d, len(conn), d).transpose(1, 0, 2)     # (n_el, 1 + d, d)
    fit = np.einsum("la,ead->eld", M, coef)
    # round-off of coordinates of size 1: 1e-12 is a thousand ulps; a node
    # in another's place is off by a quarter of a cell (0.1 here) or more
    assert np.max(np.abs(fit - X)) < 1e-12
    assert np.all(np.linalg.det(coef[:, 1:, :]) > 0)
    assert len(VTK_ORDER[cell]) == conn.shape[1]


@pytest.mark.parametrize("mesh, element, cell", [
    (MeshTet2.from_mesh(_grid(MeshTet1, sheared=False)), "tet2", "tetra10"),
    (MeshHex2.from_mesh(_grid(MeshHex1, sheared=False)), "hex2", "hexahedron27"),
], ids=["tet2", "hex2"])
def test_a_body_whose_field_is_x_reads_back_equal_to_the_points_at_every_node(tmp_path, mesh,
                                                                             element, cell):
    """Solid.output_mesh/output_data (cells in scikit-fem's order) through the series
    writer: VTK quadratic cells whose nodes carry the field u = x, read back by
    meshio and by pyvista (VTK) at every node, and each cell VTK's reference cell."""
    pytest.importorskip("meshio")
    from skfem_mortar.bodies.material import LinearElastic
    from skfem_mortar.bodies.solid import Solid

    # curve the mesh: the mid-edge and mid-face nodes move off the straight lines
    p = mesh.doflocs.copy()
    p[2] += 0.1 * np.sin(np.pi * p[0]) * np.sin(np.pi * p[1])
    body = Solid(type(mesh)(p, mesh.t), LinearElastic(E=1.0, nu=0.3), element=element)
    z = body.interpolate(lambda X: X)
    points, cells = body.output_mesh()
    point_data, cell_data = body.output_data(z)
    np.testing.assert_array_equal(point_data["displacement"], points)   # node by node
    writer = SeriesWriter(tmp_path, "body", (points, cells))
    assert vtu_text(writer.points, writer.cells, point_data, cell_data) is not None  # ours
    writer.write(1.0, point_data, cell_data)
    (t, frame), = read_series(tmp_path / "body.pvd")
    assert t == 1.0 and list(frame.cells_dict) == [cell]
    # written in binary float64: read back bit for bit, at every node
    np.testing.assert_array_equal(frame.points, points)
    np.testing.assert_array_equal(frame.point_data["displacement"], frame.points)
    # the cells are scikit-fem's elements in VTK's order: the same node sets, and
    # on these affine (before the curving) cells VTK's nodes where VTK puts them
    conn = frame.cells_dict[cell]
    np.testing.assert_array_equal(np.sort(conn, axis=1), np.sort(cells[0][1], axis=1))
    flat = points.copy()
    flat[:, 2] = mesh.doflocs[2]
    xi = _reference(cell)
    M = np.column_stack([np.ones(len(xi)), xi])
    X = flat[conn]
    coef = np.linalg.lstsq(M, X.transpose(1, 0, 2).reshape(len(xi), -1), rcond=None)[0]
    fit = np.einsum("la,ead->eld", M, coef.reshape(4, len(conn), 3).transpose(1, 0, 2))
    assert np.max(np.abs(fit - X)) < 1e-12
    pv = pytest.importorskip("pyvista")
    grid = pv.read(writer.directory / writer.frames[0][1])
    want = {"tetra10": pv.CellType.QUADRATIC_TETRA,
            "hexahedron27": pv.CellType.TRIQUADRATIC_HEXAHEDRON}[cell]
    assert set(np.asarray(grid.celltypes)) == {want}
    np.testing.assert_array_equal(grid.point_data["displacement"], grid.points)
    assert np.all(grid.compute_cell_sizes(length=False, area=False)["Volume"] > 0)
