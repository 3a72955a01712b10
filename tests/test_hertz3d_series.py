"""hertz3d against Hertz and against hertz_axi (issue 38): the quarter sphere on the rigid
plane, small strain, NTS, tet1, at refine -3 and -2 (the default).  The third mesh,
-1 (9.2e4 dofs, 45 s of CPU), is in ``benchmarks/hertz3d_series.py`` with the table of
all three (its ``run`` and ``richardson_check`` are used here).

"The same h": both scenes set the element size under the contact to
``h0 = (a / 30) 2^-refine`` (``a`` Hertz's radius), so the same ``refine`` is the same
``h0``: a/3.75, a/7.5, a/15.

Measured (errors against Hertz, tet1 on the structured grid; -1 from the benchmark):

=======  =========  ===========  ======  ===========================
refine   radius     fitted p0    peak    nodal scatter about Hertz
=======  =========  ===========  ======  ===========================
-3       3.07 %     1.87 %       0.79 %  6.39 %
-2       1.14 %     0.93 %       0.84 %  5.67 %
-1       0.14 %     0.77 %       1.11 %  2.94 %
=======  =========  ===========  ======  ===========================

The radius, the fitted p0 and the scatter fall at every level.  The largest nodal
pressure does not, and cannot: it is within 1.2 % of Hertz at every level, where
the finite hemisphere's own answer differs from Hertz's half space: hertz_axi on
fine meshes (refine 0 to 3, up to 1.5e5 dofs) converges to a fitted p0 0.81 % above
Hertz's, a radius 0.57 % below and an axis pressure 0.88 to 0.92 % above.  Against
that answer (the continuum problem both scenes discretize) the hex1 mesh's largest
nodal pressure and fitted radius do fall (the last tests; signed, against Hertz):

=======  ===============  ===============  ================================
refine   hex1 peak        hex1 radius      distance from hertz_axi refine 2
=======  ===============  ===============  ================================
-3       +0.62 %          -1.86 %          0.30 % and 1.29 %
-2       +0.75 %          -0.67 %          0.17 % and 0.10 %
-1       +0.83 %          -0.58 %          0.09 % and 0.017 %
=======  ===============  ===============  ================================

tet1's largest nodal pressure (-0.79, +0.84, +1.11 %) overshoots at -1: the nodes off
the symmetry planes read a patch bias of the Kuhn tetrahedra (+1.6 % at -1,
``benchmarks/hertz3d_series.py``); tet1's radius and fitted p0 fall against it too.
The hex1 series (36 s of CPU with PARDISO, 108 s for its first two meshes with
SuperLU) runs in CI's series step (``SKFEM_MORTAR_SERIES=1``).
"""
import importlib.util
import os
from pathlib import Path

import pytest

_spec = importlib.util.spec_from_file_location(
    "hertz3d_series", Path(__file__).resolve().parents[1] / "benchmarks" / "hertz3d_series.py")
SERIES = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(SERIES)

LEVELS = (-3, -2)


@pytest.fixture(scope="module")
def series():
    return {r: (SERIES.run("hertz3d", r), SERIES.run("hertz_axi", r)) for r in LEVELS}


def test_the_same_refine_is_the_same_h(series):
    for m3, ma in series.values():
        assert m3["element_size"] == pytest.approx(ma["element_size"], rel=1e-14)


def test_default_mesh_peak_and_radius_within_3_percent(series):
    m3 = series[-2][0]                   # the default mesh; measured 0.84 % and 1.14 %
    assert m3["peak_pressure_error"] < 0.03 and m3["contact_radius_error"] < 0.03, m3
    for m3, _ in series.values():       # the resultant is the load (a sum of 1e3 terms)
        assert m3["contact_force_error"] < 1e-10
        assert m3["peak_pressure_error"] < 0.03           # 0.79 % at -3 too


def test_radius_fitted_peak_and_nodal_scatter_fall(series):
    # measured -3 -> -2: radius 3.07 -> 1.14 %, fitted p0 1.87 -> 0.93 %, the nodal
    # scatter about Hertz's profile 6.39 -> 5.67 % (its axis node; 2.94 % at -1)
    for key in ("contact_radius_error", "fit_p0_error", "pressure_profile_error"):
        coarse, fine = (series[r][0][key] for r in LEVELS)
        assert fine < coarse, (key, coarse, fine)


def test_hertz3d_and_hertz_axi_meet_within_their_discretization_errors(series):
    # both scenes discretize one continuum problem: at -3 they differ by at most the
    # sum of their discretization errors, each measured as 2 |q(h) - q(h/2)| (a
    # first-order error's Richardson estimate); against Hertz the same statement would
    # hold by the triangle inequality and test nothing
    (m3, ma), (m3f, maf) = series[-3], series[-2]
    for key in ("peak_pressure_fit", "contact_radius"):
        gap, bound = SERIES.richardson_check(m3, m3f, ma, maf, key)
        assert gap <= bound, (key, gap, bound)


#: hertz_axi's refine 2 (4.3e4 dofs, 2 s) stands for the finite hemisphere's answer: it
#: moves by 0.036 % (peak) and 0.008 % (radius) of Hertz's values to refine 3, below
#: the smallest hex1 distance it is compared with (0.09 % and 0.017 % at -1)
REFERENCE_REFINE = 2
_HEX: dict = {}


def _hex(refine: int) -> dict:
    """hertz3d on hex1 at ``refine`` (NTS, small strain, rigid plane), computed once."""
    if refine not in _HEX:
        _HEX[refine] = SERIES.run("hertz3d", refine, "nts", "hex1")
    return _HEX[refine]


@pytest.fixture(scope="module")
def reference():
    return SERIES.run("hertz_axi", REFERENCE_REFINE)


def _distances(refine: int, reference: dict) -> dict:
    """``|q_3d - q_axi| / q_Hertz`` of the largest nodal pressure and the fitted radius."""
    m = _hex(refine)
    return {k: abs(m[k] - reference[k]) / m[k + "_exact"]
            for k in ("peak_pressure", "contact_radius")}


def _falls(coarse: int, fine: int, reference: dict) -> None:
    # a fall, not a rate: the distances halve per level (0.30, 0.17, 0.09 % peak)
    # but the radius's last one is near the reference's own 0.008 %
    a, b = _distances(coarse, reference), _distances(fine, reference)
    for key in a:
        assert b[key] < a[key], (key, coarse, a[key], fine, b[key])


@pytest.mark.skipif(os.environ.get("SKFEM_MORTAR_SERIES") != "1",
                    reason="three hex1 meshes (36 s of CPU with PARDISO, minutes with "
                           "SuperLU): CI's series step, SKFEM_MORTAR_SERIES=1")
def test_hex1_peak_and_radius_approach_the_finite_hemispheres_answer(reference):
    # against Hertz they rise towards the hemisphere's own offset (+0.62, +0.75, +0.83 %
    # peak), against the hemisphere's answer they fall at every level
    _falls(-3, -2, reference)
    _falls(-2, -1, reference)
    assert _hex(-2)["peak_pressure_error"] < 0.03 and _hex(-2)["contact_radius_error"] < 0.03
