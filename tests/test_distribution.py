"""The distribution's configuration (issue 19, item 2): licence metadata, one
source of the version, dependencies that are all imported (the heavy ones
lazily), and an sdist that holds what the tests need.  Building the archives
is ``.ci/wheel``'s job (too slow for the suite)."""
from __future__ import annotations

import ast
import os
import re
from pathlib import Path

import pytest

import skfem_mortar

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "skfem_mortar"
tomllib = pytest.importorskip("tomllib")  # Python >= 3.11 (the suite runs on 3.11+)


@pytest.fixture(scope="module")
def project() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())


def _name(requirement: str) -> str:
    """The distribution name of a requirement string (``dask[distributed]>=1`` -> dask)."""
    return re.match(r"[A-Za-z0-9._-]+", requirement).group(0).lower().replace("_", "-")


#: distribution name -> the module it is imported as, where the two differ
IMPORT_NAME = {"scikit-fem": "skfem"}

#: the tools of the dev extra: run by the developer, never imported by the package
#: (shapely: the tests' independent polygon intersection)
TOOLS = {"pytest", "pytest-xdist", "nbmake", "ipykernel", "shapely"}


def _imports(path: Path) -> list[tuple[str, bool]]:
    """Top-level module of every import in ``path`` and whether it is at module
    level (False: inside a function or class, i.e. lazy)."""
    tree = ast.parse(path.read_text(), str(path))
    top = {id(n) for n in tree.body}
    # an import under `if TYPE_CHECKING:` or `try:` at module level counts as module level
    for n in tree.body:
        if isinstance(n, (ast.If, ast.Try)):
            top |= {id(m) for m in ast.walk(n)}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name.split(".")[0], id(node) in top) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            out.append((node.module.split(".")[0], id(node) in top))
    return out


@pytest.fixture(scope="module")
def imported() -> dict[str, set[bool]]:
    """Module -> {at module level?} over every import in the package."""
    seen: dict[str, set[bool]] = {}
    for path in PACKAGE.rglob("*.py"):
        for mod, at_top in _imports(path):
            seen.setdefault(mod, set()).add(at_top)
    return seen


def test_licence_metadata_is_pep_639(project):
    build = project["build-system"]["requires"]
    assert "setuptools>=77" in build  # the first setuptools that reads `license-files`
    meta = project["project"]
    assert meta["license"] == "BSD-3-Clause" and meta["license-files"] == ["LICENSE"]
    assert not [c for c in meta.get("classifiers", []) if c.startswith("License ::")]
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("BSD 3-Clause License") and "Neither the name" in text


