"""Output files, written atomically: result series (PVD + VTU), summary.json and
contact.csv (the checkpoint a run resumes from is written and read by
:mod:`skfem_mortar.output.checkpoint`, which imports this module).

Every file is first written under a temporary name in the target directory and
then renamed (``os.replace`` is atomic on POSIX), so a reader never sees a
half-written file. Nothing non-finite is ever written: a NaN raises ValueError.
"""
from __future__ import annotations

import json
import math
import os
import signal
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

from .vtk_cells import vtk_cells

__all__ = ["atomic_path", "write_json", "write_contact_csv", "SeriesWriter", "read_series", "frame_mesh",
           "vtu_text"]


def _hold_sigint():
    """Block SIGINT in this thread where the platform can (its previous mask), else None."""
    if not hasattr(signal, "pthread_sigmask"):
        return None
    return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})


def _release_sigint(held) -> None:
    """Restore the mask :func:`_hold_sigint` saved (a pending Ctrl-C is raised here)."""
    if held is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


@contextmanager
def atomic_path(path: str | os.PathLike, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it to ``path`` on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    # Ctrl-C held off from the file's creation to inside the try: a KeyboardInterrupt
    # between them left a temporary behind (seen under load)
    held = _hold_sigint()
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix or ".tmp",
                                   dir=path.parent)
    except BaseException:
        _release_sigint(held)     # a failed creation must not leave Ctrl-C blocked
        raise
    tmp = Path(tmp)
    try:
        os.close(fd)
        _release_sigint(held)
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


def write_contact_csv(path: str | os.PathLike, data: dict[str, np.ndarray],
                      coords: tuple[str, ...] | None = None) -> None:
    """Write ``x,y[,z],gap,pressure,has_master`` (one row per slave node) atomically;
    ``coords`` names the coordinate columns, which hold ``data["x"]``, ``data["y"]``
    (and ``data["z"]``) in that order (default: ``("r", "z")`` when ``data`` has
    ``r`` -- an axisymmetric pair's
    :meth:`~skfem_mortar.contact.pair.ContactPair.contact_data` --, ``("x", "y",
    "z")`` when it has ``z`` -- a 3D pair's --, else ``("x", "y")``).

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
    if coords is None:
        coords = ("r", "z") if "r" in data else ("x", "y", "z") if "z" in data else ("x", "y")
    gap = np.asarray(data["gap"], dtype=float)
    has = np.asarray(data.get("has_master", np.isfinite(gap)), dtype=bool)
    if "distance" in data:
        gap = np.where(has, gap, np.asarray(data["distance"], dtype=float))
    xyz = [np.asarray(data[k], dtype=float) for k in ("x", "y", "z")[:len(coords)]]
    arr = np.column_stack(xyz + [gap, np.asarray(data["pressure"], dtype=float),
                                 has.astype(float)])
    if not np.all(np.isfinite(arr)):
        raise ValueError("non-finite contact data (a gap where a node faces no master needs "
                         "data['distance']): refusing to write contact.csv")
    n = len(coords) + 2                       # the coordinates, the gap and the pressure
    lines = [",".join(coords) + ",gap,pressure,has_master"]
    lines += [",".join(f"{v:.12g}" for v in row[:n]) + f",{int(row[n])}" for row in arr]
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
    """One frame as a ``meshio.Mesh``: points in 3D (z = 0), 2D vector point
    fields with a zero z component (ParaView's Warp By Vector and pyvista take
    3-component vectors) and 3D cells in VTK's node order (an output gives them in
    scikit-fem's: :func:`~skfem_mortar.output.vtk_cells.vtk_cells`); what the
    series files hold and :func:`~skfem_mortar.output.views.to_pyvista` shows."""
    return _meshio_frame(points, vtk_cells(_points3(points), cells), point_data, cell_data)


def _meshio_frame(points: np.ndarray, cells: list, point_data: dict, cell_data: dict):
    """:func:`frame_mesh` of cells already in VTK's order."""
    import meshio  # lazily: the command line starts fast

    return meshio.Mesh(_points3(points), cells,
                       point_data={k: _vectors3(v) for k, v in point_data.items()},
                       cell_data=cell_data)


#: VTK cell type numbers of the meshio cell types :func:`vtu_text` writes itself
VTK_TYPES = {"vertex": 1, "line": 3, "triangle": 5, "quad": 9, "tetra": 10, "hexahedron": 12,
             "line3": 21, "triangle6": 22, "tetra10": 24, "quad9": 28, "hexahedron27": 29}
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
        Reference mesh: points (N, 2) or (N, 3), cells as meshio takes them,
        3D cells in scikit-fem's local node order (:func:`frame_mesh`).
    """

    def __init__(self, directory: str | os.PathLike, name: str, mesh: tuple):
        self.directory = Path(directory)
        self.name = name
        self.points = _points3(mesh[0])
        self.cells = vtk_cells(self.points, mesh[1])
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

                meshio.write(tmp, _meshio_frame(self.points, self.cells, point_data, cell_data),
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

