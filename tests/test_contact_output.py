"""What the contact output files say where a slave node faces no master: a
``has_master`` mask and, as the gap, the node's distance to the master surface,
the same in the VTU series and in contact.csv (never a NaN, never a 0 that
reads as touching)."""
import numpy as np
import skfem

from skfem_mortar import ContactPair, Dirichlet, Model, NeoHooke, Solid, solve
from skfem_mortar.output.contact_output import ContactOutput
from skfem_mortar.output.io import read_series
from skfem_mortar.contact.surfaces import ContactSurface


def overhang(method="mortar"):
    """A block [0.6, 1.2] x [0, 0.3] pressed 0.01 into a block [0, 1] x [-0.4, 0]:
    its bottom overhangs the lower block by 0.2."""
    def mesh(x0, x1, y0, y1, nx, ny):
        m = skfem.MeshTri.init_tensor(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
        return m.with_boundaries({"top": lambda x: np.isclose(x[1], y1),
                                  "bottom": lambda x: np.isclose(x[1], y0)})
    top = Solid(mesh(0.6, 1.2, 0.0, 0.3, 6, 3), NeoHooke(E=10.0, nu=0.3), name="top")
    low = Solid(mesh(0.0, 1.0, -0.4, 0.0, 8, 4), NeoHooke(E=10.0, nu=0.3), name="low")
    pair = ContactPair(ContactSurface.from_solid(top, "bottom"),
                       ContactSurface.from_solid(low, "top"), method=method)
    model = Model([top, low, pair,
                   Dirichlet(top, top.dofs_on("top", component=1), -0.01, name="push"),
                   Dirichlet(top, top.dofs_on("top", component=0), name="hold"),
                   Dirichlet(low, low.dofs_on("bottom"), name="clamp")])
    return model, pair


def test_a_node_facing_no_master_is_written_with_its_distance_and_a_mask(tmp_path):
    model, pair = overhang()
    result = solve(model, 1)
    d = pair.contact_data(result.z)
    off = ~d["has_master"]
    assert off.any() and d["has_master"].any()
    assert np.all(np.isnan(d["gap"][off]))  # the Python API: undefined
    # an overhanging node (x > 1) is nearest the lower block's corner, where it is now
    xm = pair.master.x(result.z)
    corner = xm[:, np.argmax(xm[0])]
    x, y = d["x"][off], d["y"][off]
    far = x > corner[0] + 1e-9
    assert far.any()
    np.testing.assert_allclose(d["distance"][off][far],
                               np.hypot(x[far] - corner[0], y[far] - corner[1]), rtol=1e-12)
    point, _ = ContactOutput(pair).output_data(result.z)
    assert np.all(np.isfinite(point["gap"]))
    np.testing.assert_array_equal(point["has_master"], d["has_master"].astype(float))
    np.testing.assert_array_equal(point["gap"][off], d["distance"][off])
    np.testing.assert_array_equal(point["gap"][~off], d["gap"][~off])
    result.save(tmp_path)
    frame = read_series(tmp_path / f"{pair.name}.pvd")[-1][1]
    assert np.all(np.isfinite(frame.point_data["gap"]))
    assert np.all(frame.point_data["gap"][off & (d["x"] > 1.0 + 1e-9)] > 0.0)
    csv = np.genfromtxt(tmp_path / "contact.csv", delimiter=",", names=True)
    np.testing.assert_allclose(csv["gap"], point["gap"], rtol=1e-11, atol=1e-15)  # %.12g
    np.testing.assert_array_equal(csv["has_master"], point["has_master"])
