"""The small things a user trips on (issue 19, item 5): contact data along the
surface, ``bench --max-dofs`` as a bound, load factors at 12 digits, no VTK
X-server warning off screen, a progress bar that never warns."""
from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import skfem_mortar
from skfem_mortar.app import bench
from skfem_mortar.app.cli import main
from skfem_mortar.app.runner import build_scene, load_factor_value, run_scene
from skfem_mortar.output import views
from skfem_mortar.output.contact_output import ContactOutput
from skfem_mortar.output.checkpoint import read_checkpoint
from skfem_mortar.solver import observers


# ------------------------------------------------------------ contact data order
@pytest.fixture(scope="module")
def hertz():
    """The hertz scene's model, solved in one step: the slave is the cylinder's
    arc, whose surface nodes (sorted by mesh vertex) are not in chain order."""
    setup, _, _ = build_scene("hertz", {"refine": -2}, "mortar")
    from skfem_mortar import solve

    result = solve(setup.model, 1)
    return setup.model.contact_tables()[0], result


def test_contact_data_follows_the_curved_surface(hertz):
    pair, result = hertz
    d = pair.contact_data(result.z)
    k = d["node"]
    s = pair.slave
    assert sorted(k) == list(range(s.n_nodes))            # every node once
    assert not np.all(np.diff(s.X[0]) > 0)                # the surface's own order is not x
    # consecutive rows are the two ends of a segment: the rows walk the chain
    seg = {frozenset(map(int, e)) for e in s.segments}
    assert all(frozenset((int(a), int(b))) in seg for a, b in zip(k[:-1], k[1:]))
    assert np.all(np.diff(d["x"]) > 0)                    # the arc: x grows along it
    assert d["x"][0] < d["x"][-1]                         # open chain: smaller x first
    # every entry is on the same rows: the positions of those nodes, and the
    # active nodes are the pressed ones
    np.testing.assert_array_equal(d["x"], s.x(result.z)[0][k])
    np.testing.assert_array_equal(d["y"], s.x(result.z)[1][k])
    assert np.all(d["pressure"][pair.active[k]] > 0) and np.all(d["pressure"][~pair.active[k]] == 0)


def test_contact_output_keeps_the_surface_node_order(hertz):
    """The VTU series of the slave surface writes its points in the surface's
    order: its point data go back to that order."""
    pair, result = hertz
    d = pair.contact_data(result.z)
    points, _ = ContactOutput(pair).output_mesh()
    point, _ = ContactOutput(pair).output_data(result.z)
    x = points[:, 0] + point["displacement"][:, 0]
    back = np.argsort(d["node"])
    np.testing.assert_allclose(x, d["x"][back], rtol=0, atol=1e-14)  # X + u vs x: round-off
    np.testing.assert_array_equal(point["pressure"], d["pressure"][back])
    assert point["pressure"].max() > 0


def test_a_closed_slave_is_listed_around_its_chain():
    """A ring cable seen from outside (a closed chain, its nodes numbered
    against the chain's direction): the rows go around the chain once."""
    from skfem_mortar import Cable, ContactPair
    from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane

    ring = Cable.ring(1.0, 16, name="ring")
    pair = ContactPair(ContactSurface.from_cable(ring, side="left"),
                       RigidPlane((0.0, -1.0), (0.0, 1.0)), method="nts")
    d = pair.contact_data(np.zeros(ring.n_dofs + pair.n_dofs))
    k = list(d["node"])
    assert sorted(k) == list(range(16)) and k != list(range(16))
    chain = {(int(a), int(b)) for a, b in pair.slave.segments}  # directed
    assert all((a, b) in chain for a, b in zip(k, k[1:] + k[:1]))


