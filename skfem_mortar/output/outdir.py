"""An output directory holds one run: the manifest of its files, under the lock
of :mod:`skfem_mortar.output.lock` (offered here too: ``output_lock``,
``LOCK_NAME``, ``OutputDirError``, ``check_out_dir``).

The manifest ``DIR/.skfem-mortar-run.json`` names the run (its identity: scene,
method, parameters, steps) and the top-level entries it writes (series, their
frame directories, ``checkpoint/``, ``summary.json``, ``contact.csv``, pictures).
It is written before the run writes anything else, so every file in the
directory is either the run's (listed, or a temporary file of a listed one) or
not ours. A new run into a directory that holds another run's files refuses
unless told to replace them; replacing removes exactly the listed files of the
old run (``summary.json`` first, then the checkpoint index, so nothing half
removed passes for a finished or resumable run), never a file it does not list.
"""
from __future__ import annotations

import json
import os
import re
from pathlib import Path
from typing import Any, Iterable

from .lock import (LOCK_NAME, MAX_META_BYTES, OutputDirError, check_out_dir,  # noqa: F401
                   output_lock)

__all__ = ["OutputDirError", "LOCK_NAME", "MANIFEST_NAME", "check_out_dir", "output_lock",
           "read_manifest", "claim", "adopt", "add_to_manifest", "remove_run",
           "remove_temporaries", "entries"]

MANIFEST_NAME = ".skfem-mortar-run.json"
MANIFEST_FORMAT = "skfem-mortar outputs 1"
#: the frame files of a series directory ``<name>/<name>_NNNN.vtu``
_FRAME = re.compile(r"(?P<name>.+)_\d{4,}\.vtu")


# -- the manifest -----------------------------------------------------------------

def _plain_names(names: Iterable[Any]) -> list[str]:
    """The entries that are plain names inside the directory (no path, not '.', '..')."""
    return [n for n in names if isinstance(n, str) and n not in ("", ".", "..")
            and Path(n).name == n and "/" not in n and "\\" not in n]


def read_manifest(directory: str | os.PathLike) -> dict | None:
    """The manifest of the run in ``directory``, None if there is none or it is
    not one (its entries are then not taken for ours)."""
    path = Path(directory) / MANIFEST_NAME
    try:
        if path.stat().st_size > MAX_META_BYTES:
            return None
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    if not (isinstance(data, dict) and data.get("format") == MANIFEST_FORMAT
            and isinstance(data.get("files"), list)):
        return None
    data["files"] = _plain_names(data["files"])
    return data


def _write_manifest(directory: Path, command: str, identity: dict, files: Iterable[str]) -> None:
    from .io import write_json

    write_json(directory / MANIFEST_NAME,
               {"format": MANIFEST_FORMAT, "command": command, "identity": identity,
                "files": sorted(set(_plain_names(files)))})


def add_to_manifest(directory: str | os.PathLike, names: Iterable[str]) -> None:
    """List ``names`` as files of the run in ``directory`` (before writing them)."""
    directory = Path(directory)
    man = read_manifest(directory)
    if man is None:
        raise OutputDirError(f"{directory} has no run manifest to add {list(names)} to")
    _write_manifest(directory, man["command"], man["identity"], man["files"] + list(names))


def _is_ours(name: str, files: list[str]) -> bool:
    """A listed entry, the lock or manifest, or a temporary file of one of them."""
    if name in files or name in (LOCK_NAME, MANIFEST_NAME) or name.startswith(LOCK_NAME + "."):
        return True
    return name.startswith(".") and any(name.startswith(f".{f}.")
                                        for f in files + [MANIFEST_NAME])


def _foreign(directory: Path, files: list[str]) -> list[str]:
    """Entries of ``directory`` that are not the run's."""
    return sorted(p.name for p in directory.iterdir() if not _is_ours(p.name, files))


def _present(directory: Path, files: list[str]) -> bool:
    return any((directory / f).exists() for f in files)


def _describe_run(man: dict) -> str:
    ident = man.get("identity") or {}
    if not isinstance(ident, dict):
        ident = {}
    return (f"{man.get('command', 'run')} of scene {ident.get('scene')!r}, method "
            f"{ident.get('method')!r}, {ident.get('steps')} steps")


