"""Quadratic contact segments in the scenes: the patch test, Hertz orders, Newton's rate.

The kernels' own tests (finite differences of G and H, the dual basis) are in
tests/test_mortar_quadratic.py and tests/test_nts_quadratic.py.
"""
from __future__ import annotations

import importlib.util
import math
import pathlib

import numpy as np
import pytest

from skfem_mortar.app.runner import build_scene, run_scene
from skfem_mortar.solver.stepping import solve

ROOT = pathlib.Path(__file__).resolve().parents[1]

# Newton stops at rtol 1e-10 of the force scale; with q = 1e4 and E = 1e6 the
# relative pressure errors left are ~1e-12 (round-off of sums over the
# segments): 1e-9 leaves a margin and fails for any discretization error (the
# linear NTS mismatch error is 6e-2)
ROUND_OFF = 1e-9

PATCHES = [{"n_top": 5, "n_bottom": 4},                                   # non-matching
           {"n_top": 5, "n_bottom": 4, "offset": 0.13, "top_width": 0.8},  # master overhangs
           {"n_top": 7, "n_bottom": 4, "offset": -0.1, "top_width": 1.3}]  # slave overhangs


@pytest.mark.parametrize("element", ["tri2", "quad2"])
@pytest.mark.parametrize("method", ["mortar", "mortar-dual"])
@pytest.mark.parametrize("patch", PATCHES, ids=["plain", "master_overhang", "slave_overhang"])
def test_non_matching_quadratic_patch_passes_to_round_off(element, method, patch):
    r = run_scene("patch", params={"element": element, **patch}, method=method)
    m = r["metrics"]
    assert r["converged"]
    assert m["pressure_error"] < ROUND_OFF
    assert m["contact_force_error"] < ROUND_OFF
    assert m["support_reaction_error"] < ROUND_OFF
    assert m["unsupported_pressure"] < ROUND_OFF
    # every surface node, vertices and mid nodes, is a slave node
    n_el = patch["n_top"]
    assert m["n_overlap"] <= 2 * n_el + 1


@pytest.mark.parametrize("element", ["tri2", "quad2"])
def test_matching_quadratic_patch_passes_with_nts(element):
    # NTS with the consistent tributary weights (L/6, 2L/3, L/6): node on node
    m = run_scene("patch", params={"element": element, "n_top": 4, "n_bottom": 4},
                  method="nts")["metrics"]
    assert m["pressure_error"] < ROUND_OFF
    assert m["support_reaction_error"] < ROUND_OFF


