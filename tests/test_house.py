"""The house (issues 33 and 34): no import circle inside the package, one job per module.

Read from the source, nothing imported: every module's imports (those inside functions
too) and its lines of code (blank lines, comments and docstrings not counted). Both tests
print what they found on failure, and with ``-v`` or ``-s`` on success. There is no
allow-list: a module that grows past the limit is split by job.
"""
import ast
import io
import pathlib
import tokenize

import pytest

import skfem_mortar

ROOT = pathlib.Path(skfem_mortar.__file__).parent

#: the most lines of code of a module, and of a function, anywhere in the package
#: (``contact/`` included since the contact layer's redesign, issue 34)
MODULE_LIMIT = 500
FUNCTION_LIMIT = 80

#: how many of the largest modules and functions the report shows
SHOWN = 5


# --- the counting -----------------------------------------------------------------

def code_lines(source):
    """The numbers of the lines of ``source`` that hold code: not blank, not only a
    comment, not part of a docstring (of the module, a class or a function)."""
    tree = ast.parse(source)
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if (body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
                    and isinstance(body[0].value.value, str)):
                docstrings.update(range(body[0].lineno, body[0].end_lineno + 1))
    skipped = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT,
               tokenize.DEDENT, tokenize.ENCODING, tokenize.ENDMARKER}
    lines = set()
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type not in skipped:
            lines.update(range(tok.start[0], tok.end[0] + 1))
    return lines - docstrings


def sizes(source):
    """``(lines of code of the module, [(lines of code, function name), ...])``; a
    function's count includes what is nested in it."""
    lines = code_lines(source)
    functions = [(sum(1 for n in lines if node.lineno <= n <= node.end_lineno), node.name)
                 for node in ast.walk(ast.parse(source))
                 if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))]
    return len(lines), functions


# --- the imports ------------------------------------------------------------------

def _module_name(path, root):
    parts = path.relative_to(root.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def package_sources(root=ROOT):
    """``{module name: (source, is a package)}`` of every module below ``root``."""
    return {_module_name(p, root): (p.read_text(), p.name == "__init__.py")
            for p in sorted(root.rglob("*.py"))}


def imports(name, source, is_package, known):
    """The modules of ``known`` that module ``name`` imports, anywhere in its source.

    Relative imports are resolved; ``from pkg import x`` imports ``pkg`` and, where ``x``
    is a submodule, ``pkg.x`` too; a name that is no module stands for the nearest
    module above it (``import a.b.C`` -> ``a.b``)."""
    package = name if is_package else name.rpartition(".")[0]
    targets = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            targets += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                frm = ".".join(base + ([node.module] if node.module else []))
            else:
                frm = node.module or ""
            targets += [frm] + [f"{frm}.{alias.name}" for alias in node.names]
    found = set()
    for target in targets:
        while target and target not in known:
            target = target.rpartition(".")[0]
        if target and target != name:
            found.add(target)
    return found


def import_graph(sources):
    """``{module: the package modules it imports}`` of ``{module: (source, is a package)}``."""
    return {name: imports(name, source, is_package, sources)
            for name, (source, is_package) in sources.items()}


def circles(graph):
    """The import circles of ``graph``: its strongly connected sets of more than one
    module (or one that imports itself), each sorted, in sorted order (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1 or v in graph.get(v, ()):
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


# --- the house --------------------------------------------------------------------

def _largest(rows, title):
    rows = sorted(rows, reverse=True)[:SHOWN]
    return "\n".join([f"the {len(rows)} largest {title}:"]
                     + [f"  {n:5d}  {what}" for n, what in rows])


def _show(request, capsys, report):
    if request.config.getoption("verbose") > 0:
        with capsys.disabled():
            print("\n" + report)
    else:
        print(report)  # shown with -s


def test_no_import_circle_in_the_package(request, capsys):
    found = circles(import_graph(package_sources()))
    report = "\n".join([f"{len(found)} import circle(s):"]
                       + [f"  {len(c)}: {' <-> '.join(c)}" for c in found])
    _show(request, capsys, report)
    assert found == [], report


def test_modules_and_functions_are_not_too_long(request, capsys):
    modules, functions = [], []
    for name, (source, _) in package_sources().items():
        module_lines, function_lines = sizes(source)
        modules.append((module_lines, name))
        functions += [(n, f"{name}.{f}") for n, f in function_lines]
    report = "\n".join([_largest(modules, f"modules (limit {MODULE_LIMIT} lines of code)"),
                        _largest(functions, f"functions (limit {FUNCTION_LIMIT} lines of code)")])
    _show(request, capsys, report)
    too_long = ([m for m in modules if m[0] > MODULE_LIMIT]
                + [f for f in functions if f[0] > FUNCTION_LIMIT])
    assert too_long == [], f"too long: {sorted(too_long, reverse=True)}\n{report}"


# --- the counting and the circle finder find what is there ------------------------

SOURCE = '''"""A module docstring
over two lines."""
import os  # a comment after code counts as code

# a comment alone


class A:
    """A class docstring."""

    x = """not a docstring:
    two lines of code"""

    def f(self):
        """A function docstring."""
        # a comment
        return (1,
                2)
'''


def test_code_lines_skip_blank_lines_comments_and_docstrings():
    assert sorted(code_lines(SOURCE)) == [3, 8, 11, 12, 14, 17, 18]
    module_lines, functions = sizes(SOURCE)
    assert module_lines == 7
    assert functions == [(3, "f")]


def test_the_circle_finder_finds_a_circle_through_any_kind_of_import():
    sources = {
        "pkg": ("", True),
        "pkg.a": ("from . import b\n", False),                        # a submodule by name
        "pkg.b": ("def f():\n    from .sub.c import x\n", False),     # inside a function
        "pkg.sub": ("", True),
        "pkg.sub.c": ("import pkg.a.Thing\n", False),                 # a name in a module
        "pkg.d": ("from .a import y\nfrom ..elsewhere import z\n", False),  # imports into it
        "pkg.e": ("from .e import me\n", False),                      # imports itself: no circle
    }
    graph = import_graph(sources)
    assert graph["pkg.a"] == {"pkg", "pkg.b"}
    assert graph["pkg.b"] == {"pkg.sub.c"}
    assert graph["pkg.sub.c"] == {"pkg.a"}
    assert graph["pkg.d"] == {"pkg.a"}
    assert circles(graph) == [["pkg.a", "pkg.b", "pkg.sub.c"]]
    assert circles({"x": {"y"}, "y": {"x"}, "z": {"x"}}) == [["x", "y"]]
    assert circles({"x": {"y"}, "y": set()}) == []


def test_architecture_lists_every_module():
    """docs/architecture.md, "The modules": one line per module of the package, so
    that the tree a reader sees is the tree there is (a new module without its
    line, or a line for a module gone, fails)."""
    import re

    doc = (ROOT.parent / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = doc.split("## The modules", 1)[1].split("\n## ", 1)[0]
    listed = set(re.findall(r"^\| `([\w/]+\.py)` \|", section, re.M))
    present = {p.relative_to(ROOT).as_posix() for p in ROOT.rglob("*.py")}
    assert present - listed == set(), f"modules without a line: {sorted(present - listed)}"
    assert listed - present == set(), f"lines for no module: {sorted(listed - present)}"