def test_the_version_has_one_source(project):
    assert "version" not in project["project"] and "version" in project["project"]["dynamic"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {
        "attr": "skfem_mortar.__version__"}
    # setuptools reads the attribute without importing: it must be a literal
    tree = ast.parse((PACKAGE / "__init__.py").read_text())
    literal = [n.value.value for n in tree.body if isinstance(n, ast.Assign)
               and [t.id for t in n.targets if isinstance(t, ast.Name)] == ["__version__"]
               and isinstance(n.value, ast.Constant)]
    assert literal == [skfem_mortar.__version__]
    assert re.fullmatch(r"\d+\.\d+\.\d+((a|b|rc|\.dev)\d+)?", skfem_mortar.__version__)
    assert f"## [{skfem_mortar.__version__}]" in (ROOT / "CHANGELOG.md").read_text()


def test_no_invented_project_urls(project):
    """The project has no public home yet: no URLs rather than made-up ones."""
    assert "urls" not in project["project"]


def test_every_declared_dependency_is_imported(project, imported):
    meta = project["project"]
    declared = [_name(r) for r in meta["dependencies"]]
    # dev and docs are tools around the package (pytest, sphinx), not parts of it
    extras = [_name(r) for name, reqs in meta["optional-dependencies"].items()
              for r in reqs if name not in ("dev", "docs")]
    dev = {_name(r) for r in meta["optional-dependencies"]["dev"]}
    # ipywidgets: the one dev entry the package looks for; skfem-mortar: the dev
    # extra pulls [distributed], so the README's install runs every test
    assert dev - TOOLS == {"ipywidgets", "skfem-mortar"}
    for dist in declared + extras:
        assert IMPORT_NAME.get(dist, dist) in imported, f"{dist} is declared but never imported"
    # ipywidgets is looked for (importlib.util.find_spec), not imported by name
    assert '"ipywidgets"' in (PACKAGE / "solver" / "observers.py").read_text()


def test_every_third_party_import_is_declared(project, imported):
    """The other way round: what the package imports is the standard library,
    itself, or declared (a bare install must not miss a module)."""
    import sys

    meta = project["project"]
    declared = {IMPORT_NAME.get(_name(r), _name(r)) for r in meta["dependencies"]}
    extras = {IMPORT_NAME.get(_name(r), _name(r)) for reqs in
              meta["optional-dependencies"].values() for r in reqs}
    third = {m for m in imported if m not in sys.stdlib_module_names and m != "skfem_mortar"}
    assert third <= declared | extras, third - declared - extras
    # an extra is never imported at module level: a bare install imports every module
    for mod in (extras - declared) & set(imported):
        assert imported[mod] == {False}, f"{mod} (an extra) is imported at module level"


@pytest.mark.parametrize("heavy", ["pyvista", "vtk", "matplotlib", "dask", "meshio", "tqdm"])
def test_heavy_parts_are_imported_lazily(imported, heavy):
    """Imported only inside the functions that draw, write, distribute or
    show progress (a run needs none of them: tests/test_exports.py)."""
    assert imported.get(heavy, {False}) == {False}, f"{heavy} imported at module level"


def _manifest_files() -> set[str]:
    """The files MANIFEST.in adds to the sdist (setuptools' own evaluation of it)."""
    from setuptools.command.egg_info import FileList

    here = os.getcwd()
    os.chdir(ROOT)
    try:
        files = FileList()
        files.allfiles = []  # the checkout's files, without .git and virtual environments
        for top, dirs, names in os.walk("."):
            dirs[:] = [d for d in dirs if d == ".ci" or not d.startswith(".")]
            files.allfiles += [os.path.join(top, n)[2:] for n in names]
        for line in (ROOT / "MANIFEST.in").read_text().splitlines():
            line = line.split("#", 1)[0].strip()
            if line:
                files.process_template_line(line)
        return {f.replace(os.sep, "/") for f in files.files}
    finally:
        os.chdir(here)


def test_the_sdist_holds_what_the_tests_need():
    files = _manifest_files()
    need = ["README.md", "LICENSE", "CHANGELOG.md", "pyproject.toml", ".ci/run", ".ci/wheel"]
    for folder in ("tests", "docs", "examples", "notebooks"):
        need += [p.relative_to(ROOT).as_posix() for p in (ROOT / folder).rglob("*")
                 if p.is_file() and "__pycache__" not in p.parts
                 and ".ipynb_checkpoints" not in p.parts]
    # the benchmark scripts the tests import (by path: tests/test_extremes_table.py)
    tests_text = "".join(p.read_text() for p in (ROOT / "tests").glob("*.py"))
    scripts = set(re.findall(r'"benchmarks"\s*/\s*"([\w.]+\.py)"', tests_text))
    assert "extremes_table.py" in scripts  # the scan finds them
    need += [f"benchmarks/{s}" for s in scripts]
    missing = [f for f in need if f not in files]
    assert not missing, missing
    assert not [f for f in files if f.startswith("benchmarks/kratos/")]  # third-party data
    assert not [f for f in files if "__pycache__" in f or f.endswith(".pyc")]


def test_the_wheel_script_builds_installs_and_collects():
    script = (ROOT / ".ci" / "wheel").read_text()
    assert os.access(ROOT / ".ci" / "wheel", os.X_OK)
    for step in ("-m build", "pip install -q \"$WHEEL\"", "skfem-mortar\" demo",
                 "figure.png", "--collect-only"):
        assert step in script, step
