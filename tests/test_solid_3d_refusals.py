"""What a 3D model refuses, each a ValueError naming the argument: unknown element
names and mesh/element mismatches (listing the allowed ones), serendipity
hexahedra (naming hex2), plane= and thickness=, an axisymmetric geometry with a
3D mesh, 2D and 3D bodies in one model, a cable in a 3D model, contact on a 3D
body; meshes with unreferenced nodes, flat or inverted elements (naming them)."""
import meshio
import numpy as np
import pytest
from skfem import MeshHex1, MeshQuad, MeshTet1, MeshTri

from skfem_mortar import Cable, Model
from skfem_mortar.bodies.hyperelastic import NeoHooke
from skfem_mortar.bodies.solid import Solid

LAW = NeoHooke(E=1.0, nu=0.3)
ALL = ("['hex1', 'hex1-md', 'hex2', 'p2p1', 'quad1', 'quad2', 'tet1', 'tet2', 'tri1', "
       "'tri2']")


def cube_tet():
    return MeshTet1.init_tensor(*(np.linspace(0.0, 1.0, 3),) * 3)


def test_an_unknown_element_name_lists_every_element():
    with pytest.raises(ValueError, match=r"element must be one of " + ALL.replace("[", r"\[")
                       .replace("]", r"\]") + r" \(got 'tet3'\)"):
        Solid(cube_tet(), LAW, "tet3")


@pytest.mark.parametrize("mesh, element, fits", [
    (MeshHex1(), "tet1", "['hex1', 'hex1-md', 'hex2']"),
    (MeshHex1(), "p2p1", "['hex1', 'hex1-md', 'hex2']"),
    (MeshTet1(), "hex1-md", "['p2p1', 'tet1', 'tet2']"),
    (MeshTet1(), "tri1", "['p2p1', 'tet1', 'tet2']"),
    (MeshTri(), "hex2", "['tri1', 'tri2']"),
    (MeshQuad(), "tet2", "['quad1', 'quad2']"),
])
def test_a_mesh_element_mismatch_lists_the_elements_of_the_mesh(mesh, element, fits):
    with pytest.raises(ValueError, match=rf"element '{element}' needs a .D mesh of .*got "
                       rf"{type(mesh).__name__}; element must be one of "
                       + fits.replace("[", r"\[").replace("]", r"\]")):
        Solid(mesh, LAW, element)


@pytest.mark.parametrize("element", ["hex20", "HexS2", "serendipity"])
def test_serendipity_names_are_refused_naming_hex2(element):
    with pytest.raises(ValueError, match=r"serendipity.*use element 'hex2' \(27-node"):
        Solid(MeshHex1(), LAW, element)


def test_a_meshio_mesh_of_20_node_hexahedra_is_refused_naming_hex2():
    """meshio reads gmsh's 20-node hexahedra as 'hexahedron20' (skfem has no mesh of
    them); handed on, the mesh is refused with the element to use."""
    cells = [("hexahedron20", np.arange(20)[None, :])]
    mesh = meshio.Mesh(np.random.default_rng(0).random((20, 3)), cells)
    with pytest.raises(ValueError, match=r"mesh holds hexahedron20 cells.*'hex2'"):
        Solid(mesh, LAW, "hex2")


def test_plane_is_refused_for_a_3d_mesh():
    with pytest.raises(ValueError, match=r"plane applies to a 2D body only.*plane='strain'"):
        Solid(cube_tet(), LAW, "tet1", plane="strain")
    assert Solid(cube_tet(), LAW, "tet1").plane is None


def test_thickness_is_refused_in_a_3d_model():
    with pytest.raises(ValueError, match=r"thickness applies to a plane model only; a '3d' "
                       r"model has none \(got thickness=2\)"):
        Model([Solid(cube_tet(), LAW, "tet1")], thickness=2.0)


@pytest.mark.parametrize("geometry", ["axisymmetric", "plane"])
def test_a_3d_body_in_a_2d_geometry_is_refused_naming_the_geometry(geometry):
    solid = Solid(cube_tet(), LAW, "tet1", name="block")
    assert solid.geometries == ("3d",)
    with pytest.raises(ValueError, match=rf"'block' \(Solid\) works in a '3d' geometry, and "
                       rf"this model's geometry is '{geometry}'"):
        Model([solid], geometry=geometry)
    assert Model([solid]).geometry == "3d"


