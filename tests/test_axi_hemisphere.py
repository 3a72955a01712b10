"""A hemisphere pressed on a rigid plate in an axisymmetric model, every method: the
pair solves with its multipliers totals over the revolution (the contact resultant is the load),
the pressure follows Hertz's, and contact.csv names its columns r, z; with Coulomb and
Tresca friction along the meridian."""
import numpy as np
import pytest

from skfem_mortar import (ContactPair, ContactSurface, Coulomb, LinearElastic, Model, RigidPlane,
                          Solid, Traction, Tresca, solve)
from skfem_mortar.output.io import write_contact_csv
from skfem_mortar.scenes.hertz import graded_quarter_disk

R, E, NU, F = 1.0, 1.0, 0.3, 1e-4
METHODS = ("nts", "mortar", "mortar-dual")


def _hemisphere(method, friction=None, element="tri1"):
    """The quarter disk of ``hertz`` (radius 1, graded to h = 0.01 near the pole, about
    a / 4) revolved, on the plate z = 0, loaded by a dead traction of total ``F`` on
    its flat top; linear elastic (small strain: Hertz's setting)."""
    mesh = graded_quarter_disk(R, 0.01, 0.1, element)
    body = Solid(mesh, LinearElastic(E=E, nu=NU), element=element, name="ball")
    pair = ContactPair(ContactSurface.from_solid(body, "arc"),
                       RigidPlane((0.0, 0.0), (0.0, 1.0), length=4.0), method=method, name="c",
                       friction=friction)
    load = Traction(body, "top", [0.0, -F / (np.pi * R * R)], name="load")
    return pair, Model([body, pair, load], geometry="axisymmetric")


@pytest.mark.parametrize("method", METHODS)
def test_a_hemisphere_on_a_plate_carries_its_load_by_contact(method, tmp_path):
    pair, model = _hemisphere(method)
    res = solve(model, n_steps=2)
    assert res.converged
    # the multipliers are totals over the revolution: the resultant is the load to
    # Newton's tolerance (rtol 1e-10 of the force scale F); the radial total is 0 for
    # NTS (the plate's normal is axial) and the residual gaps' share of the slave
    # normals' derivatives for mortar (measured 9.5e-7 F standard, 6e-10 F dual)
    fr, fz = pair.total_force(res.z)
    assert fz == pytest.approx(F, rel=1e-9) and abs(fr) <= 1e-5 * F
    d = pair.contact_data(res.z)
    a = (3 * F * R * (1 - NU * NU) / (4 * E)) ** (1 / 3)      # Hertz: a = 0.0409
    p0 = 3 * F / (2 * np.pi * a * a)
    act = d["pressure"] > 0
    # the contact radius within one element (h = 0.01) of Hertz's; the peak within 5 %
    # (measured at h = a / 4: nts and mortar-dual -0.65 %, mortar +3.0 %; nts +1.5 % at
    # h = a / 30); the axis node in contact, its pressure within 20 % of p0 (measured
    # nts and mortar-dual -5.6 %, nts's lam / (2 pi h^2 / 6); mortar -14.7 %: the
    # standard multipliers' end value; nodal readings at h = a / 4, O(h))
    assert abs(d["r"][act].max() - a) <= 0.011
    assert d["pressure"].max() == pytest.approx(p0, rel=0.05)
    assert d["r"][0] == 0.0 and d["pressure"][0] == pytest.approx(p0, rel=0.2)
    assert np.array_equal(d["r"], d["x"]) and np.array_equal(d["z"], d["y"])
    write_contact_csv(tmp_path / "contact.csv", d)
    head = (tmp_path / "contact.csv").read_text().splitlines()[0]
    assert head == "r,z,gap,pressure,has_master"


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("friction", [Coulomb(0.3), Tresca(1e-3)], ids=["coulomb", "tresca"])
def test_friction_along_the_meridian(method, friction):
    """Friction runs through the unchanged laws, one tangential component along the
    meridian; the axis node cannot slip (symmetry holds it): its row is open, where
    a stick row would constrain the held radial dof twice (singular: every mortar
    run diverged before).  The resultant is still the load; every slipping node's
    tangential traction is at its bound, and none above."""
    pair, model = _hemisphere(method, friction)
    res = solve(model, n_steps=2)
    assert res.converged
    assert pair.total_force(res.z)[1] == pytest.approx(F, rel=1e-9)
    d = pair.contact_data(res.z)
    assert d["r"][0] == 0.0 and d["status"][0] == "open" and d["tangential_traction"][0] == 0
    # Coulomb: the centre sticks, the rim slips (Mindlin); Tresca's bound 1e-3 is below
    # every pressure of the zone (p0 = 0.029), so the whole zone slips
    assert (d["status"] == "slip").any()
    assert (d["status"] == "stick").any() == isinstance(friction, Coulomb)
    t, p, slip = np.abs(d["tangential_traction"]), d["pressure"], d["status"] == "slip"
    bound = 0.3 * p if isinstance(friction, Coulomb) else np.full(p.shape, 1e-3)
    # the KKT check's tolerances (K_LAM = 1e-6 of the bound, Newton's round-off)
    assert np.all(t <= bound * (1 + 1e-6) + 1e-12)
    np.testing.assert_allclose(t[slip], bound[slip], rtol=1e-6, atol=1e-12)


def test_nts_reads_the_pressure_of_a_weightless_axis_vertex_from_its_mid_node():
    """Quadratic (tri2): the pole cell's axis vertex weighs 2 pi int N_A r dGamma,
    -1e-5 of its mid node's (0 on a straight cell); its NTS force is about 0 and says
    nothing of the pressure, which contact_data reads from the mid node instead
    (pair_output.weightless_read): measured 0.996 p0 there, not 1.4e-7 p0."""
    pair, model = _hemisphere("nts", element="tri2")
    res = solve(model, n_steps=2)
    ev = pair.evaluate(res.z, tangent=False, with_lam=False)
    seg = pair.slave.segments
    pole = seg[(seg == 0).any(axis=1)][0]            # surface node 0 is the axis vertex
    assert pair.slave.X[0, 0] <= 1e-15 and abs(ev.area[0]) <= 1e-4 * ev.area[pole[2]]
    d = pair.contact_data(res.z)
    at = {n: i for i, n in enumerate(d["node"])}
    assert d["pressure"][at[0]] == d["pressure"][at[pole[2]]]
    a = (3 * F * R * (1 - NU * NU) / (4 * E)) ** (1 / 3)
    assert d["pressure"][at[0]] == pytest.approx(3 * F / (2 * np.pi * a * a), rel=0.02)
