"""The segmentation protocol (contact/segmentation.py): integration cells, origins, registry."""
from __future__ import annotations

import types

import numpy as np
import pytest

from skfem_mortar.contact import segmentation as sgm
from skfem_mortar.contact.cells import cell_type
from skfem_mortar.contact.mortar_method import Mortar
from skfem_mortar.contact.mortar_quadratic_segmentation import nodal_normals, segment_lines


def chain(n, f, x0, x1, k):
    """``n`` cells on ``y = f(x)`` from ``x0`` to ``x1``; ``k = 3``: line3 (start, end, mid)."""
    xv = np.linspace(x0, x1, n + 1)
    X, Y, seg = list(xv), list(f(xv)), []
    for i in range(n):
        if k == 3:
            xm = 0.5 * (xv[i] + xv[i + 1]) + 0.1 * (xv[i + 1] - xv[i]) * np.sin(7.0 * i)
            X.append(xm)
            Y.append(f(xm))
            seg.append([i, i + 1, n + 1 + i])
        else:
            seg.append([i, i + 1])
    return np.array([X, Y], float), np.array(seg)


def pair(ks, km):
    """A slave arc (outward normal down) over a curved master (normal up), partly covered."""
    xs, ss = chain(5, lambda x: 1.02 - np.sqrt(1.0 - x * x), -0.3, 0.3, ks)
    xm, sm = chain(4, lambda x: 0.05 * x * x - 0.01 * x + 0.005, 0.17, -0.41, km)
    return xs, ss, xm, sm


def _cells(ks, km):
    return tuple(cell_type("line3" if k == 3 else "line2") for k in (ks, km))


def _master_point(xm, sm, e_m, eta, km):
    """``x_m(eta)`` on the master cells (line2 or line3 shape functions)."""
    N = cell_type("line3" if km == 3 else "line2").shape(eta[None, :])   # (k, n)
    return np.einsum("an,ina->in", N, xm[:, sm[e_m]])


@pytest.mark.parametrize("ks,km", [(2, 2), (3, 3), (2, 3), (3, 2)])
def test_integration_cells_record_their_vertices_and_origins(ks, km):
    """Every end point is a slave vertex (xi = -1 or 1) or a projected master vertex
    (xi_m = -1 or 1, the one ``src`` names); a slave vertex's master coordinate is
    where its nodal normal line meets the master cell (distance to that line below
    1e-12: Newton converged to round-off on unit-size data)."""
    xs, ss, xm, sm = pair(ks, km)
    sg = segment_lines(xs, ss, xm, sm, _cells(ks, km), frozen=False)
    assert sg.n > 4
    org = sg.origin
    slave_end = org == sgm.SLAVE_VERTEX
    assert slave_end.any() and (~slave_end).any()
    np.testing.assert_array_equal(np.abs(sg.xi[slave_end]), 1.0)
    np.testing.assert_array_equal(sg.xi_m[~slave_end], np.where(sg.src[~slave_end] == 0,
                                                                -1.0, 1.0))
    n = nodal_normals(xs, ss)
    for col in (0, 1):
        at = slave_end[:, col]
        node = ss[sg.e_s[at], col]                      # xi = -1: start, 1: end
        x_m = _master_point(xm, sm, sg.e_m[at], sg.xi_m[at, col], km)
        d = x_m - xs[:, node]
        assert np.abs(d[0] * n[1, node] - d[1] * n[0, node]).max() < 1e-12
    xi_s, xi_m = sg.vertices()
    assert xi_s.shape == xi_m.shape == (sg.n, 2, 1)


def test_the_two_line_segmentations_agree_on_straight_cells():
    """On line2 cells the closed-form segmentation and the Newton one give the same
    integration cells, origins and master coordinates (1e-12: Newton's round-off)."""
    xs, ss, xm, sm = pair(2, 2)
    from skfem_mortar.contact import mortar_quadratic_segmentation as mqs
    from skfem_mortar.contact import mortar_segmentation as ms
    a = ms.segment(xs, ss, xm, sm, frozen=False)
    b = mqs.segment(xs, ss, xm, sm, frozen=False)
    np.testing.assert_array_equal(a.e_s, b.e_s)
    np.testing.assert_array_equal(a.src, b.src)
    np.testing.assert_allclose(a.xi, b.xi, atol=1e-12)
    np.testing.assert_allclose(a.xi_m, b.xi_m, atol=1e-12)


@pytest.mark.parametrize("segmentation", ["iteration", "step"])
def test_a_registered_segmentation_is_the_one_the_method_uses(monkeypatch, segmentation):
    """A segmentation registered for the slave cell type is what Mortar segments with,
    under both policies (here the built-in one, counted)."""
    calls = []

    def counted(*args, **kw):
        calls.append(kw.get("frozen"))
        return segment_lines(*args, **kw)
    monkeypatch.setitem(sgm.SEGMENTATIONS, "line3", counted)
    xs, ss, xm, sm = pair(3, 3)
    s = types.SimpleNamespace(segments=ss, n_nodes=xs.shape[1], cell="line3")
    m = types.SimpleNamespace(segments=sm, n_nodes=xm.shape[1], cell="line3")
    meth = Mortar(s, m, multiplier_space="dual", segmentation=segmentation)
    meth.begin_step(xs, xm, True)
    ev = meth.evaluate(xs, xm, np.ones(xs.shape[1]), True)
    assert ev.info["n_segments"] > 0
    assert calls == ([True] if segmentation == "step" else [False])


def test_registry_refusals(monkeypatch):
    line2, tri3 = cell_type("line2"), cell_type("tri3")
    with pytest.raises(ValueError, match="one dimension"):
        sgm.segmentation_for((line2, tri3))
    # a dimension without a default (surfaces have one once contact.segmentation3d
    # is imported: taken away here)
    monkeypatch.delitem(sgm.DEFAULTS, 2, raising=False)
    with pytest.raises(ValueError, match="dimension 2"):
        sgm.segmentation_for((tri3, tri3))
    with pytest.raises(ValueError, match="callable"):
        sgm.register_segmentation("line2", 3)
    with pytest.raises(ValueError, match="registered cell types"):
        sgm.register_segmentation("line7", segment_lines)
    assert sgm.segmentation_for((line2, cell_type("line3"))) is segment_lines


def test_kernel_cells_are_checked():
    """Connectivity that does not have its cell's node count, or a cell a kernel
    does not evaluate, is refused naming the parameter."""
    xs, ss, xm, sm = pair(2, 2)
    with pytest.raises(ValueError, match="seg_s must have shape"):
        sgm.line_cells(ss, sm, ("line3", "line2"))
    with pytest.raises(ValueError, match="master cells must be one of"):
        sgm.check_kernel_cells((cell_type("line2"), cell_type("tri3")), ("line2",), "k")
