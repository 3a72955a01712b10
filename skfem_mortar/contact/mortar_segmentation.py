"""Mortar geometry in 2D: slave normal field, projections, mortar segments.

The line2 segmentation of the one mortar kernel (:mod:`skfem_mortar.contact.mortar_kernel`;
its points: :mod:`skfem_mortar.contact.line_points`, which takes :func:`slave_element` and
:func:`project_on_slave` in jets for the end points).  Every function is vectorized over
elements (or mortar segments) and works on plain arrays and on the forward-mode jets of
:mod:`skfem_mortar.contact.jets`, so the same code gives the values and their exact first
and second derivatives.  Points and vectors are pairs ``(x, y)``.

Step 1, slave normal field (:func:`nodal_normals`, :func:`slave_element`)
-------------------------------------------------------------------------
A slave segment ``e = (a, b)`` with tangent ``t = x_b - x_a`` has the outward
unit normal ``nu_e = (t_y, -t_x) / |t|``.  The nodal normal of a slave node is
the normalized average of the unit normals of its (one or two, degenerate ones
left out) slave segments,
``n_A = (nu_prev + nu_next) / |nu_prev + nu_next|``, and it is interpolated
linearly (not normalized) along the slave segment,

    x_s(xi) = N_1(xi) x_a + N_2(xi) x_b,   n~(xi) = N_1(xi) n_a + N_2(xi) n_b,
    N_1 = (1 - xi)/2,  N_2 = (1 + xi)/2,   xi in [-1, 1].

Step 2, projections along this field
------------------------------------
* :func:`project_point_on_slave` (a master node onto a slave element): the
  ``xi`` solving ``(x_s(xi) - x_C) x n~(xi) = 0`` (``x`` the 2D cross
  product), a quadratic in ``xi``, solved by Newton's method from the
  flat-surface (linear) estimate.
* a slave point onto a master element: the line ``x_m(s) = x_m1 + s (x_m2 - x_m1)``
  (``s = N_2(xi2)`` in [0, 1]) meets ``x_s(xi) + alpha n~(xi)`` where
  ``(x_m(s) - x_s) x n~ = 0``, linear in ``s`` (in jets:
  :mod:`~skfem_mortar.contact.line_points`; the master coordinates of the segment
  ends in values: :func:`segment`).

Step 3, mortar segments (:func:`segment`)
-----------------------------------------
For a candidate pair (slave element e, master element m) whose unit normals
face each other (``nu_e . nu_m < 0``), the two master nodes project to
``p_1, p_2`` on e; the mortar segment is ``[xi_a, xi_b] = [max(-1, min p),
min(1, max p)]`` in the slave parameter, and ``eta in [-1, 1]`` runs over it
(the kernel's Gauss points).  Only roots in [-1, 1] are used as
values: a master node beyond an end of e (its master parameter past that of the
slave end point projected onto the master line along its normal) counts as
``p = +-inf``, clipped to that end; this decides far master nodes, whose
quadratic has no real root or spurious ones against a turning normal field
(a long master segment against a curved slave) (a slave node projecting inside the
master element makes that slave end an end point; this is the projection of the
slave nodes onto the master).  Segments with ``xi_b - xi_a <= XI_TOL`` are
dropped (a segment that short contributes O(XI_TOL) to every integral, below
round-off of the weighted gaps for elements of any practical size), as are
slave or master elements shorter than ``LEN_TOL`` times the mean element
length of their surface (degenerate, no normal).  Partial overlap at the ends
of either surface is just the clipping above.

Differentiation
---------------
:class:`Jet` carries a value with its gradient and Hessian with respect to a
small set of local variables (the coordinates of the nodes a segment depends
on), stacked over segments and Gauss points.  Composing jets applies the chain
rule exactly, so first and second derivatives of every quantity of the mortar
integral are exact.  Implicitly defined quantities (the projection of a master
node, a root of a quadratic f) are differentiated by one Newton step in jet
arithmetic started from the converged value (exact gradient) plus the
second-order implicit-function term ``-c2 d^2 / f'`` (exact Hessian).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .normals import mirror_nodes
from .segmentation import Segmentation
from .surfaces import segment_lengths, segments_at_nodes
from .jets import Jet, _outer, _val, cross, inv, normalize, sqrt, where

__all__ = ["Jet", "Segmentation", "segment", "nodal_normals", "mirror_normal", "SlaveElement",
           "slave_element", "project_point_on_slave", "project_on_slave",
           "clip_to_slave",
           "XI_TOL", "LEN_TOL"]

XI_TOL = 1e-10
"""Mortar segments shorter than this in the slave parameter (of length 2) are dropped."""
LEN_TOL = 1e-10
"""Elements shorter than this times the mean element length are degenerate and dropped."""


# ------------------------------------------------------ step 1: slave normal field
def _unit_normal(x1, y1, x2, y2):
    """Right-hand unit normal of the segment 1 -> 2 (jets)."""
    return normalize(y2 - y1, x1 - x2)


def mirror_normal(n: tuple, mirrored) -> tuple:
    """Step 1, mirror normals: ``normalize(n - (e·n) e)`` where ``on``, for each
    ``(e, on)`` of ``mirrored`` (2D, jets or arrays of one length), elsewhere ``n``
    unchanged (:mod:`~skfem_mortar.contact.normals`).  On the axis of an
    axisymmetric model (``e = e_r``) the normal becomes axial, with zero derivatives."""
    nx, ny = n
    for e, on in mirrored:
        if not np.any(on):
            continue
        d = nx * e[0] + ny * e[1]
        px, py = nx - d * e[0], ny - d * e[1]
        with np.errstate(divide="ignore", invalid="ignore"):
            r = inv(sqrt(px * px + py * py))
            nx, ny = where(on, px * r, nx), where(on, py * r, ny)
    return nx, ny


def nodal_normals(xs: np.ndarray, seg: np.ndarray, second: bool = True, nv: int = 6,
                  mirror=()):
    """Step 1: averaged unit normals of all slave nodes, as jets in the node's 6 local variables.

    ``n_k = normalize(w_p nu(p, k) + w_n nu(k, n))`` with ``nu(i, j)`` the
    right-hand unit normal of the segment ``i -> j``, ``p``, ``n`` the
    previous and next node along the chain and ``w = 0`` where that neighbour is
    missing (chain ends) or its segment is degenerate (shorter than ``LEN_TOL``
    times the mean length); a dummy position is used there.  Local variables:
    ``(x_p, y_p, x_k, y_k, x_n, y_n)``; with ``nv = 0`` values only.  ``mirror``:
    symmetry lines ``(e, c)`` (:func:`~skfem_mortar.contact.normals.mirror_nodes`), a
    node on one takes its mirror normal (:func:`mirror_normal`).

    Returns
    -------
    (nx, ny) : Jet (n_s,)
    pnode, nnode : int ndarray (n_s,), the neighbours (the node itself where missing).
    """
    n_s = xs.shape[1]
    ends, starts = segments_at_nodes(seg, n_s)
    k = np.arange(n_s)
    # degenerate (near zero length) segments take no part in the average
    length = segment_lengths(xs, seg)
    good = length > LEN_TOL * (length.mean() if length.size else 0.0)
    has_p = (ends >= 0) & good[np.maximum(ends, 0)]
    has_n = (starts >= 0) & good[np.maximum(starts, 0)]
    pnode = np.where(has_p, seg[np.maximum(ends, 0), 0], k)
    nnode = np.where(has_n, seg[np.maximum(starts, 0), 1], k)
    # a missing neighbour gets a dummy position (weight 0, any nonzero offset)
    xk = xs
    xp = np.where(has_p, xs[:, pnode], xk - [[1.0], [0.0]])
    xn = np.where(has_n, xs[:, nnode], xk + [[1.0], [0.0]])
    wp, wn = has_p * 1.0, has_n * 1.0
    if nv == 0:       # values: the same operations on arrays (no jet overhead), wrapped
        npx, npy = _unit_values(xp[0], xp[1], xk[0], xk[1])
        nnx, nny = _unit_values(xk[0], xk[1], xn[0], xn[1])
        nx, ny = _normalize_values(npx * wp + nnx * wn, npy * wp + nny * wn)
        if mirror:
            nx, ny = mirror_normal((nx, ny), mirror_nodes(xs, mirror))
        return (Jet.constant(nx, 0, second), Jet.constant(ny, 0, second)), pnode, nnode
    J = [Jet.variable(c, i, nv, second) if i < nv else Jet.constant(c, nv, second)
         for i, c in enumerate((xp[0], xp[1], xk[0], xk[1], xn[0], xn[1]))]
    npx, npy = _unit_normal(J[0], J[1], J[2], J[3])
    nnx, nny = _unit_normal(J[2], J[3], J[4], J[5])
    nx, ny = normalize(npx * wp + nnx * wn, npy * wp + nny * wn)
    if mirror:
        nx, ny = mirror_normal((nx, ny), mirror_nodes(xs, mirror))
    return (nx, ny), pnode, nnode


def _unit_values(x1, y1, x2, y2):
    """:func:`_unit_normal` on arrays: ``(y2 - y1, x1 - x2) / |.|`` by the jets' own
    operations (``r = 1 / sqrt(x x + y y)``, ``x r``), so the values are theirs to the bit."""
    return _normalize_values(y2 - y1, x1 - x2)


def _normalize_values(x, y):
    """``normalize`` on arrays, by the jets' operations (``r = 1 / sqrt(x x + y y)``)."""
    r = 1.0 / np.sqrt(x * x + y * y)
    return x * r, y * r


