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
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

__all__ = ["atomic_path", "write_json", "write_contact_csv", "SeriesWriter", "read_series",
           "write_checkpoint", "read_checkpoint"]


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
    """Write ``x,y,gap,pressure`` (one row per slave node) atomically.

    A slave node that faces no master segment has no gap: its ``gap`` cell is
    left empty (``data["gap"]`` is NaN there). Any other non-finite value is an
    error: nothing non-finite is written.
    """
    cols = ["x", "y", "gap", "pressure"]
    arr = np.column_stack([np.asarray(data[c], dtype=float) for c in cols])
    bad = ~np.isfinite(arr)
    bad[:, 2] &= ~np.isnan(arr[:, 2])
    if bad.any():
        raise ValueError("non-finite contact data: refusing to write contact.csv")
    lines = [",".join(cols)]
    for row in arr:
        lines.append(",".join("" if np.isnan(v) else f"{v:.12g}" for v in row))
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

    def write(self, t: float, point_data: dict, cell_data: dict,
              index: int | None = None) -> Path:
        """Write frame ``index`` (default: the next one) at time ``t``."""
        import meshio  # lazily: the command line starts fast

        _check_finite_fields(point_data, cell_data, t)
        index = len(self.frames) if index is None else index
        del self.frames[index:]
        rel = f"{self.name}/{self.name}_{index:04d}.vtu"
        # ParaView's Warp By Vector takes 3-component vectors: 2D vectors get z = 0
        point_data = {k: _vectors3(v) for k, v in point_data.items()}
        mesh = meshio.Mesh(self.points, self.cells, point_data=point_data,
                           cell_data=cell_data)
        with atomic_path(self.directory / rel, suffix=".vtu") as tmp:
            meshio.write(tmp, mesh, file_format="vtu")
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


def write_checkpoint(path: str | os.PathLike, meta: dict, states: np.ndarray,
                     history: list[dict]) -> None:
    """Everything needed to resume: the run's identity, all states, the step records."""
    if not np.all(np.isfinite(states)):
        raise ValueError("non-finite state: refusing to write the checkpoint")
    with atomic_path(path, suffix=".npz") as tmp:
        with open(tmp, "wb") as f:
            np.savez(f, states=states, meta=json.dumps(meta), history=json.dumps(history))


def read_checkpoint(path: str | os.PathLike) -> tuple[dict, np.ndarray, list[dict]]:
    with np.load(path) as data:
        return (json.loads(str(data["meta"])), np.array(data["states"]),
                json.loads(str(data["history"])))
