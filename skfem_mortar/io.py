"""Output files, written atomically: result series (XDMF), summary.json, contact.csv.

Every file is first written under a temporary name in the target directory and
then renamed (``os.replace`` is atomic on POSIX), so a reader never sees a
half-written file. Nothing non-finite is ever written: a NaN raises ValueError.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

__all__ = ["atomic_path", "write_json", "write_contact_csv", "write_series"]


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
    """Write ``x,y,gap,pressure`` (one row per slave node) atomically."""
    cols = ["x", "y", "gap", "pressure"]
    arr = np.column_stack([np.asarray(data[c], dtype=float) for c in cols])
    if not np.all(np.isfinite(arr)):
        raise ValueError("non-finite contact data: refusing to write contact.csv")
    with atomic_path(path) as tmp:
        np.savetxt(tmp, arr, delimiter=",", header=",".join(cols), comments="",
                   fmt="%.12g")


def _points3(points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=float)
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return points


def write_series(path: str | os.PathLike, mesh: tuple, frames: Sequence[tuple]) -> None:
    """Write a time series as XDMF + HDF5 (meshio), atomically.

    Parameters
    ----------
    path : path
        Target ``.xdmf`` file; its ``.h5`` companion goes beside it.
    mesh : (points, cells)
        Reference mesh (points (N, 2) or (N, 3); cells as meshio takes them).
    frames : sequence of (time, point_data, cell_data)
        One entry per output step.
    """
    import meshio  # lazily: the command line starts fast

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    points, cells = mesh
    for t, pdata, cdata in frames:
        for name, arr in list(pdata.items()) + [(k, a) for k, v in cdata.items() for a in v]:
            if not np.all(np.isfinite(np.asarray(arr, dtype=float))):
                raise ValueError(f"non-finite values in field {name!r} at t={t}: "
                                 "refusing to write them")
    tmpdir = Path(tempfile.mkdtemp(prefix=f".{path.stem}.", dir=path.parent))
    try:
        # meshio's TimeSeriesWriter puts the .h5 into the *current* directory,
        # so write from inside the temporary directory
        cwd = os.getcwd()
        os.chdir(tmpdir)
        try:
            with meshio.xdmf.TimeSeriesWriter(path.name) as writer:
                writer.write_points_cells(_points3(points), cells)
                for t, pdata, cdata in frames:
                    writer.write_data(float(t), point_data=pdata, cell_data=cdata)
        finally:
            os.chdir(cwd)
        # the .xdmf refers to its .h5 by file name, so both keep their names
        for f in sorted(tmpdir.iterdir(), key=lambda p: p.suffix != ".h5"):
            os.replace(f, path.parent / f.name)
    finally:
        shutil.rmtree(tmpdir, ignore_errors=True)
