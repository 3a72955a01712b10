"""Pictures: the paper-style figure (pyvista, off-screen) and line plots (matplotlib).

All heavy imports happen inside the functions, so importing this module is cheap.
"""
from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

__all__ = ["figure", "draw", "plot_pressure", "plot_newton", "Picture"]

#: meshio cell type -> VTK cell type id
_VTK = {"line": 3, "triangle": 5, "quad": 9, "triangle6": 22, "quad8": 23, "quad9": 28}
#: preferred colouring field, in order
_COLOUR_BY = ("von_mises", "tension")


def _grid(item, z: np.ndarray | None):
    import pyvista as pv

    points, cells = item.output_mesh()
    points = np.column_stack([points, np.zeros(len(points))]) if points.shape[1] == 2 else points
    points = np.array(points, dtype=float)
    pdata, cdata = item.output_data(z)
    if z is not None and "displacement" in pdata:
        d = np.asarray(pdata["displacement"], dtype=float)
        points[:, :d.shape[1]] += d
    grid = pv.UnstructuredGrid({_VTK[t]: np.asarray(c) for t, c in cells}, points)
    # pyvista orders cell blocks by VTK type id: keep cell data only for one block
    if len(cells) == 1:
        for name, arrays in cdata.items():
            grid.cell_data[name] = np.asarray(arrays[0], dtype=float)
    return grid


class Picture(type(Path())):  # the concrete Path class: Path itself takes no subclass before 3.12
    """The path of a PNG written here; a notebook shows the picture inline."""

    def _repr_png_(self) -> bytes | None:
        """The PNG's bytes (None, i.e. the text repr, for a path that is none)."""
        return self.read_bytes() if self.suffix.lower() == ".png" and self.is_file() else None


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


def _prepare_offscreen() -> None:
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


def figure(setup, result, path: str | os.PathLike, title: str = "",
           window_size: tuple[int, int] = (1600, 700)) -> Path:
    """The picture of a scene's run: :func:`draw` of the bodies among
    ``setup.outputs`` (the contact outputs are shown by ``setup.contact``)
    at ``result``'s first and last state.  Reads only ``setup.outputs`` and
    ``setup.contact`` of the :class:`~skfem_mortar.scenes.Setup`.
    """
    from ..core.model import Item

    return draw([o for o in setup.outputs if isinstance(o, Item)], result.states[0],
                result.z, path, title=title, window_size=window_size,
                contact=setup.contact)