# ------------------------------------------------------------------- bench bound
def test_bench_never_runs_a_size_above_max_dofs(tmp_path, monkeypatch, capsys):
    """hertz sizes (displacement dofs): 1288, 2364, 5256, ...; with --max-dofs
    3000 the third is never run (it used to be run, then the loop stopped)."""
    ran = []

    def fake(scene, params, method, steps, path=None):
        n = bench.size_of(scene, params, method)
        ran.append(n)
        return {"scene": scene, "params": params, "method": method, "status": "ok",
                "n_dofs": n, "n_multipliers": n // 50, "newton_iterations": 1,
                "factorizations": 1, "krylov_iterations": 0, "max_iterations_per_step": 1, "wall_time_s": 1.0, "peak_rss_mb": 1.0,
                "time_per_iteration_s": {p: 1e-3 * n for p in bench.PHASES},
                "contact_share": 0.5}

    monkeypatch.setattr(bench, "_one", fake)
    assert main(["bench", "--scene", "hertz", "--max-dofs", "3000", "--out",
                 str(tmp_path / "b"), "--no-progress"]) == 0
    assert ran == [1288, 2364]
    rows = json.loads((tmp_path / "b" / "bench.json").read_text())["scenes"]["hertz"]["rows"]
    assert [r["status"] for r in rows] == ["ok", "ok", "skipped: 5256 dofs > max_dofs 3000"]
    assert "skipped: 5256 dofs > max_dofs 3000" in capsys.readouterr().out
    # a bound below the smallest size runs nothing (and still writes its files)
    ran.clear()
    report = bench.run_bench(tmp_path / "c", scenes=("hertz",), max_dofs=1000)
    assert ran == [] and report["scenes"]["hertz"]["rows"][0]["status"].startswith("skipped")
    assert (tmp_path / "c" / "bench.png").exists()


def test_size_of_is_the_runs_n_dofs():
    summary = run_scene("hertz", {"refine": -2}, "mortar")
    assert bench.size_of("hertz", {"refine": -2}, "mortar") == summary["n_dofs"]


# ------------------------------------------------------------------ load factors
def _digits(v: float) -> int:
    """Significant digits of the shortest repr of ``v``."""
    mantissa = repr(float(v)).lower().split("e")[0].replace("-", "").replace(".", "")
    return len(mantissa.strip("0"))


def test_load_factors_in_summary_json_and_console_have_12_digits(tmp_path):
    """Ten steps of 0.1 add up to 0.30000000000000004 at the third: summary.json
    and the console say 0.3, the checkpoint keeps the sum itself."""
    out = tmp_path / "run"
    run_scene("block", {}, steps=10, out=out)
    saved = json.loads((out / "summary.json").read_text())["steps"]
    full = read_checkpoint(out / "checkpoint").load_factors[1:]
    assert any(_digits(lf) > 12 for lf in full)  # the case exists (or this test proves nothing)
    assert [s["load_factor"] for s in saved] == [load_factor_value(lf) for lf in full]
    assert saved[2]["load_factor"] == 0.3
    assert all(_digits(s["load_factor"]) <= 12 and _digits(s["increment"]) <= 12 for s in saved)
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["run", "block", "--steps", "10", "--json", "--no-progress"]) == 0
    printed = json.loads(buf.getvalue())["steps"]
    assert [s["load_factor"] for s in printed] == [s["load_factor"] for s in saved]
    assert "0.30000000000000004" not in buf.getvalue()


def test_load_factor_value_rounds_to_12_significant_digits():
    assert load_factor_value(0.1 + 0.2) == 0.3
    assert load_factor_value(1.0) == 1.0
    assert load_factor_value(0.123456789012345) == 0.123456789012
    assert load_factor_value(1e-4 / 3) == 3.33333333333e-05


def test_console_metrics_have_12_digits(capsys):
    assert main(["run", "block", "--steps", "1", "--no-progress"]) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if " = " in ln]
    assert lines
    for ln in lines:
        value = ln.split(" = ", 1)[1]
        with contextlib.suppress(ValueError):
            assert _digits(float(value)) <= 12, ln


# --------------------------------------------------------------------- VTK, X
_DRAW = r"""
import numpy as np
from skfem_mortar import Cable
from skfem_mortar.output import views
cable = Cable.between((0.0, 0.0), (1.0, 0.0), 1.2, 8, name="cable")
z = np.zeros(cable.n_dofs)
views.prepare_offscreen()  # what the package does before a pyvista render
import pyvista as pv
p = pv.Plotter(off_screen=True, window_size=(200, 120))
p.add_mesh(views.to_pyvista([cable], z)["cable"])
p.screenshot("fig.png")
print("drawn")
"""


