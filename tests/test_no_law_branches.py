"""No module of ``contact/`` outside a friction law's or a multiplier space's own
module names a law or the dual space: the pair and the kernels reach them only
through their protocols (:class:`~skfem_mortar.contact.friction.FrictionLaw`,
:class:`~skfem_mortar.contact.multiplier_spaces.MultiplierSpace`).

What it checks, on the syntax tree of every module of ``skfem_mortar/contact/``
except :data:`OWN` (so docstrings and comments do not count):

* no name (``ast.Name``: a variable, an import alias, ``isinstance(x, Tresca)``),
  attribute (``ast.Attribute``: ``self.dual``, ``friction.Coulomb``), argument or
  keyword (``def f(dual=...)``, ``f(dual=True)``) or imported name spelled
  ``Coulomb``, ``Tresca`` or ``dual``;
* no string constant ``"Coulomb"``, ``"Tresca"``, ``"dual"`` (or one naming them
  as a word, e.g. ``"mortar-dual"``) as an operand of a comparison or as the name
  of a ``getattr``/``hasattr``/``setattr`` call;
* no comparison ``friction is None`` / ``is not None`` / ``== None`` (``friction``
  a name, an attribute such as ``self.friction``, or ``getattr(p, "friction", None)``).
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

CONTACT = Path(__file__).resolve().parents[1] / "skfem_mortar" / "contact"

#: the law's and the spaces' own modules
OWN = {"friction.py", "multiplier_spaces.py"}

NAMES = {"Coulomb", "Tresca", "dual"}
WORD = re.compile(r"(?<![A-Za-z0-9_])(Coulomb|Tresca|dual)(?![A-Za-z0-9_])")


def _named(node: ast.AST) -> str | None:
    """The identifier a node spells, if it is one of :data:`NAMES`."""
    name = None
    if isinstance(node, ast.Name):
        name = node.id
    elif isinstance(node, ast.Attribute):
        name = node.attr
    elif isinstance(node, ast.arg):
        name = node.arg
    elif isinstance(node, ast.keyword):
        name = node.arg
    elif isinstance(node, ast.alias):
        name = (node.asname or node.name).split(".")[-1]
    return name if name in NAMES else None


def _is_friction(node: ast.AST) -> bool:
    """``friction``, ``x.friction`` or ``getattr(x, "friction", ...)``."""
    return ((isinstance(node, ast.Name) and node.id == "friction")
            or (isinstance(node, ast.Attribute) and node.attr == "friction")
            or (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id == "getattr" and len(node.args) > 1
                and isinstance(node.args[1], ast.Constant) and node.args[1].value == "friction"))


def _is_none(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and node.value is None


def _word(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and isinstance(node.value, str) and bool(
        WORD.search(node.value))


def offences(src: str) -> list[str]:
    """Where ``src`` names a law or the dual space (module doc), as ``line: what``."""
    out = []
    for node in ast.walk(ast.parse(src)):
        name = _named(node)
        if name is not None:
            out.append(f"{getattr(node, 'lineno', '?')}: names {name!r}")
        if isinstance(node, ast.Compare):
            operands = [node.left, *node.comparators]
            if any(_word(o) for o in operands):
                out.append(f"{node.lineno}: compares with a string naming a law or dual")
            if any(_is_friction(o) for o in operands) and any(_is_none(o) for o in operands):
                out.append(f"{node.lineno}: friction compared with None")
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id in ("getattr", "hasattr", "setattr") and len(node.args) > 1
                and _word(node.args[1])):
            out.append(f"{node.lineno}: {node.func.id} of an attribute naming a law or dual")
    return out


MODULES = sorted(p.name for p in CONTACT.glob("*.py") if p.name not in OWN)


@pytest.mark.parametrize("module", MODULES)
def test_module_names_no_law_and_no_dual(module):
    assert offences((CONTACT / module).read_text()) == []


@pytest.mark.parametrize("src", [
    "from .friction import Coulomb", "isinstance(f, Tresca)", "x = self.dual",
    "def f(dual=False): pass", "f(dual=True)", "if self.friction is None: pass",
    "if friction is not None: pass", "getattr(p, 'friction', None) is not None",
    "if kind == 'dual': pass",
    "if method != 'mortar-dual': pass", "getattr(d, 'dual', False)"])
def test_the_check_sees_each_form(src):
    """Each form the module doc names is caught (so the check can fail)."""
    assert offences(src)


def test_the_check_ignores_docstrings_and_comments():
    assert offences('"""Coulomb and Tresca, dual."""\n# friction is None\nx = "dual mortar"\n'
                    ) == []
