"""The model figure's artists (matplotlib, imported when called): a body's
polygons and lines, the contact points, support markers, load arrows, rigid
surfaces, the legend's handles and a colour key.
"""
from __future__ import annotations

import textwrap

import numpy as np

from .plot_common import CONSTANT_SPREAD, _flat, _value, colour_ticks
from .plot_geometry import _shapes, _thin

#: colour maps: solids, cables, contact pressure
_CMAP = {"von_mises": "viridis", "tension": "plasma", "pressure": "inferno"}
#: meshes with more cells are drawn without element edges (they would turn grey)
_MAX_EDGED_CELLS = 4000
_KEY_FONT = 9


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