def test_off_screen_picture_prints_no_vtk_warning(tmp_path):
    """A demo-like off-screen picture without an X display: stderr stays empty
    (VTK printed "bad X server connection" on every demo before)."""
    pytest.importorskip("pyvista")
    env = {k: v for k, v in os.environ.items()
           if k not in ("DISPLAY", "WAYLAND_DISPLAY", "VTK_DEFAULT_OPENGL_WINDOW")}
    # the child imports this package (it runs in tmp_path: a relative path would not)
    root = str(Path(skfem_mortar.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([root] + [p for p in [env.get("PYTHONPATH")] if p])
    if sys.platform.startswith("linux") and views._headless_window(env) is None:
        pytest.skip("neither EGL nor OSMesa is installed: VTK cannot draw off screen here")
    proc = subprocess.run([sys.executable, "-c", _DRAW], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0 and "drawn" in proc.stdout, proc.stderr
    assert (tmp_path / "fig.png").stat().st_size > 1000
    assert "X server" not in proc.stderr and "WARN" not in proc.stderr, proc.stderr


def test_headless_window_only_where_no_display_and_no_user_choice():
    pick = views._headless_window
    assert pick({"DISPLAY": ":0"}) is None
    assert pick({"WAYLAND_DISPLAY": "wayland-0"}) is None
    assert pick({"VTK_DEFAULT_OPENGL_WINDOW": "vtkXOpenGLRenderWindow"}) is None
    if sys.platform.startswith("linux"):
        assert pick({}) in (None, "vtkEGLRenderWindow", "vtkOSOpenGLRenderWindow")
    else:
        assert pick({}) is None


# ------------------------------------------------------------------ progress bar
def test_progress_bar_text_form_outside_a_notebook():
    from tqdm.std import tqdm

    assert not observers.in_notebook()
    assert observers.progress_class() is tqdm


def test_progress_bar_in_a_notebook_without_ipywidgets_is_text(monkeypatch):
    """tqdm.auto warns "IProgress not found" there; the bar takes the text form."""
    from importlib import util
    from tqdm.std import tqdm

    real = util.find_spec
    monkeypatch.setattr(observers, "in_notebook", lambda: True)
    monkeypatch.setattr(util, "find_spec", lambda n, *a: None if n == "ipywidgets" else real(n, *a))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert observers.progress_class() is tqdm


def test_progress_bar_in_a_notebook_with_ipywidgets_is_the_widget(monkeypatch):
    pytest.importorskip("ipywidgets")
    from tqdm.notebook import tqdm

    monkeypatch.setattr(observers, "in_notebook", lambda: True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert observers.progress_class() is tqdm


def test_in_notebook_reads_the_ipython_shell(monkeypatch):
    class ZMQInteractiveShell:  # the class name IPython's kernel shell has
        pass

    class TerminalInteractiveShell:
        pass

    class ColabShell(ZMQInteractiveShell):
        pass

    fake = type(sys)("IPython")
    monkeypatch.setitem(sys.modules, "IPython", fake)
    for k in [k for k in os.environ if k == "QT_API" or k.startswith("SPYDER")]:
        monkeypatch.delenv(k)
    for shell, expected in ((ZMQInteractiveShell(), True), (ColabShell(), True),
                            (TerminalInteractiveShell(), False), (None, False)):
        fake.get_ipython = lambda shell=shell: shell
        assert observers.in_notebook() is expected
    fake.get_ipython = ZMQInteractiveShell
    monkeypatch.setenv("QT_API", "pyqt5")  # Qt Console shows no widgets
    assert observers.in_notebook() is False


def test_a_solve_with_progress_warns_nothing(capsys):
    from skfem_mortar import Cable, Dirichlet, FollowerPressure, Model, solve

    cable = Cable.between((-1.0, 0.0), (1.0, 0.0), 2.4, 8, EA=50.0, law="svk")
    model = Model([cable, FollowerPressure(cable, 1.0, side="left"),
                   Dirichlet(cable, cable.support_dofs())])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert solve(model, 2, progress=True).converged
    assert "load steps" in capsys.readouterr().err
