"""The command-line contract: listing, bad input (exit 2), JSON on stdout."""
import json
import subprocess
import sys

import pytest

from skfem_mortar.app.cli import main
from skfem_mortar.scenes import Param


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "skfem_mortar.app.cli", *args],
                          capture_output=True, text=True)


def test_unknown_scene_exit_2():
    proc = run_cli("run", "no-such-scene")
    assert proc.returncode == 2
    assert "unknown scene 'no-such-scene'" in proc.stderr
    assert proc.stdout == ""


def test_set_without_equals_exit_2(capsys):
    with pytest.raises(SystemExit) as exc:  # argument refusals exit as argparse's do
        main(["run", "block", "--set", "E"])
    assert exc.value.code == 2
    assert "NAME=VALUE" in capsys.readouterr().err


def test_steps_must_be_positive(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", "block", "--steps", "0"])
    assert exc.value.code == 2
    assert "--steps: must be an integer >= 1" in capsys.readouterr().err


def test_scenes_json_lists_parameters(capsys):
    assert main(["scenes", "--json"]) == 0
    scenes = json.loads(capsys.readouterr().out)
    for s in scenes:
        assert s["name"] and isinstance(s["parameters"], dict)


@pytest.mark.parametrize("value, ok", [("0.3", True), ("0.5", False), ("-1", False),
                                        ("nan", False), ("abc", False)])
def test_param_range(value, ok):
    p = Param("nu", 0.3, "Poisson ratio", low=-1.0, high=0.5,
              low_inclusive=False, high_inclusive=False)
    if ok:
        assert p.parse(value) == float(value)
    else:
        with pytest.raises(ValueError, match=r"'nu' must be a float in \(-1, 0.5\)"):
            p.parse(value)


def test_int_and_choice_params():
    assert Param("n", 3, kind=int, low=1).parse("7") == 7
    with pytest.raises(ValueError, match="'n'"):
        Param("n", 3, kind=int, low=1).parse("2.5")
    with pytest.raises(ValueError, match="one of tri1, quad1"):
        Param("element", "tri1", kind=str, choices=("tri1", "quad1")).parse("hex")


def test_a_run_ends_without_the_teardown_and_loses_nothing(tmp_path):
    """``entry`` ends a ``run`` with ``os._exit`` (the interpreter's teardown,
    ~0.1 s, skipped): the exit code, the last line on stdout and every output
    file are there as after a normal exit (``SKFEM_MORTAR_NORMAL_EXIT=1``, the
    same metrics), and a run refused during its set-up keeps its exit code
    and its message."""
    import os

    def cli(*args, **env):
        return subprocess.run([sys.executable, "-m", "skfem_mortar.app.cli", *args],
                              capture_output=True, text=True, env={**os.environ, **env})
    out = tmp_path / "ok"
    ok = cli("run", "hertz", "--set", "refine=-2", "--steps", "1", "--out", str(out),
             "--no-progress")
    assert ok.returncode == 0, ok.stderr
    assert ok.stdout.rstrip().endswith(f"results written to {out}")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["converged"] and (out / "contact.csv").read_text().count("\n") > 10
    normal = cli("run", "hertz", "--set", "refine=-2", "--steps", "1", "--out",
                 str(tmp_path / "normal"), "--no-progress", SKFEM_MORTAR_NORMAL_EXIT="1")
    assert normal.returncode == 0  # the same metric lines (the first holds the time)
    assert normal.stdout.splitlines()[1:-1] == ok.stdout.splitlines()[1:-1]
    assert (json.loads((tmp_path / "normal" / "summary.json").read_text())["metrics"]
            == summary["metrics"])
    bad = cli("run", "hertz", "--set", "load=-1", "--out", str(tmp_path / "bad"),
              "--no-progress")
    assert bad.returncode == 2 and "load" in bad.stderr and bad.stdout == "", bad.stderr
