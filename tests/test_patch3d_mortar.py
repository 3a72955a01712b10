"""Scene ``patch3d`` solved (issue 38): exact with mortar and mortar-dual on every
pairing, either body as slave, small and finite strain, Gauss rules of degree 2, 5
and 8; the two sides' contact forces cancel; NTS misses by a stated band; the
trapezoid variant at its quadrature error.

The meshes are the smallest non-matching ones (2 lower cells a side under 4 upper
ones, the whole top covered: ``margin=0``), so the set runs in seconds; the default
mesh (8 under 4, crossing grid lines) is measured in the report of this work
(pressure 1.1e-14 on hex1 with mortar)."""
import pytest

from skfem_mortar.app.runner import run_scene
from skfem_mortar.scenes._patch3d import PAIRINGS
from skfem_mortar.solver.newton import NewtonOptions

#: the patch test's round-off: Newton to rtol 1e-13 on about 200 dofs, the exact state
#: from nested brentq solves (each block alone: 1.7e-12, tests/test_patch3d_parts.py);
#: measured 3e-15 to 3e-14 here, the issue asks 1e-12 of the pressure
EXACT = 1e-12
SMALL = {"n_lower": 2, "n_upper": 4, "margin": 0}


def _run(method, **params):
    values = {k: str(v) for k, v in {**SMALL, **params}.items()}
    return run_scene("patch3d", values, method=method,
                     newton=NewtonOptions(rtol=1e-13))["metrics"]


#: each pairing and slave choice at both strains across the two methods (finite strain
#: where pairing index + slave choice is even, small where odd, flipped for mortar-dual)
CASES = [(m, e, s, ("finite", "small")[(i + j + k) % 2])
         for k, m in enumerate(("mortar", "mortar-dual"))
         for i, e in enumerate(PAIRINGS) for j, s in enumerate(("upper", "lower"))]


@pytest.mark.parametrize("method,element,slave,kinematics", CASES)
def test_patch3d_is_exact_with_mortar(method, element, slave, kinematics):
    m = _run(method, element=element, slave=slave, kinematics=kinematics)
    for key in ("pressure_error", "displacement_error", "contact_force_error",
                "support_reaction_error", "force_balance"):
        assert m[key] < EXACT, (key, m)


@pytest.mark.parametrize("n_gauss", [2, 5, 8])
def test_patch3d_is_exact_at_every_gauss_rule(n_gauss):
    """Affine faces: the integrands are polynomials of degree 2 on each plane cell, which
    the rule of degree 2 integrates exactly."""
    m = _run("mortar-dual", element="tet1/hex1", slave="lower", n_gauss=n_gauss)
    assert m["pressure_error"] < EXACT and m["force_balance"] < EXACT, m


def test_patch3d_nts_misses_on_non_matching_meshes():
    """NTS fails the patch test when the coarse face is the slave (its nodal forces land
    on every other master node): measured 18.2 % in pressure here (the band 10 % to 30 %
    states it; 19 % to 52 % on the NTS tests' 4 on 6 meshes, tests/test_nts3d.py); the
    two sides' forces still cancel to round-off."""
    m = _run("nts", element="hex1", slave="lower")
    assert 0.1 < m["pressure_error"] < 0.3, m
    assert m["force_balance"] < EXACT, m


def test_patch3d_trapezoids_at_their_quadrature_error():
    """Trapezoidal quad4 slave faces (``distort``): ``N_A`` and the dual basis are
    rational on the auxiliary plane, so the rule leaves an error that falls with its
    degree: measured 5.6e-7 at degree 5 and 2.7e-12 at 8 (the bounds 1e-5 and 1e-10)."""
    errors = [_run("mortar-dual", element="hex1", n_lower=4, n_upper=2, distort=0.3,
                   slave="lower", n_gauss=g)["pressure_error"] for g in (5, 8)]
    assert errors[1] < 1e-10 < errors[0] < 1e-5, errors
