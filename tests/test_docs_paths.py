"""Nothing in the package, the README, the docs, the examples or the notebooks
points outside the repository.

Scanned: ``skfem_mortar/**/*.py``, ``README.md``, ``docs/**/*.{md,rst,py}``
(not the build's output), ``examples/*`` and ``notebooks/*.ipynb``. Refused:
paths of the machine the project was written on, the names of background
documents that are not in the repository, ``http(s)://`` links (a paper is
cited as text: authors and year), Markdown and reST links or directives whose
target resolves outside the repository or to no file, and repository paths
named in the text (``docs/methods.rst``, ``benchmarks/...``) that do not exist.

Also here, because the docs build is a separate CI step (``.ci/docs``): the
API reference lists every public name, and every example has the title
docstring the gallery needs.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: written by the docs build, not sources
GENERATED = ("_build", "generated", "auto_examples", "sg_execution_times.rst")

#: strings that name something outside the repository (case-insensitive)
FORBIDDEN = ("../shared", "/work/", "shared/docs", "benchmarks section", "benchmarks.md",
             "formulation.md")
URL = re.compile(r"\bhttps?://", re.I)
#: [text](target) and ![alt](target) in Markdown
MD_LINK = re.compile(r"!?\[[^\]\n]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
#: reST directives that name a file
RST_FILE = re.compile(r"^\s*\.\.\s+(?:image|figure|include|literalinclude|csv-table)::\s*(\S+)",
                      re.M)
#: :doc:`target` or :doc:`title <target>`
RST_DOC = re.compile(r":doc:`(?:[^`<]*<)?([^`>]+)>?`")
#: a repository path named in the text: a top-level folder of the project, then a file
REPO_PATH = re.compile(r"(?<![\w./-])((?:docs|tests|examples|benchmarks|notebooks|skfem_mortar|\.ci)"
                       r"/[\w./-]*\w\.(?:py|md|rst|txt|json|png|ipynb|toml|csv))\b")


def _sources() -> list[Path]:
    files = sorted((ROOT / "skfem_mortar").rglob("*.py"))
    files.append(ROOT / "README.md")
    for ext in ("md", "rst", "py"):
        files += [p for p in sorted(DOCS.rglob(f"*.{ext}"))
                  if not p.relative_to(DOCS).parts[0] in GENERATED]
    files += sorted(p for p in (ROOT / "examples").rglob("*") if p.is_file()
                    and p.suffix in (".py", ".rst", ".txt", ".md"))
    files += sorted((ROOT / "notebooks").rglob("*.ipynb"))
    return [p for p in files if ".ipynb_checkpoints" not in p.parts and "__pycache__" not in p.parts]


SOURCES = _sources()


def _rel(path: Path) -> str:
    return str(path.relative_to(ROOT))


def _inside(target: Path) -> bool:
    try:
        target.resolve().relative_to(ROOT)
        return True
    except ValueError:
        return False


def test_the_scan_sees_the_project():
    # guards the scan itself: a wrong root or glob would make every test below pass
    names = {_rel(p) for p in SOURCES}
    for expected in ("README.md", "skfem_mortar/contact/mortar.py", "docs/architecture.md",
                     "docs/conf.py", "docs/formulation.rst", "examples/hertz.py",
                     "notebooks/01_block.ipynb"):
        assert expected in names, expected


@pytest.mark.parametrize("path", SOURCES, ids=_rel)
def test_no_outside_paths_or_links(path):
    text = path.read_text(encoding="utf-8")
    lower = text.lower()
    found = [s for s in FORBIDDEN if s in lower]
    assert not found, f"{_rel(path)} names {found}: point at a file of the repository instead"
    urls = [text[m.start():m.start() + 60].split()[0] for m in URL.finditer(text)]
    assert not urls, (f"{_rel(path)} links outside the repository: {urls} "
                      "(cite papers as text: authors and year)")


def _targets(path: Path, text: str) -> list[tuple[str, Path]]:
    """(as written, resolved path) of every file link of a Markdown or reST file."""
    out = []
    if path.suffix == ".md" or path.suffix == ".ipynb":
        for m in MD_LINK.finditer(text):
            target = m.group(1).split("#")[0]
            if target and not target.startswith(("mailto:", "#")):
                out.append((m.group(1), path.parent / target))
    if path.suffix in (".rst", ".py", ".txt"):
        for m in RST_FILE.finditer(text):
            target = m.group(1)
            # Sphinx reads a leading "/" as the docs source folder
            out.append((target, DOCS / target[1:] if target.startswith("/") else path.parent / target))
    return out


@pytest.mark.parametrize("path", [p for p in SOURCES if p.suffix in (".md", ".rst", ".ipynb", ".txt")
                                  or (p.suffix == ".py" and "skfem_mortar" not in p.parts)],
                         ids=_rel)
def test_file_links_resolve_inside_the_repository(path):
    text = path.read_text(encoding="utf-8")
    for written, target in _targets(path, text):
        if URL.match(written):
            continue  # refused by test_no_outside_paths_or_links
        assert _inside(target), f"{_rel(path)}: {written!r} points outside the repository"
        assert target.exists(), f"{_rel(path)}: {written!r} names no file"


def _doc_exists(name: str) -> bool:
    if name.startswith("auto_examples/"):   # the gallery's page of examples/NAME.py
        rest = name.split("/", 1)[1]
        return rest == "index" or (ROOT / "examples" / f"{rest}.py").is_file()
    return any((DOCS / f"{name}{ext}").is_file() for ext in (".rst", ".md"))


@pytest.mark.parametrize("path", [p for p in SOURCES if p.suffix in (".rst", ".md")
                                  and DOCS in p.parents], ids=_rel)
def test_doc_references_name_pages(path):
    # the docs pages all live in docs/ itself, so a relative :doc: is relative to it
    for m in RST_DOC.finditer(path.read_text(encoding="utf-8")):
        name = m.group(1).strip().lstrip("/")
        assert _doc_exists(name), f"{_rel(path)}: :doc:`{m.group(1)}` names no page"


@pytest.mark.parametrize("path", SOURCES, ids=_rel)
def test_repository_paths_in_the_text_exist(path):
    missing = sorted({m.group(1) for m in REPO_PATH.finditer(path.read_text(encoding="utf-8"))
                      if not (ROOT / m.group(1)).exists()})
    assert not missing, f"{_rel(path)} names files that are not in the repository: {missing}"


def test_the_checks_catch_what_they_should(tmp_path):
    # each rule against a line that breaks it, so a broken pattern cannot pass silently
    assert URL.search("see https://example.org")
    assert "../shared" in "equations in `../shared/docs/formulation.md`".lower()
    md = DOCS / "x.md"
    assert [w for w, _ in _targets(md, "![pic](../../outside.png) [a](architecture.md#x)")] == \
        ["../../outside.png", "architecture.md#x"]
    assert not _inside(DOCS / "../../outside.png")
    assert _inside(DOCS / "architecture.md")
    assert [w for w, _ in _targets(DOCS / "x.rst", ".. image:: /figure.png\n")] == ["/figure.png"]
    assert RST_DOC.findall(":doc:`methods` and :doc:`the gallery <auto_examples/index>`") == \
        ["methods", "auto_examples/index"]
    assert _doc_exists("methods") and _doc_exists("auto_examples/hertz")
    assert not _doc_exists("auto_examples/no_such_example") and not _doc_exists("no_such_page")
    assert REPO_PATH.findall("see ``docs/robustness.md``, section 0; DIR/x.pvd") == \
        ["docs/robustness.md"]


def test_api_reference_lists_every_public_name():
    import skfem_mortar

    api = (DOCS / "api.rst").read_text(encoding="utf-8")
    listed = set(re.findall(r"^\s{3}~?([\w.]+)\s*$", api, re.M))
    for name, module in skfem_mortar._EXPORTS.items():
        full = f"skfem_mortar.{module}.{name}"
        assert full in listed, f"docs/api.rst does not list {full}"


@pytest.mark.parametrize("path", sorted((ROOT / "examples").glob("*.py")), ids=_rel)
def test_example_starts_with_a_titled_docstring(path):
    # sphinx-gallery needs a module docstring whose first line is the title, underlined
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
    assert doc, f"{_rel(path)} has no module docstring (the gallery needs one)"
    title, underline = doc.split("\n")[:2]
    assert title.strip() and set(underline) == {"="} and len(underline) >= len(title), _rel(path)


def test_the_notebooks_are_stored_with_their_outputs():
    """A reader sees the notebooks as they ran (the README's test command runs
    them again, with --nbmake): every code cell that ran has an execution count,
    and each notebook shows something."""
    import json

    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        nb = json.loads(path.read_text())
        code = [c for c in nb["cells"] if c["cell_type"] == "code" and "".join(c["source"]).strip()]
        assert code and all(c.get("execution_count") for c in code), path.name
        assert any(c.get("outputs") for c in code), path.name
