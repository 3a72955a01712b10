"""The lock of an output directory: one run at a time.

The lock ``DIR/.skfem-mortar.lock`` is created atomically with its content:
written to a temporary file beside it, then linked into place (``os.link``
fails if the lock exists), so no run ever sees a lock without its content.
It holds, as JSON, the host, the process id (and, on Linux, that process's
start time, so that a reused pid is not taken for the run), the start time,
the command and a token. A second run on a locked directory is refused. A lock
whose process is gone (same host, pid not alive) is stale: it is taken over
with a one-line note. A lock taken on another host is never judged: the run is
refused, naming that host. A lock that cannot be read (empty, not JSON, no
host or pid: left by a kill while an older version wrote it, or on a file
system without hard links, where it is created with ``O_CREAT | O_EXCL`` and
then written) is being written while it is younger than
:data:`UNREADABLE_LOCK_AGE_S` (60 s): the run is refused; older, it is stale
and taken over with the same one-line note.
"""
from __future__ import annotations

import errno
import json
import logging
import os
import socket
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

__all__ = ["OutputDirError", "LOCK_NAME", "UNREADABLE_LOCK_AGE_S", "MAX_META_BYTES",
           "check_out_dir", "output_lock"]

LOCK_NAME = ".skfem-mortar.lock"
#: a lock or manifest larger than this is not ours (bytes)
MAX_META_BYTES = 1 << 20
#: age (seconds, by its modification time) from which a lock that cannot be
#: read is stale: writing one takes microseconds, so a lock unreadable for a
#: minute was left by a kill between its creation and its content
UNREADABLE_LOCK_AGE_S = 60.0
#: the errors of ``os.link`` on a file system without hard links
_NO_LINK = {errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.ENOSYS, errno.EXDEV}

_log = logging.getLogger(__name__)
#: directories this process holds the lock of, with the nesting depth
_HELD: dict[str, int] = {}


class OutputDirError(ValueError):
    """An output directory that cannot be used: a file, busy, or holding other files."""


def check_out_dir(path: str | os.PathLike) -> Path:
    """``path`` as an output directory: not empty text, not an existing file.

    Raises
    ------
    OutputDirError
        For ``""`` or a path that exists and is not a directory.
    """
    if str(path).strip() == "":
        raise OutputDirError("--out must name a directory, got empty text")
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise OutputDirError(f"--out {p} is an existing file, not a directory")
    return p


# -- the lock file ----------------------------------------------------------------

def _proc_stat(pid: int) -> list[str] | None:
    """Fields 3... of ``/proc/<pid>/stat`` (state first), None where there is none."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return text.rsplit(")", 1)[-1].split()


def _pid_start(pid: int) -> str | None:
    """Start time of process ``pid`` (clock ticks since boot; Linux only, else None)."""
    fields = _proc_stat(pid)
    return fields[19] if fields and len(fields) > 19 else None


def _alive(pid: int, start: str | None) -> bool:
    """Whether process ``pid`` runs and is the one started at ``start`` (if known)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # someone else's process
    fields = _proc_stat(pid)
    if fields is None:
        return True  # no /proc: the pid is all we know
    if fields[0] == "Z":
        return False  # a zombie has finished
    return start is None or len(fields) <= 19 or fields[19] == start


def _describe_lock(held: dict) -> str:
    return (f"{held.get('command', 'a run')} of pid {held.get('pid')} on host "
            f"{held.get('host')!r}, started {held.get('started')}")


def _read_lock(path: Path) -> dict | None:
    """The lock's content; None if it vanished; {} if unreadable (being written,
    or not a lock: no host and pid)."""
    try:
        if path.stat().st_size > MAX_META_BYTES:
            return {}
        held = json.loads(path.read_text())
    except FileNotFoundError:
        return None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return {}
    if not isinstance(held, dict):
        return {}
    pid = held.get("pid")
    if not (isinstance(held.get("host"), str) and isinstance(pid, int)
            and not isinstance(pid, bool) and pid > 0):
        return {}
    return held


def _age(path: Path) -> float | None:
    """Seconds since ``path`` was last modified (None if it vanished)."""
    try:
        return time.time() - path.stat().st_mtime
    except FileNotFoundError:
        return None


def _is_stale(held: dict) -> bool:
    """A lock of this host whose process is gone."""
    pid = held.get("pid")
    if held.get("host") != socket.gethostname() or not (isinstance(pid, int) and pid > 0):
        return False
    start = held.get("pid_start")
    return not _alive(pid, start if isinstance(start, str) else None)


def _put_back(aside: Path, path: Path) -> None:
    """Put a live lock that was moved aside back in its place, never over a lock
    that a third run created meanwhile (then the moved one is kept aside, named
    in a warning: two runs may both believe they hold the directory)."""
    try:
        os.link(aside, path)
        aside.unlink(missing_ok=True)
        return
    except FileExistsError:
        pass
    except OSError:  # no hard links here: a rename, where no lock has appeared
        if not path.exists():
            os.replace(aside, path)
            return
    _log.warning("%s: a lock moved aside as stale was another run's, and a third run has "
                 "taken the directory meanwhile; the moved lock is kept as %s",
                 path.parent, aside.name)


