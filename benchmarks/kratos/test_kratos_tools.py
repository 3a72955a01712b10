"""Tests of the Kratos side-by-side tools that need no Kratos (mesh refinement,
error metrics).  Run: ``python -m pytest -q -p no:cacheprovider benchmarks/kratos``."""
from __future__ import annotations

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_meshes as mm  # noqa: E402
from side_by_side import errors, hertz  # noqa: E402


@pytest.fixture(scope="module")
def coarse():
    return mm.read_mdpa(mm.SOURCE)


@pytest.fixture(scope="module")
def fine(coarse):
    return mm.refine(coarse)


def _areas(mesh: mm.Mdpa) -> np.ndarray:
    out = []
    for b in mesh.blocks:
        if b.kind == "Elements":
            p = np.array([[mesh.nodes[n][:2] for n in row] for row in b.conn])
            x, y = p[..., 0], p[..., 1]
            out.append(0.5 * (x * np.roll(y, -1, 1) - np.roll(x, -1, 1) * y).sum(axis=1))
    return np.concatenate(out)


def test_source_mesh_is_the_test_mesh(coarse):
    # the counts of hertz_simple (3556 nodes, 3400 quadrilaterals, 50 line loads,
    # 152 contact nodes: 111 on the arc incl. the bottom point, 41 on the plate)
    c = mm.check(coarse)
    assert (c["nodes"], c["elements"]) == (3556, 3400)
    assert sum(len(b.ids) for b in coarse.blocks if b.kind == "Conditions") == 50
    assert c["contact_nodes"] == 152


def test_refine_counts_and_consistency(coarse, fine):
    c = mm.check(fine)  # raises on unknown nodes, clockwise elements, arc off the circle
    assert c["elements"] == 4 * 3400
    assert sum(len(b.ids) for b in fine.blocks if b.kind == "Conditions") == 2 * 50
    # every contact chain of n nodes gains its n - 1 edge midpoints: 111 -> 221, 41 -> 81
    assert c["contact_nodes"] == 221 + 81
    for old, new in zip(coarse.parts, fine.parts):
        assert len(new.elements) == 4 * len(old.elements)
        assert len(new.conditions) == 2 * len(old.conditions)
        if new.elements or new.conditions:
            # element/condition parts hold exactly their entities' nodes
            conn = {int(n) for b in fine.blocks for i, row in zip(b.ids, b.conn)
                    if (b.kind == "Elements" and int(i) in set(new.elements))
                    or (b.kind == "Conditions" and int(i) in set(new.conditions))
                    for n in row}
            assert set(new.nodes) == conn


def test_refine_approaches_the_exact_area(coarse, fine):
    # the half disk of radius 8 plus the plate 20 x 1; the meshes inscribe the
    # arc by chords, each missing a circular segment of about h^3 / (12 R):
    # halving every arc edge (midpoint on the circle) leaves 2 (1/2)^3 = 1/4
    # of the deficit (0.3: the few long edges far from contact are not yet
    # in the asymptotic range)
    exact = 0.5 * np.pi * mm.RADIUS ** 2 + 20.0 * 1.0
    d0, d1 = exact - _areas(coarse).sum(), exact - _areas(fine).sum()
    assert 0.0 < d1 < 0.3 * d0
    assert (_areas(fine) > 0).all()


def test_arc_midpoints_on_circle(fine):
    contact = next(p for p in fine.parts if "Contact_Part" in p.header)
    xy = np.array([fine.nodes[n][:2] for n in contact.nodes])
    arc = xy[xy[:, 1] > 1.0 + 1e-9]
    # new nodes are exact to the printed round-off of the coarse nodes (5 decimals)
    assert np.abs(np.hypot(*(arc - mm.CENTRE).T) - mm.RADIUS).max() < 1e-5


def test_write_read_roundtrip(fine, tmp_path):
    path = tmp_path / "m.mdpa"
    mm.write_mdpa(fine, str(path))
    back = mm.read_mdpa(str(path))
    assert back.nodes.keys() == fine.nodes.keys()
    # 10 printed decimals
    assert max(abs(back.nodes[n][k] - fine.nodes[n][k]) for n in fine.nodes
               for k in range(2)) < 1e-9
    for b0, b1 in zip(fine.blocks, back.blocks):
        assert (b0.conn == b1.conn).all() and (b0.props == b1.props).all()
    assert [p.nodes for p in back.parts] == [p.nodes for p in fine.parts]


def test_make_rejects_bad_levels(tmp_path):
    with pytest.raises(ValueError, match="levels"):
        mm.make(str(tmp_path), (3,))


def test_errors_on_the_exact_profile():
    ex = hertz()
    a, p0 = ex["half_width"], ex["peak_pressure"]
    h = a / 20.5
    x = np.arange(-40, 41) * h  # nodes at multiples of h, both sides
    p = p0 * np.sqrt(np.clip(1 - (x / a) ** 2, 0, None))
    e = errors(x, p)
    assert abs(e["peak_error"]) < 1e-14       # the node at x = 0 carries p0
    # the last node in compression is at 20 h, the next at 21 h: the half-width
    # midway, 20.5 h = a (round-off of a few ulps)
    assert abs(e["half_width_error"]) < 1e-12
    # nodes at multiples of a / 20, the one at x = a given zero pressure: the
    # last compressed node is at 19 h, the half-width 19.5 h = 0.975 a
    x20 = np.arange(0, 41) * (a / 20)
    p20 = p0 * np.sqrt(np.clip(1 - (x20[:20] / a) ** 2, 0, None))
    e = errors(x20, np.concatenate([p20, np.zeros(21)]))
    assert e["half_width_error"] == pytest.approx(-0.025, abs=1e-12)
    assert abs(e["interior_offset"]) < 1e-14
    e = errors(x, 1.01 * p, offset=0.01)
    assert abs(e["peak_error"]) < 1e-14 and e["peak_error_raw"] == pytest.approx(0.01)
