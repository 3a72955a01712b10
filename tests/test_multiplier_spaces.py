"""The multiplier spaces: the built-ins' readings, the dual coefficients, the registry."""
from __future__ import annotations

import numpy as np
import pytest

from skfem_mortar.contact.methods import make_method
from skfem_mortar.contact.multiplier_spaces import (DualSpace, MultiplierSpace, StandardSpace,
                                                    make_space, register_space,
                                                    registered_spaces, space_for,
                                                    unregister_space)
from skfem_mortar.scenes import get_scene

AREA = np.array([0.5, 1.0, 0.0, 0.25])  # a node without a tributary length reads as 1


def test_the_built_in_methods_read_through_their_spaces():
    setup = get_scene("patch").build(get_scene("patch").resolve({}), "nts")
    pair = next(it for it in setup.model.items if hasattr(it, "discretization"))
    names = {m: space_for(make_method(m, pair.slave, pair.master)).name
             for m in ("nts", "mortar", "mortar-dual")}
    assert names == {"nts": "nodal", "mortar": "standard", "mortar-dual": "dual"}
    assert {"nodal", "standard", "dual"} <= set(registered_spaces())


@pytest.mark.parametrize("name", ["nodal", "standard", "dual"])
def test_pressure_and_multipliers_are_inverse(name):
    """``multipliers(pressure(lam)) = lam`` where a node has a tributary length
    (to round-off: one division and one multiplication, 2 ulp)."""
    s = make_space(name)
    lam = np.array([1.0, -2.0, 3.0, 0.7])
    back = s.multipliers(s.pressure(lam, AREA), AREA)
    on = AREA > 0
    assert np.allclose(back[on], lam[on], rtol=4e-16, atol=0)


def test_the_readings_of_force_and_traction_multipliers():
    nodal, standard = make_space("nodal"), make_space("standard")
    lam, g = np.array([1.0, 2.0, 3.0, 4.0]), np.array([0.1, 0.2, 0.3, 0.4])
    area = np.where(AREA > 0, AREA, 1.0)
    assert np.array_equal(nodal.pressure(lam, AREA), lam / area)
    assert np.array_equal(standard.pressure(lam, AREA), lam)
    assert np.array_equal(nodal.gap_length(g, AREA), g)
    assert np.array_equal(standard.gap_length(g, AREA), g / area)
    h = np.mean(AREA[AREA > 0])
    assert nodal.row_scale(AREA) == 1.0 and standard.row_scale(AREA) == h
    assert nodal.complementarity(3.0, AREA) == 3.0
    assert standard.complementarity(3.0, AREA) == 3.0 / (h * h)
    assert nodal.p_ref(2.0, AREA) == 2.0 * h and standard.p_ref(2.0, AREA) == 2.0 * h ** 2
    assert nodal.bound_moves and not standard.bound_moves
    assert standard.row_scale(np.zeros(3)) == 1.0   # no tributary length yet: unit scale


def test_dual_coefficients_are_biorthogonal_and_the_kernels():
    """``A_e = D_e M_e^-1`` on a line2 cell over ``[lo, hi]``: ``A M = D``
    (``int Phi_A N_B = delta_AB int N_A``), ``[[2, -1], [-1, 2]]`` on the whole cell, and
    the kernel's entry-by-entry inverse (``cell_coefficients``, what it runs on jets) equal
    to the solve, to round-off (1e-13: a 2x2 solve of a matrix of condition <= 1e3 on
    these parts)."""
    xi, w = np.polynomial.legendre.leggauss(4)
    parts = [(-1.0, 1.0), (-0.3, 0.8), (0.2, 0.9)]
    D, M = [], []
    for lo, hi in parts:
        x = 0.5 * (lo + hi) + 0.5 * (hi - lo) * xi
        N = np.array([(1 - x) / 2, (1 + x) / 2])
        ww = 0.5 * (hi - lo) * w
        M.append((N * ww) @ N.T)
        D.append(np.diag(N @ ww))
    A = DualSpace.coefficients(np.array(D), np.array(M))
    assert np.allclose(A[0], [[2.0, -1.0], [-1.0, 2.0]], rtol=0, atol=1e-13)
    for k, (lo, hi) in enumerate(parts):
        assert np.allclose(A[k] @ M[k], D[k], rtol=0, atol=1e-13)
        C = DualSpace.cell_coefficients([D[k][0, 0], D[k][1, 1]],
                                        {(a, b): M[k][a, b] for a in range(2) for b in range(a, 2)})
        assert np.allclose([[C[a, b] for b in range(2)] for a in range(2)], A[k], rtol=0,
                           atol=1e-13)
    assert np.allclose(A[0], [[2.0, -1.0], [-1.0, 2.0]], rtol=0, atol=1e-13)
    assert np.array_equal(DualSpace.transformation(3), np.eye(3))


