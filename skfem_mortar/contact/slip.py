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

Mortar (:func:`mortar_slip`)
----------------------------
The weighted objective slip of Gitterle, Popp, Gee, Wall (2010), at slave
node ``A`` with the nodal tangent ``tau_A = (n_y, -n_x)`` (the averaged
nodal normal turned by -90 degrees):

    u_t,A = - tau_A . [ sum_B (D_AB - D_AB^prev) x_B - sum_C (M_AC - M_AC^prev) x_C ],

``D^prev``, ``M^prev`` the mortar integrals of the last converged step
(history) and ``x`` the current positions.  Rigid motions of the whole pair
leave ``D`` and ``M`` unchanged, so the slip vanishes exactly; a translation
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

``r_A`` and its derivatives from :func:`skfem_mortar.contact.mortar.tangential_evaluate`
(the mortar kernel's jets: nodal normals, segment end points, dual
coefficients, projections), ``w_A`` linear in ``x`` and ``tau_A`` a jet of
the node and its two neighbours, so

    G = dr/dx + tau . W + w . T,
    H = H_r + T^T Lam W + W^T Lam T + sum_A lam_A w_A . d^2 tau_A/dx^2

(``W = dw/dx``, ``T = dtau/dx``, ``Lam`` the multipliers per component).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from . import mortar
from .jets import Jet
from .mortar_segmentation import nodal_normals
from .nts import project
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


