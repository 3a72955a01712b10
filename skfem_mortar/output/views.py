"""Views with pyvista: the outputs at a state as pyvista data, and the off-screen
set-up a pyvista render needs where no display is there.

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

__all__ = ["to_pyvista", "prepare_offscreen"]


#: the environment variable that picks VTK's OpenGL window class (VTK >= 9.4)
_VTK_WINDOW = "VTK_DEFAULT_OPENGL_WINDOW"


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
    if (not sys.platform.startswith("linux") or _VTK_WINDOW in environ
            or environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY")):
        return None
    from ctypes.util import find_library

    for lib, window in (("EGL", "vtkEGLRenderWindow"), ("OSMesa", "vtkOSOpenGLRenderWindow")):
        if find_library(lib):
            return window
    return None


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

