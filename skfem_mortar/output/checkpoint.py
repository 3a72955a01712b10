"""The checkpoint a run resumes from: written step by step, read and validated.

``<out>/checkpoint/`` holds one file per converged step, ``step_NNNNNN.npz``
(the state, the step's record, the step-size controller after it and every
stateful item's ``state_dict``), and ``index.json`` (format, run identity, the
number of steps it vouches for).  A step is written as its own file first,
the index is rewritten last, both atomically (:func:`~skfem_mortar.output.io.atomic_path`):
a kill at any moment leaves an index whose steps are all complete, and a step
file the index does not list (at most the one being written) is ignored.
Writing a step costs the size of one state, whatever the number of steps done.

A step file is read only once it is known to be one of ours: a zip archive
whose members are stored uncompressed ``.npy`` arrays (as ``numpy.savez``
writes them), named ``header``, ``z`` and ``item_<i>``, whose array headers
(read with ``numpy.lib.format``, before any array is) declare exactly the
bytes the member holds, ``z`` a float64 vector of the model's size.  Anything
else (a plain ``.npy``, another zip, a truncated file, a header claiming more
than the file holds) is refused naming the file, nothing allocated for it.
"""
from __future__ import annotations

import json
import math
import os
import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .io import _check_finite_json, atomic_path, write_json

__all__ = ["CHECKPOINT_FORMAT", "MAX_STEPS", "MAX_INDEX_BYTES", "Checkpoint",
           "write_checkpoint", "read_checkpoint", "clear_checkpoint", "prune_checkpoint"]

CHECKPOINT_FORMAT = "skfem-mortar checkpoint 2"
#: most steps a checkpoint may list (file names have six digits)
MAX_STEPS = 999_999
#: largest index file accepted (bytes)
MAX_INDEX_BYTES = 1 << 20
_STEP = re.compile(r"step_(\d{6})\.npz")


@dataclass
class Checkpoint:
    """A checkpoint as read and validated by :func:`read_checkpoint`.

    Attributes
    ----------
    directory : Path
    run : str
        Token of the run that wrote it (every step file carries it).
    meta : dict
        The run's identity (scene, method, parameters, steps).
    states : ndarray (k + 1, n)
        ``states[0]`` the initial unknowns, ``states[j]`` after step ``j``.
    history : list of dict
        The step records of steps ``1..k``.
    controllers : list of dict or None
        Per state the step-size controller after it (None for ``states[0]``).
    items : list of dict
        Per state ``{item name: {key: array}}``.
    """

    directory: Path
    run: str
    meta: dict
    states: np.ndarray
    history: list[dict] = field(default_factory=list)
    controllers: list[dict | None] = field(default_factory=list)
    items: list[dict[str, dict[str, np.ndarray]]] = field(default_factory=list)

    @property
    def index_path(self) -> Path:
        return self.directory / "index.json"

    def step_path(self, k: int) -> Path:
        return _step_path(self.directory, k)

    @property
    def load_factors(self) -> np.ndarray:
        return np.array([0.0] + [h["load_factor"] for h in self.history])


def _step_path(directory: Path, k: int) -> Path:
    return Path(directory) / f"step_{k:06d}.npz"


