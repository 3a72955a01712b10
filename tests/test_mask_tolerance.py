"""The mask tolerance is the multiplier space's, per dimension of the slave cells
(``multiplier_spaces`` module doc, "The masked band"): the kernel masks a slave node
whose support ratio ``r = s_A / w_A`` is at most its space's ``mask_tolerance``.

Lines: a flat line2 slave ``[0, 1]`` in four elements, a flat master from
``0.25 (1 - f)`` on, so the end element ``[0, 0.25]`` is covered over the fraction ``f``
at its far end and its outer node's support ratio is ``r = f^2``
(``s = 0.25 f^2 / 2`` against ``w = 0.25 / 2``).  Faces are checked in a solved body by
``tests/test_partly_projected3d.py`` (every kept node above the faces' tolerance; widths
in the former band masked and exact).
"""
import numpy as np
import pytest

from skfem_mortar.contact import mortar_kernel
from skfem_mortar.contact import mortar_quadratic_segmentation  # noqa: F401 (registers the lines)
from skfem_mortar.contact.multiplier_spaces import (MASK_TOL, StandardSpace, make_space,
                                                    mask_tolerance, register_space,
                                                    registered_spaces, unregister_space)


def _outer_node(frac: float, space):
    xs = np.vstack([np.linspace(1.0, 0.0, 5), np.zeros(5)])     # the outer node last
    xm = np.vstack([[0.25 * (1 - frac), 0.6, 1.2], np.full(3, 0.01)])
    seg = np.column_stack([np.arange(4), np.arange(1, 5)])
    segm = np.column_stack([np.arange(2), np.arange(1, 3)])
    ev = mortar_kernel.evaluate(xs, seg, xm, segm, tangent=False, space=space)
    return ev.area[-1] / (0.25 / 2), bool(ev.mask[-1])


def test_the_builtin_tolerances():
    """Faces: 1e-2 standard, 1e-3 dual (the measured band); lines: 1e-6 for both."""
    assert mask_tolerance("standard", 2) == 1e-2 and mask_tolerance("dual", 2) == 1e-3
    assert mask_tolerance("standard", 1) == mask_tolerance("dual", 1) == MASK_TOL == 1e-6
    assert mask_tolerance(None, 2) == MASK_TOL
    assert mask_tolerance(make_space("nodal"), 2) == MASK_TOL


@pytest.mark.parametrize("frac, kept", [(5e-4, False), (2e-3, True)])
def test_the_kernel_masks_lines_by_the_space(frac, kept):
    """``f = 5e-4``: ``r = 2.5e-7``, masked; ``f = 2e-3``: ``r = 4e-6``, kept (above 1e-6)
    by both spaces."""
    for space in ("standard", "dual"):
        r, inside = _outer_node(frac, space)
        assert r == pytest.approx(frac ** 2, rel=1e-9)
        assert inside == kept == (r > mask_tolerance(space, 1)), (space, r)


class _Coarse(StandardSpace):
    """A registered space of its own tolerance (standard multipliers otherwise)."""

    name = "coarse-mask"
    mask_tolerance = 0.1


def test_a_registered_space_brings_its_own_tolerance():
    register_space(_Coarse())
    try:
        # r = 0.04: kept by standard multipliers, masked at the space's 0.1
        assert _outer_node(0.2, "standard")[1]
        assert not _outer_node(0.2, "coarse-mask")[1]
        assert mask_tolerance(_Coarse(), 1) == mask_tolerance(_Coarse(), 2) == 0.1
    finally:
        unregister_space("coarse-mask")


@pytest.mark.parametrize("bad", [1.0, -1e-3, "1e-2", True, float("nan"), {2: 2.0}])
def test_a_bad_tolerance_is_refused_at_registration(bad):
    class Bad(StandardSpace):
        name = "bad-mask"
        mask_tolerance = bad

    with pytest.raises(ValueError, match="mask_tolerance"):
        register_space(Bad())
    assert "bad-mask" not in registered_spaces()
