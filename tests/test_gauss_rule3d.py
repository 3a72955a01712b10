"""The lowest Gauss rule on quad4 faces that are not parallelograms
(contact/points3d.py, ``check_rule``): degree 2 stalls Newton on patch3d's trapezoid
variant (the rule's error jumps where slave and master edges cross) and so does degree
3 (the same 4-point rule), so both are refused there by name, and still taken on parallelograms (where it is exact) and on tri3."""
import numpy as np
import pytest

from skfem_mortar.contact.points3d import AFFINE_TOL, N_GAUSS_BILINEAR, check_rule

SQUARE = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])


def _faces(points):
    """One face of the nodes ``points (k, 3)``: ``(X (3, k), segments (1, k))``."""
    P = np.asarray(points, dtype=float)
    return P.T, np.arange(len(P))[None]


def _sheared(rng):
    """A random parallelogram in space: the square through a random affine map."""
    A = rng.uniform(-1.0, 1.0, (3, 3)) + 2.0 * np.eye(3)
    return SQUARE @ A.T + rng.uniform(-1.0, 1.0, 3)


def _trapezoid(top=0.7):
    return [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5 + top / 2, 1.0, 0.0], [0.5 - top / 2, 1.0, 0.0]]


@pytest.mark.parametrize("side", [0, 1])
@pytest.mark.parametrize("n_gauss", [1, 2, 3])
def test_low_rules_are_refused_on_a_trapezoid_of_either_side(side, n_gauss):
    faces = [_faces(SQUARE), _faces(SQUARE)]
    faces[side] = _faces(_trapezoid())
    with pytest.raises(ValueError, match=rf"n_gauss must be an integer in \[4, 20\].*"
                       rf"{('slave', 'master')[side]} faces.*got {n_gauss}"):
        check_rule(("quad4", "quad4"), n_gauss, tuple(faces), high=20)


def test_low_rules_are_taken_on_parallelograms_and_triangles():
    """Affine faces (random parallelograms in space) and tri3 faces of any shape: the
    integrands are polynomials on each cell, degree 2 integrates them exactly."""
    rng = np.random.default_rng(7)
    for _ in range(50):
        check_rule(("quad4", "quad4"), 1, (_faces(_sheared(rng)), _faces(_sheared(rng))))
    tri = _faces(rng.uniform(-1.0, 1.0, (3, 3)))
    check_rule(("tri3", "quad4"), 2, (tri, _faces(_sheared(rng))))
    check_rule(("tri3", "tri3"), 1, (tri, tri))


def test_the_refusal_starts_at_the_stated_tolerance():
    """The bilinear term measured against the longest diagonal: a trapezoid whose top
    is shorter by 10x the tolerance (relative to the diagonal) is refused, by a tenth of
    it taken (round-off of a parallelogram mesh is far below 1e-10)."""
    d = np.sqrt(2.0)
    check_rule(("quad4", "quad4"), 2, (_faces(_trapezoid(1.0 - 0.1 * AFFINE_TOL * d)),
                                       _faces(SQUARE)))
    with pytest.raises(ValueError, match="n_gauss"):
        check_rule(("quad4", "quad4"), 2, (_faces(_trapezoid(1.0 - 10 * AFFINE_TOL * d)),
                                           _faces(SQUARE)))
    for n_gauss in (N_GAUSS_BILINEAR, 5, 20):
        check_rule(("quad4", "quad4"), n_gauss, (_faces(_trapezoid()), _faces(_trapezoid())))



def _patch(n_gauss, distort):
    from skfem_mortar.app.runner import run_scene
    values = {"n_lower": "4", "n_upper": "2", "margin": "0", "element": "hex1",
              "slave": "lower", "distort": str(distort), "n_gauss": str(n_gauss)}
    return run_scene("patch3d", values, method="mortar-dual")["metrics"]


def test_patch3d_trapezoids_refuse_the_rules_that_stall():
    """patch3d's trapezoid variant with degree 2 or 3 is refused when the pair is made
    (it stalled: check_rule's docstring); without ``distort`` degree 2 is exact (1e-12:
    the patch test's round-off bound)."""
    for n_gauss in (2, 3):
        with pytest.raises(ValueError, match=r"n_gauss must be an integer in \[4, 20\]"):
            _patch(n_gauss, 0.3)
    assert _patch(2, 0.0)["pressure_error"] < 1e-12
