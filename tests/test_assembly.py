"""Assembly paths: the Solid's own kernels against the skfem forms, and the model's
fixed CSR pattern against a plain COO sum, also when an item's pattern changes."""
import numpy as np
import pytest
import scipy.sparse as sp
from skfem import MeshQuad, MeshTri

from skfem_mortar.bodies.materials import NeoHooke, SaintVenantKirchhoff
from skfem_mortar.core.item import Contribution, Item
from skfem_mortar.core.model import Model
from skfem_mortar.bodies.solid import Solid


def _deformation(X):
    return np.array([0.1 * X[0] ** 2 + 0.05 * X[1], 0.2 * X[0] * X[1] - 0.1 * X[1] ** 2])


@pytest.mark.parametrize("element", ["tri1", "tri2", "quad1", "quad2"])
@pytest.mark.parametrize("material", [NeoHooke(E=10.0, nu=0.3),
                                      SaintVenantKirchhoff(E=3.0, nu=0.2)])
def test_solid_kernels_match_skfem_forms(element, material):
    mesh = (MeshTri() if element.startswith("tri") else MeshQuad()).refined(2)
    s = Solid(mesh, material, element=element)
    Model([s])
    z = s.interpolate(_deformation)
    c = s.assemble(z, 1.0)
    K = sp.coo_matrix((c.k_vals, (c.k_rows, c.k_cols)), shape=(s.n_dofs,) * 2).tocsr()
    R = np.bincount(c.r_index, c.r_value, minlength=s.n_dofs)
    r_ref, K_ref = s.assemble_forms(z)
    np.testing.assert_allclose(R, r_ref, atol=1e-13 * np.abs(r_ref).max())
    assert abs(K - K_ref).max() <= 1e-13 * abs(K_ref).max()
    # the residual alone is the same too
    c0 = s.assemble(z, 1.0, tangent=False)
    np.testing.assert_allclose(np.bincount(c0.r_index, c0.r_value, minlength=s.n_dofs), R)


def test_tri1_one_point_rule_is_exact():
    """The centroid rule of tri1 gives what skfem's three-point rule gives."""
    mesh = MeshTri().refined(2)
    s1 = Solid(mesh, NeoHooke(E=10.0, nu=0.3), element="tri1")
    s3 = Solid(mesh, NeoHooke(E=10.0, nu=0.3), element="tri1", intorder=2)
    assert s1.basis.X.shape[1] == 1 and s3.basis.X.shape[1] > 1
    Model([s1]), Model([s3])
    z = s1.interpolate(_deformation)
    for a, b in zip(s1.assemble_forms(z), s3.assemble_forms(z)):
        a, b = (a.toarray(), b.toarray()) if sp.issparse(a) else (a, b)
        np.testing.assert_allclose(a, b, atol=1e-12 * np.abs(b).max())


def test_one_point_tangent_kernel_is_the_general_one():
    """With one quadrature point (tri1) the Solid takes its own kernels
    (``_tangents_one_point``, blocks of elements, and ``_residuals``); they form
    the same products and two-term sums as the general ``einsum``, so element
    tangents and residuals agree to a rounding of such a sum at most: 2 eps
    of the largest entry (on this numpy they are equal to the last bit)."""
    s = Solid(MeshTri().refined(3), NeoHooke(E=10.0, nu=0.3), element="tri1")
    Model([s])
    assert s._dx.shape[1] == 1 and s._comp_slices is not None
    F = s.deformation_gradient(s.interpolate(_deformation))
    P, A = s.material.stress_and_tangent(F)
    re = np.einsum("lJeq,lJeq->le", P[s._comp], s._dNdx)
    assert np.abs(s._residuals(P) - re).max() <= 2 * np.finfo(float).eps * np.abs(re).max()
    ref = s._tangents(A * s._dx)
    for chunk in (7, 8192):  # blocks that split the elements, and one block
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr("skfem_mortar.bodies.solid.CHUNK", chunk)
            ke = s._tangents_one_point(A)
        assert np.abs(ke - ref).max() <= 2 * np.finfo(float).eps * np.abs(ref).max()


class Wandering(Item):
    """A toy item on two dofs of a body whose tangent entries move every call."""

    def __init__(self, n, name="wandering"):
        self.n, self.name, self.calls = n, name, 0

    def assemble(self, z, load_factor, tangent=True):
        self.calls += 1
        i, j = self.calls % self.n, (3 * self.calls + 1) % self.n
        c = Contribution(np.array([i, j]), np.array([1.0, -1.0]))
        if tangent:
            c.k_rows = np.array([i, j, i])
            c.k_cols = np.array([j, i, i])
            c.k_vals = np.array([0.5, 0.5, 2.0 + self.calls])
        return c


def _reference(model, z):
    parts = [it.assemble(z, 1.0) for it in model.items]
    c = Contribution.concat(parts)
    return sp.coo_matrix((c.k_vals, (c.k_rows, c.k_cols)), shape=(model.n, model.n)).tocsr()


def test_model_fixed_pattern_matches_coo_sum():
    mesh = MeshTri().refined(2)
    s = Solid(mesh, NeoHooke(E=10.0, nu=0.3), element="tri1", name="a")
    t = Solid(MeshQuad().refined(1), NeoHooke(E=5.0, nu=0.2), element="quad1", name="b")
    w = Wandering(s.n_dofs)
    model = Model([s, t, w])
    rng = np.random.default_rng(1)
    for k in range(5):
        z = 0.01 * rng.standard_normal(model.n)
        R, K, _ = model.assemble(z, 1.0)
        w.calls -= 1  # the reference sees the same wandering entries
        K_ref = _reference(model, z)
        assert K.shape == K_ref.shape
        assert abs(K - K_ref).max() <= 1e-14 * abs(K_ref).max()
        assert K.has_sorted_indices
    # the bodies are summed into a fixed pattern; the wandering item is not in it
    assert model._pattern is not None and model._pattern.items == (0, 1)
    assert bool(model._varying[2]) and not model._varying[:2].any()


def test_model_pattern_rebuilt_when_an_item_changes_once():
    """An item whose indices equal the previous call's at first and change later."""
    s = Solid(MeshTri().refined(1), NeoHooke(E=10.0, nu=0.3), element="tri1")
    w = Wandering(s.n_dofs)
    model = Model([s, w])
    z = model.zeros()
    for k in range(4):
        if k < 2:
            w.calls = 0  # the same entries in the first calls: looks stable
        R, K, _ = model.assemble(z, 1.0)
        w.calls -= 1
        K_ref = _reference(model, z)
        assert abs(K - K_ref).max() <= 1e-14 * abs(K_ref).max()
    assert model._pattern.items == (0,)
