"""Mortar geometry of curved 3-node segments: normal field, projections, mortar segments.

Steps 1 to 3 of the mortar method on lines (the one kernel
:mod:`skfem_mortar.contact.mortar_kernel` integrates on its segments), for surfaces
of 3-node segments ``(start, end, mid)`` (order 2) against surfaces of either
order; a 2-node surface is handled by the same code with its shape functions.
Every function is vectorized over elements (or candidate pairs, or mortar
segments and Gauss points) and works on plain arrays and on the forward-mode
jets of :mod:`skfem_mortar.contact.jets`.  Points and vectors are pairs ``(x, y)``.

Geometry of a segment (``xi`` in [-1, 1])
-----------------------------------------
``x(xi) = sum_A N_A(xi) x_A`` with, for 3 nodes (start, end, mid),
``N_1 = xi (xi - 1)/2``, ``N_2 = xi (xi + 1)/2``, ``N_3 = 1 - xi^2``, and for 2
nodes ``N_1 = (1 - xi)/2``, ``N_2 = (1 + xi)/2``.  In monomials
``x(xi) = P_0 + P_1 xi + P_2 xi^2`` (:func:`element_polynomial`; for 3 nodes
``P_0 = x_3``, ``P_1 = (x_2 - x_1)/2``, ``P_2 = (x_1 + x_2)/2 - x_3``).  The
tangent is ``t = dx/dxi = P_1 + 2 P_2 xi`` and the outward unit normal its
right-hand normal ``nu = (t_y, -t_x)/|t|`` (start -> end, as for 2-node segments).

Step 1, slave normal field (:func:`element_normals`)
----------------------------------------------------
The nodal normal of a vertex is the normalized sum of the unit normals of its
(one or two) slave elements at that end, ``n_A = normalize(nu_prev(+1) +
nu_next(-1))``; a mid node takes its element's own normal ``n_3 = nu(0)``
(which depends on the two vertices only, ``t(0) = P_1``).  The field is
interpolated with the element's shape functions and not normalized,
``n~(xi) = sum_A N_A(xi) n_A``, ``n = n~/|n~|``.  A slave element's normal
field therefore depends on its own nodes and on the nodes of its neighbours
(:func:`slave_slots`): for 3-node segments the previous element's start and
mid node and the next element's end and mid node (7 nodes); for 2-node
segments the previous and the next node (4 nodes, as the linear kernel).

Step 2, projections along the slave normal field
------------------------------------------------
* :func:`project_on_slave`: a point ``x_C`` (a master vertex) onto the curved
  slave element, the ``xi`` solving ``f(xi) = (x_s(xi) - x_C) x n~(xi) = 0``
  (``x`` the 2D cross product; a quartic for 3 nodes), by Newton's method from
  the orthogonal projection onto the chord.
* :func:`project_on_master`: a point ``x_0`` along a direction ``d`` onto the
  curved master element, ``F(eta) = (x_m(eta) - x_0) x d = 0`` (a quadratic in
  ``eta``), by Newton's method from ``-F_0/F_1``; used for the slave element
  ends (along their nodal normals, to decide on which side of the slave element
  a master vertex lies) and for the Gauss points (along ``n~(xi)``).

Step 3, mortar segments (:func:`segment`)
-----------------------------------------
For a candidate pair (slave element e, master element m) whose chords face
each other, the two master vertices project to ``p_1, p_2`` on e and the
mortar segment is ``[max(-1, min p), min(1, max p)]`` on the slave parameter,
one per overlapping pair.  As for 2-node segments
(:mod:`skfem_mortar.contact.mortar_segmentation`), a master vertex beyond an
end of e (its master parameter past that of the slave end projected onto the
master curve along its nodal normal) counts as ``+-inf`` and is clipped, which
also decides far vertices whose quartic has no root or spurious ones; segments
shorter than ``XI_TOL`` in ``xi`` and degenerate elements (chord below
``LEN_TOL`` times the mean) are dropped.  The mid nodes of the master never
bound a mortar segment: a master element is one curve from its start to its end.
"""
from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np

