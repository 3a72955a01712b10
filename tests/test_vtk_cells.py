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


def _x_field_case(mesh, elem):
    basis = Basis(mesh, ElementVector(elem()))
    comp = np.zeros(basis.N, dtype=np.int64)
    for c, idx in enumerate(basis.split_indices()):
        comp[idx] = c
    u = basis.doflocs[comp, np.arange(basis.N)]     # the field u = x, dof by dof
    return basis, u


@pytest.mark.parametrize("mesh, elem, cell", [
    (MeshTet2.from_mesh(_grid(MeshTet1, sheared=False)), ElementTetP2, "tetra10"),
    (MeshHex2.from_mesh(_grid(MeshHex1, sheared=False)), ElementHex2, "hexahedron27"),
], ids=["tet2", "hex2"])
def test_a_field_equal_to_x_reads_back_equal_to_the_points_at_every_node(tmp_path, mesh, elem,
                                                                        cell):
    pytest.importorskip("meshio")
    # curve the mesh: the mid-edge and mid-face nodes move off the straight lines
    p = mesh.doflocs.copy()
    p[2] += 0.1 * np.sin(np.pi * p[0]) * np.sin(np.pi * p[1])
    mesh = type(mesh)(p, mesh.t)
    basis, u = _x_field_case(mesh, elem)
    points, cells = basis_cells(basis)
    field = nodal_vectors(basis, u)
    assert vtu_text(points, cells, {"displacement": field}, {}) is not None   # our writer
    writer = SeriesWriter(tmp_path, "body", (points, cells))
    writer.write(1.0, {"displacement": field}, {})
    (t, frame), = read_series(tmp_path / "body.pvd")
    assert t == 1.0
    assert list(frame.cells_dict) == [cell]
    np.testing.assert_array_equal(frame.cells_dict[cell], cells[0][1])
    # written in binary float64: read back bit for bit
    np.testing.assert_array_equal(frame.point_data["displacement"], frame.points)
    np.testing.assert_array_equal(frame.points, points)
    # and pyvista (VTK) reads quadratic cells: ParaView draws them curved
    pv = pytest.importorskip("pyvista")
    grid = pv.read(writer.directory / writer.frames[0][1])
    want = {"tetra10": pv.CellType.QUADRATIC_TETRA,
            "hexahedron27": pv.CellType.TRIQUADRATIC_HEXAHEDRON}[cell]
    assert set(np.asarray(grid.celltypes)) == {want}
    np.testing.assert_array_equal(grid.points, points)
