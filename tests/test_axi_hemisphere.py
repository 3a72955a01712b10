"""A hemisphere pressed on a rigid plate in an axisymmetric model: the pair solves
with its multipliers totals over the revolution (the contact resultant is the load),
the pressure follows Hertz's, and contact.csv names its columns r, z."""
import numpy as np
import pytest

from skfem_mortar import (ContactPair, ContactSurface, LinearElastic, Model, RigidPlane, Solid,
                          Traction, solve)
from skfem_mortar.output.io import write_contact_csv
from skfem_mortar.scenes.hertz import graded_quarter_disk

R, E, NU, F = 1.0, 1.0, 0.3, 1e-4
METHODS = ("nts",)


def _hemisphere(method):
    """The quarter disk of ``hertz`` (radius 1, graded to h = 0.01 near the pole, about
    a / 4) revolved, on the plate z = 0, loaded by a dead traction of total ``F`` on
    its flat top; linear elastic (small strain: Hertz's setting)."""
    mesh = graded_quarter_disk(R, 0.01, 0.1, "tri1")
    body = Solid(mesh, LinearElastic(E=E, nu=NU), name="ball")
    pair = ContactPair(ContactSurface.from_solid(body, "arc"),
                       RigidPlane((0.0, 0.0), (0.0, 1.0), length=4.0), method=method, name="c")
    load = Traction(body, "top", [0.0, -F / (np.pi * R * R)], name="load")
    return pair, Model([body, pair, load], geometry="axisymmetric")


@pytest.mark.parametrize("method", METHODS)
def test_a_hemisphere_on_a_plate_carries_its_load_by_contact(method, tmp_path):
    pair, model = _hemisphere(method)
    res = solve(model, n_steps=2)
    assert res.converged
    # the multipliers are totals over the revolution: the resultant is the load to
    # Newton's tolerance (rtol 1e-10 of the force scale F), radial total 0 on the plate
    fr, fz = pair.total_force(res.z)
    assert fz == pytest.approx(F, rel=1e-9) and abs(fr) <= 1e-12 * F
    d = pair.contact_data(res.z)
    a = (3 * F * R * (1 - NU * NU) / (4 * E)) ** (1 / 3)      # Hertz: a = 0.0409
    p0 = 3 * F / (2 * np.pi * a * a)
    act = d["pressure"] > 0
    # the contact radius within one element (h = 0.01) of Hertz's; the peak within 3 %
    # (measured -0.65 % here, +1.5 % at h = a / 30); the axis node in contact, its
    # pressure lam / (2 pi h^2 / 6) within 10 % of p0 (measured -5.6 %: NTS's nodal
    # reading of a point force, O(h), not exact)
    assert abs(d["r"][act].max() - a) <= 0.011
    assert d["pressure"].max() == pytest.approx(p0, rel=0.03)
    assert d["r"][0] == 0.0 and d["pressure"][0] == pytest.approx(p0, rel=0.1)
    assert np.array_equal(d["r"], d["x"]) and np.array_equal(d["z"], d["y"])
    write_contact_csv(tmp_path / "contact.csv", d)
    head = (tmp_path / "contact.csv").read_text().splitlines()[0]
    assert head == "r,z,gap,pressure,has_master"