def nts_slip(xs: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, xi_prev: np.ndarray,
             segment_prev: np.ndarray, segment: np.ndarray | None = None,
             lam_t: np.ndarray | None = None, tangent: bool = True,
             **project_options: Any) -> SlipEval:
    """NTS slip ``u_t = S(e, xi) - S(e_prev, xi_prev)`` and its exact derivatives (module doc).

    Parameters
    ----------
    xs, xm : ndarray (2, n_s), (2, n_m)
        Current slave and master node coordinates.
    seg_m : int ndarray (n_seg, 2)
        Master segments (one oriented chain, open or closed).
    xi_prev : ndarray (n_s,)
        Parameter in [0, 1] along ``segment_prev`` at the last converged step
        (``info["xi"]`` of :func:`skfem_mortar.contact.nts.evaluate`).
    segment_prev : int ndarray (n_s,)
        The master segment of each node at the last converged step (-1: none,
        then the slip is undefined and zero: ``mask`` False).
    segment : int ndarray (n_s,), optional
        The current segment of each node (the pair's projection, ``info["segment"]``
        of its NTS evaluation, with its hysteresis and locks); by default
        :func:`skfem_mortar.contact.nts.project` with ``project_options``.
    lam_t : ndarray (n_s,), optional
        Tangential multipliers, for ``H``.
    tangent : bool
        Build ``G`` (and ``H`` with ``lam_t``).

    Returns
    -------
    SlipEval
    """
    xs, xm = np.asarray(xs, float), np.asarray(xm, float)
    seg_m = np.asarray(seg_m, dtype=np.int64).reshape(-1, 2)
    n_s, n_m, n_seg = xs.shape[1], xm.shape[1], len(seg_m)
    xi_prev = np.asarray(xi_prev, float)
    segment_prev = np.asarray(segment_prev, dtype=np.int64)
    for name, a in (("xi_prev", xi_prev), ("segment_prev", segment_prev)):
        if a.shape != (n_s,):
            raise ValueError(f"{name} must have shape ({n_s},), got {a.shape}")
    if segment_prev.size and (segment_prev.min() < -1 or segment_prev.max() >= n_seg):
        raise ValueError(f"segment_prev must index master segments in [-1, {n_seg})")
    if segment is None:
        segment = project(xs, xm, seg_m, **project_options)["segment"]
    segment = np.asarray(segment, dtype=np.int64)
    if segment.shape != (n_s,):
        raise ValueError(f"segment must have shape ({n_s},), got {segment.shape}")
    if lam_t is not None:
        lam_t = np.asarray(lam_t, float)
        if lam_t.shape != (n_s,):
            raise ValueError(f"lam_t must have shape ({n_s},), got {lam_t.shape}")
    has = (segment >= 0) & (segment_prev >= 0)
    steps, found, fw, bw = _chain_steps(seg_m, n_m, np.where(has, segment_prev, -1),
                                        np.where(has, segment, -1))
    mask = has & found
    second = tangent and lam_t is not None
    k = np.flatnonzero(mask)
    e = segment[k]
    # xi l on the current segment: (x - x1) . e
    x1, x2 = xm[:, seg_m[e, 0]], xm[:, seg_m[e, 1]]
    s_jet = _coordinate_jet(xs[:, k], x1, x2, second)
    # the lengths: (node, segment, weight) -- previous segment, those crossed, current
    ep, xp, st = segment_prev[k], xi_prev[k], steps[k]
    terms = [(k, ep, np.where(st > 0, 1.0 - xp, -xp))]           # S(e_p, xi_p) and the start
    back = st < 0
    terms.append((k[back], e[back], -np.ones(int(back.sum()))))   # backward: the whole of e
    for j in range(int(np.abs(st).max(initial=0)) - 1):           # the segments in between
        fwd_j, bwd_j = fw[j][k], bw[j][k]
        inside = np.abs(st) > j + 1
        terms.append((k[inside], np.where(st > 0, fwd_j, bwd_j)[inside],
                      np.where(st > 0, 1.0, -1.0)[inside]))
    u = np.zeros(n_s)
    u[k] = s_jet.v
    lens = []
    for nodes, segs, w in terms:
        lj = _length_jet(xm[:, seg_m[segs, 0]], xm[:, seg_m[segs, 1]], second)
        np.add.at(u, nodes, w * lj.v)
        lens.append((nodes, segs, w, lj))
    tan = np.zeros((2, n_s))
    l_e = np.hypot(*(x2 - x1))
    tan[:, k] = (x2 - x1) / np.where(l_e > 0, l_e, 1.0)
    info = {"crossed": np.where(mask, steps, 0)}
    if not tangent:
        return SlipEval(u=u, G=None, H=None, tangent=tan, mask=mask, info=info)
    ndof = 2 * n_s + 2 * n_m
    dofs = [np.hstack([_node_dofs(n_s, k, False), _node_dofs(n_s, seg_m[e, 0], True),
                       _node_dofs(n_s, seg_m[e, 1], True)])]
    rows, vals, hess = [k], [s_jet.g.T], [None if not second else s_jet.hessian()]
    for nodes, segs, w, lj in lens:
        dofs.append(np.hstack([_node_dofs(n_s, seg_m[segs, 0], True),
                               _node_dofs(n_s, seg_m[segs, 1], True)]))
        rows.append(nodes)
        vals.append(w[:, None] * lj.g.T)
        hess.append(None if not second else w * lj.hessian())
    Gr = np.concatenate([np.repeat(r, d.shape[1]) for r, d in zip(rows, dofs)])
    Gc = np.concatenate([d.ravel() for d in dofs])
    G = sp.csr_matrix((np.concatenate([v.ravel() for v in vals]), (Gr, Gc)), shape=(n_s, ndof))
    H = None
    if second:
        Hr, Hc, Hv = [], [], []
        for r, d, h in zip(rows, dofs, hess):
            nv = d.shape[1]
            Hr.append(np.repeat(d, nv, axis=1).ravel())
            Hc.append(np.tile(d, (1, nv)).ravel())
            Hv.append((h * lam_t[r]).transpose(2, 0, 1).ravel())
        H = sp.csr_matrix((np.concatenate(Hv), (np.concatenate(Hr), np.concatenate(Hc))),
                          shape=(ndof, ndof))
    return SlipEval(u=u, G=G, H=H, tangent=tan, mask=mask, info=info)


# --------------------------------------------------------------------- mortar
def _as_csr(M: Any, shape: tuple[int, int], name: str) -> sp.csr_matrix:
    M = sp.csr_matrix(M, dtype=float)
    if M.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {M.shape}")
    return M


def mortar_history(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                   **kernel_options: Any) -> dict[str, sp.csr_matrix]:
    """The history of :func:`mortar_slip` at a converged state: ``D_prev``, ``M_prev``.

    The mortar integrals of :func:`skfem_mortar.contact.mortar.evaluate`
    (values only; ``kernel_options`` as there: ``dual``, ``n_gauss``,
    ``crosspoints``, ...), which the pair also has as ``info["D"]``,
    ``info["M"]`` of its last evaluation at the converged state.
    """
    ev = mortar.evaluate(xs, seg_s, xm, seg_m, tangent=False, **kernel_options)
    return {"D_prev": ev.info["D"], "M_prev": ev.info["M"]}


