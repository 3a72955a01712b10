"""The slip within a load step, its exact first and second derivatives, NTS and mortar.

The slip ``u_t`` of a slave node is the tangential motion of the slave
relative to the master since the last converged load step, along the node's
tangent ``tau`` (the direction of the tangential multiplier, see
:mod:`skfem_mortar.contact.friction` for the signs).  Each function here is a
pure function of the current positions and of history arrays the contact
pair keeps from the last converged step, and returns a :class:`SlipEval`:
``u``, ``G = du/dx`` (csr, the local dof order of
:mod:`~skfem_mortar.contact.contact_eval`: slave node k -> 2k, 2k + 1; master
node j -> 2 n_s + 2j, 2 n_s + 2j + 1) and, given the tangential multipliers
``lam_t``, ``H = sum_A lam_t,A d^2 u_A/dx^2``.

NTS (:func:`nts_slip`)
----------------------
With the closest-point projection of :func:`skfem_mortar.contact.nts.project`
(segment ``e`` and parameter ``xi`` in [0, 1] along it) and the arc length
along the master chain at the *current* positions,
``S(e, xi) = sum_{k before e} l_k + xi l_e``, the slip is

    u_t = S(e, xi) - S(e_prev, xi_prev),      tau = e_e = (x_2 - x_1) / l_e,

where ``e_prev, xi_prev`` are the node's segment and parameter at the last
converged step (history).  On one segment this is ``(xi - xi_prev) l_e``, the
change of the local coordinate times the current segment length; across
segments it sums ``(1 - xi_prev) l_prev``, the lengths of the segments
crossed within the step and ``xi l_e`` (backwards likewise, negative).  Only
differences of arc length enter, and only over the segments between the two
points, so it is frame-indifferent: a rigid motion of both bodies leaves
``e``, ``xi`` and every length unchanged.  With ``xi l_e = (x - x_1) . e_e``
(the unclipped projection) ``u_t`` is a smooth function of the slave node and
the master nodes of the segments from ``e_prev`` to ``e`` for fixed segments;
its derivatives are exact (jets, :mod:`skfem_mortar.contact.jets`).  The
derivative of the segment lengths crossed is part of it (a stretching master
changes the slip).  This follows Wriggers, *Computational Contact Mechanics*
(2006), section 4.3 (the slip as the change of the convective coordinate
times the metric), with the crossing of segments written as arc length.

On curved 3-node master segments (``x(t) = sum_a N_a(t) x_a``, ``t`` in
``[-1, 1]``, :mod:`~skfem_mortar.contact.curves`; any curved line cell) the arc length is
measured along the current curves: on one segment ``u_t = int_{t_prev}^{t}
|x'(s)| ds`` (``t_prev = 2 xi_prev - 1``), across segments the rest of the
previous one, the crossed ones whole and the part of the current one
(backwards the same, negative), each by the Gauss rule of
:func:`~skfem_mortar.contact.curves.arc_length` with the current
parameter ``t`` a jet (two Newton steps of the projection in jets), so the
derivatives are exact for the rule; ``tau`` is the curve's unit tangent at
the projection.  On a straight segment with a centred mid node it is the
linear rule; a rigid motion leaves parameters and arc lengths unchanged.

Mortar (:func:`mortar_slip`)
----------------------------
The weighted objective slip of Gitterle, Popp, Gee, Wall (2010), at slave
node ``A`` with the nodal tangent ``tau_A = (n_y, -n_x)`` (the averaged
nodal normal turned by -90 degrees):

    u_t,A = - tau_A . [ sum_B (D_AB - D_AB^prev) x_B - sum_C (M_AC - M_AC^prev) x_C ],

``D^prev``, ``M^prev`` the mortar integrals of the last converged step (history) and
``x`` the current positions (any line cells on either side: the one mortar kernel's
``D``, ``M`` and nodal normals,
:func:`~skfem_mortar.contact.mortar_slip_cells.tangential_evaluate`).  Rigid motions of
the whole pair leave ``D`` and ``M`` unchanged, so the slip vanishes exactly; a translation
alone also cancels by ``sum_B D_AB = sum_C M_AC`` (both integrate ``Phi_A``
over the same mortar segments).  The sign: for a slave sliding by ``d`` along
``tau_A`` over a fixed flat master, ``u_t,A = d int Phi_A = d D_AA`` (dual) or
``d area_A`` (standard: ``sum_B D_AB``); it is the slave's relative motion,
like NTS's (the weighted version of the non-objective
``-tau_A . [D (x_s - x_s^prev) - M (x_m - x_m^prev)]`` up to the sign with
which the weighted relative position ``D x_s - M x_m`` changes tangentially).
It is written as

    u_t,A = r_A(x) + tau_A(x) . w_A(x),   r_A = tau_A . (sum_C M_AC x_C - sum_B D_AB x_B),
                                          w_A = sum_B D_AB^prev x_B - sum_C M_AC^prev x_C,

``r_A`` and its derivatives from
:func:`skfem_mortar.contact.mortar_slip_cells.tangential_evaluate` (the one
mortar kernel with the slip's integrand ``Phi_A tau_A . (x_m - x_s)`` on its
integration cells: end points, projections, multiplier functions and the
nodal normals chained in at assembly), ``w_A`` linear in ``x`` and ``tau_A``
a function of the nodal normal ``n_A`` (its derivatives over the node's
neighbourhood from the same chained normals,
:func:`~skfem_mortar.contact.mortar_slip_cells.tangent_jets`), so

    G = dr/dx + tau . W + w . T,
    H = H_r + T^T Lam W + W^T Lam T + sum_A lam_A w_A . d^2 tau_A/dx^2

(``W = dw/dx``, ``T = dtau/dx``, ``Lam`` the multipliers per component).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from .cells import CellType
from .curves import (arc_length, cell_nodes, check_line, curve, ends, is_affine,
                     project_values, projection_jets)
from .scatter import Triplets
from .surface_kinds import CURVE, surface_kind
from .segmentation import line_cells
from .jets import Jet
from .mortar_slip_cells import tangent_jets, tangential_evaluate
from .nts_projection import project
from ..core.chain import segments_at_nodes

__all__ = ["SlipEval", "nts_slip", "mortar_slip", "mortar_history", "MORTAR_HISTORY",
           "NTS_HISTORY"]

#: the arrays the contact pair keeps from the last converged step for the slip
NTS_HISTORY = ("xi_prev", "segment_prev")
MORTAR_HISTORY = ("D_prev", "M_prev")


@dataclass
class SlipEval:
    """Slips of the slave nodes with their derivatives.

    Attributes
    ----------
    u : ndarray (n_s,)
        The slip ``u_t`` (NTS: a length; mortar: weighted, a length squared).
        Zero where ``mask`` is False.
    G : csr_matrix (n_s, 2 n_s + 2 n_m) or None
        ``du/dx`` (local dof order); None without ``tangent``.
    H : csr_matrix (2 n_s + 2 n_m, 2 n_s + 2 n_m) or None
        ``sum_A lam_t,A d^2 u_A/dx^2``; only with ``lam_t`` and ``tangent``.
    tangent : ndarray (2, n_s)
        The unit tangent ``tau`` of each slave node, the direction along which
        ``lam_t`` acts on the slave (and ``-lam_t`` on the master); zero where
        NTS finds no segment.
    mask : bool ndarray (n_s,)
        Nodes whose slip is defined (a master partner now, and for NTS a
        converged segment connected to the current one).
    info : dict
        NTS: ``crossed`` (segments crossed in the step, signed); mortar: the
        current ``D``, ``M`` (the next step's history), ``r`` and ``w``.
    """

    u: np.ndarray
    G: sp.csr_matrix | None
    H: sp.csr_matrix | None
    tangent: np.ndarray
    mask: np.ndarray
    info: dict = field(default_factory=dict)


# ------------------------------------------------------------------------ NTS
def _chain_steps(seg_m: np.ndarray, n_m: int, start: np.ndarray, target: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, list[np.ndarray], list[np.ndarray]]:
    """Walk along the master chain from ``start`` towards ``target`` both ways.

    Returns the signed number of segments from ``start`` to ``target`` (``+k``
    forward, ``-k`` backward, the shorter; 0 where equal), a bool array of the
    nodes where ``target`` was reached, and the segments visited at each step
    forward and backward (for the lengths in between).
    """
    n_seg = len(seg_m)
    ending, starting = segments_at_nodes(seg_m, n_m)
    steps = np.zeros(start.shape, dtype=np.int64)
    found = start == target
    fwd, bwd = start.copy(), start.copy()
    fw_hist, bw_hist = [], []
    for k in range(1, n_seg + 1):
        if found.all():
            break
        fwd = np.where(fwd >= 0, starting[seg_m[np.maximum(fwd, 0), 1]], -1)
        bwd = np.where(bwd >= 0, ending[seg_m[np.maximum(bwd, 0), 0]], -1)
        fw_hist.append(fwd)
        bw_hist.append(bwd)
        hit_f = ~found & (fwd == target) & (fwd >= 0)
        hit_b = ~found & ~hit_f & (bwd == target) & (bwd >= 0)
        steps[hit_f], steps[hit_b] = k, -k
        found |= hit_f | hit_b
    return steps, found, fw_hist, bw_hist


def _length_jet(x1: np.ndarray, x2: np.ndarray, second: bool) -> Jet:
    """``|x2 - x1|`` as a jet of ``(x1, y1, x2, y2)``."""
    V = [Jet.variable(c, i, 4, second) for i, c in enumerate((x1[0], x1[1], x2[0], x2[1]))]
    dx, dy = V[2] - V[0], V[3] - V[1]
    return (dx * dx + dy * dy).sqrt()


def _coordinate_jet(x: np.ndarray, x1: np.ndarray, x2: np.ndarray, second: bool) -> Jet:
    """``(x - x1) . (x2 - x1) / |x2 - x1|`` (= ``xi l``) as a jet of ``(x, x1, x2)``."""
    V = [Jet.variable(c, i, 6, second)
         for i, c in enumerate((x[0], x[1], x1[0], x1[1], x2[0], x2[1]))]
    tx, ty = V[4] - V[2], V[5] - V[3]
    rx, ry = V[0] - V[2], V[1] - V[3]
    return (rx * tx + ry * ty) / (tx * tx + ty * ty).sqrt()


def _node_dofs(n_s: int, nodes: np.ndarray, master: bool) -> np.ndarray:
    """Local dofs (m, 2) of slave or master nodes."""
    base = 2 * n_s if master else 0
    return base + 2 * nodes[:, None] + np.arange(2)


def _assemble(n_s: int, ndof: int, parts: list, lam_t: np.ndarray | None, second: bool
              ) -> tuple[sp.csr_matrix, sp.csr_matrix | None]:
    """``G`` and ``H`` of a sum of weighted jets: ``parts`` holds
    ``(rows (m,), dofs (m, nv), weight (m,), jet)``, each adding ``weight * jet``
    to the slip of its row's node (the jet's variables are the local dofs)."""
    Gt = Triplets()
    for r, d, w, j in parts:
        Gt.rows(r, d, w[:, None] * j.g.T)
    G = Gt.csr((n_s, ndof))
    if not second:
        return G, None
    Ht = Triplets()
    for r, d, w, j in parts:
        Ht.block(d, w * j.hessian() * lam_t[r])
    return G, Ht.csr((ndof, ndof))


def _segment_dofs(n_s: int, seg_m: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """Local dofs (m, 2 k) of the master nodes of the segments ``segs``."""
    return np.hstack([_node_dofs(n_s, seg_m[segs, a], True) for a in range(seg_m.shape[1])])


def _linear_parts(xs, xm, seg_m, k, e, terms, second):
    """The jets of the 2-node slip: ``xi l`` on the current segment and the weighted
    segment lengths of ``terms``; and the tangents ``e`` of the current segments."""
    n_s = xs.shape[1]
    x1, x2 = xm[:, seg_m[e, 0]], xm[:, seg_m[e, 1]]
    parts = [(k, np.hstack([_node_dofs(n_s, k, False), _segment_dofs(n_s, seg_m, e)]),
              np.ones(k.size), _coordinate_jet(xs[:, k], x1, x2, second))]
    for nodes, segs, w in terms:
        parts.append((nodes, _segment_dofs(n_s, seg_m, segs), w,
                      _length_jet(xm[:, seg_m[segs, 0]], xm[:, seg_m[segs, 1]], second)))
    l_e = np.hypot(*(x2 - x1))
    return parts, (x2 - x1) / np.where(l_e > 0, l_e, 1.0)


def _node_jets(P: tuple, second: bool) -> tuple:
    """The nodes ``P`` of cells as jets of their own ``2 n`` coordinates."""
    nv = 2 * len(P)
    V = [Jet.variable(c, i, nv, second) for i, c in enumerate(v for pt in P for v in pt)]
    return tuple((V[2 * a], V[2 * a + 1]) for a in range(len(P)))


def _curve_parts(xs, xm, seg_m, k, e, ep, xp, st, crossed, second, cell):
    """The jets of the slip along curved line cells (module doc): the arc length
    from the previous to the current projection, on the current curve."""
    n_s = xs.shape[1]
    P = cell_nodes(xm, seg_m, e)
    xi, _ = project_values(cell, xs[:, k], P)
    js, JP, z = projection_jets(cell, xs[:, k], P, xi, second)
    nv = 2 + 2 * cell.n_nodes
    one = Jet.constant(np.ones(k.size), nv, second)
    xpc = 2.0 * xp - 1.0                              # [0, 1] -> the curve's [-1, 1]
    start = Jet.constant(np.where(st == 0, xpc, -1.0), nv, second)
    back = st < 0
    # the current segment: from xi_prev (same segment), from its start (forward), or
    # from xi to its end (backward, negative)
    a_e = arc_length(cell, JP, Jet.where(back, z, start), Jet.where(back, one, z))
    parts = [(k, np.hstack([_node_dofs(n_s, k, False), _segment_dofs(n_s, seg_m, e)]),
              np.where(back, -1.0, 1.0), a_e)]
    moved = st != 0
    kp, epm, xpm, fwd = k[moved], ep[moved], xpc[moved], st[moved] > 0
    JPp = _node_jets(cell_nodes(xm, seg_m, epm), second)
    # the previous segment: from xi_prev to its end (forward) or from its start (backward)
    a_p = arc_length(cell, JPp, np.where(fwd, xpm, -1.0), np.where(fwd, 1.0, xpm))
    parts.append((kp, _segment_dofs(n_s, seg_m, epm), np.where(fwd, 1.0, -1.0), a_p))
    for nodes, segs, w in crossed:                    # whole segments in between
        full = arc_length(cell, _node_jets(cell_nodes(xm, seg_m, segs), second),
                          -np.ones(segs.size), np.ones(segs.size))
        parts.append((nodes, _segment_dofs(n_s, seg_m, segs), w, full))
    _, t, _ = curve(cell, P, z.v)
    lt = np.hypot(t[0], t[1])
    return parts, np.vstack(t) / np.where(lt > 0, lt, 1.0)


def nts_slip(xs: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, xi_prev: np.ndarray,
             segment_prev: np.ndarray, segment: np.ndarray | None = None,
             lam_t: np.ndarray | None = None, tangent: bool = True,
             cell: "str | CellType | None" = None, **project_options: Any) -> SlipEval:
    """NTS slip ``u_t = S(e, xi) - S(e_prev, xi_prev)`` and its exact derivatives (module doc).

    Parameters
    ----------
    xs, xm : ndarray (2, n_s), (2, n_m)
        Current slave and master node coordinates.
    seg_m : int ndarray (n_seg, 2) or (n_seg, 3)
        Master segments (one oriented chain, open or closed; 3 columns: curved
        3-node segments (start, end, mid), the slip is then the arc length along
        the current curves).
    xi_prev : ndarray (n_s,)
        Parameter in [0, 1] along ``segment_prev`` at the last converged step
        (``info["xi"]`` of :func:`skfem_mortar.contact.nts.evaluate`).
    segment_prev : int ndarray (n_s,)
        The master segment of each node at the last converged step (-1: none,
        then the slip is undefined and zero: ``mask`` False).
    segment : int ndarray (n_s,), optional
        The current segment of each node (the pair's projection, ``info["segment"]``
        of its NTS evaluation, with its hysteresis and locks); by default
        :func:`skfem_mortar.contact.nts.project` (with ``cell``) with ``project_options``.
    lam_t : ndarray (n_s,), optional
        Tangential multipliers, for ``H``.
    tangent : bool
        Build ``G`` (and ``H`` with ``lam_t``).
    cell : str or CellType, optional
        The master cell type, ``line2`` or ``line3`` (default: the line of
        ``seg_m``'s columns, :func:`~skfem_mortar.contact.segmentation.line_cells`).

    Returns
    -------
    SlipEval
    """
    xs, xm = np.asarray(xs, float), np.asarray(xm, float)
    seg_m = _segments(seg_m)
    cell = check_line(line_cells(seg_m, seg_m, None if cell is None else (cell, cell))[1],
                      "nts_slip")
    n_s, n_m, n_seg = xs.shape[1], xm.shape[1], len(seg_m)
    xi_prev = np.asarray(xi_prev, float)
    segment_prev = np.asarray(segment_prev, dtype=np.int64)
    for name, a in (("xi_prev", xi_prev), ("segment_prev", segment_prev)):
        if a.shape != (n_s,):
            raise ValueError(f"{name} must have shape ({n_s},), got {a.shape}")
    if segment_prev.size and (segment_prev.min() < -1 or segment_prev.max() >= n_seg):
        raise ValueError(f"segment_prev must index master segments in [-1, {n_seg})")
    if segment is None:
        segment = project(xs, xm, seg_m, cell=cell, **project_options)["segment"]
    segment = np.asarray(segment, dtype=np.int64)
    if segment.shape != (n_s,):
        raise ValueError(f"segment must have shape ({n_s},), got {segment.shape}")
    if lam_t is not None:
        lam_t = np.asarray(lam_t, float)
        if lam_t.shape != (n_s,):
            raise ValueError(f"lam_t must have shape ({n_s},), got {lam_t.shape}")
    has = (segment >= 0) & (segment_prev >= 0)
    steps, found, fw, bw = _chain_steps(ends(seg_m, cell), n_m, np.where(has, segment_prev, -1),
                                        np.where(has, segment, -1))
    mask = has & found
    second = tangent and lam_t is not None
    k = np.flatnonzero(mask)
    e = segment[k]
    ep, xp, st = segment_prev[k], xi_prev[k], steps[k]
    crossed = []                                                  # the segments in between
    for j in range(int(np.abs(st).max(initial=0)) - 1):
        fwd_j, bwd_j = fw[j][k], bw[j][k]
        inside = np.abs(st) > j + 1
        crossed.append((k[inside], np.where(st > 0, fwd_j, bwd_j)[inside],
                        np.where(st > 0, 1.0, -1.0)[inside]))
    if not is_affine(cell):
        parts, tan_k = _curve_parts(xs, xm, seg_m, k, e, ep, xp, st, crossed, second, cell)
    else:
        # the lengths: (node, segment, weight) -- previous segment, backward: the
        # whole of e, those crossed
        back = st < 0
        terms = [(k, ep, np.where(st > 0, 1.0 - xp, -xp)),
                 (k[back], e[back], -np.ones(int(back.sum())))] + crossed
        parts, tan_k = _linear_parts(xs, xm, seg_m, k, e, terms, second)
    u = np.zeros(n_s)
    for nodes, _, w, j in parts:
        np.add.at(u, nodes, w * j.v)
    tan = np.zeros((2, n_s))
    tan[:, k] = tan_k
    info = {"crossed": np.where(mask, steps, 0)}
    if not tangent:
        return SlipEval(u=u, G=None, H=None, tangent=tan, mask=mask, info=info)
    G, H = _assemble(n_s, 2 * n_s + 2 * n_m, parts, lam_t, second)
    return SlipEval(u=u, G=G, H=H, tangent=tan, mask=mask, info=info)


# --------------------------------------------------------------------- mortar
def _as_csr(M: Any, shape: tuple[int, int], name: str) -> sp.csr_matrix:
    M = sp.csr_matrix(M, dtype=float)
    if M.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {M.shape}")
    return M


def _segments(seg: Any) -> np.ndarray:
    seg = np.asarray(seg, dtype=np.int64)
    return seg.reshape(-1, 2) if seg.ndim == 1 else seg  # a flat list of (start, end) pairs


def _cells(seg_s: np.ndarray, seg_m: np.ndarray, cells) -> tuple:
    """The cells of a mortar call: line cells (the one kernel's 2D segmentations)."""
    cells = line_cells(seg_s, seg_m, cells)
    for what, c in zip(("slave", "master"), cells):
        if surface_kind(c) != CURVE:
            raise ValueError(f"cells must be line cells (curves) for the mortar slip, got "
                             f"{what} {c.name} (friction in 3D is not offered yet)")
    return cells


def mortar_history(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                   cells: tuple | None = None, **kernel_options: Any
                   ) -> dict[str, sp.csr_matrix]:
    """The history of :func:`mortar_slip` at a converged state: ``D_prev``, ``M_prev``.

    The mortar integrals of the one kernel (:func:`skfem_mortar.contact.mortar_kernel.evaluate`,
    values only; ``kernel_options`` as there: ``space``, ``n_gauss``, ``crosspoints``,
    ...), which the pair also has as ``info["D"]``, ``info["M"]`` of its last evaluation
    at the converged state.
    """
    seg_s, seg_m = _segments(seg_s), _segments(seg_m)
    ev = tangential_evaluate(xs, seg_s, xm, seg_m, tangent=False,
                             cells=_cells(seg_s, seg_m, cells), **kernel_options)
    return {"D_prev": ev.info["D"], "M_prev": ev.info["M"]}


def mortar_slip(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                D_prev: Any, M_prev: Any, lam_t: np.ndarray | None = None,
                tangent: bool = True, cells: tuple | None = None,
                **kernel_options: Any) -> SlipEval:
    """Weighted objective mortar slip (module doc) and its exact derivatives.

    Parameters
    ----------
    xs, xm : ndarray (d, n_s), (d, n_m)
        Current slave and master node coordinates.
    seg_s, seg_m : int ndarray (n, k)
        Slave and master cells (any line cell of the table).
    D_prev, M_prev : sparse or dense (n_s, n_s), (n_s, n_m)
        The mortar integrals ``int Phi_A N_B``, ``int Phi_A N_C`` at the last
        converged step (:func:`mortar_history`), with the same multiplier
        functions (``space``) as now.
    lam_t : ndarray (n_s,), optional
        Tangential multipliers, for ``H``.
    tangent : bool
        Build ``G`` (and ``H`` with ``lam_t``).
    cells : (slave, master) cell types, optional
        Default: the lines of the connectivities' columns
        (:func:`~skfem_mortar.contact.segmentation.line_cells`).
    **kernel_options
        ``space``, ``n_gauss``, ``segmentation``, ``pairs``, ``margin``, ``crosspoints``,
        ``reach``, ``measure`` of :func:`skfem_mortar.contact.mortar_kernel.evaluate`.

    Returns
    -------
    SlipEval
        ``mask`` the mortar mask (nodes with a mortar support); ``info``:
        ``D``, ``M`` (current, the next step's history), ``r``, ``w``.
    """
    xs, xm = np.asarray(xs, float), np.asarray(xm, float)
    seg_s, seg_m = _segments(seg_s), _segments(seg_m)
    cells = _cells(seg_s, seg_m, cells)
    d, n_s, n_m = xs.shape[0], xs.shape[1], xm.shape[1]
    Dp = _as_csr(D_prev, (n_s, n_s), "D_prev")
    Mp = _as_csr(M_prev, (n_s, n_m), "M_prev")
    if lam_t is not None:
        lam_t = np.asarray(lam_t, float)
        if lam_t.shape != (n_s,):
            raise ValueError(f"lam_t must have shape ({n_s},), got {lam_t.shape}")
    second = tangent and lam_t is not None
    ev = tangential_evaluate(xs, seg_s, xm, seg_m, lam=lam_t, tangent=tangent, cells=cells,
                             **kernel_options)
    # w_A = sum_B Dp_AB x_B - sum_C Mp_AC x_C, from the history's entries (row A, node
    # column in the local order: B or n_s + C, value Dp_AB or -Mp_AC)
    Dc, Mc = Dp.tocoo(), Mp.tocoo()
    hist = (np.concatenate([Dc.row, Mc.row]), np.concatenate([Dc.col, n_s + Mc.col]),
            np.concatenate([Dc.data, -Mc.data]))
    x = np.hstack([xs, xm])
    w = np.zeros((d, n_s))
    for i in range(d):
        w[i] = np.bincount(hist[0], weights=hist[2] * x[i, hist[1]], minlength=n_s)
    tau = ev.info["tangent"]
    u = ev.g + np.sum(tau * w, axis=0)
    info = {"D": ev.info["D"], "M": ev.info["M"], "r": ev.g, "w": w}
    if not tangent:
        return SlipEval(u=u, G=None, H=None, tangent=tau, mask=ev.mask, info=info)
    G, H = _history_terms(ev, hist, w, lam_t, second, d * (n_s + n_m))
    return SlipEval(u=u, G=G, H=H, tangent=tau, mask=ev.mask, info=info)


def _history_terms(ev, hist: tuple, w: np.ndarray, lam_t: np.ndarray | None, second: bool,
                   ndof: int) -> tuple[sp.csr_matrix, sp.csr_matrix | None]:
    """``G = dr/dx + tau . W + w . T``, ``H = H_r + T^T Lam W + W^T Lam T + sum_A lam_A w_A .
    d2tau_A/dx2`` (module doc); ``T = dtau/dx`` from the kernel's chained normals
    (:func:`~.mortar_slip_cells.tangent_jets`), ``W`` from ``hist`` (rows, node columns, values)."""
    nn = ev.info["normals"]
    tau, dtau, d2tau = tangent_jets(nn, second)
    d, n_s = w.shape
    K = nn.nodes.shape[1]
    nodes = np.where(nn.nodes >= 0, nn.nodes, nn.nodes[:, :1])    # padding: zero values
    dofs = (d * nodes[:, :, None] + np.arange(d)).reshape(n_s, K * d)
    rows, cols, vals = hist
    cols = d * cols[:, None] + np.arange(d)                        # (nnz, d) dofs of W
    Gt = Triplets()
    Gt.rows(rows, cols, tau[:, rows].T * vals[:, None])            # tau_A . W_A
    Gt.rows(np.arange(n_s), dofs, np.einsum("in,inkc->nkc", w, dtau).reshape(n_s, K * d))
    G = (ev.G + Gt.csr((n_s, ndof))).tocsr()                       # + w_A . T_A
    if not second:
        return G, None
    # W^T Lam T: [d B + i, dofs_A] += lam_A Dp_AB dtau_i(A) (and -Mp_AC likewise)
    Tl = (dtau * lam_t[:, None, None]).reshape(d, n_s, K * d)[:, rows]   # (d, nnz, K d)
    Xt = Triplets()
    Xt.rows(cols.ravel(), np.repeat(dofs[rows], d, axis=0),
            (Tl * vals[:, None]).transpose(1, 0, 2).reshape(-1, K * d))
    X = Xt.csr((ndof, ndof))
    h = np.einsum("in,inkcle->kclen", w * lam_t, d2tau).reshape(K * d, K * d, n_s)
    Ht = Triplets()
    Ht.block(dofs, h)
    return G, (ev.H + X + X.T + Ht.csr((ndof, ndof))).tocsr()
