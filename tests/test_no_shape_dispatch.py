"""No code in ``contact/`` or ``output/`` reads a cell type from an array's shape.

A surface carries its cell type (``surface.cell``); a connectivity's column count
does not identify it (three columns are a quadratic line in 2D and a linear
triangle in 3D; the tests' ``line2x2`` has line3's count and is not line3).  This
AST check finds the comparisons that would dispatch on it: ``.shape[...]``,
``np.shape(...)[...]`` or ``len(...)`` of a connectivity array compared with an
integer literal (or a tuple of them, ``in (2, 3)``).  A connectivity is a name
(or attribute) that reads like one: ``seg``, ``seg_s``, ``segments``, ``conn``,
``cells``, ``elements``, ``facets``, ``t`` (a mesh's element array).
"""
from __future__ import annotations

import ast
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1] / "skfem_mortar"
FOLDERS = ("contact", "output")
CONNECTIVITY = re.compile(r"^(seg\w*|\w*_seg|segments|conn\w*|cells?|elements?|facets|t)$")


def _root_name(node: ast.AST) -> str | None:
    """The last name of ``a.b.seg[...]`` / ``np.asarray(seg)``: what the array is called."""
    while True:
        if isinstance(node, ast.Subscript):
            node = node.value
        elif isinstance(node, ast.Call) and node.args:
            node = node.args[0]
        elif isinstance(node, ast.Attribute):
            return node.attr
        elif isinstance(node, ast.Name):
            return node.id
        else:
            return None


def _count_of_connectivity(node: ast.AST) -> bool:
    """``X.shape[i]``, ``np.shape(X)[i]`` or ``len(X)`` with ``X`` a connectivity."""
    if isinstance(node, ast.Subscript):
        base = node.value
        if isinstance(base, ast.Attribute) and base.attr == "shape":
            name = _root_name(base.value)
        elif (isinstance(base, ast.Call) and isinstance(base.func, ast.Attribute)
              and base.func.attr == "shape" and base.args):
            name = _root_name(base.args[0])
        else:
            return False
    elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
          and node.func.id == "len" and node.args):
        name = _root_name(node.args[0])
    else:
        return False
    return name is not None and CONNECTIVITY.match(name) is not None


def _int_literal(node: ast.AST) -> bool:
    if isinstance(node, ast.Constant):
        return isinstance(node.value, int) and not isinstance(node.value, bool)
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return bool(node.elts) and all(_int_literal(e) for e in node.elts)
    return False


def dispatches(source: str) -> list[int]:
    """Line numbers of comparisons of a connectivity's count with an integer literal."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(_count_of_connectivity(s) for s in sides) and any(_int_literal(s)
                                                                   for s in sides):
                found.append(node.lineno)
    return found


def test_the_check_finds_what_it_looks_for():
    """Each pattern the check exists for is found; counts of other arrays are not."""
    bad = ["seg.shape[1] == 3", "if segments.shape[-1] != 2: pass",
           "k = seg_m.shape[1] not in (2, 3)", "len(seg) == 3", "np.shape(s.segments)[1] == 3",
           "np.asarray(seg).shape[1] == 2", "3 == self.slave.segments.shape[1]"]
    good = ["seg.shape[1] == cell.n_nodes", "x.shape[1] == 2", "points.shape[1] == 2",
            "len(pairs) == 2", "n = seg.shape[1]"]
    for src in bad:
        assert dispatches(src), src
    for src in good:
        assert not dispatches(src), src


@pytest.mark.parametrize("folder", FOLDERS)
def test_no_cell_type_from_connectivity_shape(folder):
    """No module of ``contact/`` or ``output/`` compares a connectivity's column
    count (or length) with an integer literal."""
    offenders = {}
    for path in sorted((ROOT / folder).rglob("*.py")):
        lines = dispatches(path.read_text())
        if lines:
            offenders[str(path.relative_to(ROOT))] = lines
    assert offenders == {}, f"cell type read from an array's shape: {offenders}"