class SlaveElement(NamedTuple):
    """Step 1: position and normal field of slave elements, both linear in ``xi``.

    ``x_s(xi) = x0 + xi dx`` and ``n~(xi) = n0 + xi dn`` on ``xi in [-1, 1]``,
    with ``x0 = (x_a + x_b)/2``, ``dx = (x_b - x_a)/2``, ``n0 = (n_a + n_b)/2``,
    ``dn = (n_b - n_a)/2`` (each a pair of arrays or jets, one entry per element).
    """

    x0: tuple
    dx: tuple
    n0: tuple
    dn: tuple


def slave_element(xa, xb, na, nb) -> SlaveElement:
    """Step 1: the fields of :class:`SlaveElement` from the end nodes and their nodal normals."""
    return SlaveElement(x0=((xa[0] + xb[0]) * 0.5, (xa[1] + xb[1]) * 0.5),
                        dx=((xb[0] - xa[0]) * 0.5, (xb[1] - xa[1]) * 0.5),
                        n0=((na[0] + nb[0]) * 0.5, (na[1] + nb[1]) * 0.5),
                        dn=((nb[0] - na[0]) * 0.5, (nb[1] - na[1]) * 0.5))


# ------------------------------------------------------------ step 2: projections
def project_on_slave(el: SlaveElement, xc, n_newton: int = 8):
    """Step 2: slave parameter ``xi`` of the projection of the point ``xc`` along ``n~``.

    Solves ``f(xi) = (x_s(xi) - x_c) x n~(xi) = c0 + c1 xi + c2 xi^2 = 0``:
    Newton on values from the linear estimate ``-c0 / c1``; with jet inputs then
    one Newton step in jet arithmetic from the converged value plus the
    second-order implicit function term, for exact first and second derivatives.

    Returns
    -------
    xi : ndarray or Jet
    ok : bool ndarray, whether the value iteration converged to a finite root.
    """
    d0x = el.x0[0] - xc[0]
    d0y = el.x0[1] - xc[1]
    (d1x, d1y), (n0x, n0y), (n1x, n1y) = el.dx, el.n0, el.dn
    c0 = cross(d0x, d0y, n0x, n0y)
    c1 = cross(d0x, d0y, n1x, n1y) + cross(d1x, d1y, n0x, n0y)
    c2 = cross(d1x, d1y, n1x, n1y)
    v0, v1, v2 = _val(c0), _val(c1), _val(c2)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = -v0 / v1
        for _ in range(n_newton):
            xi = xi - (v0 + xi * (v1 + xi * v2)) / (v1 + 2.0 * xi * v2)
        res = v0 + xi * (v1 + xi * v2)
        scale = np.abs(v0) + np.abs(v1) + np.abs(v2)
        ok = np.isfinite(xi) & (np.abs(res) <= 1e-10 * scale + 1e-300)
    xi = np.where(ok, xi, 0.0)
    if not isinstance(c0, Jet):
        return xi, ok
    # one Newton step in jets from the converged value xi0 (a constant):
    #   xi1 = xi0 - f(xi0) / f'(xi0)            exact value and gradient;
    # f is quadratic, so 0 = f(xi0) + f'(xi0) d + c2 d^2 for d = xi - xi0 and
    #   xi = xi1 - c2 d^2 / f'(xi0) + O(|dq|^3),  d^2 having the Hessian 2 g g^T,
    # which makes the Hessian exact too (implicit function theorem).
    f0 = c0 + c1 * xi + c2 * (xi * xi)
    df0 = c1 + c2 * (2.0 * xi)
    xj = xi - f0 * df0.inv()
    if xj.h is not None:
        corr = -2.0 * c2.v / df0.v
        xj = Jet(xj.v, xj.g, xj.h + _outer(xj.g, xj.g * corr))
    return xj, ok


