"""Pictures: the paper-style figure of a run and line plots (matplotlib, off-screen).

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

Views with pyvista (the outputs as pyvista data, the off-screen set-up) are in
:mod:`.views`.

All heavy imports happen inside the functions, so importing this module is cheap.
"""
from __future__ import annotations

import os
import textwrap
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

__all__ = ["figure", "draw", "render", "plot_pressure", "pressure_figure", "plot_newton",
           "relative_spread", "colour_ticks", "tick_labels", "CONSTANT_SPREAD",
           "FIELD_WORDS", "PRESSURE_WORDS", "TANGENTIAL_WORDS", "Picture"]

#: preferred colouring field, in order
_COLOUR_BY = ("von_mises", "tension")
#: a field with relative spread ``(max - min) / max|f|`` below this is drawn in
#: one colour with its value (a frictionless cable's tension, a patch test's
#: pressure): stretching round-off or a 0.01 % variation over a colour map
#: would suggest a variation that is not there
CONSTANT_SPREAD = 1e-3
#: the fields in words, with their unit convention
FIELD_WORDS = {
    "von_mises": "von Mises stress (force/length\u00b2)",
    "tension": "cable tension (force)",
}
PRESSURE_WORDS = ("contact pressure (traction, force/length\u00b2 per unit thickness, "
                  "> 0 compression)")
TANGENTIAL_WORDS = ("tangential traction, dashed (on the slave along its tangent, "
                    "force/length\u00b2 per unit thickness)")
#: colour maps: solids, cables, contact pressure
_CMAP = {"von_mises": "viridis", "tension": "plasma", "pressure": "inferno"}
#: polygon vertex order of each meshio cell type (midside nodes between their corners)
_POLYGON = {"triangle": [0, 1, 2], "quad": [0, 1, 2, 3],
            "triangle6": [0, 3, 1, 4, 2, 5], "quad8": [0, 4, 1, 5, 2, 6, 3, 7],
            "quad9": [0, 4, 1, 5, 2, 6, 3, 7]}
_LINE = {"line": [0, 1], "line3": [0, 2, 1]}
#: shape functions (start, end, mid) of a 3-node line at 9 points along it: curved
#: traces are drawn through these, not as chords
_XI = np.linspace(-1.0, 1.0, 9)
_LINE3_SAMPLES = np.stack([0.5 * _XI * (_XI - 1), 0.5 * _XI * (_XI + 1), 1 - _XI ** 2])
#: markers and arrows are thinned so that no two are closer than this (inches
#: on the picture): they would pile up where the mesh is fine
_SUPPORT_SPACING = 0.11
_ARROW_SPACING = 0.16
#: the length of a load arrow, as a fraction of the model's size
_ARROW_LENGTH = 0.07
#: meshes with more cells are drawn without element edges (they would turn grey)
_MAX_EDGED_CELLS = 4000
#: layout, in inches: a row of colour keys, the gaps around the keys
_KEY_ROW = 1.1
_KEY_GAP = 0.55
_KEY_BAR = 0.16
_KEYS_PER_ROW = 3
_KEY_FONT = 9


class Picture(type(Path())):  # the concrete Path class: Path itself takes no subclass before 3.12
    """The path of a PNG written here; a notebook shows the picture inline."""

    def _repr_png_(self) -> bytes | None:
        """The PNG's bytes (None, i.e. the text repr, for a path that is none)."""
        return self.read_bytes() if self.suffix.lower() == ".png" and self.is_file() else None


# -- numbers on keys ------------------------------------------------------------
def relative_spread(values: np.ndarray) -> float:
    """``(max f - min f) / max |f|`` over the finite values (0 for none or all zero)."""
    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    if v.size == 0:
        return 0.0
    scale = float(np.abs(v).max())
    return 0.0 if scale == 0.0 else float((v.max() - v.min()) / scale)