def write_checkpoint(directory: str | os.PathLike, meta: dict, run: str, k: int,
                     z: np.ndarray, record: dict | None = None,
                     controller: dict | None = None,
                     items: dict[str, dict[str, np.ndarray]] | None = None) -> int:
    """Add step ``k`` to the checkpoint in ``directory``: its file, then the index.

    Parameters
    ----------
    directory : path
        The checkpoint directory (created if needed).
    meta : dict
        The run's identity (JSON-ready).
    run : str
        Token of this run (the same for all its steps).
    k : int
        Step number (0: the initial state).
    z : ndarray (n,)
        The converged unknowns.
    record, controller : dict, optional
        The step's record and the step-size controller after it (None for step 0).
    items : dict, optional
        ``{item name: state_dict}`` of the stateful items.

    Returns
    -------
    int
        Bytes written (the step file and the index).

    Raises
    ------
    ValueError
        On a non-finite state or item value (nothing is written then).
    """
    directory = Path(directory)
    if not 0 <= k <= MAX_STEPS:
        raise ValueError(f"checkpoint step {k} outside [0, {MAX_STEPS}]")
    z = np.asarray(z, dtype=float)
    arrays, names = {"z": z}, []
    for name, state in (items or {}).items():
        for key, value in state.items():
            arrays[f"item_{len(names)}"] = np.asarray(value)
            names.append([name, key])
    bad = [n for n, a in arrays.items() if a.dtype.kind == "f" and not np.all(np.isfinite(a))]
    if bad:
        raise ValueError(f"non-finite checkpoint data ({', '.join(bad)}) at step {k}: "
                         "refusing to write it")
    header = {"run": run, "step": int(k), "record": record, "controller": controller,
              "items": names}
    _check_finite_json(header, "checkpoint header")
    path = _step_path(directory, k)
    with atomic_path(path, suffix=".npz") as tmp:
        with open(tmp, "wb") as f:
            np.savez(f, header=np.array(json.dumps(header)), **arrays)
        size = tmp.stat().st_size
    index = directory / "index.json"
    write_json(index, {"format": CHECKPOINT_FORMAT, "run": run, "meta": meta, "steps": int(k)})
    return size + index.stat().st_size


def clear_checkpoint(directory: str | os.PathLike) -> None:
    """Remove a checkpoint: its index first (so that nothing half-removed is ever
    taken for a checkpoint), then every step and temporary file."""
    directory = Path(directory)
    (directory / "index.json").unlink(missing_ok=True)
    prune_checkpoint(directory, -1)


def prune_checkpoint(directory: str | os.PathLike, keep: int) -> None:
    """Remove the step files after step ``keep`` (unlisted leftovers of a kill
    or of another run) and the temporary files a kill left behind."""
    directory = Path(directory)
    if not directory.is_dir():
        return
    for p in directory.iterdir():
        m = _STEP.fullmatch(p.name)
        if (m and int(m.group(1)) > keep) or (p.name.startswith(".") and p.is_file()):
            p.unlink(missing_ok=True)


def read_checkpoint(directory: str | os.PathLike, meta: dict | None = None,
                    n: int | None = None, max_bytes: int | None = None) -> Checkpoint | None:
    """Read and validate the checkpoint in ``directory``.

    Checked before anything is used: the index (format, identity ``meta``, step
    count within [0, ``MAX_STEPS``], size), and per step file: its size (at most
    ``max_bytes``), that it is a readable archive of this run holding this step,
    the state (float, shape ``(n,)``, finite), the record (load factors strictly
    increasing within (0, 1], counts >= 0, finite residuals), the controller
    entry, and finite item arrays.

    Parameters
    ----------
    directory : path
    meta : dict, optional
        This run's identity; a checkpoint of another run is refused.
    n : int, optional
        Number of unknowns of the model.
    max_bytes : int, optional
        Largest step file accepted.

    Returns
    -------
    Checkpoint or None
        None when there is no index (no checkpoint).

    Raises
    ------
    ValueError
        Naming the file and what is wrong with it.
    """
    directory = Path(directory)
    index_path = directory / "index.json"
    if not index_path.exists():
        return None
    index = _read_index(index_path, meta)
    ck = Checkpoint(directory, index["run"], index["meta"], np.zeros((0, 0)))
    states = []
    for k in range(index["steps"] + 1):
        path = _step_path(directory, k)
        z, header, items = _read_step(path, ck.run, k, n, max_bytes)
        n = z.size
        _check_step(path, header, k, ck.history[-1]["load_factor"] if k > 1 else 0.0)
        states.append(z)
        if k:
            ck.history.append(header["record"])
        ck.controllers.append(header["controller"])
        ck.items.append(items)
    ck.states = np.array(states)
    return ck


class _Refused(ValueError):
    """A checkpoint file refused (its message names the file)."""


def _refuse(path: Path, what: str) -> ValueError:
    return _Refused(f"checkpoint {path}: {what}; remove it or run without --resume")


