"""A cell type and a segmentation registered from a test file: ``line2x2``.

``line2x2`` has three nodes (start, middle, end) and piecewise-linear geometry
through the middle node: line3's column count, and not line3.  A kernel that read
the cell type from the connectivity's columns would integrate it as a parabola
(with line3's node order, start, end, mid, even through the wrong nodes).

What holds now: the cell and its segmentation register (the segmentation splits
line2x2 cells, slave and master, into their line2 halves, so every integration cell
lies in one smooth piece); the mortar kernels' values-only parts read its row
(tributary weights and supports by its shape functions and composite rule, the
crosspoint merge along its edge); the fast curved kernel's monomials, read from the
rows, refuse it (it is no polynomial on [-1, 1]), so the mortar methods evaluate it
with the one kernel (contact/mortar_kernel.py), whose dual basis sums D_e, M_e over
the cell's integration cells; and the contact patch test passes on line2x2 surfaces
with NTS, mortar and mortar-dual through the unchanged pair and spaces, its VTU and
CSV outputs read back.
"""
from __future__ import annotations

import csv
import types

import meshio
import numpy as np
import pytest

import skfem_mortar.scenes.patch as patch_scene
from skfem_mortar.app.runner import run_scene
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.contact.surfaces import ContactSurface

from skfem_mortar.contact import segmentation as sgm
from skfem_mortar.contact.cells import CELLS, CellType, cell_type, line_quadrature, register_cell
from skfem_mortar.contact.mortar_support import merge_matrix
from skfem_mortar.contact.mortar_support import multiplier_support, tributary_weights
from skfem_mortar.contact.mortar_quadratic_segmentation import monomials, segment_lines


def _shape(xi):
    x = np.asarray(xi, dtype=float)[0]
    left, right = np.minimum(x, 0.0), np.maximum(x, 0.0)
    return np.stack([-left, 1.0 + left - right, right])


def _dshape(xi):
    x = np.asarray(xi, dtype=float)[0]
    neg = (x < 0.0) * 1.0
    return np.stack([-neg, 2.0 * neg - 1.0, 1.0 - neg])[:, None]


def _d2shape(xi):
    x = np.asarray(xi, dtype=float)[0]
    return np.zeros((3, 1, 1) + x.shape)


def _quadrature(degree):
    """Gauss on each half of [-1, 1] (the shape functions are linear on each)."""
    x, w = line_quadrature(degree)
    return np.hstack([(x - 1.0) * 0.5, (x + 1.0) * 0.5]), np.hstack([w, w]) * 0.5


LINE2X2 = CellType("line2x2", 1, 3, (0, 2), ((0, 1, 2),),
                   np.array([[-1.0, 0.0, 1.0]]), _shape, _dshape, _d2shape, _quadrature, 1)


def _halves(seg: np.ndarray) -> np.ndarray:
    """The line2 halves (start, middle), (middle, end) of line2x2 cells, cell by cell."""
    return np.stack([seg[:, [0, 1]], seg[:, [1, 2]]], 1).reshape(-1, 2)


