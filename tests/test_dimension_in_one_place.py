"""House rule "dimension in one place" (issue 34): no module of ``contact/`` compares a
``.dim`` with an integer literal, outside the cell table and the segmentations.

What differs between curves and faces is picked by a cell's surface kind
(:mod:`skfem_mortar.contact.surface_kinds`); the dimension and the element order live
where cells are made.  The check is on the syntax tree: ``x.dim == 2``, ``c.dim != 1``,
``1 < cell.dim`` and the like (either side) are found; ``cell.dim + 1`` or a dict keyed
by dimension are not comparisons.
"""
from __future__ import annotations

import ast
import pathlib

import skfem_mortar.contact as contact

ROOT = pathlib.Path(contact.__file__).parent

#: modules that may compare a dimension, and why
ALLOWED = {
    "cells.py": "the cell table itself",
    "cell_map.py": "the reference-to-physical map of a cell row",
    "normals.py": "shape checks of nodal normals over a cell row",
    "curves.py": "check_line: the line cells' input check",
    "projection.py": "closest point in a cell's own coordinates: a closed form on lines",
    "line_points.py": "the 2D segmentation (integration points of lines)",
    "mortar_quadratic_segmentation.py": "the 2D segmentation's input check",
    "segmentation3d.py": "the 3D segmentation",
    "dual3d.py": "the 3D dual space's input check on face cells",
    "integration_points.py": "the layout of a segmentation's integration points",
    "segmentation.py": "the segmentation registry (by dimension)",
    "surface_kinds.py": "the kind of a cell: curves or faces, by dimension",
}


def _is_dim(node: ast.AST) -> bool:
    return isinstance(node, ast.Attribute) and node.attr == "dim"


def _is_int(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and type(node.value) is int


def dim_comparisons(path: pathlib.Path) -> list[int]:
    """Line numbers of comparisons of a ``.dim`` with an integer literal in ``path``."""
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(_is_dim(a) for a in sides) and any(_is_int(a) for a in sides):
                out.append(node.lineno)
    return out


def test_finder_finds_dimension_tests(tmp_path):
    """The finder sees both sides and chained comparisons, and not arithmetic."""
    probe = tmp_path / "probe.py"
    cases = {"a.dim == 2": True, "1 != c.cell.dim": True, "0 < c.dim < 3": True,
             "c.dim + 1": False, "c.ndim == 2": False, "c.dim == d": False}
    for src, found in cases.items():
        probe.write_text(src + "\n")
        assert bool(dim_comparisons(probe)) is found, src


def test_no_dimension_branch_outside_cells_and_segmentations():
    found = {p.name: dim_comparisons(p) for p in sorted(ROOT.glob("*.py"))}
    bad = {k: v for k, v in found.items() if v and k not in ALLOWED}
    assert not bad, f"compare .dim with a literal only in {sorted(ALLOWED)}; ask surface_kinds: {bad}"
    unused = sorted(k for k in ALLOWED if k not in found)
    assert not unused, f"no such module: {unused}"