def _read_index(path: Path, meta: dict | None) -> dict:
    if path.stat().st_size > MAX_INDEX_BYTES:
        raise _refuse(path, f"index larger than {MAX_INDEX_BYTES} bytes")
    try:
        index = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise _refuse(path, f"not a readable index ({exc})") from None
    if not (isinstance(index, dict) and set(index) == {"format", "run", "meta", "steps"}):
        raise _refuse(path, "not a checkpoint index (entries format, run, meta, steps)")
    if index["format"] != CHECKPOINT_FORMAT:
        raise _refuse(path, f"format {index['format']!r}, expected {CHECKPOINT_FORMAT!r}")
    if not isinstance(index["run"], str) or not index["run"]:
        raise _refuse(path, "no run token")
    steps = index["steps"]
    if not (isinstance(steps, int) and not isinstance(steps, bool) and 0 <= steps <= MAX_STEPS):
        raise _refuse(path, f"step count {steps!r} outside [0, {MAX_STEPS}]")
    if meta is not None and index["meta"] != meta:
        raise ValueError(f"resume: checkpoint {path} belongs to another run "
                         f"({index['meta']}); use another --out or drop --resume")
    return index


def _read_step(path: Path, run: str, k: int, n: int | None, max_bytes: int | None
               ) -> tuple[np.ndarray, dict, dict]:
    """The state, header and item states of one step file, checked."""
    if not path.is_file():
        raise _refuse(path, f"step {k} listed by the index is missing")
    size = path.stat().st_size
    if max_bytes is not None and size > max_bytes:
        raise _refuse(path, f"{size} bytes, more than the {max_bytes} a step of this "
                            "model can take")
    try:
        _check_members(path, size, n)
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
        header = json.loads(str(arrays.pop("header")))
    except _Refused:
        raise
    except _UNREADABLE as exc:
        raise _refuse(path, f"not a readable step file ({type(exc).__name__}: {exc})") from None
    if not (isinstance(header, dict)
            and set(header) == {"run", "step", "record", "controller", "items"}):
        raise _refuse(path, "not a step file (header entries)")
    if header["run"] != run or header["step"] != k:
        raise _refuse(path, f"holds step {header['step']!r} of run {header['run']!r}, "
                            f"not step {k} of run {run!r} (a leftover of another run)")
    z = arrays.pop("z", None)
    if z is None or z.dtype != np.float64 or z.ndim != 1 or (n is not None and z.size != n):
        raise _refuse(path, f"state of shape {getattr(z, 'shape', None)} and type "
                            f"{getattr(z, 'dtype', None)}, expected float64 ({n},)")
    if not np.all(np.isfinite(z)):
        raise _refuse(path, "non-finite values in the state")
    return z, header, _items(path, header["items"], arrays)


#: what reading a file that is not a step file of ours may raise
_UNREADABLE = (OSError, ValueError, EOFError, KeyError, RuntimeError, NotImplementedError,
               zipfile.BadZipFile)
#: the members of a step file: the header, the state, the item arrays
_MEMBER = re.compile(r"(header|z|item_\d{1,6})\.npy")
#: the .npy format versions ``numpy.savez`` writes, and their header readers
_NPY_HEADERS = {(1, 0): np.lib.format.read_array_header_1_0,
                (2, 0): np.lib.format.read_array_header_2_0}


def _check_members(path: Path, size: int, n: int | None) -> None:
    """Refuse a step file that is not ours before any array of it is read:
    not a zip (a plain ``.npy``, a truncated file), members other than
    ``header``, ``z`` and ``item_<i>`` stored uncompressed, or an array header
    that does not declare exactly the bytes its member holds (a header
    claiming terabytes), a header that is not text, a state that is not
    float64 of shape ``(n,)``, item arrays that are not numbers.

    Raises
    ------
    ValueError
        Naming ``path`` and what is wrong.
    """
    with zipfile.ZipFile(path) as zf:
        infos = zf.infolist()
        names = [i.filename for i in infos]
        if (len(set(names)) != len(names) or not {"header.npy", "z.npy"} <= set(names)
                or not all(_MEMBER.fullmatch(m) for m in names)):
            raise _refuse(path, f"not a step file (members {sorted(names)[:5]}, expected "
                                "header, z and item_<i>)")
        if (any(i.compress_type != zipfile.ZIP_STORED or i.file_size != i.compress_size
                for i in infos) or sum(i.file_size for i in infos) > size):
            raise _refuse(path, "not a step file (compressed members, or members larger "
                                "than the file)")
        for info in infos:
            with zf.open(info) as f:
                version = np.lib.format.read_magic(f)
                if version not in _NPY_HEADERS:
                    raise _refuse(path, f"member {info.filename}: .npy format {version}")
                shape, _, dtype = _NPY_HEADERS[version](f)
                held = info.file_size - f.tell()
            _check_array(path, info.filename[:-4], shape, dtype, held, n)