def _whole(e: np.ndarray, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A half's cell and coordinates back on its line2x2 cell: ``xi = (xi_half -+ 1)/2``."""
    second = e % 2
    return e // 2, (xi + np.where(second, 1.0, -1.0)[:, None]) * 0.5


def segment_line2x2(xs, seg_s, xm, seg_m, cells, pairs=None, margin=None, frozen=True,
                    reach=0.0, mirror=()):
    """The line2 segmentation of the halves of line2x2 cells (on either side), mapped
    back: every integration cell lies in one half (one smooth piece).  ``src`` names the
    master cell's local node whose projection ends the cell (0, 1 or 2 on a line2x2
    master: a half's vertices are nodes (0, 1) or (1, 2))."""
    line2 = cell_type("line2")
    split = cells[1].name == "line2x2"
    sg = segment_lines(xs, _halves(seg_s), xm, _halves(seg_m) if split else seg_m,
                       (line2, line2), margin=margin, frozen=frozen, reach=reach,
                       mirror=mirror)
    e_s, xi = _whole(sg.e_s, sg.xi)
    e_m, xi_m, src = sg.e_m, sg.xi_m, sg.src
    if split:
        src = np.where(src >= 0, src + (e_m % 2)[:, None], src)
        e_m, xi_m = _whole(e_m, xi_m)
    n = len(seg_s)
    elem_xi = np.tile([1.0, -1.0], (n, 1))
    np.minimum.at(elem_xi[:, 0], e_s, xi[:, 0])
    np.maximum.at(elem_xi[:, 1], e_s, xi[:, 1])
    return sgm.Segmentation(e_s=e_s, e_m=e_m, xi=xi, src=src, elem_xi=elem_xi,
                            elem_node=np.full((n, 2), -1), frozen=frozen, xi_m=xi_m)


@pytest.fixture
def line2x2(monkeypatch):
    """``line2x2`` and its segmentation registered for one test, then removed."""
    register_cell(LINE2X2)
    monkeypatch.setitem(sgm.SEGMENTATIONS, "line2x2", segment_line2x2)
    yield LINE2X2
    CELLS.pop("line2x2")


def _surfaces():
    """A flat slave of 4 line2x2 cells (9 nodes) above a flat line2 master (5 cells)."""
    xs = np.vstack([np.linspace(0.0, 1.0, 9), np.full(9, 0.01)])
    ss = np.array([[2 * i, 2 * i + 1, 2 * i + 2] for i in range(4)])
    xm = np.vstack([np.linspace(1.1, -0.1, 6), np.zeros(6)])
    sm = np.array([[i, i + 1] for i in range(5)])
    s = types.SimpleNamespace(segments=ss, n_nodes=9, cell="line2x2", X=xs)
    m = types.SimpleNamespace(segments=sm, n_nodes=6, cell="line2", X=xm)
    return s, m


def test_line2x2_registers_and_its_segmentation_covers_its_halves(line2x2):
    """The table takes the row (its checks: identity at the nodes, shapes); the
    registered segmentation is found for it, and its integration cells of a flat
    slave fully over a flat master cover every slave cell exactly once."""
    assert cell_type("line2x2") is line2x2 and line2x2.n_nodes == cell_type("line3").n_nodes
    seg = sgm.segmentation_for((line2x2, cell_type("line2")))
    assert seg is segment_line2x2
    s, m = _surfaces()
    sg = seg(s.X, s.segments, m.X, m.segments, (line2x2, cell_type("line2")))
    covered = np.bincount(sg.e_s, weights=sg.xi[:, 1] - sg.xi[:, 0], minlength=4)
    np.testing.assert_allclose(covered, 2.0, rtol=1e-14)   # the length of [-1, 1]


def _line2x2_surfaces(monkeypatch):
    """The patch scene's surfaces as line2x2 cells: two neighbouring line2 facets of a
    quad1 block make one cell (start, middle, end), so the surface has the line2
    surface's functions and its cells have line3's column count."""
    orig = ContactSurface.from_solid

    def from_solid(body, boundary, name=""):
        s = orig(body, boundary, name=name)
        seg = s.segments
        assert s.cell.name == "line2" and len(seg) % 2 == 0
        assert (seg[1::2, 0] == seg[::2, 1]).all()          # chained, start to end
        cells = np.column_stack([seg[::2, 0], seg[::2, 1], seg[1::2, 1]])
        return ContactSurface(body, s.nodes, cells, name=s.name, cell="line2x2")
    monkeypatch.setattr(patch_scene, "ContactSurface",
                        types.SimpleNamespace(from_solid=from_solid))


def _patch(method, params, tmp_path=None):
    summary, result, setup = run_scene("patch", {"element": "quad1", **params}, method,
                                       out=tmp_path, return_result=True)
    pair = next(it for it in setup.model.items if isinstance(it, ContactPair))
    return summary, result, setup.model, pair


#: non-matching for mortar (6 slave cells on 4); NTS passes the patch test on matching
#: meshes only (the scene's preflight says so), 4 on 4
PATCH = {"mortar": {"n_top": 6, "n_bottom": 4}, "mortar-dual": {"n_top": 6, "n_bottom": 4},
         "nts": {"n_top": 4, "n_bottom": 4}}


@pytest.mark.parametrize("method", ["nts", "mortar", "mortar-dual"])
def test_line2x2_patch_test(line2x2, method, monkeypatch, tmp_path):
    """The contact patch test on line2x2 surfaces through the unchanged pair, spaces and
    the one mortar kernel: the uniform pressure to 1e-10 of itself (round-off of a
    solve at 1e4: measured 8e-14), the same displacements as the line2 surfaces (the same
    functions; 1e-10 of the largest: round-off, measured below 1e-13 for mortar and
    NTS; mortar-dual's basis is biorthogonal per line2x2 cell instead of per line2 cell,
    both exact here), and the VTU and CSV outputs read back."""
    params = PATCH[method]
    s0, r0, m0, p0 = _patch(method, params)
    _line2x2_surfaces(monkeypatch)
    s1, r1, m1, p1 = _patch(method, params, tmp_path)
    assert p1.slave.cell is line2x2 and p1.master.cell is line2x2
    assert s1["converged"] and s1["metrics"]["pressure_error"] <= 1e-10
    u0, u1 = r0.z[:m0.n_u], r1.z[:m1.n_u]
    assert np.abs(u1 - u0).max() <= 1e-10 * np.abs(u0).max()
    with open(tmp_path / "contact.csv") as f:
        rows = list(csv.DictReader(f))            # the last step's slave nodes
    assert len(rows) == p1.slave.n_nodes == params["n_top"] + 1
    np.testing.assert_allclose([float(r["pressure"]) for r in rows], 1e4, rtol=1e-10)
    np.testing.assert_allclose([float(r["gap"]) for r in rows], 0.0, atol=1e-12)
    vtu = sorted((tmp_path / "contact").glob("*.vtu"))
    mesh = meshio.read(vtu[-1])
    assert mesh.points.shape[0] == p1.slave.n_nodes
    # line2x2 has no VTK cell: written as the straight pieces of its edge
    assert sum(len(c.data) for c in mesh.cells) == 2 * len(p1.slave.segments)


def test_line2x2_weights_and_supports_come_from_its_row(line2x2):
    """The mortar kernels' tributary weights and supports read the cell's shape
    functions and composite rule: the hat functions' integrals over each half,
    ``l_1/2, (l_1 + l_2)/2, l_2/2``, where a parabola through the nodes differs."""
    xs = np.array([[0.0, 0.3, 1.0], [0.0, 0.2, 0.0]])
    seg = np.array([[0, 1, 2]])
    l1, l2 = np.hypot(0.3, 0.2), np.hypot(0.7, 0.2)
    np.testing.assert_allclose(tributary_weights(xs, seg, line2x2, 1),
                               [l1 / 2, (l1 + l2) / 2, l2 / 2], rtol=1e-14)
    sg = sgm.Segmentation(e_s=np.array([0, 0]), e_m=np.array([0, 0]),
                          xi=np.array([[-1.0, 0.0], [0.0, 0.5]]), src=np.full((2, 2), -1),
                          elem_xi=np.array([[-1.0, 0.5]]), elem_node=np.full((1, 2), -1))
    # the first half whole, the second from xi = 0 to 0.5 (N_3 = xi there: l2 / 8)
    np.testing.assert_allclose(multiplier_support(xs, seg, sg, line2x2, 1),
                               [l1 / 2, l1 / 2 + l2 * 0.375, l2 * 0.125], rtol=1e-14)


def test_line2x2_merge_follows_its_edge(line2x2):
    """A merged start node goes to the middle node, column 1 (its neighbour along the
    edge), not to column 2 as the line3 layout (start, end, mid) would send it; a
    merged middle node in halves to both ends."""
    T = merge_matrix(np.array([[True, False, False], [False, True, False]]), line2x2)
    np.testing.assert_array_equal(T[0], [[0, 0, 0], [1, 1, 0], [0, 0, 1]])
    np.testing.assert_array_equal(T[1], [[1, 0.5, 0], [0, 0, 0], [0, 0.5, 1]])
    with pytest.raises(ValueError, match="merged"):
        merge_matrix(np.zeros((1, 2), bool), line2x2)


def test_the_curved_kernels_monomials_come_from_the_rows_and_refuse_line2x2(line2x2):
    """The curved mortar kernel writes its geometry in the monomials of the cell's row
    (exact for line2, line3: the Taylor coefficients at 0 are dyadic); line2x2 is no
    polynomial on [-1, 1] and is refused naming it, not integrated as a parabola."""
    np.testing.assert_array_equal(monomials(cell_type("line2")), [[0.5, -0.5, 0], [0.5, 0.5, 0]])
    np.testing.assert_array_equal(monomials(cell_type("line3")),
                                  [[0, -0.5, 0.5], [0, 0.5, 0.5], [1, 0, -1]])
    with pytest.raises(ValueError, match="line2x2"):
        monomials(line2x2)
