"""The layered layout (docs/architecture.md): every former module path still imports.

A moved module's old path warns (DeprecationWarning) and is the very module object of its
new path, so private names and monkeypatching through the old path keep working. The
former modules ``skfem_mortar.contact`` and ``skfem_mortar.loads`` are packages now that
resolve the old module's names to the same objects. ``import skfem_mortar`` stays lazy.
"""
import importlib
import subprocess
import sys
import warnings

import pytest

MOVED = {
    "model": "core.model", "errors": "core.errors", "coo": "core.coo", "timing": "core.timing",
    "materials": "bodies.materials", "solid": "bodies.solid", "mixed": "bodies.mixed",
    "sri": "bodies.sri", "cable": "bodies.cable", "cable_laws": "bodies.cable_laws",
    "checks": "bodies.checks",
    "traction": "loads.traction",
    "surfaces": "contact.surfaces", "search": "contact.search",
    "discretization": "contact.discretization", "nts": "contact.nts",
    "mortar_method": "contact.mortar_method", "mortar": "contact.mortar",
    "mortar_segmentation": "contact.mortar_segmentation", "jets": "contact.jets",
    "contact_eval": "contact.contact_eval", "active_set": "contact.active_set",
    "preflight": "contact.preflight",
    "newton": "solver.newton", "stepping": "solver.stepping", "linsolve": "solver.linsolve",
    "observers": "solver.observers",
    "contact_output": "output.contact_output", "io": "output.io", "outdir": "output.outdir",
    "plot": "output.plot",
    "runner": "app.runner", "cli": "app.cli", "demo": "app.demo", "study": "app.study",
    "study_report": "app.study_report", "bench": "app.bench",
}

#: former module -> (its new module, the names it offered)
RENAMED = {
    "contact": ("contact.pair", ["ContactPair", "METHODS", "log"]),
    "loads": ("loads.pressure", ["FollowerPressure", "facet_load_matrix"]),
}

#: modules added after the move: they never had a flat path, so they have no shim
NEW = {"contact.tie"}


@pytest.mark.parametrize("old", sorted(MOVED))
def test_old_path_warns_and_is_the_new_module(old):
    new = importlib.import_module(f"skfem_mortar.{MOVED[old]}")
    sys.modules.pop(f"skfem_mortar.{old}", None)
    with pytest.warns(DeprecationWarning,
                      match=rf"skfem_mortar\.{old} moved to skfem_mortar\.{MOVED[old]};"):
        shim = importlib.import_module(f"skfem_mortar.{old}")
    assert shim is new
    assert sys.modules[f"skfem_mortar.{old}"] is new


@pytest.mark.parametrize("old", sorted(RENAMED))
def test_former_module_names_resolve_to_the_same_objects(old):
    new_name, names = RENAMED[old]
    new = importlib.import_module(f"skfem_mortar.{new_name}")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        package = importlib.import_module(f"skfem_mortar.{old}")
    for name in names + list(package.__all__):
        assert getattr(package, name) is getattr(new, name)
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        package.Nope  # noqa: B018


def test_submodules_of_a_former_module_are_not_its_names():
    from skfem_mortar.contact import nts, pair

    assert nts.__name__ == "skfem_mortar.contact.nts"
    assert pair.ContactPair.__module__ == "skfem_mortar.contact.pair"


def test_import_is_lazy_and_old_cli_path_runs():
    """The packages of the former modules load nothing either until a name is asked."""
    code = ("import sys, skfem_mortar, skfem_mortar.contact, skfem_mortar.loads; "
            "print(' '.join(sorted(m for m in sys.modules if m.startswith('skfem_mortar.'))))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True).stdout.split()
    assert loaded == ["skfem_mortar._former", "skfem_mortar.contact", "skfem_mortar.loads"]
    proc = subprocess.run([sys.executable, "-W", "default", "-m", "skfem_mortar.cli", "--help"],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "usage: skfem-mortar" in proc.stdout
    assert "skfem_mortar.cli moved to skfem_mortar.app.cli" in proc.stderr


def test_every_moved_module_has_a_shim():
    import pathlib

    import skfem_mortar

    root = pathlib.Path(skfem_mortar.__file__).parent
    layers = {p.parent.name for p in root.glob("*/__init__.py")} - {"scenes"}
    moved = {f"{layer}.{p.stem}" for layer in layers for p in (root / layer).glob("*.py")
             if p.stem != "__init__"}
    assert moved == set(MOVED.values()) | {new for new, _ in RENAMED.values()} | NEW