from ..core.chain import segments_at_nodes
from .jets import inv, sqrt, value
from . import mortar_segmentation
from .cells import CellType
from .mortar_segmentation import LEN_TOL, _side, clip_to_slave, master_coordinates, mirror_normal
from .normals import mirror_nodes
from .segmentation import Segmentation, line_cells, register_default
from .search import box_pairs

__all__ = ["monomials", "shape_values", "element_polynomial", "poly", "poly_derivative",
           "element_normals", "slave_slots", "SlaveSlots", "nodal_normals",
           "project_on_slave", "project_on_master", "candidate_pairs",
           "segment", "segment_lines", "Segmentation", "chord_lengths"]


@lru_cache(maxsize=None)
def monomials(cell: CellType) -> np.ndarray:
    """Monomial coefficients ``C`` (n_nodes, 3) of a line cell's shape functions,
    ``N_A(xi) = sum_p C[A, p] xi^p``, read from its row: the Taylor coefficients
    ``N(0)``, ``N'(0)``, ``N''(0)/2`` (line2: ``[[1/2, -1/2, 0], [1/2, 1/2, 0]]``;
    line3: ``[[0, -1/2, 1/2], [0, 1/2, 1/2], [1, 0, -1]]``, exact in floating point).

    Raises
    ------
    ValueError
        When the cell is not a line whose shape functions are one polynomial of
        degree at most 2 on ``[-1, 1]`` (checked against ``cell.shape`` at the
        reference nodes and at seven points inside): the kernels of this module
        and :mod:`~skfem_mortar.contact.mortar_quadratic` write the geometry in
        these monomials.
    """
    if cell.dim != 1:
        raise ValueError(f"cell must be a line (dim 1) for the curved mortar kernel, got "
                         f"{cell.name} (dim {cell.dim})")
    zero = np.zeros((1, 1))
    C = np.stack([np.asarray(cell.shape(zero))[:, 0], np.asarray(cell.dshape(zero))[:, 0, 0],
                  0.5 * np.asarray(cell.d2shape(zero))[:, 0, 0, 0]], 1) + 0.0
    x = np.concatenate([np.asarray(cell.ref_nodes, dtype=float)[0], np.linspace(-0.9, 0.9, 7)])
    if not np.allclose(C @ np.stack([x ** 0, x, x * x]), np.asarray(cell.shape(x[None])),
                       rtol=0.0, atol=1e-12):
        raise ValueError(f"cells must be one polynomial of degree <= 2 on [-1, 1] for the "
                         f"curved mortar kernel, got {cell.name}")
    C.setflags(write=False)
    return C


def interior(cell: CellType) -> list[int]:
    """The columns of a line cell that are not its two corners (line3: the mid node)."""
    return [a for a in range(cell.n_nodes) if a not in cell.corners]

_NEWTON = 12  # Newton iterations on values (quadratic convergence from the chord estimate)


