"""Output files, written atomically: result series (PVD + VTU), summary.json,
contact.csv, and the checkpoint a run resumes from.

Every file is first written under a temporary name in the target directory and
then renamed (``os.replace`` is atomic on POSIX), so a reader never sees a
half-written file. Nothing non-finite is ever written: a NaN raises ValueError.
"""
from __future__ import annotations

import json
import math
import os
import re
import tempfile
import zipfile
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

__all__ = ["atomic_path", "write_json", "write_contact_csv", "SeriesWriter", "read_series", "frame_mesh",
           "vtu_text", "Checkpoint", "write_checkpoint", "read_checkpoint", "clear_checkpoint",
           "prune_checkpoint"]


@contextmanager
def atomic_path(path: str | os.PathLike, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it to ``path`` on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix or ".tmp",
                               dir=path.parent)
    os.close(fd)
    tmp = Path(tmp)
    try:
        yield tmp
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _check_finite_json(obj: Any, where: str = "summary") -> None:
    if isinstance(obj, float) and not math.isfinite(obj):
        raise ValueError(f"non-finite value at {where}: refusing to write it")
    if isinstance(obj, dict):
        for k, v in obj.items():
            _check_finite_json(v, f"{where}.{k}")
    elif isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj):
            _check_finite_json(v, f"{where}[{i}]")


def write_json(path: str | os.PathLike, data: dict) -> None:
    """Write ``data`` as JSON atomically (ValueError on NaN or inf)."""
    _check_finite_json(data)
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(data, indent=2) + "\n")


def write_contact_csv(path: str | os.PathLike, data: dict[str, np.ndarray]) -> None:
    """Write ``x,y,gap,pressure,has_master`` (one row per slave node) atomically.

    With friction (``data`` has ``tangential_traction``, ``slip`` and ``status``,
    :meth:`~skfem_mortar.contact.pair.ContactPair.contact_data` of a friction
    pair) three more columns ``tangential_traction,slip,status`` follow (the
    status as ``open``, ``stick`` or ``slip``); a frictionless file is unchanged.

    ``has_master`` is 1 where the node faces a master segment. Elsewhere the
    gap is undefined and the ``gap`` column holds the node's distance to the
    master surface (``data["distance"]``, as in the VTU series): no NaN and no
    0 that reads as touching. Without ``has_master`` the nodes with a finite
    gap count as facing a master. Any non-finite value written is an error.
    """
    gap = np.asarray(data["gap"], dtype=float)
    has = np.asarray(data.get("has_master", np.isfinite(gap)), dtype=bool)
    if "distance" in data:
        gap = np.where(has, gap, np.asarray(data["distance"], dtype=float))
    arr = np.column_stack([np.asarray(data["x"], dtype=float), np.asarray(data["y"], dtype=float),
                           gap, np.asarray(data["pressure"], dtype=float), has.astype(float)])
    if not np.all(np.isfinite(arr)):
        raise ValueError("non-finite contact data (a gap where a node faces no master needs "
                         "data['distance']): refusing to write contact.csv")
    lines = ["x,y,gap,pressure,has_master"]
    lines += [",".join(f"{v:.12g}" for v in row[:4]) + f",{int(row[4])}" for row in arr]
    if "tangential_traction" in data:  # a pair with friction: three more columns
        t = np.asarray(data["tangential_traction"], dtype=float)
        u = np.asarray(data["slip"], dtype=float)
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(u))):
            raise ValueError("non-finite tangential traction or slip: refusing to write "
                             "contact.csv")
        status = [str(v) for v in np.asarray(data["status"])]
        lines[0] += ",tangential_traction,slip,status"
        lines[1:] = [f"{line},{a:.12g},{b:.12g},{c}" for line, a, b, c in
                     zip(lines[1:], t, u, status)]
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n")


def _points3(points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=float)
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return points


def _vectors3(arr: np.ndarray) -> np.ndarray:
    """A point field of 2D vectors ``(N, 2)`` as ``(N, 3)`` with a zero z column;
    anything else unchanged."""
    arr = np.asarray(arr)
    if arr.ndim == 2 and arr.shape[1] == 2:
        return np.column_stack([arr, np.zeros(arr.shape[0], dtype=arr.dtype)])
    return arr


def frame_mesh(points: np.ndarray, cells: list, point_data: dict, cell_data: dict):
    """One frame as a ``meshio.Mesh``: points in 3D (z = 0) and 2D vector point
    fields with a zero z component (ParaView's Warp By Vector and pyvista take
    3-component vectors); what the series files hold and
    :func:`~skfem_mortar.output.views.to_pyvista` shows."""
    import meshio  # lazily: the command line starts fast

    return meshio.Mesh(_points3(points), cells,
                       point_data={k: _vectors3(v) for k, v in point_data.items()},
                       cell_data=cell_data)


