"""Pictures: the paper-style figure of a run (matplotlib, off-screen).

The figure (:func:`draw`, :func:`figure`, ``Result.plot``) is drawn with
matplotlib's object API (no pyplot state, no display): the meshes as polygon
collections, cables as line collections, the contact nodes as points, with
coordinate axes in both panels.  What it promises, and ``tests/test_figures.py``
checks on the artists:

- one colour key per field and body (and per contact pair), each in its own
  axes of a grid below the panels, so no two keys overlap;
- a field whose relative spread ``(max - min) / max|f|`` is below
  :data:`CONSTANT_SPREAD` is drawn in one colour and its key states the value;
- every other key has ticks whose labels all differ (:func:`tick_labels`);
- the contact pressure's colour range starts at 0;
- fields are named in words with their unit convention (the package is
  unit-free: "force/length^2" means the model's force over its length squared);
- supports (``Dirichlet`` items) are marked at their nodes by triangles
  (filled: both components held; open, pointing along the held component:
  one; squares: a prescribed non-zero displacement), loads (items of phase
  ``"loads"``: tractions, follower pressures, point loads) by arrows of one
  length at the loaded nodes, along the nodal load at the state drawn, outside
  the body; rigid contact surfaces as grey lines;
- both panels have coordinate axes with ticks, at one scale.

What the figure shows is taken from the model by :mod:`.plot_geometry` and drawn
by :mod:`.plot_draw`; the words, key numbers and the PNG file are
:mod:`.plot_common`'s.  The line plots (:func:`plot_pressure`,
:func:`plot_newton`) are in :mod:`.plot_lines`, their names offered here too.
Views with pyvista (the outputs as pyvista data, the off-screen set-up) are in
:mod:`.views`.

All heavy imports happen inside the functions, so importing this module is cheap.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .plot_common import (CONSTANT_SPREAD, FIELD_WORDS, PRESSURE_WORDS, TANGENTIAL_WORDS, Picture,
                          _flat, _save, _titled, colour_ticks, relative_spread, tick_labels)
from .plot_draw import (_KEY_FONT, _draw_body, _draw_key, _draw_loads, _draw_points, _draw_rigid,
                        _draw_supports, _legend_handles)
from .plot_geometry import (_arrows, _body_field, _limits, _model_size, _positions, _rigid_masters,
                            _supports, _tables)
from .plot_lines import plot_newton, plot_pressure, pressure_figure

__all__ = ["figure", "draw", "render", "plot_pressure", "pressure_figure", "plot_newton",
           "relative_spread", "colour_ticks", "tick_labels", "CONSTANT_SPREAD",
           "FIELD_WORDS", "PRESSURE_WORDS", "TANGENTIAL_WORDS", "Picture"]

#: markers and arrows are thinned so that no two are closer than this (inches
#: on the picture): they would pile up where the mesh is fine
_SUPPORT_SPACING = 0.11
_ARROW_SPACING = 0.16
#: layout, in inches: a row of colour keys, the gaps around the keys
_KEY_ROW = 1.1
_KEY_GAP = 0.55
_KEY_BAR = 0.16
_KEYS_PER_ROW = 3


def figure(setup, result, path: str | os.PathLike, title: str = "",
           window_size: tuple[int, int] = (1600, 700)) -> Path:
    """The picture of a scene's run: :func:`draw` of the bodies among
    ``setup.outputs`` (the contact outputs are shown by ``setup.contact``)
    at ``result``'s first and last state, with the supports and loads of
    ``result.model``.  Reads only ``setup.outputs`` and ``setup.contact`` of
    the :class:`~skfem_mortar.scenes.Setup`.
    """
    from ..core.item import Item

    return draw([o for o in setup.outputs if isinstance(o, Item)], result.states[0],
                result.z, path, title=title, window_size=window_size,
                contact=setup.contact, items=result.model.items,
                load_factor=float(result.load_factors[-1]))


def draw(bodies: Sequence, z0: np.ndarray, z1: np.ndarray, path: str | os.PathLike, *,
         contact=None, title: str = "", window_size: tuple[int, int] = (1600, 700),
         items: Sequence = (), load_factor: float = 1.0) -> Path:
    """Initial configuration (left, at ``z0``) and deformed model (right, at
    ``z1``), written as PNG: :func:`render`, saved at 120 dpi."""
    return _save(render(bodies, z0, z1, contact=contact, title=title,
                        window_size=window_size, items=items, load_factor=load_factor),
                 path)


def render(bodies: Sequence, z0: np.ndarray, z1: np.ndarray, *, contact=None,
           title: str = "", window_size: tuple[int, int] = (1600, 700),
           items: Sequence = (), load_factor: float = 1.0) -> Any:
    """The figure of :func:`draw` as a matplotlib ``Figure`` (not saved).

    Parameters
    ----------
    bodies : sequence of Output
        Drawn as meshes (:class:`~skfem_mortar.core.item.Output`): solids
        coloured by von Mises stress, cables by tension, each with its key.
    z0, z1 : ndarray
        The unknowns of the left and the right panel.
    contact : callable(z) -> dict, ContactTable, or a sequence of them, optional
        A contact pair's ``contact_data``: its slave nodes with a pressure
        ``> 0`` at ``z1`` are drawn as points coloured by the pressure, on a
        range from 0.
    title : str
        Above both panels.
    window_size : (int, int)
        Width and height in pixels at 120 dpi (the height grows by a row per
        three colour keys beyond the first three).
    items : sequence of Item
        The model's items: its ``Dirichlet`` items are marked as supports and
        its load items (``phase == "loads"``) as arrows at ``load_factor``, at
        the geometry of each panel.
    load_factor : float
        The load factor of ``z1`` (the loads of both panels are drawn at it).

    Raises
    ------
    ValueError
        For a ``window_size`` below 200 pixels or too small for the panels, a
        non-finite ``load_factor``, a ``contact`` that is not a callable or a
        contact pair, a cell type that cannot be drawn, or a 3D body
        (:func:`~skfem_mortar.output.render3d.render3d` draws those).

    Returns
    -------
    matplotlib.figure.Figure
        Its panels have gid ``"panel"``, its keys gid ``"colour key"`` (and the
        key's title as label), the support markers gid ``"supports"``, the load
        arrows gid ``"loads"``, each body's collection its name.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    bodies = list(bodies)
    if len(window_size) != 2 or min(window_size) < 200:
        raise ValueError(f"window_size must be (width, height) in pixels, each >= 200, "
                         f"got {window_size!r}")
    if not np.isfinite(load_factor):
        raise ValueError(f"load_factor must be finite, got {load_factor!r}")
    solid = [b.name for b in bodies if getattr(b, "dim", 2) == 3]
    if solid:
        raise ValueError(f"bodies: {solid[0]!r} is a 3D body; 3D models are drawn by "
                         f"output.render3d.render3d (pyvista), this figure is 2D")
    dpi = 120.0
    first, last = [_positions(b, z0) for b in bodies], [_positions(b, z1) for b in bodies]
    shapes = [(a[0], b[0], b[1]) for a, b in zip(first, last)]
    supports = _supports(items, load_factor)
    loads = [it for it in items if getattr(it, "phase", None) == "loads"
             and getattr(it, "body", None) is not None]
    size = _model_size(shapes)
    arrows = [[_arrows(it, z, load_factor, size) for it in loads] for z in (z0, z1)]

    # the colour keys: one per body with a field, one per contact pair in contact
    keys = _body_keys(bodies, last)
    tables = _tables(contact)
    rigids = _rigid_masters(tables)
    points = _contact_points(tables, z1)

    # layout (inches): title, legend, two panels, rows of keys
    key_list = [k for k in keys if k is not None] + points
    n_rows = -(-len(key_list) // _KEYS_PER_ROW)
    W = window_size[0] / dpi
    H = window_size[1] / dpi + _KEY_ROW * max(0, n_rows - 1)
    fig = Figure(figsize=(W, H), dpi=dpi)
    FigureCanvasAgg(fig)  # off-screen; its renderer measures the artists
    top, legend_h, under, left, right, gap = 0.45, 0.35, 0.55, 0.75, 0.3, 0.75
    base = 0.1 + _KEY_ROW * n_rows + under
    ph = H - top - legend_h - 0.3 - base
    pw = (W - left - right - gap) / 2
    if ph < 1.0 or pw < 1.0:
        raise ValueError(f"window_size {window_size!r} leaves no room for the panels")
    panels = [fig.add_axes([(left + k * (pw + gap)) / W, base / H, pw / W, ph / H])
              for k in range(2)]

    lim = _limits(shapes, points, arrows)
    per_inch = max((lim[1] - lim[0]) / pw, (lim[3] - lim[2]) / ph)  # data length / inch
    for col, ax in enumerate(panels):
        ax.set_gid("panel")
        ax.set_xlim(lim[0], lim[1])
        ax.set_ylim(lim[2], lim[3])
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.tick_params(labelsize=8)
        ax.set_title("initial configuration" if col == 0
                     else f"deformed (load factor {load_factor:.3g})", fontsize=10)
        for b, (p0, p1, cells), key in zip(bodies, shapes, keys):
            _draw_body(ax, b.name, p0 if col == 0 else p1, cells, key if col else None)
        if col == 1:
            for pt in points:
                pt["artist"] = _draw_points(ax, pt)
        _draw_supports(ax, supports, z0 if col == 0 else z1, _SUPPORT_SPACING * per_inch)
        _draw_loads(ax, arrows[col], _ARROW_SPACING * per_inch)
        for rigid in rigids:
            _draw_rigid(ax, rigid, z0 if col == 0 else z1)
    if title:
        fig.suptitle(title, y=1 - 0.08 / H, va="top", fontsize=12)
    handles = _legend_handles(supports, any(len(a[0]) for a in arrows[1] + arrows[0]),
                              rigid=bool(rigids))
    if handles:
        fig.legend(handles=handles, loc="upper center", ncol=len(handles), frameon=False,
                   fontsize=_KEY_FONT, bbox_to_anchor=(0.5, 1 - top / H))

    # the keys, row by row under the panels
    cols = min(_KEYS_PER_ROW, max(1, len(key_list)))
    kw = (W - left - right - _KEY_GAP * (cols - 1)) / cols
    for i, k in enumerate(key_list):
        row, c = divmod(i, _KEYS_PER_ROW)
        y = 0.1 + _KEY_ROW * (n_rows - 1 - row) + 0.4
        cax = fig.add_axes([(left + c * (kw + _KEY_GAP)) / W, y / H, kw / W, _KEY_BAR / H])
        _draw_key(fig, cax, k, k.get("artist"), width_in=kw)
    return fig


def _body_keys(bodies: Sequence, last: list) -> list[dict | None]:
    """Per body, the colour key of its field at the right panel's state (None
    for a body without one)."""
    keys: list[dict | None] = []
    for b, (_, _, cdata) in zip(bodies, last):
        field, values = _body_field(cdata)
        if field is not None and sum(v.size for v in values):
            v = _flat(values)
            keys.append({"field": field, "values": values,
                         "title": _titled(b.name, FIELD_WORDS.get(field, field)),
                         "lo": float(np.nanmin(v)), "hi": float(np.nanmax(v)),
                         "constant": relative_spread(v) < CONSTANT_SPREAD})
        else:
            keys.append(None)
    return keys


def _contact_points(tables: list, z1: np.ndarray) -> list[dict]:
    """Per contact table with a node in contact at ``z1`` (pressure ``> 0``): those
    nodes, their pressures and the colour key on ``[0, max]``."""
    points = []
    for name, fun, _ in tables:
        c = fun(z1)
        p = np.asarray(c["pressure"], dtype=float)
        on = p > 0
        if on.any():
            words = _titled(name, PRESSURE_WORDS)
            points.append({"x": np.column_stack([np.asarray(c["x"])[on],
                                                 np.asarray(c["y"])[on]]),
                           "values": p[on], "title": words, "field": "pressure",
                           "lo": 0.0, "hi": float(p[on].max()),
                           "constant": relative_spread(p[on]) < CONSTANT_SPREAD})
    return points