def test_a_model_of_2d_and_3d_bodies_is_refused_naming_both():
    solid3 = Solid(cube_tet(), LAW, "tet1", name="block")
    solid2 = Solid(MeshTri(), LAW, "tri1", name="plate")
    with pytest.raises(ValueError, match=r"items mix 2D and 3D bodies: 'block' \(Solid\) 3D, "
                       r"'plate' \(Solid\) 2D"):
        Model([solid3, solid2])


def test_a_cable_in_a_3d_model_is_refused_naming_it():
    cable = Cable(np.array([[0.0, 1.0], [0.0, 0.0]]), name="rope")
    with pytest.raises(ValueError, match=r"items mix 2D and 3D bodies: 'block' \(Solid\) 3D, "
                       r"'rope' \(Cable\) 2D"):
        Model([Solid(cube_tet(), LAW, "tet1", name="block"), cable])
    with pytest.raises(ValueError, match=r"'rope' \(Cable\) works in a 'plane' geometry, and "
                       r"this model's geometry is '3d': it has no form in that geometry"):
        Model([cable], geometry="3d")


def test_a_3d_body_against_a_plane_rigid_line_is_refused():
    """A 3D body's faces against a 2D rigid line (RigidPlane): the pair refuses the
    mix of faces and curves and names the 3D rigid masters."""
    from skfem_mortar.contact.pair import ContactPair
    from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane

    mesh = cube_tet().with_boundaries({"top": lambda x: np.isclose(x[2], 1.0)})
    solid = Solid(mesh, LAW, "tet1", name="block")
    with pytest.raises(ValueError, match=r"must both be faces or both be curves; in 3D use "
                                         r"RigidPlane3D"):
        pair = ContactPair(ContactSurface.from_solid(solid, "top"),
                           RigidPlane((0.0, 2.0), (0.0, -1.0)))
        Model([solid, pair])


def test_unreferenced_nodes_are_refused_naming_them():
    mesh = cube_tet()
    p = np.hstack([mesh.p, [[5.0, 6.0], [5.0, 6.0], [5.0, 6.0]]])
    n = mesh.p.shape[1]
    with pytest.raises(ValueError, match=rf"2 node\(s\) belong to no element \(nodes "
                       rf"\[{n}, {n + 1}\]\)"):
        Solid(MeshTet1(p, mesh.t), LAW, "tet1")


def test_a_flat_tetrahedron_is_refused_naming_it():
    p = np.array([[0.0, 1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0, 1.0],
                  [0.0, 0.0, 0.0, 1.0, 0.0]])
    t = np.array([[0, 1, 2, 3], [0, 1, 2, 4]]).T
    with pytest.raises(ValueError, match=r"1 element\(s\) of zero volume \(elements \[1\]\)"):
        Solid(MeshTet1(p, t), LAW, "tet1")


def test_a_folded_tetrahedral_mesh_is_refused_naming_the_elements():
    """The centre node of a 2 x 2 x 2 cube pushed through the face x = 1: skfem's
    tetrahedra come in both orientations, so only the fold tells."""
    mesh = cube_tet()
    p = mesh.p.copy()
    centre = int(np.flatnonzero(np.all(np.isclose(p, 0.5), axis=0))[0])
    p[0, centre] = 1.3
    with pytest.raises(ValueError, match=r"inverted element\(s\): elements \d+ and \d+ lie "
                       r"on the same side of their shared facet \d+"):
        Solid(MeshTet1(p, mesh.t), LAW, "tet1")


def test_a_hexahedron_turned_inside_out_is_refused_naming_it():
    """Two corners of element 3 swapped: det J changes sign inside it."""
    mesh = MeshHex1.init_tensor(*(np.linspace(0.0, 1.0, 3),) * 3)
    t = mesh.t.copy()
    t[[0, 1], 3] = t[[1, 0], 3]
    with pytest.raises(ValueError, match=r"inverted element\(s\) \(elements \[3\]\): det J "
                       r"changes sign"):
        Solid(MeshHex1(mesh.p, t), LAW, "hex1")


def test_non_finite_nodes_are_refused_naming_them():
    mesh = cube_tet()
    p = mesh.p.copy()
    p[1, 4] = np.nan
    with pytest.raises(ValueError, match=r"node coordinates must be finite \(nodes \[4\]\)"):
        Solid(MeshTet1(p, mesh.t), LAW, "tet1")