def chord_lengths(x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """``|x_end - x_start|`` of each segment (the chord of a curved one)."""
    return np.hypot(*(x[:, seg[:, 1]] - x[:, seg[:, 0]]))


def shape_values(cell: CellType, xi):
    """``N_A(xi)`` of ``cell`` (:func:`monomials`), a list of ``n_nodes`` arrays or jets
    of the shape of ``xi``."""
    C = monomials(cell)
    quadratic = bool(C[:, 2].any())
    return [poly([C[a, 0], C[a, 1], C[a, 2] if quadratic else None], xi)
            for a in range(cell.n_nodes)]


def poly(c: list, xi):
    """``c_0 + c_1 xi + c_2 xi^2`` by Horner (``c_2`` None: linear); ``c_p`` scalars,
    arrays or jets broadcasting against ``xi``."""
    if c[2] is None:
        return xi * c[1] + c[0]
    return (xi * c[2] + c[1]) * xi + c[0]


def poly_derivative(c: list, xi):
    """``c_1 + 2 c_2 xi``."""
    if c[2] is None:
        return c[1]
    return xi * (c[2] * 2.0) + c[1]


def element_polynomial(nodes: list, cell: CellType) -> list:
    """Monomial coefficients ``[P_0, P_1, P_2]`` of ``x(xi) = sum_A N_A x_A``,
    ``P_p = sum_A C[A, p] x_A`` (:func:`monomials`; zero terms skipped, a
    coefficient 1 taken as it is).

    ``nodes``: the ``n_nodes`` node positions (pairs) in the cell's column order;
    ``P_2`` is None for cells of degree 1.  Each ``P_p`` is a pair.
    """
    C = monomials(cell)
    out = []
    for p in range(3):
        acc = None
        for a, c in enumerate(C[:, p]):
            if c == 0.0:
                continue
            term = nodes[a] if c == 1.0 else (nodes[a][0] * c, nodes[a][1] * c)
            acc = term if acc is None else (acc[0] + term[0], acc[1] + term[1])
        out.append(acc)
    return out


def _components(P: list, i: int) -> list:
    return [None if p is None else p[i] for p in P]


def curve(P: list, xi):
    """``x(xi)`` as a pair from the coefficients of :func:`element_polynomial`."""
    return poly(_components(P, 0), xi), poly(_components(P, 1), xi)


def tangent(P: list, xi):
    """``dx/dxi`` as a pair."""
    return poly_derivative(_components(P, 0), xi), poly_derivative(_components(P, 1), xi)


def _tangent_at(nodes: list, cell: CellType, xi: float):
    """``dx/dxi`` at a fixed ``xi`` as the combination ``sum_A N_A'(xi) x_A``."""
    C = monomials(cell)
    d = C[:, 1] + 2.0 * C[:, 2] * xi
    tx = sum(nodes[a][0] * d[a] for a in range(cell.n_nodes))
    ty = sum(nodes[a][1] * d[a] for a in range(cell.n_nodes))
    return tx, ty


def normalize(x, y):
    """``(x, y) / |(x, y)|`` for jets or arrays."""
    r = inv(sqrt(x * x + y * y))
    return x * r, y * r


def _unit_normal(t):
    """Right-hand unit normal ``(t_y, -t_x)/|t|``."""
    return normalize(t[1], -t[0])


# ------------------------------------------------------ step 1: slave normal field
class SlaveSlots(NamedTuple):
    """Local slave nodes of each slave element (step 1).

    Attributes
    ----------
    nodes : int ndarray (n_el, 3 k - 2)
        Own nodes (start, end[, mid]), then the previous element's start[, mid],
        then the next element's end[, mid]; where a neighbour is missing (chain
        end or degenerate) its slots hold the own start (resp. end) node.
    pos : ndarray (2, n_el, 3 k - 2)
        Positions of the slots; a missing neighbour gets dummy positions along
        ``x`` (its end tangent is nonzero, its weight zero).
    wp, wn : ndarray (n_el,)
        1.0 where the previous (next) element takes part in the vertex normal, else 0.0.
    cell : CellType
        The slave cell type.
    mirrored : tuple of (e, on)
        Symmetry lines ``e`` with ``on`` (n_el, k): which of the element's own nodes
        lie on each (:func:`~skfem_mortar.contact.normals.mirror_nodes`; they take
        the mirror normal, :func:`element_normals`).
    """

    nodes: np.ndarray
    pos: np.ndarray
    wp: np.ndarray
    wn: np.ndarray
    cell: CellType
    mirrored: tuple = ()

    def mirrored_of(self, el: np.ndarray) -> tuple:
        """:attr:`mirrored` of the elements ``el``."""
        return tuple((e, on[el]) for e, on in self.mirrored)

    @property
    def k(self) -> int:
        """Nodes per element."""
        return self.cell.n_nodes


def slave_slots(xs: np.ndarray, seg: np.ndarray, cell: CellType, mirror=()) -> SlaveSlots:
    """The local slave nodes of every slave element and their positions (values):
    its own nodes, then the previous element's start and interior nodes, then the
    next element's end and interior nodes (:func:`interior`); ``mirror``: symmetry
    lines ``(e, c)`` of the normals (:attr:`SlaveSlots.mirrored`)."""
    k = cell.n_nodes
    c0, c1 = cell.corners
    inner = interior(cell)
    ref = np.asarray(cell.ref_nodes, dtype=float)[0]
    n_s = xs.shape[1]
    ending, starting = segments_at_nodes(seg[:, [c0, c1]], n_s)
    length = chord_lengths(xs, seg)
    good = length > LEN_TOL * (length.mean() if length.size else 0.0)
    pe, ne = ending[seg[:, c0]], starting[seg[:, c1]]
    has_p = (pe >= 0) & good[np.maximum(pe, 0)]
    has_n = (ne >= 0) & good[np.maximum(ne, 0)]
    pe, ne = np.maximum(pe, 0), np.maximum(ne, 0)
    s, t = seg[:, c0], seg[:, c1]
    prev = [seg[pe, c0]] + [seg[pe, a] for a in inner]   # start, interior of the previous
    nxt = [seg[ne, c1]] + [seg[ne, a] for a in inner]    # end, interior of the next
    # dummy neighbours along x (the reference coordinate shifted by one cell length)
    dprev = [ref[c0] - ref[c1]] + [ref[a] - ref[c1] for a in inner]
    dnext = [ref[c1] - ref[c0]] + [ref[a] - ref[c0] for a in inner]
    cols = [seg[:, a] for a in range(k)]
    cols += [np.where(has_p, q, s) for q in prev] + [np.where(has_n, q, t) for q in nxt]
    nodes = np.stack(cols, 1)
    pos = xs[:, nodes].copy()
    ex = np.array([1.0, 0.0])[:, None]
    for j, d in enumerate(dprev):   # dummy: tangent at the end of the missing element is e_x
        pos[:, ~has_p, k + j] = xs[:, s[~has_p]] + d * ex
    for j, d in enumerate(dnext):
        pos[:, ~has_n, 2 * k - 1 + j] = xs[:, t[~has_n]] + d * ex
    mirrored = tuple((e, on[seg]) for e, on in mirror_nodes(xs, mirror))
    return SlaveSlots(nodes, pos, has_p * 1.0, has_n * 1.0, cell, mirrored)


def element_normals(slot_pos: list, cell: CellType, wp, wn, mirrored=()) -> list:
    """Step 1: the nodal normals of an element's own nodes, in column order.

    ``slot_pos``: the ``3 k - 2`` slot positions of :class:`SlaveSlots` (pairs of
    arrays or jets).  Corners: ``normalize(wp nu_prev(end) + nu(start))`` and
    ``normalize(nu(end) + wn nu_next(start))``; an interior node: ``nu`` at its
    reference coordinate (line3's mid node: ``nu(0)``).  A node on a symmetry line
    of ``mirrored`` (:meth:`SlaveSlots.mirrored_of` of the elements) takes its mirror
    normal (:func:`~skfem_mortar.contact.mortar_segmentation.mirror_normal`).

    Returns
    -------
    list of ``k`` pairs.
    """
    k = cell.n_nodes
    c0, c1 = cell.corners
    inner = interior(cell)
    ref = np.asarray(cell.ref_nodes, dtype=float)[0]
    own = slot_pos[:k]
    prev, nxt = [None] * k, [None] * k             # the neighbours in their own columns
    prev[c0], prev[c1], nxt[c0], nxt[c1] = slot_pos[k], own[c0], own[c1], slot_pos[2 * k - 1]
    for j, a in enumerate(inner):
        prev[a], nxt[a] = slot_pos[k + 1 + j], slot_pos[2 * k + j]
    nu_p = _unit_normal(_tangent_at(prev, cell, ref[c1]))
    nu_n = _unit_normal(_tangent_at(nxt, cell, ref[c0]))
    nu_a = _unit_normal(_tangent_at(own, cell, ref[c0]))
    nu_b = _unit_normal(_tangent_at(own, cell, ref[c1]))
    out = [None] * k
    out[c0] = normalize(nu_p[0] * wp + nu_a[0], nu_p[1] * wp + nu_a[1])
    out[c1] = normalize(nu_b[0] + nu_n[0] * wn, nu_b[1] + nu_n[1] * wn)
    for a in inner:
        out[a] = _unit_normal(_tangent_at(own, cell, ref[a]))
    for a in range(k) if mirrored else ():
        out[a] = mirror_normal(out[a], [(e, on[:, a]) for e, on in mirrored])
    return out


def _slot_pairs(pos: np.ndarray) -> list:
    return [(pos[0, :, j], pos[1, :, j]) for j in range(pos.shape[2])]


def nodal_normals(xs: np.ndarray, seg: np.ndarray, cell: CellType | None = None,
                  mirror=()) -> np.ndarray:
    """Step 1 (values): the nodal normal of every slave node, (2, n_s).

    Vertices: the normalized sum of the adjacent elements' unit normals at that
    vertex; mid nodes: their element's normal at ``xi = 0``.  ``cell``: the slave
    cell type (default: the line of the connectivity's columns,
    :func:`~skfem_mortar.contact.segmentation.line_cells`); ``mirror`` symmetry lines
    (:func:`slave_slots`).
    """
    xs = np.asarray(xs, dtype=float)
    seg = np.asarray(seg, dtype=np.int64)
    cell = line_cells(seg, seg, None if cell is None else (cell, cell))[0]
    sl = slave_slots(xs, seg, cell, mirror)
    nrm = element_normals(_slot_pairs(sl.pos), cell, sl.wp, sl.wn, sl.mirrored)
    out = np.zeros((2, xs.shape[1]))
    for a in range(sl.k):
        out[0, seg[:, a]] = value(nrm[a][0])
        out[1, seg[:, a]] = value(nrm[a][1])
    return out


# ------------------------------------------------------------ step 2: projections
def _slave_residual(P, Q, xc, xi):
    """``f = (x_s(xi) - x_c) x n~(xi)`` and ``f'`` (arrays or jets)."""
    xx, xy = curve(P, xi)
    tx, ty = tangent(P, xi)
    nx, ny = curve(Q, xi)
    dnx, dny = tangent(Q, xi)
    rx, ry = xx - xc[0], xy - xc[1]
    f = rx * ny - ry * nx
    df = tx * ny - ty * nx + rx * dny - ry * dnx
    return f, df


def project_on_slave(P: list, Q: list, xc, xi0=None, n_newton: int = _NEWTON):
    """Step 2: slave parameter of the projection of ``x_c`` along ``n~`` (values).

    Newton on ``f(xi) = (x_s(xi) - x_c) x n~(xi) = 0`` from ``xi0`` (default:
    the orthogonal projection onto the chord).

    Returns
    -------
    xi : ndarray
    ok : bool ndarray, a finite root with ``|f| <= 1e-10`` of its scale.
    """
    if xi0 is None:
        sx, sy = curve(P, -1.0)
        ex, ey = curve(P, 1.0)
        dx, dy = ex - sx, ey - sy
        xi0 = 2.0 * ((xc[0] - sx) * dx + (xc[1] - sy) * dy) / (dx * dx + dy * dy) - 1.0
    xi = np.clip(np.asarray(xi0, dtype=float), -2.0, 2.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for _ in range(n_newton):
            f, df = _slave_residual(P, Q, xc, xi)
            xi = xi - f / df
        f, _ = _slave_residual(P, Q, xc, xi)
        sx, sy = curve(P, 0.0)
        reach = (np.hypot(sx - xc[0], sy - xc[1]) + sum(np.hypot(*p) for p in P[1:] if p is not None))
        scale = reach * sum(np.hypot(*q) for q in Q if q is not None)
        ok = np.isfinite(xi) & (np.abs(f) <= 1e-10 * scale + 1e-300)
    return np.where(ok, xi, 0.0), ok


def _values(C: list) -> list:
    return [None if c is None else (value(c[0]), value(c[1])) for c in C]


def _master_residual(R, x0, d, eta):
    mx, my = curve(R, eta)
    tx, ty = tangent(R, eta)
    return (mx - x0[0]) * d[1] - (my - x0[1]) * d[0], tx * d[1] - ty * d[0]


def project_on_master(R: list, x0, d, n_newton: int = _NEWTON):
    """Step 2: master parameter ``eta`` where ``x_0 + alpha d`` meets the master curve (values).

    Newton on ``F(eta) = (x_m(eta) - x_0) x d`` (quadratic in ``eta``, linear
    for a 2-node master) from ``-F(0)/F'(0)``.

    Returns
    -------
    eta : ndarray
        NaN where there is no root.
    ok : bool ndarray, a finite root.
    """
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        f, df = _master_residual(R, x0, d, 0.0)
        eta = np.clip(-f / df, -3.0, 3.0)
        for _ in range(n_newton if R[2] is not None else 0):
            f, df = _master_residual(R, x0, d, eta)
            eta = eta - f / df
        f, df = _master_residual(R, x0, d, eta)
        scale = (np.hypot(*R[1]) + (0.0 if R[2] is None else np.hypot(*R[2]))) * np.hypot(*d)
        ok = np.isfinite(eta) & (np.abs(f) <= 1e-10 * scale + 1e-300)
    return np.where(ok, eta, np.nan), ok


# ------------------------------------------------------- step 3: mortar segments
def candidate_pairs(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                    margin: float | None = None, reach: float = 0.0, widen: float = 0.0
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Candidate element pairs: bounding boxes of all element nodes (ends and mids).

    Global ``margin``: boxes within ``margin + widen``; default local, within
    ``l_i + l_j + reach + widen`` (``l`` the chord lengths), as
    :func:`~skfem_mortar.contact.search.segment_pairs` for 2-node segments.
    """
    def boxes(x, seg):
        p = x[:, seg]                      # (2, n_el, k)
        return p.min(axis=2), p.max(axis=2)
    lo_s, hi_s = boxes(xs, seg_s)
    lo_m, hi_m = boxes(xm, seg_m)
    if margin is not None:
        return box_pairs(lo_s, hi_s, lo_m, hi_m, float(margin) + widen)
    ls, lm = chord_lengths(xs, seg_s), chord_lengths(xm, seg_m)
    return box_pairs(lo_s - ls, hi_s + ls, lo_m - lm, hi_m + lm, float(reach) + widen)


def _hull(e_s, xi, node_lo, node_hi, n_es):
    """Projectable part of each slave element: the extreme end points of its segments
    and the master nodes giving them (-1 a slave end)."""
    elem_xi = np.tile(np.array([1.0, -1.0]), (n_es, 1))
    elem_node = np.full((n_es, 2), -1, dtype=np.int64)
    np.minimum.at(elem_xi[:, 0], e_s, xi[:, 0])
    np.maximum.at(elem_xi[:, 1], e_s, xi[:, 1])
    at_lo = xi[:, 0] == elem_xi[e_s, 0]
    at_hi = xi[:, 1] == elem_xi[e_s, 1]
    elem_node[e_s[at_lo], 0] = node_lo[at_lo]
    elem_node[e_s[at_hi], 1] = node_hi[at_hi]
    return elem_xi, elem_node


def element_fields(xs: np.ndarray, seg_s: np.ndarray, cell: CellType, mirror=()
                   ) -> tuple[list, list]:
    """Position and normal-field coefficients ``P``, ``Q`` of every slave element (values;
    ``mirror``: symmetry lines of the normals, :func:`slave_slots`)."""
    sl = slave_slots(xs, seg_s, cell, mirror)
    pos = _slot_pairs(sl.pos)
    nrm = element_normals(pos, cell, sl.wp, sl.wn, sl.mirrored)
    return (element_polynomial(pos[:cell.n_nodes], cell),
            element_polynomial([(value(n[0]), value(n[1])) for n in nrm], cell))


def _chord_side(p: np.ndarray, lost: np.ndarray, c: tuple, xa: tuple, xb: tuple) -> np.ndarray:
    """The side of a master vertex ``c`` where the side rule had no slave end projected
    onto the master curve (``lost``: the Newton projection onto the curve's quadratic
    extension found no root) and its own projection lay outside the slave cell
    (``p = +-inf``, possibly from a spurious root of the wrong sign): beyond the slave
    end b (``+inf``) where the vertex lies past b along the slave chord
    ``x_a -> x_b``, beyond a (``-inf``) where past a, else ``p`` kept."""
    dx, dy = xb[0] - xa[0], xb[1] - xa[1]
    t = 2.0 * ((c[0] - xa[0]) * dx + (c[1] - xa[1]) * dy) / (dx * dx + dy * dy) - 1.0
    side = np.where(t > 1.0, np.inf, np.where(t < -1.0, -np.inf, p))
    return np.where(lost & np.isinf(p), side, p)


def _take(C: list, idx) -> list:
    return [None if c is None else (c[0][idx], c[1][idx]) for c in C]


def segment(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
            pairs: tuple[np.ndarray, np.ndarray] | None = None, margin: float | None = None,
            frozen: bool = True, reach: float = 0.0,
            cells: tuple[CellType, CellType] | None = None, mirror=()) -> Segmentation:
    """Step 3: the mortar segments of curved (or straight) slave and master elements.

    Parameters as :func:`skfem_mortar.contact.mortar_segmentation.segment`;
    ``seg_s``, ``seg_m`` of 2 or 3 columns (start, end[, mid]).  The end points
    ``xi`` are the projections of the master vertices onto the curved slave
    elements along the slave normal field (``src`` 0 or 1: the master element's
    start or end vertex), clipped to [-1, 1].  ``mirror``: symmetry lines of the
    slave normals (:func:`slave_slots`).

    Returns
    -------
    Segmentation
    """
    xs = np.asarray(xs, dtype=float).reshape(2, -1)
    xm = np.asarray(xm, dtype=float).reshape(2, -1)
    seg_s = np.asarray(seg_s, dtype=np.int64)
    seg_m = np.asarray(seg_m, dtype=np.int64)
    cs, cm = line_cells(seg_s, seg_m, cells)   # default: (n, 2) or (n, 3) (start, end[, mid])
    candidates = None
    if pairs is None:
        pairs = candidates = candidate_pairs(xs, seg_s, xm, seg_m, margin, reach)
    i_s = np.asarray(pairs[0], dtype=np.int64)
    i_m = np.asarray(pairs[1], dtype=np.int64)
    ls, lm = chord_lengths(xs, seg_s), chord_lengths(xm, seg_m)
    good_s = ls > LEN_TOL * max(ls.mean() if ls.size else 0.0, 1e-300)
    good_m = lm > LEN_TOL * max(lm.mean() if lm.size else 0.0, 1e-300)
    keep = good_s[i_s] & good_m[i_m]
    i_s, i_m = i_s[keep], i_m[keep]

    Pe, Qe = element_fields(xs, seg_s, cs, mirror)
    P, Q = _take(Pe, i_s), _take(Qe, i_s)
    R = element_polynomial([(xm[0, seg_m[i_m, a]], xm[1, seg_m[i_m, a]])
                            for a in range(cm.n_nodes)], cm)
    c1 = (xm[0, seg_m[i_m, 0]], xm[1, seg_m[i_m, 0]])
    c2 = (xm[0, seg_m[i_m, 1]], xm[1, seg_m[i_m, 1]])
    ts = xs[:, seg_s[i_s, 1]] - xs[:, seg_s[i_s, 0]]
    tm = xm[:, seg_m[i_m, 1]] - xm[:, seg_m[i_m, 0]]
    facing = (ts[0] * tm[0] + ts[1] * tm[1]) < 0.0
    p1, ok1 = project_on_slave(P, Q, c1)
    p2, ok2 = project_on_slave(P, Q, c2)
    # sides: the slave ends projected along their nodal normals onto the master
    # curve (eta_a, eta_b); a master vertex (eta = -1 or +1) past eta_b is beyond
    # the slave end b, past eta_a beyond a (see mortar_segmentation._side)
    xa, xb = curve(P, -1.0), curve(P, 1.0)
    na, nb = curve(Q, -1.0), curve(Q, 1.0)
    eta_a, _ = project_on_master(R, xa, na)
    eta_b, _ = project_on_master(R, xb, nb)
    with np.errstate(invalid="ignore"):
        dab = eta_b - eta_a
        p1, ok1 = _side(p1, ok1, -1.0 - eta_a, -1.0 - eta_b, dab)
        p2, ok2 = _side(p2, ok2, 1.0 - eta_a, 1.0 - eta_b, dab)
    lost = ~(np.isfinite(eta_a) & np.isfinite(eta_b))
    if lost.any():
        p1, p2 = _chord_side(p1, lost, c1, xa, xb), _chord_side(p2, lost, c2, xa, xb)
    keep, xi, src = clip_to_slave(p1, p2, facing & ok1 & ok2)
    e_s, e_m = i_s[keep], i_m[keep]
    xi_m = master_coordinates(src, eta_a[keep], eta_b[keep])
    node_lo = np.where(src[:, 0] >= 0, seg_m[e_m, np.maximum(src[:, 0], 0)], -1)
    node_hi = np.where(src[:, 1] >= 0, seg_m[e_m, np.maximum(src[:, 1], 0)], -1)
    elem_xi, elem_node = _hull(e_s, xi, node_lo, node_hi, seg_s.shape[0])
    return Segmentation(e_s=e_s, e_m=e_m, xi=xi, src=src, elem_xi=elem_xi,
                        elem_node=elem_node, frozen=frozen, candidates=candidates, xi_m=xi_m)


def segment_lines(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                  cells: tuple[CellType, CellType],
                  pairs: tuple[np.ndarray, np.ndarray] | None = None,
                  margin: float | None = None, frozen: bool = True,
                  reach: float = 0.0, mirror=()) -> Segmentation:
    """The 2D segmentation (:class:`~skfem_mortar.contact.segmentation.Segmenter`) of
    lines of any order: master vertices projected onto the slave lines along the
    slave normal field, clipped to the slave cell.

    Two straight lines (both cells affine, :attr:`~.cells.CellType.affine`: ``line2``)
    take :func:`~skfem_mortar.contact.mortar_segmentation.segment` (closed-form
    projections), any other pair :func:`segment` (Newton projections on the
    cells' curves).  ``mirror``: symmetry lines ``(e, c)`` of the slave normals
    (:func:`~skfem_mortar.contact.normals.mirror_nodes`).
    """
    if cells[0].affine and cells[1].affine:
        return mortar_segmentation.segment(xs, seg_s, xm, seg_m, pairs=pairs, margin=margin,
                                           frozen=frozen, reach=reach, mirror=mirror)
    return segment(xs, seg_s, xm, seg_m, pairs=pairs, margin=margin, frozen=frozen,
                   reach=reach, cells=cells, mirror=mirror)


register_default(1, segment_lines)
