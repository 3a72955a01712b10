"""hertz3d against Hertz and against hertz_axi (issue 38): the quarter sphere on the rigid
plane, small strain, NTS, on the default mesh (hex1) at refine -3 and -2 (the default);
the third mesh, -1 (9.2e4 dofs, 45 s of CPU), in CI's series step
(``SKFEM_MORTAR_SERIES=1``) and in ``benchmarks/hertz3d_series.py`` with the table of
all three (its ``run`` and ``richardson_check`` are used here).

"The same h": both scenes set the element size under the contact to
``h0 = (a / 30) 2^-refine`` (``a`` Hertz's radius), so the same ``refine`` is the same
``h0``: a/3.75, a/7.5, a/15.

Hertz (a half space, ``a / R -> 0``) is not the answer of the problem both scenes
discretize: hertz_axi on fine meshes (refine 0 to 3, up to 1.5e5 dofs) converges to a
fitted p0 0.81 % above Hertz's, a radius 0.57 % below and an axis pressure 0.88 to
0.92 % above.  So the largest nodal pressure cannot approach Hertz's p0; it approaches
that finite hemisphere's answer, which hertz_axi at refine 2 stands for.

Measured (hex1, the default; signed errors against Hertz; the distance from the
hemisphere's answer in units of Hertz's value):

=======  ========  ========  =======  =======  =========================
refine   peak      radius    fit p0   scatter  distance: peak, radius
=======  ========  ========  =======  =======  =========================
-3       +0.62 %   -1.86 %   0.88 %   1.39 %   0.30 %, 1.29 %
-2       +0.75 %   -0.67 %   0.72 %   0.75 %   0.17 %, 0.10 %
-1       +0.83 %   -0.58 %   0.79 %   0.83 %   0.09 %, 0.017 %
=======  ========  ========  =======  =======  =========================

tet1 (``element=tet1``) at the same levels: peak -0.79, +0.84, +1.11 %, radius 3.07,
1.14, 0.14 %, fitted p0 1.87, 0.93, 0.77 %, scatter 6.39, 5.67, 2.94 %.  Its radius,
fitted p0 and scatter fall; its largest nodal pressure overshoots the hemisphere's
answer at -1 (distances 1.58, 0.03, 0.30 %): the nodes off the symmetry planes read a
patch bias of the Kuhn tetrahedra (+1.6 % at -1, ``benchmarks/hertz3d_series.py``),
which is why hex1 is the default.
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
#: hertz_axi's refine 2 (4.3e4 dofs, 2 s) stands for the finite hemisphere's answer: it
#: moves by 0.036 % (peak) and 0.008 % (radius) of Hertz's values to refine 3, below
#: the smallest distance it is compared with (0.09 % and 0.017 % at -1)
REFERENCE_REFINE = 2
_RUNS: dict = {}


def _run(refine: int, element: str | None = None) -> dict:
    """hertz3d (NTS, small strain, rigid plane) at ``refine`` on ``element`` (None: the
    scene's default mesh), computed once per module."""
    key = (refine, element)
    if key not in _RUNS:
        _RUNS[key] = SERIES.run("hertz3d", refine, "nts", element)
    return _RUNS[key]


@pytest.fixture(scope="module")
def series():
    return {r: (_run(r), SERIES.run("hertz_axi", r)) for r in LEVELS}


@pytest.fixture(scope="module")
def reference():
    return SERIES.run("hertz_axi", REFERENCE_REFINE)


def test_the_default_mesh_is_hex1():
    from skfem_mortar.scenes._hertz3d import PARAMS
    assert {p.name: p.default for p in PARAMS}["element"] == "hex1"


def test_the_same_refine_is_the_same_h(series):
    for m3, ma in series.values():
        assert m3["element_size"] == pytest.approx(ma["element_size"], rel=1e-14)


def test_default_mesh_peak_and_radius_within_3_percent(series):
    m3 = series[-2][0]                   # the default mesh; measured 0.75 % and 0.67 %
    assert m3["peak_pressure_error"] < 0.03 and m3["contact_radius_error"] < 0.03, m3
    for m3, _ in series.values():       # the resultant is the load (a sum of 1e3 terms)
        assert m3["contact_force_error"] < 1e-10
        assert m3["peak_pressure_error"] < 0.03           # 0.62 % at -3 too


def test_radius_fitted_peak_and_nodal_scatter_fall(series):
    # measured -3 -> -2: radius 1.86 -> 0.67 %, fitted p0 0.88 -> 0.72 %, the nodal
    # scatter about Hertz's profile 1.39 -> 0.75 % (against Hertz, whose p0 the
    # hemisphere's exceeds by 0.81 %: the fitted p0 rises to 0.79 % at -1)
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


def _distances(m: dict, reference: dict) -> dict:
    """``|q_3d - q_axi| / q_Hertz`` of the largest nodal pressure and the fitted radius."""
    return {k: abs(m[k] - reference[k]) / m[k + "_exact"]
            for k in ("peak_pressure", "contact_radius")}


def _falls(coarse: int, fine: int, reference: dict) -> None:
    # a fall, not a rate: the distances halve per level (0.30, 0.17, 0.09 % peak)
    # but the radius's last one is near the reference's own 0.008 %
    a, b = _distances(_run(coarse), reference), _distances(_run(fine), reference)
    for key in a:
        assert b[key] < a[key], (key, coarse, a[key], fine, b[key])


def test_default_mesh_peak_and_radius_approach_the_finite_hemispheres_answer(
        series, reference):
    # against Hertz the peak rises towards the hemisphere's own offset (+0.62, +0.75 %),
    # against the hemisphere's answer it falls (0.30 -> 0.17 %; radius 1.29 -> 0.10 %)
    _falls(-3, -2, reference)


@pytest.mark.skipif(os.environ.get("SKFEM_MORTAR_SERIES") != "1",
                    reason="the third mesh (45 s of CPU with PARDISO, minutes with "
                           "SuperLU): CI's series step, SKFEM_MORTAR_SERIES=1")
def test_default_mesh_third_level_keeps_approaching(series, reference):
    # -2 -> -1: peak 0.17 -> 0.09 %, radius 0.10 -> 0.017 % from the hemisphere's answer
    _falls(-2, -1, reference)
    assert _run(-1)["peak_pressure_error"] < 0.03 and _run(-1)["contact_radius_error"] < 0.03


@pytest.mark.skipif(os.environ.get("SKFEM_MORTAR_SERIES") != "1",
                    reason="tet1's two meshes (12 s of CPU with PARDISO, 40 s with SuperLU): "
                           "CI's series step, SKFEM_MORTAR_SERIES=1")
def test_tet1_within_3_percent_and_its_fits_fall():
    # tet1 (element=tet1) at -3 -> -2: peak 0.79, 0.84 %; radius 3.07 -> 1.14 %, fitted
    # p0 1.87 -> 0.93 %, scatter 6.39 -> 5.67 %; its largest nodal pressure is the
    # module docstring's exception (the Kuhn patch bias)
    coarse, fine = _run(-3, "tet1"), _run(-2, "tet1")
    assert fine["peak_pressure_error"] < 0.03 and fine["contact_radius_error"] < 0.03, fine
    for key in ("contact_radius_error", "fit_p0_error", "pressure_profile_error"):
        assert fine[key] < coarse[key], (key, coarse[key], fine[key])
