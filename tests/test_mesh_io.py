"""A gmsh .msh with quadratic volume cells and tagged quadratic boundary faces, read
into a scikit-fem mesh with its tags (output.mesh_io.read_mesh)."""
import numpy as np
import pytest
from skfem import MeshHex1, MeshHex2, MeshTet1, MeshTet2
from skfem.io.meshio import to_meshio

from skfem_mortar.output.mesh_io import read_mesh

meshio = pytest.importorskip("meshio")

TAGS = {"left": 1, "right": 2, "top": 3}


def _nearest(points, x):
    """Index of the point at each row of x (exact matches)."""
    d = np.linalg.norm(points[None, :, :] - x[:, None, :], axis=2)
    i = np.argmin(d, axis=1)
    assert np.all(d[np.arange(len(x)), i] < 1e-12)
    return i


def _face_cells(mesh, facets, quad):
    """The quadratic face cells (meshio's node order: corners, mid-edges, centre) of
    the given facets, by the positions of their nodes."""
    P = mesh.doflocs.T
    corners = mesh.facets[:, facets].T                                  # (n, k)
    k = corners.shape[1]
    if quad:    # skfem's hexahedron facets are cyclic: mid-edges 01 12 23 30, centre
        mids = [(corners[:, i], corners[:, (i + 1) % 4]) for i in range(4)]
    else:       # triangle6: 01 12 20
        mids = [(corners[:, 0], corners[:, 1]), (corners[:, 1], corners[:, 2]),
                (corners[:, 2], corners[:, 0])]
    cols = [corners] + [_nearest(P, 0.5 * (P[a] + P[b]))[:, None] for a, b in mids]
    if quad:
        cols.append(_nearest(P, P[corners].mean(axis=1))[:, None])
    assert k == (4 if quad else 3)
    return np.hstack(cols)


@pytest.mark.parametrize("kind", ["tet2", "hex2"])
def test_a_gmsh_file_with_quadratic_cells_and_tagged_faces_is_read_with_its_tags(tmp_path,
                                                                               kind):
    g = np.linspace(0.0, 1.0, 3)
    if kind == "tet2":
        mesh = MeshTet2.from_mesh(MeshTet1.init_tensor(g, g, g)).with_defaults()
        vol, face = "tetra10", "triangle6"
    else:
        mesh = MeshHex2.from_mesh(MeshHex1.init_tensor(g, g, g)).with_defaults()
        vol, face = "hexahedron27", "quad9"
    ref = to_meshio(mesh, encode_cell_data=False)
    # renumber the nodes at random and add a point no cell uses (gmsh writes its
    # geometry's points): the reader must not rely on skfem's numbering
    rng = np.random.default_rng(3)
    n = len(ref.points)
    perm = rng.permutation(n + 1)              # new number of each old node (+ 1 spare)
    points = np.empty((n + 1, 3))
    points[perm[:n]] = ref.points
    points[perm[n]] = [5.0, 5.0, 5.0]
    cells = [(vol, perm[ref.cells_dict[vol]])]
    phys, geom = [np.full(len(cells[0][1]), 10)], [np.full(len(cells[0][1]), 1)]
    for name, tag in TAGS.items():
        fc = perm[_face_cells(mesh, mesh.boundaries[name], kind == "hex2")]
        cells.append((face, fc))
        phys.append(np.full(len(fc), tag))
        geom.append(np.full(len(fc), tag))
    field = {name: np.array([tag, 2]) for name, tag in TAGS.items()}
    field["body"] = np.array([10, 3])
    path = tmp_path / f"{kind}.msh"
    meshio.write(path, meshio.Mesh(points, cells,
                                   cell_data={"gmsh:physical": phys, "gmsh:geometrical": geom},
                                   field_data=field), file_format="gmsh22", binary=False)

    got = read_mesh(path)
    assert type(got) is type(mesh)
    assert got.doflocs.shape == mesh.doflocs.shape           # the spare point dropped
    # the same geometry: every node where one was, every element's node set
    key = lambda P: np.lexsort(np.round(P, 12)[::-1])        # noqa: E731
    np.testing.assert_array_equal(got.doflocs[:, key(got.doflocs)], mesh.doflocs[:, key(mesh.doflocs)])
    vol_got = sorted(map(tuple, np.round(np.sort(got.doflocs[:, got.t].mean(axis=1).T, 0), 12)))
    assert len(vol_got) == mesh.nelements
    # each tag found by its corner nodes: the same faces (by corner coordinates)
    assert set(got.boundaries) == set(TAGS)
    for name in TAGS:
        def faces(m, f):
            return sorted(tuple(np.round(np.sort(m.p[:, m.facets[:, f]].T, axis=0).ravel(), 12))
                          for f in f)
        assert faces(got, got.boundaries[name]) == faces(mesh, mesh.boundaries[name])
        assert np.all(got.f2t[1, got.boundaries[name]] == -1)   # boundary facets
    assert list(got.subdomains) == ["body"] and got.subdomains["body"].size == mesh.nelements
    # a solid on it: the tag's dofs are those of the same face of the original
    from skfem_mortar.bodies.material import LinearElastic
    from skfem_mortar.bodies.solid import Solid
    body, body0 = (Solid(m, LinearElastic(E=1.0, nu=0.3), element=kind) for m in (got, mesh))
    at = lambda b, d: np.sort(np.round(b.basis.doflocs[:, d].T, 12), axis=0)  # noqa: E731
    np.testing.assert_array_equal(at(body, body.dofs_on("right", "z")),
                                  at(body0, body0.dofs_on("right", "z")))


def test_refusals_name_the_path(tmp_path):
    tri = meshio.Mesh(np.zeros((3, 3)), [("triangle", np.array([[0, 1, 2]]))])
    h20 = meshio.Mesh(np.zeros((20, 3)), [("hexahedron20", np.arange(20)[None])])
    with pytest.raises(ValueError, match="path: no volume cells"):
        read_mesh(meshio.Mesh(np.zeros((2, 3)), [("line", np.array([[0, 1]]))]))
    with pytest.raises(ValueError, match="serendipity.*hex2"):
        read_mesh(h20)
    assert read_mesh(tri).nelements == 1
    m = MeshTet1.init_tensor(*(np.linspace(0, 1, 2),) * 3)
    facets = set(map(tuple, np.sort(m.facets, axis=0).T))
    odd = next(c for c in ((i, j, k) for i in range(8) for j in range(i + 1, 8)
                           for k in range(j + 1, 8)) if c not in facets)
    stray = meshio.Mesh(m.p.T, [("tetra", m.t.T), ("triangle", np.array([odd]))],
                        cell_sets={"odd": [None, np.array([0])]})
    with pytest.raises(ValueError, match="path: boundary 'odd'.*no facet"):
        read_mesh(stray)