def mortar_slip(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                D_prev: Any, M_prev: Any, lam_t: np.ndarray | None = None,
                tangent: bool = True, **kernel_options: Any) -> SlipEval:
    """Weighted objective mortar slip (module doc) and its exact derivatives.

    Parameters
    ----------
    xs, xm : ndarray (2, n_s), (2, n_m)
        Current slave and master node coordinates.
    seg_s, seg_m : int ndarray (n, 2)
        Slave and master segments.
    D_prev, M_prev : sparse or dense (n_s, n_s), (n_s, n_m)
        The mortar integrals ``int Phi_A N_B``, ``int Phi_A N_C`` at the last
        converged step (:func:`mortar_history`), with the same multiplier
        functions (``dual``) as now.
    lam_t : ndarray (n_s,), optional
        Tangential multipliers, for ``H``.
    tangent : bool
        Build ``G`` (and ``H`` with ``lam_t``).
    **kernel_options
        ``dual``, ``n_gauss``, ``segmentation``, ``pairs``, ``margin``,
        ``crosspoints``, ``reach`` of :func:`skfem_mortar.contact.mortar.evaluate`.

    Returns
    -------
    SlipEval
        ``mask`` the mortar mask (nodes with a mortar support); ``info``:
        ``D``, ``M`` (current, the next step's history), ``r``, ``w``.
    """
    xs, xm = np.asarray(xs, float), np.asarray(xm, float)
    seg_s = np.asarray(seg_s, dtype=np.int64).reshape(-1, 2)
    n_s, n_m = xs.shape[1], xm.shape[1]
    Dp = _as_csr(D_prev, (n_s, n_s), "D_prev")
    Mp = _as_csr(M_prev, (n_s, n_m), "M_prev")
    if lam_t is not None:
        lam_t = np.asarray(lam_t, float)
        if lam_t.shape != (n_s,):
            raise ValueError(f"lam_t must have shape ({n_s},), got {lam_t.shape}")
    second = tangent and lam_t is not None
    ev = mortar.tangential_evaluate(xs, seg_s, xm, seg_m, lam=lam_t, tangent=tangent,
                                    **kernel_options)
    # w_A = sum_B Dp_AB x_B - sum_C Mp_AC x_C: rows 2A + i, local dof columns
    I2 = sp.identity(2, format="csr")
    W = sp.hstack([sp.kron(Dp, I2), -sp.kron(Mp, I2)], format="csr")
    xloc = np.concatenate([xs.T.ravel(), xm.T.ravel()])
    w = (W @ xloc).reshape(n_s, 2).T                               # (2, n_s)
    tau = ev.info["tangent"]
    u = ev.g + np.sum(tau * w, axis=0)
    info = {"D": ev.info["D"], "M": ev.info["M"], "r": ev.g, "w": w}
    if not tangent:
        return SlipEval(u=u, G=None, H=None, tangent=tau, mask=ev.mask, info=info)
    ndof = 2 * n_s + 2 * n_m
    (nx, ny), pnode, nnode = nodal_normals(xs, seg_s, second, 6)
    tj = (ny, -nx)                                                 # tau_A as jets (6 variables)
    node = np.arange(n_s)
    d6 = np.hstack([_node_dofs(n_s, pnode, False), _node_dofs(n_s, node, False),
                    _node_dofs(n_s, nnode, False)])                # (n_s, 6)
    # T: rows 2A + i, d tau_A,i / dx
    T = sp.csr_matrix((np.stack([tj[0].g.T, tj[1].g.T], 1).ravel(),
                       (np.repeat(np.arange(2 * n_s), 6), np.repeat(d6, 2, axis=0).ravel())),
                      shape=(2 * n_s, ndof))
    S = sp.kron(sp.identity(n_s, format="csr"), np.ones((1, 2)), format="csr")
    G = (ev.G + S @ (sp.diags(tau.T.ravel()) @ W + sp.diags(w.T.ravel()) @ T)).tocsr()
    H = None
    if second:
        L = sp.diags(np.repeat(lam_t, 2))
        cross = T.T @ L @ W
        h6 = (tj[0].hessian() * (lam_t * w[0]) + tj[1].hessian() * (lam_t * w[1]))  # (6, 6, n)
        Ht = sp.csr_matrix((h6.transpose(2, 0, 1).ravel(),
                            (np.repeat(d6, 6, axis=1).ravel(), np.tile(d6, (1, 6)).ravel())),
                           shape=(ndof, ndof))
        H = (ev.H + cross + cross.T + Ht).tocsr()
    return SlipEval(u=u, G=G, H=H, tangent=tau, mask=ev.mask, info=info)