def test_the_registry_refuses_what_does_not_fit():
    class Mine(StandardSpace):
        name = "mine"
    register_space(Mine())
    try:
        with pytest.raises(ValueError, match="registered already"):
            register_space(Mine())
        assert make_space("mine").kind == "traction"
    finally:
        unregister_space("mine")
    with pytest.raises(ValueError, match="multiplier_space must be one of"):
        make_space("mine")

    class Bad(MultiplierSpace):
        name, kind = "bad", "stress"
    with pytest.raises(ValueError, match="kind must be 'force' or 'traction'"):
        register_space(Bad())
    with pytest.raises(ValueError, match="MultiplierSpace"):
        register_space(object())


def test_a_method_naming_an_unknown_space_is_refused():
    from skfem_mortar.contact.discretization import register_method, unregister_method
    from skfem_mortar.contact.nts import NTS

    def factory(slave, master, **options):
        d = NTS(slave, master, **options)
        d.multiplier_space = "nowhere"
        return d
    setup = get_scene("patch").build(get_scene("patch").resolve({}), "nts")
    pair = next(it for it in setup.model.items if hasattr(it, "discretization"))
    register_method("nts-nowhere", factory)
    try:
        with pytest.raises(ValueError, match="multiplier_space must be one of"):
            make_method("nts-nowhere", pair.slave, pair.master)
    finally:
        unregister_method("nts-nowhere")


@pytest.mark.parametrize("k", [2, 3, 4])
def test_cell_coefficients_in_jets_are_the_arrays_and_differentiate(k):
    """DualSpace.cell_coefficients (the kernels' entry: upper triangles of M_e, jets)
    equals coefficients (np.linalg.solve) to round-off (1e-13 on well-conditioned
    SPD M_e), and its first derivatives are those of central differences (h = 1e-6:
    truncation h^2 ~ 1e-12, rounding eps/h ~ 1e-10 on entries O(1))."""
    from skfem_mortar.contact.jets import Jet
    rng = np.random.default_rng(k)
    B = rng.standard_normal((4, k, k))
    M = B @ np.swapaxes(B, 1, 2) + k * np.eye(k)
    d = rng.uniform(0.5, 1.5, (4, k))
    ref = DualSpace.coefficients(d[:, :, None] * np.eye(k), M)
    up = [(a, b) for a in range(k) for b in range(a, k)]
    A = DualSpace.cell_coefficients(list(d.T), {ab: M[:, ab[0], ab[1]] for ab in up})
    got = np.array([[A[a, b] for b in range(k)] for a in range(k)]).transpose(2, 0, 1)
    np.testing.assert_allclose(got, ref, atol=1e-13)
    nv = len(up) + k                      # variables: the entries of M's triangle, then d
    Mj = {ab: Jet.variable(M[:, ab[0], ab[1]], i, nv, False) for i, ab in enumerate(up)}
    dj = [Jet.variable(d[:, a], len(up) + a, nv, False) for a in range(k)]
    Aj = DualSpace.cell_coefficients(dj, Mj)
    h = 1e-6
    for i, ab in enumerate(up + [None] * k):
        def at(step):
            Ms = {key: M[:, key[0], key[1]] + (step if key == ab else 0.0) for key in up}
            ds = [d[:, a] + (step if ab is None and i == len(up) + a else 0.0) for a in range(k)]
            return DualSpace.cell_coefficients(ds, Ms)
        Ap, Am = at(h), at(-h)
        for key in Aj:
            np.testing.assert_allclose(Aj[key].g[i], (Ap[key] - Am[key]) / (2 * h), atol=1e-8)
    with pytest.raises(ValueError, match="k must be 2 or more"):
        DualSpace.cell_coefficients([1.0], {})
