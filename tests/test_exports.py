"""The public names of ``skfem_mortar``: every one resolves lazily to its module's object."""
import importlib
import subprocess
import sys

import pytest

import skfem_mortar


@pytest.mark.parametrize("name", sorted(skfem_mortar._EXPORTS))
def test_every_export_resolves_to_its_module_object(name):
    module = importlib.import_module(f"skfem_mortar.{skfem_mortar._EXPORTS[name]}")
    assert getattr(skfem_mortar, name) is getattr(module, name)
    assert name in skfem_mortar.__all__


def test_surfaces_are_exported_at_the_top_level():
    from skfem_mortar import ContactSurface, RigidCircle, RigidPlane
    from skfem_mortar.contact import surfaces

    assert (ContactSurface, RigidPlane, RigidCircle) == (
        surfaces.ContactSurface, surfaces.RigidPlane, surfaces.RigidCircle)
    assert issubclass(RigidPlane, ContactSurface) and issubclass(RigidCircle, ContactSurface)


def test_exports_are_lazy():
    """``import skfem_mortar`` loads none of the exported modules (the CLI starts fast)."""
    code = ("import sys, skfem_mortar; "
            "print(sorted(m for m in sys.modules if m.startswith('skfem_mortar.')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


def test_unknown_name_raises_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        skfem_mortar.Nope  # noqa: B018


def test_a_contact_run_imports_only_what_it_needs():
    """A hertz run without output files needs neither pictures (pyvista,
    matplotlib), nor clusters (dask), nor root finders (scipy.optimize, 0.3 s to
    import), nor file writers (meshio)."""
    import subprocess
    import sys

    code = ("import sys; from skfem_mortar.app.runner import run_scene; "
            "run_scene('hertz', {'refine': -2}, 'mortar'); "
            "print(' '.join(sorted({m.split('.')[0] + ('.' + m.split('.')[1] if m.startswith('scipy.') "
            "and '.' in m else '') for m in sys.modules})))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = set(out.stdout.split())
    assert "scipy.sparse" in loaded  # the check sees what is imported
    for heavy in ("pyvista", "matplotlib", "dask", "scipy.optimize", "meshio", "tqdm"):
        assert heavy not in loaded, heavy


def test_a_run_writing_its_files_imports_no_network_stack(tmp_path):
    """The VTU writer quotes names with ``html.escape``: ``xml.sax.saxutils``
    would import urllib.request, http.client and ssl (about 40 ms of a 1 s run)."""
    import subprocess
    import sys

    code = ("import sys; from skfem_mortar.app.runner import run_scene; "
            f"run_scene('hertz', {{'refine': -2}}, 'mortar', out={str(tmp_path / 'run')!r}); "
            "print(' '.join(sorted(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = set(out.stdout.split())
    assert "skfem_mortar.output.io" in loaded and (tmp_path / "run" / "contact.csv").exists()
    for heavy in ("urllib.request", "http.client", "ssl", "xml.sax"):
        assert heavy not in loaded, heavy