#: VTK cell type numbers of the meshio cell types :func:`vtu_text` writes itself
VTK_TYPES = {"vertex": 1, "line": 3, "triangle": 5, "quad": 9, "line3": 21, "triangle6": 22}
_VTK_DTYPES = {np.dtype(np.float64): "Float64", np.dtype(np.float32): "Float32",
               np.dtype(np.int64): "Int64", np.dtype(np.int32): "Int32",
               np.dtype(np.uint8): "UInt8"}


def _data_array(name: str, data: np.ndarray) -> str | None:
    """One binary ``DataArray`` (base64 of a UInt32 byte count and the raw
    little-endian bytes, what meshio writes without compression); None for a
    dtype or size it does not cover."""
    import base64
    from html import escape   # not xml.sax.saxutils: it imports urllib.request, http, ssl (~40 ms)

    data = np.ascontiguousarray(data)
    kind = _VTK_DTYPES.get(data.dtype.newbyteorder("="))
    raw = data.astype(data.dtype.newbyteorder("<"), copy=False).tobytes()
    if kind is None or data.ndim > 2 or len(raw) >= 2**32:
        return None
    comps = f' NumberOfComponents="{data.shape[1]}"' if data.ndim == 2 else ""
    body = base64.b64encode(np.array(len(raw), dtype="<u4").tobytes() + raw).decode()
    return (f'<DataArray type="{kind}" Name="{escape(name, quote=True)}"{comps} format="binary">'
            f"{body}</DataArray>")


def vtu_text(points: np.ndarray, cells: list, point_data: dict, cell_data: dict) -> str | None:
    """The VTU file of one frame (points ``(N, 3)``, meshio-style cell blocks
    ``[(type, (n, k) array)]``, point fields ``(N,)`` / ``(N, c)``, cell fields as
    one array per block), binary without compression, as meshio writes it;
    None where meshio is needed (another cell type or data type): the series
    writer then calls meshio.  Written here because importing meshio (with its
    console library) costs a small run a twentieth of a second."""
    blocks = [(t, np.asarray(c)) for t, c in cells]
    if not blocks or any(t not in VTK_TYPES or c.ndim != 2 for t, c in blocks):
        return None
    conn = np.concatenate([c.ravel() for _, c in blocks]).astype(np.int64)
    offsets = np.cumsum(np.concatenate([np.full(len(c), c.shape[1]) for _, c in blocks])
                        ).astype(np.int64)
    types = np.concatenate([np.full(len(c), VTK_TYPES[t]) for t, c in blocks]).astype(np.uint8)
    parts = [_data_array("Points", points)]
    parts_c = [_data_array(n, a) for n, a in (("connectivity", conn), ("offsets", offsets),
                                            ("types", types))]
    pd = [_data_array(k, np.asarray(v)) for k, v in point_data.items()]
    cd = []
    for k, v in cell_data.items():
        if len(v) != len(blocks):
            return None
        cd.append(_data_array(k, np.concatenate([np.asarray(a) for a in v])))
    if any(x is None for x in parts + parts_c + pd + cd):
        return None
    byte_order = "LittleEndian"
    return ('<?xml version="1.0"?>\n'
            f'<VTKFile type="UnstructuredGrid" version="0.1" byte_order="{byte_order}">\n'
            f'<UnstructuredGrid>\n<Piece NumberOfPoints="{len(points)}" '
            f'NumberOfCells="{len(types)}">\n'
            f"<Points>\n{parts[0]}\n</Points>\n<Cells>\n" + "\n".join(parts_c)
            + "\n</Cells>\n<PointData>\n" + "\n".join(pd) + "\n</PointData>\n<CellData>\n"
            + "\n".join(cd) + "\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")


def _check_finite_fields(point_data: dict, cell_data: dict, t: float) -> None:
    for name, arr in list(point_data.items()) + [(k, a) for k, v in cell_data.items()
                                                 for a in v]:
        if not np.all(np.isfinite(np.asarray(arr, dtype=float))):
            raise ValueError(f"non-finite values in field {name!r} at t={t}: "
                             "refusing to write them")


