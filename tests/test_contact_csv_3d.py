"""contact.csv of a 3D pair has the three coordinates, and no NaN where a slave node
faces no master (the README's 3D promise: ``x,y,z,gap,pressure,has_master``)."""
import csv

import numpy as np
import skfem

from skfem_mortar import ContactPair, ContactSurface, Dirichlet, LinearElastic, Model, Solid, solve
from skfem_mortar.loads.traction import Traction


def _block(lo, hi, n, z0, name):
    t = np.linspace(lo, hi, n + 1)
    mesh = skfem.MeshHex1.init_tensor(t, t, np.linspace(z0, z0 + 0.5, 3)).with_boundaries(
        {"bottom": lambda x: np.isclose(x[2], z0), "top": lambda x: np.isclose(x[2], z0 + 0.5)})
    return Solid(mesh, LinearElastic(E=1.0, nu=0.3), element="hex1", name=name)


def _rollers(b):
    return [Dirichlet(b, nodes=np.flatnonzero(np.isclose(b.mesh.p[k], 0.5)), component=k,
                      name=f"{b.name}_roller_{k}") for k in (0, 1)]


def test_a_3d_contact_csv_has_x_y_z_and_distances_where_no_master(tmp_path, recwarn):
    upper, lower = _block(0.0, 1.0, 6, 0.5, "upper"), _block(0.2, 0.8, 6, 0.0, "lower")
    pair = ContactPair(ContactSurface.from_solid(upper, "bottom"),
                       ContactSurface.from_solid(lower, "top"), method="nts", name="contact")
    model = Model([upper, lower, pair, Traction(upper, "top", (0.0, 0.0, -0.01), name="load"),
                   Dirichlet(lower, lower.dofs_on("bottom", "z"), name="support"),
                   *_rollers(upper), *_rollers(lower)], geometry="3d")
    result = solve(model, n_steps=1)
    result.save(tmp_path / "run")
    with open(tmp_path / "run" / "contact.csv", newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["x", "y", "z", "gap", "pressure", "has_master"]
    table = np.array(rows[1:], dtype=float)
    data = pair.contact_data(result.z)
    # the written coordinates are the slave nodes' current ones (12 significant digits)
    for k, name in enumerate("xyz"):
        np.testing.assert_allclose(table[:, k], data[name], rtol=1e-11, atol=1e-12)
    has = table[:, 5].astype(bool)
    assert has.any() and not has.all()           # the upper block overhangs the lower one
    assert np.all(np.isfinite(table)) and np.all(table[~has, 3] > 0.0)   # distances, no NaN
