"""hertz3d against Hertz and against hertz_axi over three meshes (issue 38): the quarter
sphere on the rigid plane, small strain, NTS, at refine -3, -2 (the default) and -1.

"The same h": both scenes set the element size under the contact to
``h0 = (a / 30) 2^-refine`` (``a`` Hertz's radius), so the same ``refine`` is the same
``h0``: a/3.75, a/7.5, a/15.

Measured (this file's runs; errors relative to Hertz):

=======  ==========  ==========  ==========  ===========  ===========  ===========
refine   3D radius   3D fit p0   3D peak     axi radius   axi fit p0   axi peak
=======  ==========  ==========  ==========  ===========  ===========  ===========
-3       4.7 %       3.8 %       8.2 %       19.7 %       5.8 %        4.0 %
-2       0.80 %      3.0 %       8.5 %       6.2 %        1.8 %        0.74 %
-1       0.063 %     2.0 %       5.5 %       0.56 %       0.15 %       0.55 %
=======  ==========  ==========  ==========  ===========  ===========  ===========

The fitted radius and the fitted peak fall at every level; the radius is within 3 % at
the default mesh.  NTS's nodal peak does not reach 3 % on these meshes: the node at the
contact point sits on few bisection tetrahedra and carries its tributary area's force
(lam_A / a_A on unstructured tri3 faces); it stays below 9 % and is stated, not
claimed to fall.  The 3D and the axisymmetric readings approach each other at every
level (the radius 15, 5.4, 0.63 % of a apart; the fitted peak 9.7, 4.8, 1.9 %).  That
they differ by at most the sum of their errors against Hertz holds by the triangle
inequality and is no test.
"""
import numpy as np
import pytest

from skfem_mortar import ContactPair, ContactSurface, Model, solve
from skfem_mortar.scenes._hertz3d import PARAMS, build_bodies, exact_hertz3d, hertz_metrics
from skfem_mortar.solver.newton import NewtonOptions

LEVELS = (-3, -2, -1)
BASE = {**{p.name: p.default for p in PARAMS}, "base": "rigid", "kinematics": "small"}


def _hertz3d(refine: int) -> dict:
    params = {**BASE, "refine": refine}
    parts = build_bodies(params)
    pair = ContactPair(ContactSurface.from_solid(*parts.slave, name="sphere_face"),
                       ContactSurface(None, None, parts.master["faces"],
                                      X=parts.master["X"], name="plane", cell="quad4"),
                       "nts", name="contact")
    res = solve(Model(parts.items + [pair], geometry="3d"), n_steps=1,
                newton=NewtonOptions(rtol=1e-12))
    z = res.z
    out = hertz_metrics(exact_hertz3d(params), pair.slave.x(z), pair.pressure_and_gap(z)[0],
                        float(pair.total_force(z)[2]), parts.symmetry, float(params["load"]))
    out["h0"] = parts.h0
    return out


def _hertz_axi(refine: int) -> dict:
    from skfem_mortar.scenes.hertz_axi import SCENE, build

    params = {**{p.name: p.default for p in SCENE.params}, "base": "rigid",
              "kinematics": "small", "refine": refine}
    setup = build(params, "nts")
    return setup.metrics(solve(setup.model, n_steps=1, newton=NewtonOptions(rtol=1e-12)))


@pytest.fixture(scope="module")
def series():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return [(_hertz3d(r), _hertz_axi(r)) for r in LEVELS]


def _fit_error(m: dict) -> float:
    return abs(m["peak_pressure_fit"] - m["peak_pressure_exact"]) / m["peak_pressure_exact"]


def test_the_same_refine_is_the_same_h(series):
    for m3, ma in series:
        assert m3["h0"] == pytest.approx(ma["element_size"], rel=1e-14)


def test_hertz3d_radius_and_fitted_peak_fall_and_the_radius_is_within_3_percent(series):
    radius = [m3["contact_radius_error"] for m3, _ in series]
    fit = [_fit_error(m3) for m3, _ in series]
    assert np.all(np.diff(radius) < 0) and np.all(np.diff(fit) < 0), (radius, fit)
    assert radius[1] < 0.03                                  # the default mesh
    for m3, _ in series:                                     # the resultant is the load
        assert m3["contact_force_error"] < 1e-10


def test_nts_nodal_peak_stays_below_9_percent(series):
    peak = [m3["peak_pressure_error"] for m3, _ in series]
    assert max(peak) < 0.09, peak


def test_hertz3d_and_hertz_axi_approach_each_other(series):
    for key in ("contact_radius", "peak_pressure_fit"):
        gap = [abs(m3[key] - ma[key]) / m3[f"{key.replace('_fit', '')}_exact"]
               for m3, ma in series]
        assert np.all(np.diff(gap) < 0), (key, gap)
