"""Views with pyvista: the outputs at a state as pyvista data, and the off-screen
set-up a pyvista render needs where no display is there, and the revolved view of
an axisymmetric result (:func:`revolve`, :func:`render_revolved`).

The package's pictures are drawn with matplotlib (:mod:`.plot`); pyvista is for
interactive views of the results (a notebook's ``.plot()``) and renders of one's
own.  pyvista is imported inside the functions.
"""
from __future__ import annotations

import os
import sys
import warnings
from typing import Mapping, Sequence

import numpy as np

__all__ = ["to_pyvista", "prepare_offscreen", "can_render", "revolve", "render_revolved"]


#: the environment variable that picks VTK's OpenGL window class (VTK >= 9.4)
_VTK_WINDOW = "VTK_DEFAULT_OPENGL_WINDOW"


def _vtk_chooses(environ: Mapping[str, str]) -> bool:
    """Whether VTK's own window choice stands: elsewhere than Linux, a display set, or
    a window class the user chose."""
    return (not sys.platform.startswith("linux") or _VTK_WINDOW in environ
            or bool(environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY")))


def _headless_window(environ: Mapping[str, str] = os.environ) -> str | None:
    """The VTK window class for off-screen rendering where no display is there
    (``environ``: the environment variables).

    On Linux without ``DISPLAY`` and ``WAYLAND_DISPLAY`` VTK tries an X window
    first and prints "bad X server connection" before it falls back to EGL:
    asking for EGL (or OSMesa) directly skips that attempt.  None (VTK's own
    choice) where a display is set, elsewhere than Linux, when the user chose
    a window class, or when neither library is installed (then VTK's own
    warnings say what is missing).
    """
    if _vtk_chooses(environ):
        return None
    from ctypes.util import find_library

    for lib, window in (("EGL", "vtkEGLRenderWindow"), ("OSMesa", "vtkOSOpenGLRenderWindow")):
        if find_library(lib):
            return window
    return None


def can_render(environ: Mapping[str, str] = os.environ) -> bool:
    """Whether VTK can draw here: a display is set, the platform is not Linux, the user
    chose a window class, or EGL or OSMesa is installed for off-screen rendering
    (:func:`_headless_window`).  False on a bare Linux without either library, where
    a render window would fail."""
    return _vtk_chooses(environ) or _headless_window(environ) is not None


def prepare_offscreen() -> None:
    """pyvista off screen, and VTK's headless window where no display is there
    (:func:`_headless_window`), before the first render window is made.

    pyvista's import pulls in pooch, whose ``tqdm.auto`` warns "IProgress not
    found" in a Jupyter kernel without ipywidgets: that one warning is
    ignored (this package's progress bar never uses ``tqdm.auto``).
    """
    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    window = _headless_window()
    if window is not None:
        os.environ[_VTK_WINDOW] = window
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="IProgress not found")
        import pyvista as pv

    pv.OFF_SCREEN = True


def to_pyvista(outputs: Sequence, z: np.ndarray, deformed: bool = True):
    """The outputs (bodies, contact surfaces: :class:`~skfem_mortar.core.item.Output`)
    at the unknowns ``z`` as a ``pyvista.MultiBlock``, one block per output with its
    point and cell fields, for interactive views in a notebook (``.plot()``) or
    anything else pyvista does.  ``deformed``: the points moved by their
    ``displacement`` field (else the reference configuration).  The same frames
    the series files hold (:func:`skfem_mortar.output.io.frame_mesh`)."""
    with warnings.catch_warnings():  # pooch's "IProgress not found" (see prepare_offscreen)
        warnings.filterwarnings("ignore", message="IProgress not found")
        import pyvista as pv

    from .io import frame_mesh

    blocks = pv.MultiBlock()
    for o in outputs:
        points, cells = o.output_mesh()
        point_data, cell_data = o.output_data(z)
        grid = pv.from_meshio(frame_mesh(points, cells, point_data, cell_data))
        if deformed and "displacement" in grid.point_data:
            grid.points = grid.points + np.asarray(grid.point_data["displacement"])
        blocks[o.name] = grid
    return blocks



#: 2D cell type -> (VTK cell type of its revolved sector, its corner count)
_REVOLVED = {"triangle": (13, 3), "quad": (12, 4), "line": (9, 2)}   # wedge, hexahedron, quad


def _sector_cells(cells: np.ndarray, n_points: int, segments: int, kind: str) -> np.ndarray:
    """The corners of each cell's sectors (``segments`` per cell): the cell's nodes at
    angle ``k`` then at ``k + 1`` (points numbered ``k * n_points + node``), with
    the VTK node order of a wedge, a hexahedron or (from a line) a quadrilateral;
    ``kind`` the cells' type, a key of :data:`_REVOLVED`."""
    k = np.arange(segments)[:, None, None]
    lo, hi = cells[None] + k * n_points, cells[None] + (k + 1) * n_points
    if kind == "line":                             # a line sweeps a quadrilateral
        return np.concatenate([lo, hi[..., ::-1]], axis=2).reshape(-1, 4)
    return np.concatenate([lo, hi], axis=2).reshape(-1, 2 * cells.shape[1])


def revolve(result, k: int = -1, *, deformed: bool = True, segments: int = 36,
            cut: float = 0.25):
    """An axisymmetric result at state ``k`` revolved about the ``z`` axis into 3D
    pyvista data, one ``UnstructuredGrid`` per output in a ``MultiBlock``.

    The meridian plane ``(r, z)`` of each output (:meth:`Result.outputs
    <skfem_mortar.solver.stepping.Result.outputs>`: its points, moved by their
    ``displacement`` when ``deformed``) is swept through the angles ``2 pi cut .. 2
    pi`` in ``segments`` sectors: points ``(r cos t, r sin t, z)``, triangles into
    wedges, quadrilaterals into hexahedra, lines (contact surfaces) into
    quadrilaterals; ``cut = 0.25`` leaves a quarter out, so the meridian sections at
    both cut faces show the fields.  Point fields are repeated at every angle (a
    vector ``(u_r, u_z)`` becomes ``(u_r cos t, u_r sin t, u_z)``), cell fields on
    every sector.

    Raises
    ------
    ValueError
        The result's model is not axisymmetric; ``segments`` not an integer >= 1;
        ``cut`` not in ``[0, 1)``.
    """
    geometry = getattr(result.model, "geometry", "plane")
    if geometry != "axisymmetric":
        raise ValueError(f"revolve needs an axisymmetric model, this one is {geometry!r}")
    if isinstance(segments, bool) or not isinstance(segments, (int, np.integer)) \
            or segments < 1:
        raise ValueError(f"segments must be an integer >= 1, got {segments!r}")
    if not 0.0 <= cut < 1.0:
        raise ValueError(f"cut must be in [0, 1) (the share of the revolution left out), "
                         f"got {cut!r}")
    with warnings.catch_warnings():  # pooch's "IProgress not found" (see prepare_offscreen)
        warnings.filterwarnings("ignore", message="IProgress not found")
        import pyvista as pv

    z = result.states[k]
    t = np.linspace(2.0 * np.pi * cut, 2.0 * np.pi, int(segments) + 1)  # the cut faces a
    # camera in the x > 0, y > 0 octant (pyvista's isometric view)
    blocks = pv.MultiBlock()
    for o in result.outputs():
        points, cells = o.output_mesh()
        point_data, cell_data = o.output_data(z)
        rz = np.asarray(points, dtype=float)[:, :2]
        if deformed and "displacement" in point_data:
            rz = rz + np.asarray(point_data["displacement"], dtype=float)[:, :2]
        n = len(rz)
        xyz = np.concatenate([np.column_stack([rz[:, 0] * np.cos(a), rz[:, 0] * np.sin(a),
                                               rz[:, 1]]) for a in t])
        kinds, conn, counts = [], [], []
        for cell_type, c in cells:
            vtk, _ = _REVOLVED[cell_type]
            sec = _sector_cells(np.asarray(c, dtype=np.int64), n, int(segments), cell_type)
            kinds.append(np.full(len(sec), vtk, dtype=np.uint8))
            conn.append(np.column_stack([np.full(len(sec), sec.shape[1]), sec]).ravel())
            counts.append(len(c))
        grid = pv.UnstructuredGrid(np.concatenate(conn), np.concatenate(kinds), xyz)
        for name, v in point_data.items():
            v = np.asarray(v, dtype=float)
            if v.ndim == 2 and v.shape[1] == 2:      # (u_r, u_z) at each angle
                v = np.concatenate([np.column_stack([v[:, 0] * np.cos(a), v[:, 0] * np.sin(a),
                                                     v[:, 1]]) for a in t])
            else:
                v = np.concatenate([v] * len(t))
            grid.point_data[name] = v
        for name, blocks_of_cells in cell_data.items():   # one array per cell block
            grid.cell_data[name] = np.concatenate(
                [np.tile(np.asarray(v, dtype=float), int(segments)) for v in blocks_of_cells])
        blocks[o.name] = grid
    return blocks


def render_revolved(result, path, k: int = -1, field: str = "von_mises", **kw):
    """A PNG of :func:`revolve` (keyword arguments ``kw`` passed on), coloured by the
    cell field ``field`` where an output has it, drawn off screen; returns the path."""
    from pathlib import Path

    prepare_offscreen()
    import pyvista as pv

    blocks = revolve(result, k, **kw)
    plotter = pv.Plotter(off_screen=True, window_size=(800, 600))
    for name in blocks.keys():
        grid = blocks[name]
        scalars = field if field in grid.cell_data else None
        plotter.add_mesh(grid, scalars=scalars, show_edges=False)
    plotter.add_axes(xlabel="x", ylabel="y", zlabel="z (axis)")
    plotter.view_isometric()
    path = Path(path)
    plotter.screenshot(str(path))
    plotter.close()
    return path
