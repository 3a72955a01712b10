"""The layered layout (docs/architecture.md): the package's top level holds only
``__init__.py`` (the former flat module paths are gone, issue 33), the layers import in
one direction, and ``import skfem_mortar`` stays lazy.
"""
import ast
import importlib.machinery
import pathlib
import subprocess
import sys

import pytest

import skfem_mortar

ROOT = pathlib.Path(skfem_mortar.__file__).parent

#: the former flat module paths (removed in issue 33; CHANGELOG says where each went)
FORMER = ("active_set", "bench", "cable", "cable_laws", "checks", "cli", "contact_eval",
          "contact_output", "coo", "demo", "discretization", "errors", "io", "jets",
          "linsolve", "materials", "mixed", "model", "mortar", "mortar_method",
          "mortar_segmentation", "newton", "nts", "observers", "outdir", "plot", "preflight",
          "runner", "search", "solid", "sri", "stepping", "study", "study_report",
          "surfaces", "timing", "traction")


def test_the_top_level_holds_only_the_package_init():
    assert sorted(p.name for p in ROOT.glob("*.py")) == ["__init__.py"]


@pytest.mark.parametrize("old", FORMER)
def test_a_former_flat_path_is_gone(old):
    # looked up in the package's own folder (an editable install of another
    # checkout would find that checkout's files through its own finder)
    assert importlib.machinery.PathFinder.find_spec(f"skfem_mortar.{old}",
                                                    skfem_mortar.__path__) is None


def test_the_layer_packages_offer_only_their_own_names():
    """``skfem_mortar.contact`` and ``skfem_mortar.loads`` were modules once; they are
    packages now and no longer stand for them: a name of ``contact.pair`` or
    ``loads.pressure`` is imported from there (or from the top level)."""
    import skfem_mortar.contact as contact
    import skfem_mortar.loads as loads

    assert sorted(contact.__all__) == ["BUILTIN_METHODS", "DEFAULT_METHOD"]
    for package, name in ((contact, "ContactPair"), (contact, "METHODS"),
                          (loads, "FollowerPressure"), (loads, "facet_load_matrix")):
        with pytest.raises(AttributeError):
            getattr(package, name)


def test_submodules_of_a_layer_package_import_from_it():
    from skfem_mortar.contact import nts, pair

    assert nts.__name__ == "skfem_mortar.contact.nts"
    assert pair.ContactPair.__module__ == "skfem_mortar.contact.pair"


def test_import_is_lazy_and_the_cli_runs():
    """``import skfem_mortar`` and the layer packages load nothing until a name is asked
    (the command line reads ``BUILTIN_METHODS`` without loading the contact code)."""
    code = ("import sys, skfem_mortar, skfem_mortar.contact, skfem_mortar.loads; "
            "print(' '.join(sorted(m for m in sys.modules if m.startswith('skfem_mortar.'))))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True).stdout.split()
    assert loaded == ["skfem_mortar.contact", "skfem_mortar.loads"]
    proc = subprocess.run([sys.executable, "-W", "error::DeprecationWarning", "-m",
                           "skfem_mortar.app.cli", "--help"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "usage: skfem-mortar" in proc.stdout


#: the layers in import order: a module imports only from its own layer and the
#: layers before it (docs/architecture.md, "The layers")
LAYERS = ("core", "output", "bodies", "loads", "contact", "solver", "scenes", "app")


def _package_imports(path):
    """The ``skfem_mortar`` subpackages a module imports, at top level or inside
    functions (``from ..x import``, ``from skfem_mortar.x import``)."""
    tree = ast.parse(path.read_text())
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level == 2 and node.module:
                found.add(node.module.split(".")[0])
            elif node.level == 0 and (node.module or "").startswith("skfem_mortar."):
                found.add(node.module.split(".")[1])
    return found


def test_the_layers_import_in_one_direction():
    against = []
    for k, layer in enumerate(LAYERS):
        for path in sorted((ROOT / layer).glob("*.py")):
            for target in _package_imports(path) & set(LAYERS):
                if LAYERS.index(target) > k:
                    against.append(f"{layer}/{path.name} -> {target}")
    assert against == []
