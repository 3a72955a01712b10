"""Mortar contact kernel in 2D: weighted gaps, their exact first and second derivatives.

Implements formulation.md, section 3, for linear 2-node segments.  For a slave
node A with multiplier shape function Phi_A (standard: Phi_A = N_A; dual:
biorthogonal to N_A), the weighted gap is

    g_A = - sum_B n_AB . x_B + sum_C n_AC . x_C
        = int_Gc Phi_A(xi1) (x_m(xi2) - x_s(xi1)) . n(xi1) dGamma,

    n_AB = int Phi_A(xi1) N_B(xi1) n dGamma   ("D"),
    n_AC = int Phi_A(xi1) N_C(xi2) n dGamma   ("M"),

with ``n = n~ / |n~|``, ``n~(xi1) = N_1 n_a + N_2 n_b`` the interpolated
averaged nodal normal of the slave surface (outward from the slave body), so
``g > 0`` is open.  The integral is split into mortar segments (see
:mod:`skfem_mortar.mortar_segmentation`); on a segment with slave end points
``xi_a, xi_b`` and the Gauss rule ``(eta_k, w_k)`` on [-1, 1],

    xi1 = (1 - eta)/2 xi_a + (1 + eta)/2 xi_b,
    dGamma = |x_b - x_a| / 2 * (xi_b - xi_a) / 2 * w_k,

and the master point ``x_m(xi2)`` is the projection of ``x_s(xi1)`` onto the
master element along ``n~(xi1)`` at each Gauss point (exact also where ``xi2``
is not linear in ``eta``: curved slave normal field).

Linearization: every segment contribution is written as a composition of
vectorized functions of the local node coordinates (4 slave nodes: previous,
a, b, next, because the nodal normals of a and b involve the neighbouring
segments; the 2 master nodes; for dual multipliers also the 2 master nodes
bounding the projectable part of the slave element) and differentiated exactly
to second order by forward-mode jets (:class:`~skfem_mortar.mortar_segmentation.Jet`).
Hence ``G = dg/dx`` and ``H = sum_A lam_A d^2 g_A/dx^2`` are exact, including
the derivatives of the nodal normals, the segment end points, the slave
Jacobian, the Gauss point projections and the dual coefficients.

Segmentation policies
---------------------
``iteration`` (default): :func:`evaluate` segments the current configuration
at every call; g is piecewise smooth (C1 across a node crossing) and G, H are
its exact derivatives.  ``step``: the caller builds
``sg = segment(xs, seg_s, xm, seg_m, frozen=True)`` after each converged load
step and passes ``segmentation=sg`` during the next step; then the pair list,
the slave-side end points ``xi_a, xi_b`` of every mortar segment and the dual
coefficients are frozen, and G, H are the exact derivatives of that frozen g
(see :func:`evaluate`).

Known limits: the projectable part of a slave element is taken as the hull of
its mortar segments (a gap in the master surface inside one slave element is
bridged by the dual coefficients); a slave element facing two overlapping
pieces of master surface integrates both; an element with both nodes
crosspoints gets no multiplier.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from .contact_eval import ContactEval
from .mortar_segmentation import (Jet, Segmentation, cross, nodal_normals,
                                  project_point_on_slave, segment)

__all__ = ["evaluate", "segment", "Segmentation", "dual_coefficients", "MASK_TOL"]

MASK_TOL = 1e-6
"""Slave nodes whose mortar support is below this fraction of their tributary length
are masked out and merged into their neighbours like crosspoints (see
:func:`evaluate`, Notes)."""
_CHUNK_ENTRIES = 200_000  # Hessian entries per block of segments: 1.6 MB arrays stay in cache


def dual_coefficients(lo, hi):
    """Dual shape function coefficients ``A_e = D_e M_e^{-1}`` on the projectable part.

    With ``D_e = diag(int N_A)`` and ``M_e = int N_A N_B`` over ``xi in [lo, hi]``
    (the slave Jacobian cancels), ``Phi_A = sum_B A_AB N_B`` satisfies
    ``int Phi_A N_B = delta_AB int N_A`` on that part (Popp et al. 2013).  On the
    full element ``A = [[2, -1], [-1, 2]]``.  Works on arrays and on jets.

    Returns
    -------
    (a11, a12, a21, a22)
    """
    def prim(f):
        return f(hi) - f(lo)
    d1 = prim(lambda x: (x - x * x * 0.5) * 0.5)                      # int N1
    d2 = prim(lambda x: (x + x * x * 0.5) * 0.5)                      # int N2
    m11 = prim(lambda x: -(1.0 - x) * (1.0 - x) * (1.0 - x) * (1.0 / 12.0))  # int N1^2
    m22 = prim(lambda x: (1.0 + x) * (1.0 + x) * (1.0 + x) * (1.0 / 12.0))   # int N2^2
    m12 = prim(lambda x: (x - x * x * x * (1.0 / 3.0)) * 0.25)         # int N1 N2
    det_inv = 1.0 / (m11 * m22 - m12 * m12)
    return (d1 * m22 * det_inv, -(d1 * m12) * det_inv,
            -(d2 * m12) * det_inv, d2 * m11 * det_inv)


def _local_nodes(sg: Segmentation, seg_s: np.ndarray, seg_m: np.ndarray,
                 pnode: np.ndarray, nnode: np.ndarray):
    """Node data of each mortar segment: slave p, a, b, n; master m1, m2, lo, hi."""
    e, m = sg.e_s, sg.e_m
    a, b = seg_s[e, 0], seg_s[e, 1]
    return (pnode[a], a, b, nnode[b], seg_m[m, 0], seg_m[m, 1],
            sg.elem_node[e, 0], sg.elem_node[e, 1])


def _embed(j: Jet, idx: np.ndarray, offset: int, nv: int) -> Jet:
    """Entries ``idx`` of a 6-variable node jet, placed at variables ``offset..offset+5``."""
    v = j.v[idx]
    if nv == 0:
        return Jet(v, np.zeros((0, v.size)), None)
    g = np.zeros((nv, v.size))
    g[offset:offset + 6] = j.g[:, idx]
    h = None
    if j.h is not None:
        h = np.zeros((nv, nv, v.size))
        h[offset:offset + 6, offset:offset + 6] = j.h[:, :, idx]
    return Jet(v, g, h)


def _first(j: Jet) -> Jet:
    """The same jet without its Hessian."""
    return Jet(j.v, j.g, None)


def _chunk(xs: np.ndarray, xm: np.ndarray, sl: np.ndarray, nd: tuple, sg: Segmentation,
           n_s: int, nv: int, second: bool, dual: bool, cp: np.ndarray, eta: np.ndarray,
           w: np.ndarray, nrm: tuple[Jet, Jet],
           lam_ab: tuple[np.ndarray, np.ndarray] | None = None
           ) -> tuple[Jet, Jet, Jet | None, dict[str, np.ndarray]]:
    """Weighted-gap contributions of the mortar segments ``sl`` (one block).

    Returns the first-order jets of ``g_a``, ``g_b`` (the contributions to the
    two slave nodes of each segment's element), the second-order jet of
    ``lam_a g_a + lam_b g_b`` (None without ``lam``) and values for D, M, area.
    Local variables: ``x`` and ``y`` of the slave nodes p, a, b, n, the master
    nodes m1, m2 and (``nv = 16``) the two master nodes bounding the
    projectable part of the slave element.
    """
    p, a, b, n, m1, m2, lo_node, hi_node = (q[sl] for q in nd)
    frozen = sg.frozen
    xi_seg, src = sg.xi[sl], sg.src[sl]
    e = sg.e_s[sl]
    pos = [xs[:, p], xs[:, a], xs[:, b], xs[:, n], xm[:, m1], xm[:, m2]]
    if nv > 12:
        pos += [xm[:, np.maximum(lo_node, 0)], xm[:, np.maximum(hi_node, 0)]]
    V = []
    for k, xk in enumerate(pos):
        if 2 * k + 1 < nv:
            V.append((Jet.variable(xk[0], 2 * k, nv, second),
                      Jet.variable(xk[1], 2 * k + 1, nv, second)))
        else:
            V.append((Jet.constant(xk[0], nv, second), Jet.constant(xk[1], nv, second)))
    Xp, Xa, Xb, Xn, M1, M2 = V[:6]
    # nodal normals: node jets in (prev, node, next) placed at slots (p, a, b) / (a, b, n)
    na = (_embed(nrm[0], a, 0, nv), _embed(nrm[1], a, 0, nv))
    nb = (_embed(nrm[0], b, 2, nv), _embed(nrm[1], b, 2, nv))

    def const(v):
        return Jet.constant(v, nv, second)

    # segment end points on the slave element
    if frozen:
        lo, hi = const(xi_seg[:, 0]), const(xi_seg[:, 1])
    else:
        p1, _ = project_point_on_slave(Xa, Xb, na, nb, M1)
        p2, _ = project_point_on_slave(Xa, Xb, na, nb, M2)
        minus, plus = const(-np.ones(e.size)), const(np.ones(e.size))
        lo = Jet.where(src[:, 0] == -1, minus, Jet.where(src[:, 0] == 0, p1, p2))
        hi = Jet.where(src[:, 1] == -1, plus, Jet.where(src[:, 1] == 0, p1, p2))

    # multiplier coefficients Phi_a = c11 N1 + c12 N2, Phi_b = c21 N1 + c22 N2
    if dual:
        exi = sg.elem_xi[e]
        if frozen or nv <= 12:
            el, eh = const(exi[:, 0]), const(exi[:, 1])
        else:
            pl, _ = project_point_on_slave(Xa, Xb, na, nb, V[6])
            ph, _ = project_point_on_slave(Xa, Xb, na, nb, V[7])
            el = Jet.where(lo_node >= 0, pl, const(-np.ones(e.size)))
            eh = Jet.where(hi_node >= 0, ph, const(np.ones(e.size)))
        c = list(dual_coefficients(el, eh))
    else:
        c = [const(np.ones(e.size)), const(np.zeros(e.size)),
             const(np.zeros(e.size)), const(np.ones(e.size))]
    cpa, cpb = cp[sl, 0], cp[sl, 1]
    if cpa.any() or cpb.any():
        # crosspoint: its multiplier is merged into the neighbour, Phi_nb = 1 on e
        one, zero = const(np.ones(e.size)), const(np.zeros(e.size))
        c[0] = Jet.where(cpa, zero, Jet.where(cpb, one, c[0]))
        c[1] = Jet.where(cpa, zero, Jet.where(cpb, one, c[1]))
        c[2] = Jet.where(cpb, zero, Jet.where(cpa, one, c[2]))
        c[3] = Jet.where(cpb, zero, Jet.where(cpa, one, c[3]))

    # Gauss-point quantities as polynomials in xi1 with segment-level coefficients:
    #   x_s = xc + xi1 d1,  n~ = n0 + xi1 n1,  dm = x_m2 - x_m1,
    #   alpha = cross(x_m1 - x_s, dm) / cross(n~, dm) = (P0 + P1 xi1) / (Q0 + Q1 xi1)
    #   (x_s + alpha n~ lies on the master line), gap g_n = alpha |n~|,
    #   |n~|^2 = R0 + R1 xi1 + R2 xi1^2.
    d1x, d1y = (Xb[0] - Xa[0]) * 0.5, (Xb[1] - Xa[1]) * 0.5
    r0x = M1[0] - (Xa[0] + Xb[0]) * 0.5
    r0y = M1[1] - (Xa[1] + Xb[1]) * 0.5
    n0x, n0y = (na[0] + nb[0]) * 0.5, (na[1] + nb[1]) * 0.5
    n1x, n1y = (nb[0] - na[0]) * 0.5, (nb[1] - na[1]) * 0.5
    dmx, dmy = M2[0] - M1[0], M2[1] - M1[1]
    P0, P1 = cross(r0x, r0y, dmx, dmy), -cross(d1x, d1y, dmx, dmy)
    Q0, Q1 = cross(n0x, n0y, dmx, dmy), cross(n1x, n1y, dmx, dmy)
    R0 = n0x * n0x + n0y * n0y
    R1 = (n0x * n1x + n0y * n1y) * 2.0
    R2 = n1x * n1x + n1y * n1y
    # slave Jacobian |x_b - x_a| / 2 times the segment's share (xi_b - xi_a) / 2
    jac = (d1x * d1x + d1y * d1y).sqrt() * ((hi - lo) * 0.5)
    # Gauss points: axis 1
    E = lambda j: j.expand()  # noqa: E731
    xi1 = E(lo) * ((1.0 - eta) * 0.5) + E(hi) * ((1.0 + eta) * 0.5)
    gn = (E(P0) + E(P1) * xi1) * (E(Q0) + E(Q1) * xi1).inv() * (
        E(R0) + (E(R1) + E(R2) * xi1) * xi1).sqrt()
    f = gn * E(jac) * w                              # g_n dGamma
    # multiplier shape functions Phi = K0 + K1 xi1 (first derivatives suffice for G)
    ka0, ka1 = (c[0] + c[1]) * 0.5, (c[1] - c[0]) * 0.5
    kb0, kb1 = (c[2] + c[3]) * 0.5, (c[3] - c[2]) * 0.5
    f1, x1 = _first(f), _first(xi1)
    ga = ((E(_first(ka0)) + E(_first(ka1)) * x1) * f1).sum(1)
    gb = ((E(_first(kb0)) + E(_first(kb1)) * x1) * f1).sum(1)
    q = None
    if second:  # sum_A lam_A g_A with its Hessian
        la, lb = lam_ab
        q = ((E(ka0 * la + kb0 * lb) + E(ka1 * la + kb1 * lb) * xi1) * f).sum(1)
    # values for D, M, area (no derivatives)
    xv, dv = xi1.v, (E(jac) * w).v
    n1, n2 = (1.0 - xv) * 0.5, (1.0 + xv) * 0.5
    pa = ka0.v[:, None] + ka1.v[:, None] * xv
    pb = kb0.v[:, None] + kb1.v[:, None] * xv
    # master parameter s in [0, 1] from x_m1: s = cross(x_m1 - x_s, n~) / cross(n~, dm)
    V = lambda j: j.v[:, None]  # noqa: E731
    nxv, nyv = V(n0x) + V(n1x) * xv, V(n0y) + V(n1y) * xv
    sv = ((V(r0x) - V(d1x) * xv) * nyv - (V(r0y) - V(d1y) * xv) * nxv) / (V(Q0) + V(Q1) * xv)
    extra = dict(
        area=np.stack([(n1 * dv).sum(1), (n2 * dv).sum(1)], 1),
        D=np.stack([(pa * n1 * dv).sum(1), (pa * n2 * dv).sum(1),
                    (pb * n1 * dv).sum(1), (pb * n2 * dv).sum(1)], 1),
        M=np.stack([(pa * (1 - sv) * dv).sum(1), (pa * sv * dv).sum(1),
                    (pb * (1 - sv) * dv).sum(1), (pb * sv * dv).sum(1)], 1),
    )
    return ga, gb, q, extra


def evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
             lam: np.ndarray | None = None, tangent: bool = True, dual: bool = False,
             n_gauss: int = 2, segmentation: Segmentation | None = None,
             pairs: tuple[np.ndarray, np.ndarray] | None = None, margin: float | None = None,
             crosspoints: np.ndarray | None = None, reach: float = 0.0,
             **options: Any) -> ContactEval:
    """Mortar weighted gaps ``g``, ``G = dg/dx`` and ``H = sum_A lam_A d^2 g_A/dx^2``.

    Parameters
    ----------
    xs, xm : ndarray (2, n_s), (2, n_m)
        Current slave and master node coordinates.
    seg_s, seg_m : int ndarray (n, 2)
        Slave and master segments (outward right-hand normals, see module doc).
    lam : ndarray (n_s,), optional
        Multipliers; with ``tangent`` the Hessian ``H`` is returned.
    tangent : bool
        Compute ``G`` (and ``H`` if ``lam``).
    dual : bool
        Dual (biorthogonal) multipliers instead of the standard ``Phi_A = N_A``.
        The coefficients are computed on the projectable part of each slave
        element and differentiated (unless the segmentation is frozen).
    n_gauss : int
        Gauss points per mortar segment; the default 2 integrates ``Phi_A N_B``,
        ``Phi_A N_C`` and the weighted gaps exactly on flat segments (products
        of two linear functions of eta); on curved surfaces the integrand is
        rational in eta and more points add accuracy (the tangent is exact
        for any rule).
    segmentation : Segmentation, optional
        Reuse these mortar segments (policy ``step``: built by :func:`segment`
        after a converged step).  If ``segmentation.frozen`` the pair list, the
        segment end points ``xi_a, xi_b`` on the slave elements and the dual
        coefficients are held fixed: the returned ``g`` is the frozen residual
        and ``G``, ``H`` its exact derivatives with those parameters fixed (the
        normals, the slave Jacobian and the Gauss-point projections onto the
        master still move; a Gauss point may then project onto the extension of
        its master element, and a slave node without a frozen segment stays out
        of ``mask`` until the next rebuild).  If not frozen only the pair list
        is reused.
        Default: segment the current configuration (policy ``iteration``).
    pairs : (i_s, i_m), optional
        Candidate element pairs (otherwise ``search.segment_pairs``).
    margin, reach : float, optional
        Search margin and motion allowance, see
        :func:`~skfem_mortar.mortar_segmentation.segment` (default: local, the
        two element lengths).
    crosspoints : int array, optional
        Slave nodes (e.g. on a Dirichlet boundary) whose multiplier is merged
        into the neighbour: on their element the neighbour's multiplier shape
        function becomes 1 and theirs 0; they are never in ``mask``.

    Notes
    -----
    ``mask`` is False for the nodes whose mortar support ``area_A`` is at most
    ``MASK_TOL = 1e-6`` times their tributary length (``area_A`` grows like the
    square of the covered fraction of the element when the sliver lies at the
    far end, so this is a covered fraction of about 1e-3): there the row of
    ``G`` nearly vanishes and, with dual multipliers, the coefficients on a
    sliver of projectable element grow like the inverse square of the covered
    fraction, so ``g_A`` is dominated by round-off (measured: 7 % error at a
    covered fraction of 1e-5, wrong sign at 1e-7).  Such a node is merged like a
    crosspoint: on its elements the neighbour's multiplier shape function is 1
    and its own 0 (``g_A = 0``), so the multipliers in ``mask`` still sum to one
    over the sliver (without the merge the sliver's traction is lost: patch
    test error ~1.8 f^2 at a covered fraction f).  ``g``, ``G`` and ``H`` are
    exact derivatives of each other for a fixed mask; when the mask switches the
    neighbour's ``g`` jumps by the node's former ``g_A`` (O(f^2 h) times the gap).

    Returns
    -------
    ContactEval
        ``info`` holds ``D`` (n_s, n_s) and ``M`` (n_s, n_m) csr, the scalar
        mortar matrices ``int Phi_A N_B`` and ``int Phi_A N_C`` (for flat
        surfaces ``n_AB = D_AB n``), and ``segmentation``.
    """
    if options:
        raise TypeError(f"unknown options for mortar.evaluate: {sorted(options)}")
    xs = np.asarray(xs, dtype=float).reshape(2, -1)
    xm = np.asarray(xm, dtype=float).reshape(2, -1)
    seg_s = np.asarray(seg_s, dtype=np.int64).reshape(-1, 2)
    seg_m = np.asarray(seg_m, dtype=np.int64).reshape(-1, 2)
    n_s, n_m = xs.shape[1], xm.shape[1]
    ndof = 2 * n_s + 2 * n_m
    sg = segmentation if segmentation is not None else segment(
        xs, seg_s, xm, seg_m, pairs=pairs, margin=margin, frozen=False, reach=reach)
    second = tangent and lam is not None
    nv = (16 if (dual and not sg.frozen) else 12) if tangent else 0
    cp_nodes = np.zeros(n_s, bool)
    if crosspoints is not None:
        cp_nodes[np.asarray(crosspoints, dtype=np.int64)] = True
    nrm, pnode, nnode = nodal_normals(xs, seg_s, second, 6 if tangent else 0)
    nd = _local_nodes(sg, seg_s, seg_m, pnode, nnode)
    p, a, b, n, m1, m2, lo_node, hi_node = nd
    # mortar supports int N_A dGamma (exact from the end points: N_A is linear) and
    # tributary lengths; a node supported over a sliver only is masked and merged
    # like a crosspoint, so that the multiplier functions still sum to one there
    ls = np.hypot(*(xs[:, seg_s[:, 1]] - xs[:, seg_s[:, 0]]))
    trib = np.zeros(n_s)
    np.add.at(trib, seg_s[:, 0], 0.5 * ls)
    np.add.at(trib, seg_s[:, 1], 0.5 * ls)
    lo_v, hi_v = sg.xi[:, 0], sg.xi[:, 1]
    half = 0.5 * ls[sg.e_s]
    support = np.zeros(n_s)
    np.add.at(support, a, half * ((hi_v - lo_v) - 0.5 * (hi_v * hi_v - lo_v * lo_v)) * 0.5)
    np.add.at(support, b, half * ((hi_v - lo_v) + 0.5 * (hi_v * hi_v - lo_v * lo_v)) * 0.5)
    mask = (support > MASK_TOL * trib) & ~cp_nodes
    merged = cp_nodes | ~mask
    cp = np.stack([merged[a], merged[b]], 1)
    eta, w = np.polynomial.legendre.leggauss(n_gauss)
    # local dofs of each segment: nodes p, a, b, n (slave), m1, m2, lo, hi (master)
    nodes = [2 * p, 2 * a, 2 * b, 2 * n, 2 * n_s + 2 * m1, 2 * n_s + 2 * m2,
             2 * n_s + 2 * np.where(lo_node >= 0, lo_node, m1),
             2 * n_s + 2 * np.where(hi_node >= 0, hi_node, m1)]
    itype = np.int32 if ndof < 2**31 - 1 else np.int64   # halves the COO index memory
    dofs = np.stack([d + k for d in nodes for k in (0, 1)], 1)[:, :nv].astype(itype)

    nseg = sg.n
    # dual multipliers on partially projectable slave elements depend on the
    # master nodes bounding the projectable part: 16 local variables there, 12 elsewhere
    groups = [(np.arange(nseg), nv)]
    if nv == 16:
        partial = (lo_node >= 0) | (hi_node >= 0)
        groups = [(np.flatnonzero(~partial), 12), (np.flatnonzero(partial), 16)]
    g = np.zeros(n_s)
    area = np.zeros(n_s)
    lamv = None if lam is None else np.asarray(lam, dtype=float)
    Gr, Gc, Gv, Hr, Hc, Hv, ex, order = [], [], [], [], [], [], [], []
    for idx_g, nv_g in groups:
        chunk = max(1, _CHUNK_ENTRIES // (n_gauss * max(nv_g, 1) ** (2 if second else 1)))
        for start in range(0, idx_g.size, chunk):  # memory blocking only; blocks are vectorized
            sl = idx_g[start:start + chunk]
            order.append(sl)
            aa, bb = a[sl], b[sl]
            lam_ab = None if lamv is None else (lamv[aa], lamv[bb])
            ga, gb, q, extra = _chunk(xs, xm, sl, nd, sg, n_s, nv_g, second, dual, cp, eta, w,
                                      nrm, lam_ab)
            ex.append(extra)
            np.add.at(g, aa, ga.v)
            np.add.at(g, bb, gb.v)
            if tangent:
                dl = dofs[sl, :nv_g]
                Gr += [np.repeat(aa.astype(itype), nv_g), np.repeat(bb.astype(itype), nv_g)]
                Gc += [dl.ravel(), dl.ravel()]
                Gv += [ga.g.T.ravel(), gb.g.T.ravel()]
                if second:
                    Hr.append(np.repeat(dl, nv_g, axis=1).ravel())
                    Hc.append(np.tile(dl, (1, nv_g)).ravel())
                    Hv.append(q.hessian().transpose(2, 0, 1).ravel())
    def cat(L, dtype=float):
        return np.concatenate(L) if nseg else np.zeros(0, dtype=dtype)
    if nseg:  # per-segment values below in the order the chunks were processed
        o = np.concatenate(order)
        a, b, m1, m2 = a[o], b[o], m1[o], m2[o]
    area_seg = cat([x["area"] for x in ex]).reshape(-1, 2)
    np.add.at(area, a, area_seg[:, 0])
    np.add.at(area, b, area_seg[:, 1])
    G = H = None
    if tangent:
        G = sp.coo_matrix((cat(Gv), (cat(Gr, itype), cat(Gc, itype))), shape=(n_s, ndof)).tocsr()
        if second:
            H = sp.coo_matrix((cat(Hv), (cat(Hr, itype), cat(Hc, itype))),
                              shape=(ndof, ndof)).tocsr()
    Dv = cat([x["D"] for x in ex]).reshape(-1, 4)
    Mv = cat([x["M"] for x in ex]).reshape(-1, 4)
    D = sp.coo_matrix((Dv.ravel(), (np.stack([a, a, b, b], 1).ravel(),
                                    np.stack([a, b, a, b], 1).ravel())), shape=(n_s, n_s)).tocsr()
    M = sp.coo_matrix((Mv.ravel(), (np.stack([a, a, b, b], 1).ravel(),
                                    np.stack([m1, m2, m1, m2], 1).ravel())),
                      shape=(n_s, n_m)).tocsr()
    return ContactEval(g=g, G=G, H=H, area=area, mask=mask,
                       info={"D": D, "M": M, "segmentation": sg, "n_segments": nseg})
