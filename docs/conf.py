"""Sphinx configuration of the skfem-mortar documentation.

Build (what ``.ci/docs`` runs, warnings as errors)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The gallery executes every script of ``examples/`` (sphinx-gallery) with
``SKFEM_MORTAR_QUICK=1`` set, and shows the pictures they write
(:mod:`gallery_scraper`).
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS))   # gallery_scraper
sys.path.insert(0, str(ROOT))   # the package of this checkout, before any installed copy

# the examples read it to run at reduced sizes; pictures off-screen, no display
os.environ["SKFEM_MORTAR_QUICK"] = "1"
os.environ.setdefault("MPLBACKEND", "agg")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

import skfem_mortar  # noqa: E402


def _demo_pictures() -> None:
    """``docs/figure.png`` and ``docs/pressure.png`` (the README's and the index
    page's pictures), drawn anew by the demo at every build."""
    import shutil
    import tempfile

    from skfem_mortar.app.demo import run_demo

    with tempfile.TemporaryDirectory() as tmp:
        run_demo(Path(tmp) / "demo", progress=False)
        for name in ("figure.png", "pressure.png"):
            shutil.copyfile(Path(tmp) / "demo" / name, DOCS / name)


_demo_pictures()

project = "skfem-mortar"
author = "the skfem-mortar developers"
copyright = "the skfem-mortar developers"
release = version = skfem_mortar.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints",
                    "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip"]
# ``x`` in a docstring is code
default_role = "literal"

# --- API reference: one page per module, class and function (autosummary)
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"           # the numpydoc Parameters sections state the types
autodoc_preserve_defaults = True
numpydoc_show_class_members = False  # autosummary lists the members
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- Markdown pages (docs/*.md)
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

# --- the gallery of examples/
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r".*\.py$",     # execute every example, not only plot_*.py
    "ignore_pattern": r"__init__\.py",
    "image_scrapers": ("matplotlib", "gallery_scraper.png_scraper"),
    "reset_modules": (),
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "min_reported_time": 0,
    "show_memory": False,
    "show_signature": False,
}

# --- every cross-reference of the hand-written pages resolves
# (the theory pages link each equation to its function; a renamed function
# must fail the build, not leave plain text behind)
_CHECKED_ROLES = {"func", "class", "meth", "mod", "attr", "obj", "exc", "doc"}


def _unresolved(app, env, node, contnode):
    """Warn (an error under ``-W``) for a reference of a hand-written page that
    resolves to nothing; docstrings (the ``generated/`` pages) are not checked."""
    doc = node.get("refdoc", "")
    target = node.get("reftarget", "")
    if doc.startswith(("generated/", "auto_examples/")) or node.get("reftype") not in _CHECKED_ROLES:
        return None
    # the pages name the package's objects in full; a short target on a page
    # comes from a docstring summary (autosummary), which is not checked here
    if node.get("reftype") != "doc" and not target.startswith("skfem_mortar"):
        return None
    from sphinx.util import logging

    logging.getLogger(__name__).warning(
        "unresolved reference %s:%s in %s", node.get("reftype"), node.get("reftarget"), doc,
        location=node)
    return None


def setup(app):
    # after the Python domain has tried (lower priority runs later)
    app.connect("missing-reference", _unresolved, priority=900)


# --- HTML
html_theme = "furo"
html_title = f"skfem-mortar {release}"
html_static_path: list[str] = []
html_show_sourcelink = False