def project_point_on_slave(xa, xb, na, nb, xc, n_newton: int = 8):
    """Step 2: :func:`project_on_slave` on the element ``x_a, x_b`` with nodal normals ``n_a, n_b``.

    Each argument is a pair ``(x, y)`` of arrays (values only) or of jets.
    """
    return project_on_slave(slave_element(xa, xb, na, nb), xc, n_newton)


# ------------------------------------------------------- step 3: mortar segments
def _element_lengths(x: np.ndarray, seg: np.ndarray) -> np.ndarray:
    d = x[:, seg[:, 1]] - x[:, seg[:, 0]]
    return np.hypot(d[0], d[1])


def _side(p, ok, dsa, dsb, dab):
    """Projection ``p`` of a master node, ``+-inf`` where it is outside [-1, 1] or missing.

    ``dsa = s_k - s_a``, ``dsb = s_k - s_b``, ``dab = s_b - s_a`` (master
    parameters, see :func:`segment`): ``+inf`` where the node lies beyond the
    slave end b, ``-inf`` beyond a (this overrides any root: against a turning
    normal field the quadratic may have spurious roots, behind the centre of
    curvature, of either sign), else the root if it is in [-1, 1] or its sign.
    Returns ``(p, ok)`` with ``ok`` False where neither a root nor a side is found.
    """
    beyond_b = dsb * dab > 0.0
    beyond_a = dsa * dab < 0.0
    decided = beyond_a ^ beyond_b
    inside = ok & (np.abs(p) <= 1.0) & ~decided
    far = np.where(decided, np.where(beyond_b, np.inf, -np.inf), np.copysign(np.inf, p))
    return np.where(inside, p, far), inside | decided | ok