def _take_over(path: Path, held: dict) -> None:
    """Move a stale lock aside; put it back if what was moved is not the lock judged
    stale (another run took it over in between, or an unreadable lock is a new
    one being written)."""
    aside = path.with_name(f"{LOCK_NAME}.{os.getpid()}.{os.urandom(4).hex()}.stale")
    try:
        os.rename(path, aside)
    except FileNotFoundError:
        return
    moved, age = _read_lock(aside), _age(aside)
    if moved != held or (not held and not (age or 0.0) >= UNREADABLE_LOCK_AGE_S):
        _put_back(aside, path)
        return
    elif held:
        _log.warning("%s: took over the stale lock of %s (that process is gone)",
                     path.parent, _describe_lock(held))
    else:
        _log.warning("%s: took over the stale lock %s (unreadable, %.0f s old: its run was "
                     "killed while taking it)", path.parent, path.name, age)
    aside.unlink(missing_ok=True)


def _busy(directory: Path, held: dict) -> OutputDirError:
    if not held:
        return OutputDirError(f"--out {directory} is in use: its lock {directory / LOCK_NAME} "
                              "is being written or unreadable (taken over once "
                              f"{UNREADABLE_LOCK_AGE_S:.0f} s old); try again then, or "
                              "remove it if no run uses the directory")
    where = "" if held.get("host") == socket.gethostname() else " (another host: not checked)"
    return OutputDirError(f"--out {directory} is in use by the {_describe_lock(held)}{where}; "
                          "wait for it to end or use another --out")


def _write_new(path: Path, info: dict) -> bool:
    """Create ``path`` (``O_CREAT | O_EXCL``) and write ``info`` into it; False if
    it exists."""
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except FileExistsError:
        return False
    try:
        with os.fdopen(fd, "w") as f:
            f.write(json.dumps(info))
    except BaseException:
        path.unlink(missing_ok=True)
        raise
    return True


def _create_lock(path: Path, info: dict) -> bool:
    """Create the lock file with ``info`` in one step (a written temporary file
    linked into place); False if it exists.  Without hard links: created, then
    written (an unreadable lock for that moment)."""
    tmp = path.with_name(f"{LOCK_NAME}.{os.getpid()}.{os.urandom(4).hex()}.tmp")
    try:
        _write_new(tmp, info)
        try:
            os.link(tmp, path)
        except FileExistsError:
            return False
        except OSError as exc:
            if exc.errno not in _NO_LINK:
                raise
            return _write_new(path, info)
        return True
    finally:
        tmp.unlink(missing_ok=True)


def _sweep(directory: Path) -> None:
    """Remove the lock's temporary files (``.tmp``, ``.stale``) that a kill left
    (older than :data:`UNREADABLE_LOCK_AGE_S`; a younger one may be in use)."""
    for p in directory.glob(f"{LOCK_NAME}.*"):
        if p.suffix in (".tmp", ".stale") and (_age(p) or 0.0) >= UNREADABLE_LOCK_AGE_S:
            p.unlink(missing_ok=True)


def _acquire(directory: Path, command: str) -> str:
    """Take the lock of ``directory``; return its token.

    Raises
    ------
    OutputDirError
        If another live run holds it, or a run on another host.
    """
    path = directory / LOCK_NAME
    token = os.urandom(16).hex()  # random, as uuid4().hex (uuid's import: 3 ms)
    pid = os.getpid()
    info = {"host": socket.gethostname(), "pid": pid, "pid_start": _pid_start(pid),
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "command": command,
            "token": token}
    for _ in range(5):  # a few rounds: a stale lock taken over, a lock that vanished
        if _create_lock(path, info):
            _sweep(directory)
            return token
        held = _read_lock(path)
        if held is None:
            continue
        if not (_is_stale(held) if held else (_age(path) or 0.0) >= UNREADABLE_LOCK_AGE_S):
            raise _busy(directory, held)
        _take_over(path, held)
    raise _busy(directory, _read_lock(path) or {})


def _release(directory: Path, token: str) -> None:
    """Remove the lock if it is still ours."""
    path = directory / LOCK_NAME
    held = _read_lock(path)
    if held and held.get("token") == token:
        path.unlink(missing_ok=True)


@contextmanager
def output_lock(directory: str | os.PathLike, command: str = "run") -> Iterator[Path]:
    """Hold the lock of the output directory ``directory`` (created if needed).

    Nested use in one process (``demo`` around its ``run_scene``) holds it once.
    The lock is released on any exit, KeyboardInterrupt included; a killed
    process leaves a stale lock that the next run takes over.

    Parameters
    ----------
    directory : path
    command : str
        What holds it (named in the refusal of a second run).

    Raises
    ------
    OutputDirError
        If ``directory`` is a file, or another run holds the lock.
    """
    directory = check_out_dir(directory)
    directory.mkdir(parents=True, exist_ok=True)
    key = str(directory.resolve())
    if _HELD.get(key):
        _HELD[key] += 1
        try:
            yield directory
        finally:
            _HELD[key] -= 1
        return
    token = _acquire(directory, command)
    _HELD[key] = 1
    try:
        yield directory
    finally:
        del _HELD[key]
        _release(directory, token)
