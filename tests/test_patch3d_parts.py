"""patch3d's parts before the 3D contact pair: the blocks, their footprint on the lower
mesh's grid lines, non-matching interfaces, trapezoids, the exact state (each block
solved alone against it) and the readings."""
import math

import numpy as np
import pytest

from skfem_mortar.core.dirichlet import Dirichlet
from skfem_mortar.core.model import Model
from skfem_mortar.loads.pressure3d import FollowerPressure3D
from skfem_mortar.scenes import Scene
from skfem_mortar.scenes._patch3d import (PAIRINGS, PARAMS, build_bodies, derived,
                                         displacement_error, exact_patch3d, patch_metrics)
from skfem_mortar.solver.newton import NewtonOptions
from skfem_mortar.solver.stepping import solve

DEFAULTS = {p.name: p.default for p in PARAMS}

#: a homogeneous state on these meshes (up to 1,500 dofs), Newton to rtol 1e-13: the
#: exact stretch comes from nested brentq solves (xtol 1e-15 on s, the law's own on l),
#: measured at most 1.7e-12 (neo-Hooke) and 3e-15 (SVK); 1e-10 still fails a miss of
#: a patch test (1e-4 and more)
EXACT = 1e-10


def _top_nodes(body, tag):
    mesh = body.mesh
    return np.unique(mesh.facets[:, mesh.boundaries[tag]])


def test_footprint_edges_on_lower_grid_lines_and_meshes_non_matching():
    parts = build_bodies(DEFAULTS)
    lo, hi = parts.footprint
    assert (lo, hi) == (1 / 8, 7 / 8)
    low = parts.lower.mesh
    covered = low.p[:, _top_nodes(parts.lower, "covered")]
    # the covered faces are whole cells of the lower mesh spanning the footprint
    assert covered[:2].min() == pytest.approx(lo, abs=1e-15)
    assert covered[:2].max() == pytest.approx(hi, abs=1e-15)
    up = parts.upper.mesh.p[:, _top_nodes(parts.upper, "bottom")]
    assert np.allclose(up[2], 0.5) and np.allclose(covered[2], 0.5)
    # non-matching: most upper interface nodes are no lower node
    d = np.linalg.norm(up[:, :, None] - covered[:, None, :], axis=0).min(axis=1)
    assert np.mean(d > 1e-3) > 0.5
    # the covered and uncovered faces tile the lower top: areas (hi - lo)^2 and the rest
    for tag, area in (("covered", (hi - lo) ** 2), ("uncovered", 1 - (hi - lo) ** 2)):
        f = low.p[:, low.facets[:, low.boundaries[tag]]]
        a = 0.5 * np.linalg.norm(np.cross(f[:, 1] - f[:, 0], f[:, 2] - f[:, 0], axis=0), axis=0)
        if f.shape[1] == 4:  # quad faces: twice a corner triangle of a parallelogram
            a *= 2.0
        assert a.sum() == pytest.approx(area, rel=1e-13)


@pytest.mark.parametrize("slave", ["upper", "lower"])
def test_slave_choice_names_the_footprint_on_either_side(slave):
    parts = build_bodies({**DEFAULTS, "slave": slave})
    names = {parts.slave[1], parts.master[1]}
    assert names == {"bottom", "covered"}
    assert (parts.slave[0] is parts.upper) == (slave == "upper")


def test_distort_makes_trapezoids_with_parallel_sides_along_x():
    parts = build_bodies({**DEFAULTS, "distort": 0.3})
    mesh = parts.upper.mesh
    f = mesh.p[:, mesh.facets[:, mesh.boundaries["bottom"]]]       # (3, 4, n)
    # corners in cyclic order around each face
    c = f.mean(axis=1, keepdims=True)
    ang = np.arctan2(f[1] - c[1], f[0] - c[0])
    f = np.take_along_axis(f, np.argsort(ang, axis=0)[None], axis=1)
    skew = np.linalg.norm(f[:, 0] + f[:, 2] - f[:, 1] - f[:, 3], axis=0)
    assert skew.max() > 0.1 / 4 and np.mean(skew > 1e-12) > 0.5   # not parallelograms
    # the two sides along x stay parallel: the y-lines are not moved
    assert np.all(np.isin(np.round(f[1], 12), np.round(np.linspace(1 / 8, 7 / 8, 5), 12)))
    # the footprint's edges and mid-planes stay on their planes
    parts0 = build_bodies(DEFAULTS)
    assert np.allclose(np.sort(mesh.p[0, mesh.p[0] < 0.13]), np.sort(
        parts0.upper.mesh.p[0, parts0.upper.mesh.p[0] < 0.13]))


