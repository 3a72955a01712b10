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
