"""The follower pressure on 3D boundary faces (loads.pressure3d): exact load
stiffness on every face type, outward orientation from the volume element."""
import numpy as np
import pytest
from skfem import (Basis, ElementHex1, ElementHex2, ElementTetP1, ElementTetP2, ElementVector,
                   MeshHex1, MeshHex2, MeshTet1, MeshTet2)

from skfem_mortar.loads.pressure3d import FollowerPressure3D
from fd import dense


class _Body:
    """The part of a solid the pressure reads: mesh, vector basis, offset, name."""

    def __init__(self, mesh, elem, offset=0):
        self.mesh, self.basis, self.offset, self.name = mesh, Basis(mesh, ElementVector(elem)), \
            offset, "body"
        self.n_dofs = self.basis.N


def _cube(cls, n=3):
    g = np.linspace(0.0, 1.0, n)
    return cls.init_tensor(g, g, g).with_defaults()


def _curved(mesh):
    """Move every node (mid-edge and mid-face nodes too) off the straight cube:
    the faces are curved and not planar."""
    p = mesh.doflocs.copy() if hasattr(mesh, "doflocs") else mesh.p.copy()
    q = p + 0.06 * np.array([np.sin(3 * p[1] + p[2]), np.cos(2 * p[0] - p[2]),
                             np.sin(p[0] + 2 * p[1])])
    return type(mesh)(q, mesh.t, mesh.boundaries)


FACES = {  # face type: (mesh, volume element)
    "tri3": lambda: (_curved(_cube(MeshTet1)), ElementTetP1()),
    "tri6": lambda: (_curved(MeshTet2.from_mesh(_cube(MeshTet1, 2)).with_defaults()),
                     ElementTetP2()),
    "quad4": lambda: (_curved(_cube(MeshHex1)), ElementHex1()),
    "quad9": lambda: (_curved(MeshHex2.from_mesh(_cube(MeshHex1, 2)).with_defaults()),
                      ElementHex2()),
}


@pytest.mark.parametrize("face", sorted(FACES))
@pytest.mark.parametrize("side", ["inward", "outward"])
def test_load_stiffness_is_the_derivative_of_the_forces(face, side):
    mesh, elem = FACES[face]()
    body = _Body(mesh, elem, offset=5)
    n = body.offset + body.n_dofs + 3
    load = FollowerPressure3D(body, 2.5, "right", side=side)
    rng = np.random.default_rng(0)
    z = 0.05 * rng.standard_normal(n)
    lf = 0.8
    R, K = dense(load.assemble(z, lf), n)
    cols = np.unique(body.offset + load._flat)
    h = 1e-6
    Kfd = np.zeros((n, cols.size))
    for j, c in enumerate(cols):
        e = np.zeros(n)
        e[c] = h
        Kfd[:, j] = (dense(load.assemble(z + e, lf, tangent=False), n)[0]
                     - dense(load.assemble(z - e, lf, tangent=False), n)[0]) / (2 * h)
    # central differences of a polynomial of degree 2 in x (the forces): the
    # truncation error vanishes, round-off is ~eps |R| / h ~ 1e-10 of the entries
    scale = np.max(np.abs(K))
    assert scale > 0.1
    assert np.max(np.abs(K[:, cols] - Kfd)) < 1e-8 * scale
    # the tangent touches only the face dofs
    assert np.all(K[np.ix_(np.setdiff1d(np.arange(n), cols), np.arange(n))] == 0)
    assert np.all(R[:body.offset] == 0) and np.all(R[-3:] == 0)


@pytest.mark.parametrize("face", sorted(FACES))
def test_every_face_points_out_of_the_body(face):
    """Pressure p on the whole boundary: sum_a f_a . x_a = -p int x . n da = -3 p V
    (divergence theorem) and the resultant vanishes; one face turned the wrong
    way would change both.  Also on the deformed body (a follower load)."""
    mesh, elem = FACES[face]()
    body = _Body(mesh, elem)
    every = mesh.boundary_facets()
    load = FollowerPressure3D(body, 3.0, every)
    rng = np.random.default_rng(1)
    for z in (np.zeros(body.n_dofs), 0.04 * rng.standard_normal(body.n_dofs)):
        f = load.forces(z)
        x = load._current(z)
        vol = _volume(body, z)
        # round-off of sums over ~1e3 nodal terms of size 1
        assert abs(np.sum(f * x) - (-3 * 3.0 * vol)) < 1e-12 * 1e3
        np.testing.assert_allclose(load.resultant(z), 0.0, atol=1e-12)


