"""A resume trusts only a step file of its own run (issue 32, class 6).

Crafted step files that reached a traceback (exit 4) or were resumed from: a
plain ``.npy``, a zip that is not ours, compressed members, an array header
claiming terabytes, and a finite state that is no converged state at its load
factor.  Each is refused with exit 2 and one line naming the file, before
anything is allocated for it or solved from it.  The run is the issue's
``skfem-mortar run patch --steps 3`` killed after its last step (no summary):
its resume restarts from step 2.
"""
import io
import re
import shutil
import zipfile

import numpy as np
import pytest
from resume_tools import edit_step

from skfem_mortar.app.cli import main

ARGS = ["patch", "--steps", "3", "--no-progress"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    out = tmp_path_factory.mktemp("finished") / "run"
    assert main(["run", *ARGS, "--out", str(out)]) == 0
    return out


@pytest.fixture
def killed(finished, tmp_path):
    """A copy of the finished run without its summary (killed after step 3)."""
    out = shutil.copytree(finished, tmp_path / "run")
    (out / "summary.json").unlink()
    return out


def _resume(out, capsys) -> tuple[int, str]:
    code = main(["run", *ARGS, "--out", str(out), "--resume"])
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    return code, err


def _npz_members(path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as zf:
        return {name: zf.read(name) for name in zf.namelist()}


def _write_zip(path, members: dict[str, bytes], compression=zipfile.ZIP_STORED) -> None:
    with zipfile.ZipFile(path, "w", compression) as zf:
        for name, data in members.items():
            zf.writestr(name, data)


def _plain_npy(path):
    """A plain .npy array of the state's size in place of the step file."""
    with open(path, "wb") as f:
        np.save(f, np.zeros(78))


def _not_ours(path):
    _write_zip(path, {"notes.txt": b"not a step file"})


def _compressed(path):
    _write_zip(path, _npz_members(path), zipfile.ZIP_DEFLATED)


def _huge_header(path):
    """``z.npy`` whose header claims 7 TiB (the member holds the real state)."""
    members = _npz_members(path)
    head = io.BytesIO()
    np.lib.format.write_array_header_1_0(head, {"descr": "<f8", "fortran_order": False,
                                                "shape": (7 * 2**40 // 8,)})
    z = np.load(io.BytesIO(members["z.npy"]))
    members["z.npy"] = head.getvalue() + z.tobytes()
    _write_zip(path, members)


def _truncated(path):
    path.write_bytes(path.read_bytes()[:path.stat().st_size - 100])


CONTAINERS = {  # what is put in place of step 2, what the refusal says
    "plain npy": (_plain_npy, "not a readable step file"),
    "zip not ours": (_not_ours, "not a step file"),
    "compressed members": (_compressed, "compressed members"),
    "header claims 7 TiB": (_huge_header, r"declares shape \(962072674304,\)"),
    "truncated": (_truncated, "not a readable step file"),
}


@pytest.mark.parametrize("what", list(CONTAINERS))
def test_a_step_file_that_is_not_ours_is_refused_unread(killed, capsys, what):
    corrupt, message = CONTAINERS[what]
    path = killed / "checkpoint" / "step_000002.npz"
    corrupt(path)
    code, err = _resume(killed, capsys)
    assert code == 2 and str(path) in err, err
    assert re.search(message, err), err
    assert not (killed / "summary.json").exists()


def _state_of_step_1(path):
    """Step 2 holding step 1's state: converged, but at another load factor."""
    with np.load(path.with_name("step_000001.npz")) as data:
        z1 = data["z"].copy()
    edit_step(path, lambda arrays, header: arrays.__setitem__("z", z1))


def _noise(path):
    """A finite state off the converged one by a millionth of its size (no
    element inverted): the issue's "garbage" that a resume solved on from."""
    rng = np.random.default_rng(32)
    edit_step(path, lambda arrays, header: arrays.__setitem__(
        "z", arrays["z"] + 1e-6 * np.abs(arrays["z"]).max() * rng.standard_normal(
            arrays["z"].size)))


def _inverted(path):
    """Random displacements of 0.3 (the patch's blocks are 1 wide): elements inverted."""
    rng = np.random.default_rng(0)
    edit_step(path, lambda arrays, header: arrays.__setitem__(
        "z", 0.3 * rng.standard_normal(arrays["z"].size)))


@pytest.mark.parametrize("corrupt, message", [
    (_state_of_step_1, "is not converged at load factor 0.6666"),
    (_noise, "is not converged at load factor 0.6666"),
    (_inverted, "inverts elements")], ids=["another step's state", "noise", "inverted"])
def test_a_state_that_is_not_converged_is_refused(killed, capsys, corrupt, message):
    path = killed / "checkpoint" / "step_000002.npz"
    corrupt(path)
    code, err = _resume(killed, capsys)
    assert code == 2 and str(path) in err and message in err, err
    assert not (killed / "summary.json").exists()


def test_the_untouched_checkpoint_resumes(killed, capsys):
    # the re-check passes a state the solver converged to (the residual Newton
    # accepted is below 1e-10 of the step's force scale, the check's bound 1e-6)
    code, err = _resume(killed, capsys)
    assert code == 0, err