def clip_to_slave(p1: np.ndarray, p2: np.ndarray, keep: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 3: the mortar segment ``[max(-1, min p), min(1, max p)]`` of each pair.

    ``p1, p2``: the slave parameters of the two master nodes (``+-inf`` beyond
    an end, see :func:`_side`); ``keep``: the pairs that may have a segment.
    Returns the pairs kept (``keep`` and longer than ``XI_TOL``), their end
    points ``xi`` (n, 2) and where these come from, ``src`` (n, 2): -1 a slave
    end, 0 or 1 the first or second master node.
    """
    # A master node projecting within XI_TOL of a slave end is that end (a slave
    # node exactly above a master node): its sliver segment on one side is
    # dropped below, so the segment on the other side must start at the slave
    # end too (src -1), or the element's segments leave the sliver uncovered and
    # the end point's derivative (the projection's) is not cancelled by the
    # sliver's: the weighted gap's gradient G jumps at the tie (and only there).
    p1 = np.where(np.abs(np.abs(p1) - 1.0) <= XI_TOL, np.copysign(1.0, p1), p1)
    p2 = np.where(np.abs(np.abs(p2) - 1.0) <= XI_TOL, np.copysign(1.0, p2), p2)
    lo = np.maximum(-1.0, np.minimum(p1, p2))
    hi = np.minimum(1.0, np.maximum(p1, p2))
    src_lo = np.where(lo == -1.0, -1, np.where(p1 <= p2, 0, 1))
    src_hi = np.where(hi == 1.0, -1, np.where(p1 <= p2, 1, 0))
    keep = keep & (hi - lo > XI_TOL)
    return (keep, np.stack([lo[keep], hi[keep]], axis=1),
            np.stack([src_lo[keep], src_hi[keep]], axis=1))


def master_coordinates(src: np.ndarray, eta_a: np.ndarray, eta_b: np.ndarray) -> np.ndarray:
    """The master coordinates (in [-1, 1]) of the end points of integration cells.

    ``src`` (n, 2) as :class:`~skfem_mortar.contact.segmentation.Segmentation`'s: a
    master vertex is at -1 or 1; a slave vertex (the cell's start at ``xi = -1``,
    its end at ``xi = 1``) at ``eta_a`` or ``eta_b``, the slave end projected onto
    the master cell along its nodal normal.
    """
    ends = np.stack([eta_a, eta_b], 1)
    return np.where(src < 0, ends, np.where(src == 0, -1.0, 1.0))


def segment(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
            pairs: tuple[np.ndarray, np.ndarray] | None = None, margin: float | None = None,
            frozen: bool = True, reach: float = 0.0, mirror=()) -> Segmentation:
    """Step 3: the mortar segments of the current coordinates (values, vectorized over pairs).

    Parameters
    ----------
    xs, xm : ndarray (2, n_s), (2, n_m)
        Current slave and master node coordinates.
    seg_s, seg_m : int ndarray (n, 2)
        Slave and master segments, oriented with outward right-hand normals.
    pairs : (i_s, i_m), optional
        Candidate element pairs; by default ``search.segment_pairs`` with ``margin``.
    margin : float, optional
        Global search margin: every pair of boxes within ``margin``.  Default:
        local, a slave element ``i`` and a master element ``j`` are candidates
        when their boxes come within ``l_i + l_j + reach`` (``l`` the element
        lengths).  The kept pairs are those whose projections overlap, which
        only needs the boxes to come within the gap; the default holds every
        pair with a gap (or a penetration) up to the two element lengths plus
        ``reach``.  Beyond that a slave node has no master partner and is
        inactive (an open gap of more than an element length).
    frozen : bool
        Stored in the result (see :class:`Segmentation`).
    reach : float
        Added to the local margin (>= 0): :class:`~skfem_mortar.contact.pair.ContactPair`
        passes twice the largest motion of a contact node since the load step
        began, so a node that penetrates deeply within one step is still paired.
    mirror : sequence of (e, c)
        Symmetry lines of the slave normals (:func:`nodal_normals`).

    Returns
    -------
    Segmentation
    """
    xs = np.asarray(xs, dtype=float).reshape(2, -1)
    xm = np.asarray(xm, dtype=float).reshape(2, -1)
    seg_s = np.asarray(seg_s, dtype=np.int64).reshape(-1, 2)
    seg_m = np.asarray(seg_m, dtype=np.int64).reshape(-1, 2)
    ls, lm = _element_lengths(xs, seg_s), _element_lengths(xm, seg_m)
    searched = pairs is None
    if searched:
        from .search import segment_pairs
        if margin is None:
            pairs = segment_pairs(xs, seg_s, xm, seg_m, float(reach), ls, lm)
        else:
            pairs = segment_pairs(xs, seg_s, xm, seg_m, margin)
    candidates = pairs if searched else None
    i_s = np.asarray(pairs[0], dtype=np.int64)
    i_m = np.asarray(pairs[1], dtype=np.int64)
    good_s = ls > LEN_TOL * max(ls.mean() if ls.size else 0.0, 1e-300)
    good_m = lm > LEN_TOL * max(lm.mean() if lm.size else 0.0, 1e-300)
    keep = good_s[i_s] & good_m[i_m]
    i_s, i_m = i_s[keep], i_m[keep]

    (nxv, nyv), _, _ = nodal_normals(xs, seg_s, second=False, nv=0, mirror=mirror)
    a, b = seg_s[i_s, 0], seg_s[i_s, 1]
    xa, xb = xs[:, a], xs[:, b]
    na = (nxv.v[a], nyv.v[a])
    nb = (nxv.v[b], nyv.v[b])
    # facing test with the master element's unit normal
    m1, m2 = xm[:, seg_m[i_m, 0]], xm[:, seg_m[i_m, 1]]
    tm = m2 - m1
    ts = xb - xa
    facing = (ts[0] * tm[0] + ts[1] * tm[1]) < 0.0   # nu_s . nu_m = t_s . t_m / (|t_s| |t_m|)
    xa_, xb_ = (xa[0], xa[1]), (xb[0], xb[1])
    p1, ok1 = project_point_on_slave(xa_, xb_, na, nb, (m1[0], m1[1]))
    p2, ok2 = project_point_on_slave(xa_, xb_, na, nb, (m2[0], m2[1]))
    # A master node whose projection is outside [-1, 1] (or has no root at all: a
    # far node against a turning normal field) only matters through its side of
    # the slave element, decided by the master parameters s_a, s_b of the slave
    # end points projected along their normals onto the master line (s = 0 at
    # m1, 1 at m2): beyond b if s_k lies past s_b, beyond a if past s_a.  Its end
    # point is then clipped at +-1 (a constant); p = +-1 is s_k = s_b or s_a, so
    # the choice is continuous with the root.
    with np.errstate(divide="ignore", invalid="ignore"):
        sa = ((m1[0] - xa[0]) * na[1] - (m1[1] - xa[1]) * na[0]) / (na[0] * tm[1] - na[1] * tm[0])
        sb = ((m1[0] - xb[0]) * nb[1] - (m1[1] - xb[1]) * nb[0]) / (nb[0] * tm[1] - nb[1] * tm[0])
        dab = sb - sa
        p1, ok1 = _side(p1, ok1, 0.0 - sa, 0.0 - sb, dab)
        p2, ok2 = _side(p2, ok2, 1.0 - sa, 1.0 - sb, dab)
    keep, xi, src = clip_to_slave(p1, p2, facing & ok1 & ok2)
    e_s, e_m = i_s[keep], i_m[keep]
    xi_m = master_coordinates(src, 2.0 * sa[keep] - 1.0, 2.0 * sb[keep] - 1.0)

    # projectable part of each slave element: extreme end points of its segments
    n_es = seg_s.shape[0]
    elem_xi = np.tile(np.array([1.0, -1.0]), (n_es, 1))
    elem_node = np.full((n_es, 2), -1, dtype=np.int64)
    if e_s.size:
        node_lo = np.where(src[:, 0] >= 0, seg_m[e_m, np.maximum(src[:, 0], 0)], -1)
        node_hi = np.where(src[:, 1] >= 0, seg_m[e_m, np.maximum(src[:, 1], 0)], -1)
        o = np.lexsort((xi[:, 0], e_s))          # first of each element: smallest xi_a
        first = np.ones(o.size, bool)
        first[1:] = e_s[o[1:]] != e_s[o[:-1]]
        elem_xi[e_s[o[first]], 0] = xi[o[first], 0]
        elem_node[e_s[o[first]], 0] = node_lo[o[first]]
        o = np.lexsort((-xi[:, 1], e_s))         # first of each element: largest xi_b
        first = np.ones(o.size, bool)
        first[1:] = e_s[o[1:]] != e_s[o[:-1]]
        elem_xi[e_s[o[first]], 1] = xi[o[first], 1]
        elem_node[e_s[o[first]], 1] = node_hi[o[first]]
    return Segmentation(e_s=e_s, e_m=e_m, xi=xi, src=src, elem_xi=elem_xi,
                        elem_node=elem_node, frozen=frozen, candidates=candidates, xi_m=xi_m)