class SeriesWriter:
    """A result series as ParaView's PVD index plus one VTU file per frame.

    Each frame is written atomically as ``<name>/<name>_NNNN.vtu`` and then the
    index ``<name>.pvd`` is rewritten atomically, so after a crash every frame
    the index lists is complete and readable (meshio reads the VTU files,
    ParaView the PVD). Frames beyond a resumed run's restart are replaced.
    The VTU data arrays are binary without compression: zlib took three
    quarters of the writing (hertz: 13.6 ms against 67 ms per body frame, on a
    loaded machine) for files 1.75 times smaller.  The common cell types are
    written here (:func:`vtu_text`), the rest by meshio.

    Parameters
    ----------
    directory : path
        Output directory.
    name : str
        Series name (the body's name).
    mesh : (points, cells)
        Reference mesh: points (N, 2) or (N, 3), cells as meshio takes them.
    """

    def __init__(self, directory: str | os.PathLike, name: str, mesh: tuple):
        self.directory = Path(directory)
        self.name = name
        self.points = _points3(mesh[0])
        self.cells = mesh[1]
        self.frames: list[tuple[float, str]] = []
        (self.directory / name).mkdir(parents=True, exist_ok=True)

    @property
    def index_path(self) -> Path:
        return self.directory / f"{self.name}.pvd"

    def adopt(self, times: Sequence[float]) -> int:
        """Take over the frames of an interrupted run that match ``times``.

        The existing index is read; its first frames are kept as long as their
        times agree with ``times`` (to the 12 digits written) and their files
        exist. Nothing is written: the index is rewritten with the next frame.

        Returns
        -------
        int
            How many frames were kept (the caller writes the others).
        """
        import xml.etree.ElementTree as ET

        self.frames = []
        try:
            listed = [(float(ds.get("timestep")), ds.get("file"))
                      for ds in ET.parse(self.index_path).getroot().iter("DataSet")]
        except (OSError, ET.ParseError, TypeError, ValueError):
            return 0
        for t, (tt, rel) in zip(times, listed):
            expected = f"{self.name}/{self.name}_{len(self.frames):04d}.vtu"
            if (rel != expected or not np.isclose(tt, t, rtol=1e-11, atol=1e-300)
                    or not (self.directory / rel).is_file()):
                break
            self.frames.append((float(t), rel))
        return len(self.frames)

    def write(self, t: float, point_data: dict, cell_data: dict,
              index: int | None = None) -> Path:
        """Write frame ``index`` (default: the next one) at time ``t``
        (:func:`vtu_text`, or meshio for what it does not cover)."""
        _check_finite_fields(point_data, cell_data, t)
        index = len(self.frames) if index is None else index
        del self.frames[index:]
        rel = f"{self.name}/{self.name}_{index:04d}.vtu"
        text = vtu_text(self.points, self.cells,
                        {k: _vectors3(v) for k, v in point_data.items()}, cell_data)
        with atomic_path(self.directory / rel, suffix=".vtu") as tmp:
            if text is not None:
                tmp.write_text(text)
            else:
                import meshio  # lazily: the command line starts fast

                meshio.write(tmp, frame_mesh(self.points, self.cells, point_data, cell_data),
                             file_format="vtu", compression=None)
        self.frames.append((float(t), rel))
        entries = "\n".join(f'    <DataSet timestep="{tt:.12g}" part="0" file="{f}"/>'
                            for tt, f in self.frames)
        with atomic_path(self.index_path) as tmp:
            tmp.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" '
                           'version="0.1">\n  <Collection>\n' + entries +
                           "\n  </Collection>\n</VTKFile>\n")
        return self.directory / rel


def read_series(path: str | os.PathLike) -> list[tuple[float, "object"]]:
    """Frames of a PVD series as ``(time, meshio.Mesh)``."""
    import xml.etree.ElementTree as ET

    import meshio

    path = Path(path)
    root = ET.parse(path).getroot()
    return [(float(ds.get("timestep")), meshio.read(path.parent / ds.get("file")))
            for ds in root.iter("DataSet")]


# -- checkpoint -------------------------------------------------------------------
#
# ``<out>/checkpoint/`` holds one file per converged step, ``step_NNNNNN.npz``
# (the state, the step's record, the step-size controller after it and every
# stateful item's ``state_dict``), and ``index.json`` (format, run identity, the
# number of steps it vouches for).  A step is written as its own file first,
# the index is rewritten last, both atomically: a kill at any moment leaves an
# index whose steps are all complete, and a step file the index does not list
# (at most the one being written) is ignored.  Writing a step costs the size of
# one state, whatever the number of steps done.

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


def _refuse(path: Path, what: str) -> ValueError:
    return ValueError(f"checkpoint {path}: {what}; remove it or run without --resume")


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
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
        header = json.loads(str(arrays.pop("header")))
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as exc:
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