def _solve_alone(parts, exact, block):
    """One block with the other replaced by what it does to it: the lower block with
    its footprint loaded by the same pressure, the upper block with its bottom held
    at the exact ``u_z``."""
    up, low = parts.upper, parts.lower
    if block == "lower":
        items = [it for it in parts.items if it is low or getattr(it, "body", None) is low]
        items.append(FollowerPressure3D(low, exact["pressure"], "covered", name="footprint"))
    else:
        items = [it for it in parts.items if it is up or getattr(it, "body", None) is up]
        bottom = up.dofs_on("bottom", "z")
        items.append(Dirichlet(up, bottom, float(exact["displacement"](
            np.array([0.0, 0.0, 0.5]))[2]), name="bottom"))
    return solve(Model(items, geometry="3d"), n_steps=2, newton=NewtonOptions(rtol=1e-13))


@pytest.mark.parametrize("element", PAIRINGS)
@pytest.mark.parametrize("law,kinematics", [("neo-hooke", "finite"), ("svk", "finite"),
                                            ("neo-hooke", "small")])
def test_each_block_alone_takes_the_exact_state(element, law, kinematics):
    params = {**DEFAULTS, "element": element, "law": law, "kinematics": kinematics,
              "distort": 0.3 if element == "hex1" else 0.0}
    parts, exact = build_bodies(params), exact_patch3d(params)
    for block in ("lower", "upper"):
        r = _solve_alone(parts, exact, block)
        body = getattr(parts, block)
        uh = body.u(r.z)[body.node_dofs]
        ue = exact["displacement"](body.X)
        assert np.abs(uh - ue).max() / np.abs(ue).max() < EXACT, block
        if block == "lower":   # the rollers carry the pressure over the current top
            reaction = body.reaction(r.residual(), parts.support)
            assert reaction == pytest.approx(exact["support_reaction"], rel=EXACT)
        else:                  # the bottom carries what contact will: p l^2 A
            reaction = body.reaction(r.residual(), body.dofs_on("bottom", "z"))
            assert reaction == pytest.approx(exact["contact_force"], rel=EXACT)


def test_small_strain_exact_state_is_the_closed_form():
    # linear elasticity: E eps = -p (1 - nu eps)^2, the smaller root in magnitude
    E, nu, p = 2.0, 0.3, 0.1
    exact = exact_patch3d({**DEFAULTS, "E": E, "nu": nu, "pressure": p,
                           "kinematics": "small"})
    a, b, c = p * nu * nu, E - 2 * p * nu, p          # p nu^2 eps^2 + (E - 2 p nu) eps + p
    eps = (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)
    assert exact["axial"] - 1.0 == pytest.approx(eps, rel=1e-13)
    assert exact["lateral"] - 1.0 == pytest.approx(-nu * eps, rel=1e-13)


def test_exact_state_refuses_a_crushing_pressure():
    with pytest.raises(ValueError, match="'pressure'"):
        exact_patch3d({**DEFAULTS, "law": "svk", "pressure": 0.5})


def test_readings_are_zero_at_the_exact_answer_and_see_a_miss():
    parts, exact = build_bodies(DEFAULTS), exact_patch3d(DEFAULTS)
    n = 25
    p = np.full(n, exact["pressure"])
    f = np.array([0.0, 0.0, exact["contact_force"]])
    m = patch_metrics(exact, p, f, -f, exact["support_reaction"], 0.0)
    for key in ("pressure_error", "force_balance", "contact_force_error",
                "support_reaction_error"):
        assert m[key] == 0.0, key
    p[3] *= 1.0 + 1e-6
    m = patch_metrics(exact, p, f, -0.9 * f, exact["support_reaction"], 0.0)
    assert m["pressure_error"] == pytest.approx(1e-6, rel=1e-6)
    assert m["force_balance"] == pytest.approx(0.1, rel=1e-12)
    z = np.zeros(sum(b.n_dofs for b in (parts.upper, parts.lower)))
    parts.upper.offset, parts.lower.offset = 0, parts.upper.n_dofs
    assert displacement_error(parts, exact, z) == pytest.approx(1.0)


def test_derived_refuses_odd_counts_and_a_small_footprint():
    def bad(**over):
        scene = Scene("patch3d_parts", "", PARAMS, build=lambda v, m: None,
                      derived=derived)
        with pytest.raises(ValueError) as e:
            scene.resolve({k: str(v) for k, v in over.items()})
        return str(e.value)
    assert "n_lower" in bad(n_lower=7)
    assert "n_upper" in bad(n_upper=5)
    assert "margin" in bad(n_lower=4, margin=2)