def _check_array(path: Path, name: str, shape: tuple, dtype: np.dtype, held: int,
                 n: int | None) -> None:
    """One member's array header against what a step file holds (see
    :func:`_check_members`); ``held``: the bytes after the header."""
    declared = math.prod(shape) * dtype.itemsize
    if dtype.hasobject or declared != held:
        raise _refuse(path, f"array {name!r} declares shape {shape} of {dtype} "
                            f"({declared} bytes), its member holds {held} bytes")
    if name == "header" and not (shape == () and dtype.kind == "U"):
        raise _refuse(path, f"header of shape {shape} and type {dtype}, expected text")
    if name == "z" and (dtype != np.float64 or len(shape) != 1
                        or (n is not None and shape[0] != n)):
        raise _refuse(path, f"state of shape {shape} and type {dtype}, expected "
                            f"float64 ({n},)")
    if name.startswith("item_") and dtype.kind not in "biuf":
        raise _refuse(path, f"item array {name!r} of type {dtype}, expected numbers")


def _items(path: Path, names, arrays: dict[str, np.ndarray]) -> dict[str, dict[str, np.ndarray]]:
    """Item states of a step file from its header's ``[name, key]`` list."""
    if not (isinstance(names, list) and all(isinstance(p, list) and len(p) == 2
                                            and all(isinstance(s, str) for s in p)
                                            for p in names)):
        raise _refuse(path, "bad item list in the header")
    if set(arrays) != {f"item_{i}" for i in range(len(names))}:
        raise _refuse(path, "item arrays do not match the header")
    out: dict[str, dict[str, np.ndarray]] = {}
    for i, (name, key) in enumerate(names):
        a = arrays[f"item_{i}"]
        if a.dtype.kind not in "biuf" or (a.dtype.kind == "f" and not np.all(np.isfinite(a))):
            raise _refuse(path, f"item {name!r} entry {key!r}: non-finite or not numeric")
        out.setdefault(name, {})[key] = a
    return out


_RECORD_KEYS = {"load_factor", "newton_iterations", "residual_norms", "n_active",
                "active_set_changes", "cuts", "increment"}
#: the linear solves' counts, in the records of checkpoints written since they came
_RECORD_COUNTS = {"factorizations", "krylov_iterations"}


def _check_step(path: Path, header: dict, k: int, lf_before: float) -> None:
    """The record of step ``k`` (none for step 0): load factor in (lf_before, 1],
    non-negative counts, finite residual norms."""
    rec, ctl = header["record"], header["controller"]
    if k == 0:
        if rec is not None or ctl is not None:
            raise _refuse(path, "the initial state carries a step record")
        return
    if not (isinstance(rec, dict) and _RECORD_KEYS <= set(rec) <= _RECORD_KEYS | _RECORD_COUNTS
            and isinstance(ctl, dict)):
        raise _refuse(path, "no step record or controller")
    lf = rec["load_factor"]
    if not (_is_number(lf) and lf_before < lf <= 1.0):
        raise _refuse(path, f"load factor {lf!r} of step {k} not in ({lf_before!r}, 1] "
                            "(load factors must increase)")
    counts = [rec[c] for c in ("newton_iterations", "n_active", "active_set_changes", "cuts",
                               *sorted(_RECORD_COUNTS & set(rec)))]
    if not all(isinstance(c, int) and c >= 0 for c in counts):
        raise _refuse(path, f"step {k}: counts must be integers >= 0, got {counts}")
    norms = rec["residual_norms"]
    if not (isinstance(norms, list) and norms and all(_is_number(r) and r >= 0 for r in norms)):
        raise _refuse(path, f"step {k}: residual norms must be finite numbers >= 0")
    if not (_is_number(rec["increment"]) and 0.0 < rec["increment"] <= 1.0):
        raise _refuse(path, f"step {k}: increment {rec['increment']!r} not in (0, 1]")


def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