def tick_labels(ticks: Sequence[float]) -> list[str]:
    """Labels of ``ticks`` with the fewest digits at which each reads its tick
    (to ``1e-6`` of the smallest tick spacing) and so no two read the same.

    Fixed-point for ``1e-3 <= max|t| < 1e5``, scientific otherwise; the same
    number of decimals on every label; a tick within ``1e-9`` of the span from 0
    reads ``0``.
    """
    t = np.asarray(ticks, dtype=float).ravel()
    if t.size == 0:
        return []
    span = float(t.max() - t.min())
    t = np.where(np.abs(t) <= 1e-9 * span, 0.0, t) + 0.0  # no "-0.00"
    top = float(np.abs(t).max())
    sci = top != 0.0 and not 1e-3 <= top < 1e5
    step = float(np.diff(np.sort(t)).min()) if t.size > 1 else top
    for d in range(0, 17):
        labels = [f"{v:.{d}e}" if sci else f"{v:.{d}f}" for v in t]
        read = np.array([float(x) for x in labels])
        if len(set(labels)) == len(labels) and np.all(np.abs(read - t) <= 1e-6 * step):
            return labels
    return labels


def colour_ticks(lo: float, hi: float, n: int = 5) -> tuple[np.ndarray, list[str]]:
    """At most ``n`` round ticks in ``[lo, hi]`` and their distinct labels.

    Raises
    ------
    ValueError
        Unless ``lo < hi`` are finite and ``n >= 2``.
    """
    from matplotlib.ticker import MaxNLocator

    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise ValueError(f"lo, hi must be finite with lo < hi, got {lo!r}, {hi!r}")
    if n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    t = MaxNLocator(nbins=n - 1, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    slack = 1e-9 * (hi - lo)
    t = t[(t >= lo - slack) & (t <= hi + slack)]
    if t.size < 2:
        t = np.array([lo, hi])
    return t, tick_labels(t)


def _flat(values) -> np.ndarray:
    """One array of the values of a key (a list of per-block arrays or one array)."""
    if isinstance(values, list):
        return np.concatenate([np.ravel(v) for v in values]) if values else np.zeros(0)
    return np.ravel(values)


def _titled(name: str, words: str) -> str:
    """``name: words``, or ``words`` alone where they already say the name."""
    return words if not name or name.lower() in words.lower() else f"{name}: {words}"


def _value(v: float) -> str:
    """A field's value in 4 significant digits (what a spread below 1e-3 can
    tell), fixed-point for ``1e-3 <= |v| < 1e5``."""
    if v != 0.0 and 1e-3 <= abs(v) < 1e5:
        return np.format_float_positional(v, precision=4, unique=False, fractional=False,
                                          trim="k").rstrip(".")  # "16.10": its 4 digits
    return f"{v:.4g}"


# -- what is drawn --------------------------------------------------------------
def _positions(item, z: np.ndarray | None) -> tuple[np.ndarray, list, dict]:
    """Points (N, 2) at ``z`` (displacement added), cell blocks, cell data."""
    points, cells = item.output_mesh()
    points = np.array(points, dtype=float)[:, :2]
    pdata, cdata = item.output_data(z)
    if z is not None and "displacement" in pdata:
        d = np.asarray(pdata["displacement"], dtype=float)
        points[:, :d.shape[1]] += d
    return points, cells, cdata


def _shapes(points: np.ndarray, cells: list) -> tuple[list, list, list[int]]:
    """Polygons (per block: array (n_cells, n_v, 2)) and line segments (per block:
    (n_cells, n_v, 2)) of the cell blocks, and the index of each block in each list."""
    polys, lines, where = [], [], []
    for kind, c in cells:
        c = np.asarray(c, dtype=np.int64)
        if kind in _POLYGON:
            polys.append(points[c[:, _POLYGON[kind]]])
            where.append(0)
        elif kind == "line3":  # the curved trace (start, end, mid), sampled
            lines.append(np.einsum("ekd,kq->eqd", points[c], _LINE3_SAMPLES))
            where.append(1)
        elif kind in _LINE:
            lines.append(points[c[:, _LINE[kind]]])
            where.append(1)
        else:
            raise ValueError(f"cell type must be one of {sorted(_POLYGON) + sorted(_LINE)} "
                             f"to be drawn, got {kind!r}")
    return polys, lines, where


def _body_field(cdata: dict) -> tuple[str | None, list]:
    """The colouring field among a body's cell data and its values per cell block."""
    field = next((f for f in _COLOUR_BY if f in cdata), None)
    if field is None:
        return None, []
    return field, [np.asarray(v, dtype=float) for v in cdata[field]]


def _node_lookup(body) -> np.ndarray | None:
    """Local dof -> flat index into ``body.node_dofs`` (2, n_nodes), -1 elsewhere."""
    nd = getattr(body, "node_dofs", None)
    if nd is None or not hasattr(body, "x"):
        return None
    nd = np.asarray(nd, dtype=np.int64)
    lookup = np.full(int(body.n_dofs), -1, dtype=np.int64)
    lookup[nd.ravel()] = np.arange(nd.size)
    return lookup


def _supports(items: Sequence, load_factor: float) -> list[dict]:
    """Per body held by ``Dirichlet`` items: its node classes (``"xy"``: both
    components held at 0, ``"x"``, ``"y"``: one, ``"driven"``: a non-zero
    prescribed value) as boolean masks over its nodes."""
    from ..core.model import Dirichlet

    per_body: dict[int, dict] = {}
    for it in items:
        if not isinstance(it, Dirichlet):
            continue
        lookup = _node_lookup(it.body)
        if lookup is None:
            continue
        entry = per_body.setdefault(id(it.body), {
            "body": it.body, "held": np.zeros(np.shape(it.body.node_dofs), dtype=bool),
            "moved": np.zeros(np.shape(it.body.node_dofs), dtype=bool)})
        dofs, vals = it.prescribed(load_factor)
        hit = lookup[dofs - it.body.offset]
        on = hit >= 0  # dofs that are not node displacements (a pressure) are not drawn
        entry["held"].flat[hit[on]] = True
        entry["moved"].flat[hit[on]] |= np.asarray(vals)[on] != 0.0
    out = []
    for e in per_body.values():
        held, moved = e["held"], e["moved"].any(axis=0)
        out.append({"body": e["body"], "driven": moved,
                    "xy": held.all(axis=0) & ~moved,
                    "x": held[0] & ~held[1] & ~moved,
                    "y": held[1] & ~held[0] & ~moved})
    return out


def _nodal_loads(item, z: np.ndarray, load_factor: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes (n,), positions (n, 2) and nodal forces (n, 2) of a load item at ``z``: minus its
    residual, on the nodes it loads (a force below ``1e-9`` of the largest is
    round-off of the assembly and not a load)."""
    body = item.body
    lookup = _node_lookup(body)
    if lookup is None:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 2)), np.zeros((0, 2))
    c = item.assemble(np.asarray(z, dtype=float), load_factor, tangent=False)
    nd = np.asarray(body.node_dofs, dtype=np.int64)
    f = np.zeros(nd.size)
    local = np.asarray(c.r_index, dtype=np.int64) - body.offset
    ok = (local >= 0) & (local < len(lookup))
    hit = lookup[local[ok]]
    np.add.at(f, hit[hit >= 0], -np.asarray(c.r_value, dtype=float)[ok][hit >= 0])
    F = f.reshape(nd.shape).T
    norm = np.hypot(F[:, 0], F[:, 1])
    loaded = np.flatnonzero(norm > 1e-9 * norm.max(initial=0.0))
    return loaded, body.x(z).T[loaded], F[loaded]


def _outward(body, z: np.ndarray) -> np.ndarray | None:
    """Per node of ``body`` (n_nodes, 2): from the mean centroid of the polygon
    cells around the node to the node, which on the boundary points out of the
    body (None for a body without polygon cells, a cable)."""
    points, cells, _ = _positions(body, z)
    polys = [(c, np.asarray(c, dtype=np.int64)) for k, c in cells if k in _POLYGON]
    if not polys or len(points) != np.shape(body.node_dofs)[1]:
        return None
    total, count = np.zeros((len(points), 2)), np.zeros(len(points))
    for _, c in polys:
        centroid = points[c].mean(axis=1)                       # (n_cells, 2)
        np.add.at(total, c.ravel(), np.repeat(centroid, c.shape[1], axis=0))
        np.add.at(count, c.ravel(), 1.0)
    return points - total / np.maximum(count, 1.0)[:, None]


def _thin(x: np.ndarray, spacing: float) -> np.ndarray:
    """Indices (ascending) of points of ``x`` (n, 2) no two closer than ``spacing``:
    one per square of side ``spacing / 2`` (vectorized), then greedily in index
    order (a loop over the at most ``O(extent / spacing)^2`` survivors)."""
    x = np.asarray(x, dtype=float).reshape(-1, 2)
    if len(x) == 0 or spacing <= 0.0:
        return np.arange(len(x))
    cells = np.floor(x / (0.5 * spacing)).astype(np.int64)
    _, first = np.unique(cells, axis=0, return_index=True)
    kept: list[int] = []
    for i in np.sort(first):
        if not kept or np.min(np.hypot(*(x[kept] - x[i]).T)) >= spacing:
            kept.append(int(i))
    return np.array(kept, dtype=np.int64)


def _model_size(shapes) -> float:
    """The largest extent of the bodies over both states (1 for no bodies)."""
    if not shapes:
        return 1.0
    xy = np.concatenate([p for s in shapes for p in s[:2]])
    return float(np.max(xy.max(axis=0) - xy.min(axis=0))) or 1.0


def _tables(contact) -> list[tuple[str, Callable, Any]]:
    """``contact`` (a callable, a ContactTable, or a sequence of them) as
    (name, callable, pair or None): the pair of a ``contact_data`` method is its owner."""
    if contact is None:
        return []
    if callable(contact) or hasattr(contact, "contact_data"):
        contact = [contact]
    out = []
    for c in contact:
        fun = getattr(c, "contact_data", c)
        if not callable(fun):
            raise ValueError(f"contact must be a callable(z) -> dict, a contact pair or a "
                             f"sequence of them, got {type(c).__name__}")
        pair = c if hasattr(c, "contact_data") else getattr(fun, "__self__", None)
        out.append((getattr(c, "name", "") if hasattr(c, "contact_data") else "", fun, pair))
    return out


def _rigid_masters(tables) -> list:
    """The rigid master surfaces (``body is None``) of the contact pairs."""
    out = []
    for _, _, pair in tables:
        master = getattr(pair, "master", None)
        if master is not None and getattr(master, "body", 0) is None:
            out.append(master)
    return out


# -- the figure -----------------------------------------------------------------
def figure(setup, result, path: str | os.PathLike, title: str = "",
           window_size: tuple[int, int] = (1600, 700)) -> Path:
    """The picture of a scene's run: :func:`draw` of the bodies among
    ``setup.outputs`` (the contact outputs are shown by ``setup.contact``)
    at ``result``'s first and last state, with the supports and loads of
    ``result.model``.  Reads only ``setup.outputs`` and ``setup.contact`` of
    the :class:`~skfem_mortar.scenes.Setup`.
    """
    from ..core.model import Item

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
        Drawn as meshes (:class:`~skfem_mortar.core.model.Output`): solids
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
        contact pair, or a cell type that cannot be drawn.

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
    dpi = 120.0
    first, last = [_positions(b, z0) for b in bodies], [_positions(b, z1) for b in bodies]
    shapes = [(a[0], b[0], b[1]) for a, b in zip(first, last)]
    supports = _supports(items, load_factor)
    loads = [it for it in items if getattr(it, "phase", None) == "loads"
             and getattr(it, "body", None) is not None]
    size = _model_size(shapes)
    arrows = [[_arrows(it, z, load_factor, size) for it in loads] for z in (z0, z1)]

    # the colour keys: one per body with a field, one per contact pair in contact
    keys: list[dict] = []
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
    points = []
    tables = _tables(contact)
    rigids = _rigid_masters(tables)
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


def _arrows(item, z: np.ndarray, load_factor: float, size: float
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The load arrows of ``item`` at ``z``: the loaded nodes (n, 2), the arrow
    vectors (n, 2: along the nodal load, all :data:`_ARROW_LENGTH` ``* size``
    long: they mark where and which way the load acts, not how much) and whether
    each arrow ends at its node (else it starts there).

    The arrows stay outside their body: on a solid the item's arrows end at
    their nodes where the load clearly pushes into the body (the mean cosine
    with :func:`_outward` below -0.25: a pressure, not a shear), else start
    there; on a cable a pressure's arrows end at the nodes (it pushes from the
    side the arrow comes from) and a point load's start there.
    """
    nodes, x, f = _nodal_loads(item, z, load_factor)
    d = _ARROW_LENGTH * size * f / np.hypot(f[:, 0], f[:, 1])[:, None] if len(f) else f
    out = _outward(item.body, z) if len(f) and hasattr(item.body, "output_mesh") else None
    if out is None:
        ends = np.full(len(f), hasattr(item, "current_pressure"))
    else:
        o = out[nodes] / np.maximum(np.hypot(*out[nodes].T), 1e-300)[:, None]
        cos = np.einsum("ij,ij->i", d, o) / (_ARROW_LENGTH * size)
        ends = np.full(len(f), bool(cos.mean() < -0.25))
    return x, d, ends


def _limits(shapes, points, arrows) -> list[float]:
    """Common axis limits of both panels: every body at both states, the contact
    points, both ends of the arrows, with a 5 % margin."""
    xy = [p for s in shapes for p in s[:2]] + [pt["x"] for pt in points]
    for panel in arrows:
        for x, d, ends in panel:
            xy += [x, x - np.where(ends[:, None], d, -d)]
    xy = np.concatenate([np.reshape(a, (-1, 2)) for a in xy if np.size(a)]) \
        if any(np.size(a) for a in xy) else np.zeros((1, 2))
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    pad = 0.05 * max(float(np.max(hi - lo)), 1e-12)
    return [lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad]


def _draw_body(ax, name: str, points: np.ndarray, cells: list, key: dict | None) -> None:
    """A body's polygons and lines, in one colour or coloured by its key's field."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.colors import Normalize

    polys, lines, where = _shapes(points, cells)
    n_cells = sum(len(p) for p in polys)
    for kind, blocks in ((0, polys), (1, lines)):
        if not blocks:
            continue
        verts = [v for b in blocks for v in b]
        if kind == 0:
            coll = PolyCollection(verts, edgecolors="0.35" if n_cells <= _MAX_EDGED_CELLS
                                  else "face", linewidths=0.25, zorder=1)
            plain = "lightsteelblue"
        else:
            coll = LineCollection(verts, linewidths=3.0, capstyle="round", zorder=2)
            plain = "tan"
        coll.set_gid(name)
        if key is None:
            coll.set_color(plain) if kind == 1 else coll.set_facecolor(plain)
        else:
            vals = np.concatenate([np.ravel(v) for v, w in zip(key["values"], where)
                                   if w == kind])
            cmap = _CMAP.get(key["field"], "viridis")
            if key["constant"]:
                import matplotlib

                one = matplotlib.colormaps[cmap](0.5)
                coll.set_color(one) if kind == 1 else coll.set_facecolor(one)
            else:
                coll.set_array(vals)
                coll.set_cmap(cmap)
                coll.set_norm(Normalize(key["lo"], key["hi"]))
            key["artist"] = coll
        ax.add_collection(coll)


def _draw_points(ax, pt: dict):
    """The contact nodes in contact, coloured by pressure on ``[0, max]``."""
    from matplotlib.colors import Normalize

    kw = dict(s=28, edgecolors="black", linewidths=0.4, zorder=4)
    if pt["constant"]:
        import matplotlib

        art = ax.scatter(pt["x"][:, 0], pt["x"][:, 1],
                         color=matplotlib.colormaps[_CMAP["pressure"]](0.5), **kw)
    else:
        art = ax.scatter(pt["x"][:, 0], pt["x"][:, 1], c=pt["values"], cmap=_CMAP["pressure"],
                         norm=Normalize(0.0, pt["hi"]), **kw)
    art.set_gid("contact pressure")
    return art


#: support marker per node class: (marker, face colour, legend label)
_SUPPORT_STYLE = {"xy": ("^", "black", "support: x, y held"),
                  "x": (">", "none", "support: x held"),
                  "y": ("^", "none", "support: y held"),
                  "driven": ("s", "tab:red", "prescribed displacement \u2260 0")}


def _draw_supports(ax, supports: list[dict], z: np.ndarray, spacing: float) -> None:
    """One marker per held node and class (:data:`_SUPPORT_STYLE`), at nodes no
    two closer than ``spacing``."""
    for s in supports:
        x = s["body"].x(z)
        for cls, (marker, face, _) in _SUPPORT_STYLE.items():
            on = np.flatnonzero(s[cls])
            on = on[_thin(x[:, on].T, spacing)]
            if on.size:
                edge = "tab:red" if cls == "driven" else "black"
                (line,) = ax.plot(x[0, on], x[1, on], linestyle="none", marker=marker,
                                  markersize=7, markerfacecolor=face, markeredgecolor=edge,
                                  markeredgewidth=1.0, zorder=5)
                line.set_gid("supports")


def _draw_loads(ax, panel: list, spacing: float) -> None:
    """The arrows of :func:`_arrows`, one quiver per load item, at nodes no two
    closer than ``spacing``."""
    for x, d, ends in panel:
        keep = _thin(x, spacing)
        x, d, ends = x[keep], d[keep], ends[keep]
        if not len(d):
            continue
        x = np.where(ends[:, None], x - d, x)
        q = ax.quiver(x[:, 0], x[:, 1], d[:, 0], d[:, 1], angles="xy", scale_units="xy",
                      scale=1.0, color="crimson", width=0.0025, headwidth=4.5,
                      headlength=5, headaxislength=4.5, zorder=6)
        q.set_gid("loads")


def _draw_rigid(ax, surface, z: np.ndarray) -> None:
    """A rigid contact surface as a thick grey polyline (clipped by the axes)."""
    from matplotlib.collections import LineCollection

    x = np.asarray(surface.x(z), dtype=float).T
    coll = LineCollection(x[np.asarray(surface.segments)], colors="0.3", linewidths=2.5,
                          zorder=2)
    coll.set_gid("rigid")
    ax.add_collection(coll)


def _legend_handles(supports: list[dict], loaded: bool, rigid: bool = False) -> list:
    from matplotlib.lines import Line2D

    handles = []
    for cls, (marker, face, label) in _SUPPORT_STYLE.items():
        if any(s[cls].any() for s in supports):
            edge = "tab:red" if cls == "driven" else "black"
            handles.append(Line2D([], [], linestyle="none", marker=marker, markersize=7,
                                  markerfacecolor=face, markeredgecolor=edge, label=label))
    if loaded:
        handles.append(Line2D([], [], linestyle="none", marker=r"$\rightarrow$",
                              markersize=14, color="crimson",
                              label="load (its direction at the state drawn)"))
    if rigid:
        handles.append(Line2D([], [], color="0.3", linewidth=2.5, label="rigid surface"))
    return handles


def _draw_key(fig, cax, key: dict, mappable, width_in: float) -> None:
    """A horizontal colour bar with distinct tick labels, or for a constant field
    a bar in its one colour with the value written under it."""
    chars = max(20, int(width_in * 72 / (0.55 * _KEY_FONT)))
    title = textwrap.fill(key["title"], chars)
    cax.set_gid("colour key")
    cax.set_label(key["title"])
    if key["constant"]:
        import matplotlib
        from matplotlib.patches import Rectangle

        one = matplotlib.colormaps[_CMAP.get(key["field"], "viridis")](0.5)
        cax.add_patch(Rectangle((0, 0), 1, 1, transform=cax.transAxes, color=one))
        cax.set_xticks([])
        cax.set_yticks([])
        value = _value(float(np.mean(_flat(key["values"]))))
        cax.text(0.5, -0.35, f"{value} everywhere (relative spread < {CONSTANT_SPREAD:g})",
                 transform=cax.transAxes, ha="center", va="top", fontsize=_KEY_FONT,
                 gid="constant value")
    else:
        cb = fig.colorbar(mappable, cax=cax, orientation="horizontal")
        ticks, labels = colour_ticks(key["lo"], key["hi"], n=6)
        cb.set_ticks(ticks, labels=labels)
        cb.minorticks_off()
        cax.tick_params(labelsize=8)
        rng = (f"max {_value(key['hi'])}" if key["field"] == "pressure"
               else f"min {_value(key['lo'])}, max {_value(key['hi'])}")
        title = f"{title}\n{rng}" if len(title) + len(rng) + 2 > chars else f"{title}, {rng}"
    cax.set_title(title, fontsize=_KEY_FONT, pad=3)


# -- line plots -----------------------------------------------------------------
def pressure_figure(curves: Sequence[dict],
                    title: str = "contact pressure along the interface"):
    """The figure of :func:`plot_pressure` (not saved).

    One panel per method: the pressure against position (solid lines, the left
    axis, starting at 0); where a curve has ``tangential_traction`` (a friction
    run), that panel gets a second axis on the right with the tangential
    traction, dashed, in the colour of the curve's pressure (lines with gid
    ``"tangential traction"``, the axis labelled :data:`TANGENTIAL_WORDS`).  A
    frictionless panel has no second axis.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods = list(dict.fromkeys(c["method"] for c in curves))
    fig, axes = plt.subplots(1, len(methods), figsize=(5.5 * len(methods), 4.2),
                             sharey=True, squeeze=False)
    for ax, m in zip(axes[0], methods):
        mine = [c for c in curves if c["method"] == m]
        twin = ax.twinx() if any(c.get("tangential_traction") is not None for c in mine) \
            else None
        for c in mine:
            order = np.argsort(c["x"])
            x = np.asarray(c["x"])[order]
            prof = c.get("profile")
            if prof is None:
                (ln,) = ax.plot(x, np.asarray(c["pressure"])[order], ".-", label=c["label"])
            else:
                (ln,) = ax.plot(prof["x"], prof["pressure"], "-", label=c["label"])
                ax.plot(x, np.asarray(c["pressure"])[order], ".", color=ln.get_color())
            ln.set_gid("pressure")
            if twin is not None and c.get("tangential_traction") is not None:
                (lt,) = twin.plot(x, np.asarray(c["tangential_traction"], dtype=float)[order],
                                  "--", color=ln.get_color(), lw=1.0)
                lt.set_gid("tangential traction")
        ax.set_title(m)
        ax.set_xlabel("x (current position of the slave node)")
        ax.grid(alpha=0.3)
        if twin is not None:
            twin.set_ylabel(textwrap.fill(TANGENTIAL_WORDS, 45), fontsize=9)
            twin.set_gid("tangential traction axis")
            ax.plot([], [], "--", color="grey", label="tangential traction (right axis)")
        ax.legend(fontsize=8)
    axes[0][0].set_ylim(bottom=0.0)
    axes[0][0].set_ylabel(textwrap.fill(PRESSURE_WORDS, 45), fontsize=9)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_pressure(curves: Sequence[dict], path: str | os.PathLike,
                  title: str = "contact pressure along the interface") -> Path:
    """Contact pressure against position, one panel per method; the pressure
    axis starts at 0 (:func:`pressure_figure`, written as a PNG).

    Parameters
    ----------
    curves : sequence of dict
        Each with ``method``, ``label`` (e.g. the load factor), ``x`` and
        ``pressure`` arrays (the nodes), optionally ``tangential_traction`` (an
        array at the same nodes: a friction run's, drawn dashed on a second axis)
        and ``profile``: a
        :func:`~skfem_mortar.output.contact_output.pressure_profile` dict, drawn as
        the continuous line (for 3-node segments, the quadratic profile) with the
        nodes as markers.
    """
    return _save(pressure_figure(curves, title), path)


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
    ax.set_ylabel("residual norm (force)")
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    if len(steps) <= 10:
        ax.legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)


def _save(fig, path) -> Path:
    from .io import atomic_path

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return Picture(path)