def _volume(body, z):
    """The current volume: int det F dV by the body's own quadrature (exact for
    these polynomial mappings: degree <= 3 (p1, p2 tets) and q-orders of hexes)."""
    from skfem.helpers import det
    from skfem import Functional

    basis = Basis(body.mesh, body.basis.elem, intorder=6)
    u = basis.interpolate(np.asarray(z)[:body.n_dofs])
    F = u.grad + np.eye(3)[:, :, None, None]

    @Functional
    def vol(w):
        return det(w.F)

    return vol.assemble(basis, F=F)


def test_a_flat_face_carries_p_times_its_area_inward():
    mesh = _cube(MeshHex1)
    body = _Body(mesh, ElementHex1())
    z = np.zeros(body.n_dofs)
    np.testing.assert_allclose(FollowerPressure3D(body, 2.0, "right").resultant(z),
                               [-2.0, 0.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(FollowerPressure3D(body, 2.0, "back", side="outward").resultant(z),
                               [0.0, 0.0, 2.0], atol=1e-14)


def test_refusals_name_the_argument():
    mesh = _cube(MeshTet1)
    body = _Body(mesh, ElementTetP1())
    with pytest.raises(ValueError, match="side"):
        FollowerPressure3D(body, 1.0, "right", side="left")
    with pytest.raises(ValueError, match="facets"):
        FollowerPressure3D(body, 1.0, "nowhere")
    inner = np.flatnonzero(mesh.f2t[1] >= 0)[:2]
    with pytest.raises(ValueError, match="facets"):
        FollowerPressure3D(body, 1.0, inner)
    with pytest.raises(ValueError, match="pressure"):
        FollowerPressure3D(body, np.nan, "right")
    from skfem import MeshTri1, ElementTriP1
    with pytest.raises(ValueError, match="body must be a solid on a 3D mesh"):
        FollowerPressure3D(_Body(MeshTri1().with_defaults(), ElementTriP1()), 1.0, "right")


@pytest.mark.parametrize("element", ["tet2", "p2p1", "hex1-md"])
def test_on_a_solid_inside_a_model_the_tangent_is_the_derivative(element):
    """Through real solids (the mixed ones carry pressure dofs after the
    displacements) placed after another body: the faces' dofs are the body's."""
    import skfem
    from skfem_mortar import Model, NeoHooke, Solid

    g = np.linspace(0.0, 1.0, 3)
    cls = skfem.MeshHex1 if element.startswith("hex") else skfem.MeshTet1
    mesh = cls.init_tensor(g, g, g).with_defaults()
    if element == "tet2":
        mesh = skfem.MeshTet2.from_mesh(mesh).with_defaults()
    first = Solid(skfem.MeshTet1.init_tensor(g, g, g), NeoHooke(E=1.0, nu=0.3),
                  element="tet1", name="first")
    body = Solid(mesh, NeoHooke(E=1.0, nu=0.3), element=element, name="body")
    load = FollowerPressure3D(body, 1.5, "top")
    model = Model([first, body, load])
    assert body.offset == first.n_dofs
    rng = np.random.default_rng(2)
    z = 0.05 * rng.standard_normal(model.n)
    R, K = dense(load.assemble(z, 1.0), model.n)
    cols = np.unique(body.offset + load._flat)
    assert cols.min() >= body.offset and cols.max() < body.offset + body.n_dofs
    assert np.all(body.basis.doflocs[1, cols - body.offset] == 1.0)     # on the face y = 1
    h = 1e-6
    for c in cols[::7]:     # every seventh face dof: the same faces, fewer solves
        e = np.zeros(model.n)
        e[c] = h
        fd = (dense(load.assemble(z + e, 1.0, tangent=False), model.n)[0]
              - dense(load.assemble(z - e, 1.0, tangent=False), model.n)[0]) / (2 * h)
        assert np.max(np.abs(K[:, c] - fd)) < 1e-8 * np.max(np.abs(K))
