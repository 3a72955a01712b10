"""The one copy of each small helper: chain geometry, boundary facets, element COO indices."""
import numpy as np
import pytest
from skfem import MeshTri

from skfem_mortar.core.coo import element_coo
from skfem_mortar.core.item import Contribution
from skfem_mortar.bodies.solid import boundary_facets
from skfem_mortar.contact.surfaces import segment_lengths, segment_normals, segments_at_nodes


def test_segment_lengths_are_those_of_segment_normals():
    x = np.array([[0.0, 3.0, 3.0], [0.0, 0.0, 4.0]])
    seg = np.array([[0, 1], [1, 2], [2, 0]])
    np.testing.assert_array_equal(segment_lengths(x, seg), [3.0, 4.0, 5.0])
    np.testing.assert_array_equal(segment_lengths(x, seg), segment_normals(x, seg)[1])


def test_segments_at_nodes_open_chain():
    seg = np.array([[0, 1], [1, 2], [2, 3]])
    ending, starting = segments_at_nodes(seg, 4)
    np.testing.assert_array_equal(ending, [-1, 0, 1, 2])
    np.testing.assert_array_equal(starting, [0, 1, 2, -1])
    # previous and next segment of each segment
    np.testing.assert_array_equal(ending[seg[:, 0]], [-1, 0, 1])
    np.testing.assert_array_equal(starting[seg[:, 1]], [1, 2, -1])


def test_element_coo_matches_both_layouts():
    d = np.array([[0, 1, 2], [2, 3, 4]])                    # (n_el, n_loc)
    rows, cols = element_coo(d)
    c = Contribution.from_dofs(d, np.zeros(d.shape), np.zeros((2, 3, 3)))
    np.testing.assert_array_equal(rows, c.k_rows)
    np.testing.assert_array_equal(cols, c.k_cols)
    rl, cl = element_coo(d.T, elements_last=True)            # (n_loc, n_loc, n_el) order
    np.testing.assert_array_equal(rl.reshape(3, 3, 2).transpose(2, 0, 1).ravel(), rows)
    np.testing.assert_array_equal(cl.reshape(3, 3, 2).transpose(2, 0, 1).ravel(), cols)


def test_boundary_facets_tag_indices_and_message():
    m = MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 3)).with_defaults()
    np.testing.assert_array_equal(boundary_facets(m, "left"), m.boundaries["left"])
    np.testing.assert_array_equal(boundary_facets(m, [[3], [1]]), [3, 1])
    with pytest.raises(ValueError, match=r"unknown boundary 'nope'; known tags: \['bottom'"):
        boundary_facets(m, "nope")
    with pytest.raises(ValueError, match=r"^nope is not one of \['bottom'"):
        boundary_facets(m, "nope", "{tag} is not one of {known}")