def _remove_dir(path: Path) -> None:
    """A listed directory: the checkpoint's files or a series' frames and temporary
    files; the directory itself if that empties it (a user's file in it stays)."""
    from .checkpoint import clear_checkpoint

    if path.is_symlink() or not path.is_dir():
        path.unlink(missing_ok=True)
        return
    if path.name == "checkpoint":
        clear_checkpoint(path)
    else:
        for p in path.iterdir():
            m = _FRAME.fullmatch(p.name)
            if p.is_file() and ((m and m.group("name") == path.name)
                                or p.name.startswith(f".{path.name}_")):
                p.unlink(missing_ok=True)
    try:
        path.rmdir()
    except OSError:
        pass  # not empty: what is left is not ours


def remove_run(directory: str | os.PathLike, man: dict) -> None:
    """Remove the files the manifest ``man`` lists and their temporary files:
    ``summary.json`` first, then the checkpoint (index first), then the rest.
    The manifest itself stays until the caller writes the next one."""
    directory = Path(directory)
    order = sorted(man["files"], key=lambda f: (f != "summary.json", f != "checkpoint", f))
    for name in order:
        path = directory / name
        if path.is_dir() and not path.is_symlink():
            _remove_dir(path)
        else:
            path.unlink(missing_ok=True)
    remove_temporaries(directory, man["files"])


def remove_temporaries(directory: str | os.PathLike, files: list[str]) -> None:
    """Remove the temporary files that a kill left beside the listed entries
    (``.<name>.*``) and inside the listed series directories (``.<name>_*``)."""
    directory = Path(directory)
    for p in directory.iterdir():
        if (p.name.startswith(".") and p.is_file() and p.name not in (LOCK_NAME, MANIFEST_NAME)
                and _is_ours(p.name, files) and not p.name.startswith(LOCK_NAME)):
            p.unlink(missing_ok=True)
    for name in files:
        sub = directory / name
        if sub.is_dir() and not sub.is_symlink() and name != "checkpoint":
            for p in sub.iterdir():
                if p.is_file() and p.name.startswith(f".{name}_"):
                    p.unlink(missing_ok=True)


def claim(directory: str | os.PathLike, identity: dict, files: Iterable[str], *,
          command: str = "run", replace: bool = False, own: bool = False) -> None:
    """Make ``directory`` (locked by the caller) the directory of a new run.

    Parameters
    ----------
    directory : path
    identity : dict
        The new run's identity (JSON-ready).
    files : iterable of str
        The top-level entries it will write.
    command : str
        What writes it (``run``, ``demo``).
    replace : bool
        Remove the files of the run the directory holds (``--replace``).
    own : bool
        The caller resumes a run with this identity that has nothing to resume
        from: that run's files may be removed without ``replace``.

    Raises
    ------
    OutputDirError
        If the directory holds entries that are no run's (never removed), or
        another run's files and neither ``replace`` nor ``own`` applies.
    """
    directory = Path(directory)
    man = read_manifest(directory)
    old = man["files"] if man else []
    foreign = _foreign(directory, old)
    if foreign:
        shown = ", ".join(foreign[:3]) + (f" and {len(foreign) - 3} more" if len(foreign) > 3
                                          else "")
        raise OutputDirError(f"--out {directory} holds files that no run there lists as its "
                             f"own ({shown}); use an empty or new --out, or remove them")
    if man is not None and _present(directory, old):
        if not (replace or (own and man.get("identity") == identity)):
            raise OutputDirError(f"--out {directory} holds the files of another run "
                                 f"({_describe_run(man)}); pass --replace to remove them "
                                 "first, --resume to continue that run, or use another --out")
        remove_run(directory, man)
    _write_manifest(directory, command, identity, files)


def adopt(directory: str | os.PathLike, identity: dict, files: Iterable[str], *,
          command: str = "run") -> None:
    """Continue the run in ``directory`` (``--resume``, checkpoint validated): its
    manifest lists ``files`` too, its temporary files and ``summary.json`` go
    (the summary is written again when the resumed run ends).

    Raises
    ------
    OutputDirError
        If the manifest names another run.
    """
    directory = Path(directory)
    man = read_manifest(directory)
    if man is not None and man.get("identity") != identity:
        raise OutputDirError(f"resume: --out {directory} holds the files of another run "
                             f"({_describe_run(man)}); drop --resume or use another --out")
    listed = list(files) + (man["files"] if man else [])
    _write_manifest(directory, command, identity, listed)
    (directory / "summary.json").unlink(missing_ok=True)
    remove_temporaries(directory, sorted(set(_plain_names(listed))))


def entries(directory: str | os.PathLike) -> set[str]:
    """The names of the top-level entries of ``directory``."""
    return {p.name for p in Path(directory).iterdir()}