def draw(bodies: Sequence, z0: np.ndarray, z1: np.ndarray, path: str | os.PathLike, *,
         contact=None, title: str = "",
         window_size: tuple[int, int] = (1600, 700)) -> Path:
    """Initial configuration (left, at ``z0``) and deformed model (right, at
    ``z1``), written as PNG.

    Parameters
    ----------
    bodies : sequence of Output
        Drawn as meshes (:class:`~skfem_mortar.core.model.Output`): solids coloured
        by von Mises stress, cables by tension.
    contact : callable(z) -> dict, optional
        A contact pair's ``contact_data``: its slave nodes in contact are drawn
        as points coloured by the contact pressure.
    """
    _prepare_offscreen()
    import pyvista as pv

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter = pv.Plotter(shape=(1, 2), off_screen=True, window_size=list(window_size))
    bounds = np.array([_grid(item, z).bounds for item in bodies for z in (z0, z1)])
    union = [bounds[:, 0].min(), bounds[:, 1].max(), bounds[:, 2].min(),
             bounds[:, 3].max(), 0.0, 0.0]
    for col, (z, label) in enumerate(((z0, "initial configuration"), (z1, "deformed"))):
        plotter.subplot(0, col)
        plotter.add_text(f"{title}  {label}".strip(), font_size=11)
        for item in bodies:
            grid = _grid(item, z)
            field = next((f for f in _COLOUR_BY if f in grid.cell_data), None)
            is_line = "line" in [t for t, _ in item.output_mesh()[1]]
            kw = dict(line_width=5, render_lines_as_tubes=True) if is_line else dict(
                show_edges=True, edge_color="gray")
            if field is not None and col == 1:
                cmap = "plasma" if field == "tension" else "viridis"
                vals = np.asarray(grid.cell_data[field])
                lo, hi = float(vals.min()), float(vals.max())
                if hi - lo <= 1e-6 * max(abs(hi), abs(lo), 1e-300):
                    # a constant field (e.g. the tension of a frictionless cable):
                    # do not colour its round-off noise
                    lo, hi = lo - 0.1 * abs(lo) - 1e-12, hi + 0.1 * abs(hi) + 1e-12
                plotter.add_mesh(grid, scalars=field, cmap=cmap, clim=[lo, hi],
                                 scalar_bar_args={"title": f"{item.name}: {field}",
                                                  "vertical": False, "height": 0.06,
                                                  "width": 0.4, "position_x": 0.55,
                                                  "position_y": 0.03 + 0.16 * is_line,
                                                  "title_font_size": 14,
                                                  "label_font_size": 12, "n_labels": 3},
                                 **kw)
            else:
                plotter.add_mesh(grid, color="tan" if is_line else "lightsteelblue", **kw)
        if col == 1 and contact is not None:
            c = contact(z1)
            on = np.asarray(c["pressure"], dtype=float) > 0  # the nodes in contact
            if on.any():
                pts = np.column_stack([c["x"][on], c["y"][on], np.full(on.sum(), 0.01)])
                cloud = pv.PolyData(pts)
                cloud["contact pressure"] = np.asarray(c["pressure"], dtype=float)[on]
                plotter.add_mesh(cloud, scalars="contact pressure", cmap="inferno",
                                 point_size=11, render_points_as_spheres=True,
                                 scalar_bar_args={"title": "contact pressure",
                                                  "vertical": False, "height": 0.06,
                                                  "width": 0.4, "position_x": 0.05,
                                                  "position_y": 0.03,
                                                  "title_font_size": 14,
                                                  "label_font_size": 12, "n_labels": 3})
        plotter.view_xy()
        plotter.reset_camera(bounds=union)  # same scale in both panels
    plotter.screenshot(str(path))
    plotter.close()
    return Picture(path)


def plot_pressure(curves: Sequence[dict], path: str | os.PathLike,
                  title: str = "contact pressure along the interface") -> Path:
    """Contact pressure against position, one panel per method.

    Parameters
    ----------
    curves : sequence of dict
        Each with ``method``, ``label`` (e.g. the load factor), ``x`` and
        ``pressure`` arrays.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods = list(dict.fromkeys(c["method"] for c in curves))
    fig, axes = plt.subplots(1, len(methods), figsize=(5.5 * len(methods), 4),
                             sharey=True, squeeze=False)
    for ax, m in zip(axes[0], methods):
        for c in (c for c in curves if c["method"] == m):
            order = np.argsort(c["x"])
            ax.plot(np.asarray(c["x"])[order], np.asarray(c["pressure"])[order],
                    ".-", label=c["label"])
        ax.set_title(m)
        ax.set_xlabel("x")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[0][0].set_ylabel("pressure (force / length)")
    fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)


def plot_newton(steps: Sequence[dict], path: str | os.PathLike,
                title: str = "Newton convergence per load step") -> Path:
    """Residual norm against iteration, one line per load step (log scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    cmap = plt.get_cmap("viridis")
    for k, s in enumerate(steps):
        r = np.maximum(np.asarray(s["residual_norms"], dtype=float), 1e-300)
        ax.semilogy(np.arange(len(r)), r, "o-", ms=3, color=cmap(k / max(1, len(steps) - 1)),
                    label=f"lf={s['load_factor']:.3g}" if len(steps) <= 10 else None)
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("Newton iteration")
    ax.set_ylabel("residual norm")
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    if len(steps) <= 10:
        ax.legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)


def _save(fig, path) -> Path:
    from .io import atomic_path

    path = Path(path)
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return Picture(path)