def _orders_module():
    spec = importlib.util.spec_from_file_location("orders", ROOT / "benchmarks" / "quadratic" / "orders.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


#: Hertz at a / R = 0.002 (load 0.0056), small strain, rigid base: the floor of the
#: contact on the current configuration against linear theory lies below the errors
#: of these levels
HERTZ = {"load": 0.0056}
#: four levels each, over the same range of dofs (tri2 has ~4x the dofs of tri1 at
#: equal h: 7e3 to 3e4 dofs for tri2 at -3..0, 2.5e3 to 2e4 for tri1 at -2..1)
LEVELS = {"tri1": (-2, -1, 0, 1), "tri2": (-3, -2, -1, 0)}


@pytest.fixture(scope="module")
def hertz_rows():
    orders = _orders_module()
    return orders, {el: [orders.run(el, r, "mortar-dual", HERTZ["load"]) for r in levels]
                    for el, levels in LEVELS.items()}


@pytest.mark.parametrize("element", ["tri1", "tri2"])
def test_hertz_pressure_orders(hertz_rows, element):
    """The L2 error of the pressure profile falls like h^1 for both elements: the
    square-root edge of the Hertz pressure, p ~ (a - |x|)^(1/2), limits the
    interpolation error in L2 to O(h) whatever the degree.  The order fitted over
    four levels (least squares) must lie in [0.4, 1.6] about that 1 (measured
    0.82 for tri1 and 0.74 for tri2 over five levels; the band is wide because the
    edge falls at a different place inside an element at each level, which
    scatters single-level orders from 0.1 to 1.3)."""
    orders, rows = hertz_rows
    l2 = orders.fitted_order(rows[element], "l2", "h")
    assert 0.4 <= l2 <= 1.6
    # the peak pressure (x = 0, where p is smooth) converges too
    assert rows[element][-1]["peak"] < rows[element][0]["peak"]


def test_hertz_quadratic_newton_rate():
    """Once the active set settles Newton converges quadratically: the relative
    residual r_{k+1} <= 1e3 r_k^2 wherever 1e-12 < r_{k+1} and r_k < 1e-4 (a
    tangent with a relative error e converges linearly at rate ~e, which fails
    this for any e > 1e-5 at r_k ~ 1e-8)."""
    setup, _, _ = build_scene("hertz", {"element": "tri2", "refine": -1,
                                        "kinematics": "small", **HERTZ}, "mortar-dual")
    res = solve(setup.model, 1)
    r = np.asarray(res.steps[0].residual_norms, dtype=float)
    r = r / r[0]
    checked = 0
    for r0, r1 in zip(r[:-1], r[1:]):
        if r0 < 1e-4 and r1 > 1e-12:
            assert r1 <= 1e3 * r0 ** 2
            checked += 1
    assert checked >= 1  # the rate was seen at least once
    assert r[-1] < 1e-10


@pytest.mark.parametrize("element", ["tri2", "quad2"])
@pytest.mark.parametrize("dual", [False, True])
def test_tie_of_quadratic_parts_passes_the_patch_test(element, dual):
    """Two quadratic blocks glued on non-matching meshes (4 and 5 elements), nu = 0,
    pulled uniformly: the tie traction is the uniform stress (to the round-off of
    the solve, rtol 1e-10 of the force scale: 1e-9 relative), the weak jump zero,
    and the two sides' tie forces balance."""
    import skfem
    from skfem_mortar import Dirichlet, Model, NeoHooke, Solid, TiePair, solve
    from skfem_mortar.contact.surfaces import ContactSurface

    def block(y0, nx, name):
        cls = skfem.MeshQuad if element.startswith("quad") else skfem.MeshTri
        m = cls.init_tensor(np.linspace(0, 1, nx + 1), np.linspace(y0, y0 + 0.5, 3))
        m = m.with_boundaries({"bottom": lambda x: np.isclose(x[1], y0),
                               "top": lambda x: np.isclose(x[1], y0 + 0.5)})
        return Solid(m, NeoHooke(E=100.0, nu=0.0), element=element, name=name)

    lower, upper = block(0.0, 4, "lower"), block(0.5, 5, "upper")
    tie = TiePair(ContactSurface.from_solid(upper, "bottom"), ContactSurface.from_solid(lower, "top"),
                  dual=dual)
    corner = int(np.argmin(np.hypot(*lower.X)))
    model = Model([lower, upper, tie, Dirichlet(lower, lower.dofs_on("bottom", "y")),
                   Dirichlet(lower, lower.dofs_at_nodes([corner], "x")),
                   Dirichlet(upper, upper.dofs_on("top", "y"), 0.05)])
    res = solve(model, 1)
    d = tie.tie_data(res.z)
    t = d["traction"][1, d["tied"]]
    assert np.ptp(t) < 1e-9 * np.abs(t).max()
    assert np.abs(d["jump"]).max() < 1e-12          # a length against O(1) coordinates
    fs, fm = tie.forces(res.z)
    assert np.abs(fs.sum(axis=1) + fm.sum(axis=1)).max() < 1e-12 * np.abs(fs).max()


def test_study_takes_the_element_as_an_axis(tmp_path):
    from skfem_mortar.app.study import run_study
    rows = run_study(["patch"], tmp_path, methods=["mortar-dual"], repeat=1,
                     sets={"element": "quad1,quad2", "n_top": "5", "n_bottom": "4"})
    assert sorted(r["param.element"] for r in rows) == ["quad1", "quad2"]
    assert all(r["status"] == "ok" for r in rows)
    assert "param.element" in (tmp_path / "results.csv").read_text().splitlines()[0]


def test_the_docs_example_runs_and_passes_the_patch_test(capsys):
    """docs/quadratic.md's example: quad2 blocks on non-matching meshes under a
    pressure of 10: every slave node reads 10 (round-off, as above)."""
    import re
    text = (ROOT / "docs" / "quadratic.md").read_text()
    (code,) = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    scope: dict = {}
    exec(compile(code, "docs/quadratic.md", "exec"), scope)
    p = scope["pair"].contact_data(scope["result"].z)["pressure"]
    assert p.size == 11
    np.testing.assert_allclose(p, 10.0, rtol=ROUND_OFF)
