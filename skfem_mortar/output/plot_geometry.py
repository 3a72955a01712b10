"""What the model figure (:mod:`skfem_mortar.output.plot`) shows, taken from the
model at a state: each body's points, polygons and lines and its colouring field,
the supports of its ``Dirichlet`` items, the load arrows of its load items, the
contact tables and rigid masters, the axis limits (numbers only, no matplotlib).
"""
from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

#: preferred colouring field, in order
_COLOUR_BY = ("von_mises", "tension")
#: polygon vertex order of each meshio cell type (midside nodes between their corners)
_POLYGON = {"triangle": [0, 1, 2], "quad": [0, 1, 2, 3],
            "triangle6": [0, 3, 1, 4, 2, 5], "quad8": [0, 4, 1, 5, 2, 6, 3, 7],
            "quad9": [0, 4, 1, 5, 2, 6, 3, 7]}
_LINE = {"line": [0, 1], "line3": [0, 2, 1]}
#: shape functions (start, end, mid) of a 3-node line at 9 points along it: curved
#: traces are drawn through these, not as chords
_XI = np.linspace(-1.0, 1.0, 9)
_LINE3_SAMPLES = np.stack([0.5 * _XI * (_XI - 1), 0.5 * _XI * (_XI + 1), 1 - _XI ** 2])
#: the length of a load arrow, as a fraction of the model's size
_ARROW_LENGTH = 0.07


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
    from ..core.dirichlet import Dirichlet

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
