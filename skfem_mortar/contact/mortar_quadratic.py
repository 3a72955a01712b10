"""Mortar contact kernel on curved 3-node segments: weighted gaps and their exact derivatives.

Frictionless mortar contact in 2D where the slave or the master surface (or
both) has 3-node segments ``(start, end, mid)`` (the P2 traces of tri2 and
quad2 bodies); the other may have 2-node segments.  Same signature and result
as :func:`skfem_mortar.contact.mortar.evaluate`; the geometry (steps 1 to 3:
normal field, projections, segmentation) is
:mod:`skfem_mortar.contact.mortar_quadratic_segmentation`.

Every slave node (vertices and mid nodes) carries a multiplier ``lam_A`` with
the shape function ``Phi_A``; the contact work is ``sum_A lam_A g_A`` with the
weighted gap::

    g_A = int_Gc Phi_A(xi) (x_m(eta(xi)) - x_s(xi)) . n(xi) dGamma,
    dGamma = |dx_s/dxi| dxi,   n = n~/|n~|,   n~ = sum_B N_B(xi) n_B,

``eta(xi)`` the master point on the slave normal line (``x_s + alpha n~`` on
the master curve), so ``g_A > 0`` is open.

Steps (each vectorized over mortar segments and Gauss points, in jets)
-----------------------------------------------------------------------
- steps 1 to 3, the slave normal field, the projections and the mortar
  segments: see :mod:`~skfem_mortar.contact.mortar_quadratic_segmentation`;

4. the Gauss rule of ``n_gauss`` points on every mortar segment
   ``[xi_a, xi_b]``: ``xi_k = (1 - eta_k)/2 xi_a + (1 + eta_k)/2 xi_b``,
   ``dGamma_k = |x_s'(xi_k)| (xi_b - xi_a)/2 w_k``.  The default 3 points are
   exact (degree 5) for the integrands of straight segments with centred mid
   nodes: ``Phi_A N_B``, ``Phi_A N_C`` and ``Phi_A g_n`` with a linear gap are
   products of two quadratics (``D``, ``M``) or of degree 3 (``g_A``); on curved
   segments ``|x_s'|`` is the square root of a quadratic and more points add
   accuracy (the tangent is exact for any rule);
5. the Gauss points projected onto the curved master along ``n~``
   (:func:`~skfem_mortar.contact.mortar_quadratic_segmentation.project_on_master`,
   Newton on values, then one Newton step in jets with the exact second-order term);
6. multiplier functions ``Phi_A`` (:func:`merge_matrix`, :func:`dual_coefficients`);
7. ``g_A`` and ``sum_A lam_A g_A`` as one integrand ``int Phi_A g_n dGamma``
   with ``g_n = (x_m - x_s) . n~/|n~|``, in jets, so ``G = dg/dx`` and
   ``H = sum_A lam_A d^2 g_A/dx^2`` are exact: the derivatives of the nodal
   normals, of the segment end points, of the curved slave Jacobian, of the
   Gauss-point projections and of the dual coefficients are all included.

Local variables of a mortar segment (slave element e, master element m): the
slave nodes that enter e's normal field (:func:`~skfem_mortar.contact.
mortar_quadratic_segmentation.slave_slots`: for 3-node segments e's start,
end and mid, the previous element's start and mid, the next element's end and
mid; for 2-node segments the previous and next node), the nodes of m and, for
dual multipliers on a partly projectable slave element, the two master
vertices bounding its projectable part: up to 2 (7 + 3 + 2) = 24 variables.

Multipliers (step 6)
--------------------
Standard: ``Phi_A = N_A``, quadratic on 3-node slave segments.  Dual:
``Phi_A = sum_B a_AB N_B`` with ``A_e = D_e M_e^{-1}``, ``D_e = diag(int N_A
dGamma)``, ``M_e = int N_A N_B dGamma`` over the projectable part ``[l, h]`` of
the slave element (the hull of its mortar segments), with the current slave
Jacobian, evaluated in jets (:func:`dual_coefficients`; the rule has
``n_gauss_element`` points, exact on straight elements, and the dual
functions are biorthogonal for that rule: ``int Phi_A N_B = delta_AB
int N_A``).

Crosspoints and boundary nodes (Popp, Wohlmuth, Gee, Wall 2012; Wohlmuth 2001,
*Discretization methods and iterative solvers based on domain decomposition*,
sect. on the modification at the boundary of the contact zone): a slave node
that is pinned (``crosspoints``) or whose mortar support is at most
``MASK_TOL`` of its tributary weight (it hangs off the master, or the support
is negative, see below) has no multiplier.  On each of its elements its shape
function is handed to a neighbour on that element, ``N~ = T N``
(:func:`merge_matrix`): a vertex's to the element's mid node (the next node
along the chain, as the linear kernel merges into the neighbour), or to the
other vertex if the mid node is merged too; a mid node's half to each kept
vertex.  So ``sum_A N~_A = sum_B N_B = 1`` on the element (constants are still
reproduced: the patch test holds), the multipliers are ``Phi = N~``
(standard) or the dual basis of the modified functions, ``A~ = D~ M~^{-1}``
with ``D~ = diag(int N~_A)``, ``M~ = int N~_A N~_B``, which is biorthogonal to
``N~`` on the element and sums to one as well.  An element with both
vertices merged keeps one multiplier (its mid node, ``N~ = 1``).

Why 3D's zero-weight problem does not arise on 3-node lines
------------------------------------------------------------
The dual basis needs ``D_e = diag(int N_A dGamma)`` invertible.  For the
quadratic 3D facets it is not: the vertex functions of tri6 integrate to zero
and those of quad8 to a negative value, so Popp, Wohlmuth, Gee and Wall (2012)
transform the basis first.  On a 3-node line ``int N_A dGamma = L/6, L/6,
2L/3`` on a straight segment of length ``L``, all positive, so ``D_e`` is
invertible and the dual basis exists on every fully projectable element
without a transformation (on curved elements the vertex weights stay positive
while the Jacobian on one half of the element is below 5 times that on the
other, i.e. for any reasonably placed mid node).  What remains is the
contact-zone boundary: on a partly projectable element ``[l, 1]`` the far
vertex's weight ``int_l^1 N_1 = (l - 1)^2 (2 l + 1)/12 (L/2)`` is negative for
``l > -1/2``.  A node whose total support is not positive is masked and
merged as above, so every multiplier kept has a positive ``D_AA`` (summed over
its elements).

Active set on weighted gaps of quadratic segments
-------------------------------------------------
Hueber, Mair and Wohlmuth (2005) point out that with standard quadratic
multipliers the nodal conditions ``g_A >= 0``, ``lam_A >= 0`` are conditions on
weighted quantities (the vertex weights are a sixth of the mid node's, and
``Phi_A`` changes sign inside the element), not pointwise statements on the
gap or the pressure between nodes.  The contact pair applies the nodal
complementarity ``lam_A - max(0, lam_A - c g_A) = 0`` to the weighted gaps in
both cases.  With the dual basis ``lam_A`` are the nodal values of a
biorthogonal traction field, ``lam_A D_AA`` is the nodal force of that node
alone, so the condition is a nodal traction condition that can be checked
pointwise (what ``tail_signal`` reads); with the standard basis the condition
is the one of the discrete problem on the weighted gaps ``g_A``, and the
pair's release signal reads the normal nodal forces ``G^T lam``.
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .cells import CellType
from .measures import PLANE, Measure
from .normals import mirror_of_axis
from .contact_eval import ContactEval
from .mortar_support import multiplier_support, tributary_weights
from .scatter import Triplets
from .jets import Jet, at_gauss, constant_like, value, where
from .mortar import MASK_TOL, biorthogonal, gauss_rule
from .multiplier_spaces import DualSpace, MultiplierSpace, make_space
from .segmentation import Segmentation, check_kernel_cells, line_cells
from .mortar_quadratic_segmentation import (SlaveSlots, curve, element_normals,
                                            element_polynomial, nodal_normals,
                                            project_on_master,
                                            project_on_master_jet, project_on_slave_jet,
                                            segment, shape_values, slave_slots, tangent)

__all__ = ["evaluate", "tangential_evaluate", "segment", "Segmentation", "merge_matrix", "dual_coefficients",
           "N_GAUSS", "N_GAUSS_ELEMENT", "MASK_TOL"]

N_GAUSS = 3
"""Default Gauss points per mortar segment (exact to degree 5, see the module doc)."""
N_GAUSS_ELEMENT = 5
"""Default Gauss points of the element rule of ``D_e``, ``M_e`` (dual basis) and of
the tributary weights (exact to degree 9; the integrands of a straight element
have degree 4)."""
_CHUNK_ENTRIES = 200_000  # Hessian entries per block of segments
_DUAL = DualSpace()        # the biorthogonal space's A_e = D_e M_e^-1 (dual_coefficients)


def _check_rule(name: str, n: Any) -> int:
    if not isinstance(n, (int, np.integer)) or not 1 <= n <= 10:
        raise ValueError(f"{name} must be an integer in [1, 10], got {n!r}")
    return int(n)


def _as_arrays(xs, seg_s, xm, seg_m, cells=None):
    """The coordinates and connectivities as arrays, checked against ``cells``
    (:func:`~skfem_mortar.contact.segmentation.line_cells`: line2 or line3), and the
    two cell types."""
    xs = np.asarray(xs, dtype=float).reshape(2, -1)
    xm = np.asarray(xm, dtype=float).reshape(2, -1)
    seg_s = np.asarray(seg_s, dtype=np.int64)
    seg_m = np.asarray(seg_m, dtype=np.int64)
    cells = line_cells(seg_s, seg_m, cells)
    check_kernel_cells(cells, ("line2", "line3"), "the curved mortar kernel")
    return xs, seg_s, xm, seg_m, cells


def _expand(C: list) -> list:
    """Per-segment coefficients ``(n,)`` with a Gauss-point axis ``(n, 1)``."""
    return [None if c is None else (at_gauss(c[0]), at_gauss(c[1])) for c in C]


def _segment_points(lo, hi, eta: np.ndarray):
    """``xi_k = (1 - eta_k)/2 lo + (1 + eta_k)/2 hi`` (n, n_points) and ``(hi - lo)/2`` (n, 1)."""
    return (at_gauss(lo) * ((1.0 - eta) * 0.5) + at_gauss(hi) * ((1.0 + eta) * 0.5),
            at_gauss((hi - lo) * 0.5))


def _jacobian(P: list, xi):
    tx, ty = tangent(P, xi)
    j2 = tx * tx + ty * ty
    return j2.sqrt() if isinstance(j2, Jet) else np.sqrt(j2)


# ------------------------------------------------ step 6: multiplier shape functions
def merge_matrix(merged: np.ndarray, cell: CellType) -> np.ndarray:
    """The crosspoint/boundary modification ``N~_A = sum_B T_AB N_B`` per element.

    ``merged`` (n, n_nodes) bool: the element's nodes without a multiplier, in the
    columns of ``cell``.  Kept nodes keep their function; a merged node's goes to
    the nearest kept node on each side along the cell's edge (``cell.edges``), in
    halves when there is one on both sides, whole when on one.  For line3 (edge
    start, mid, end) a merged vertex's goes to the mid node if that is kept, else
    to the other vertex; a merged mid node's in halves to the kept vertices; for
    line2 a merged node's to the other.  Merged rows are zero.  ``sum_A T_AB = 1``
    for every ``B`` unless the whole element is merged, so ``sum_A N~_A = 1``.

    Returns
    -------
    T : ndarray (n, n_nodes, n_nodes)
    """
    merged = np.asarray(merged, dtype=bool)
    n, k = merged.shape
    if k != cell.n_nodes or cell.dim != 1:
        raise ValueError(f"merged must have the columns of the line cell {cell.name} "
                         f"({cell.n_nodes} nodes), got shape {merged.shape}")
    keep = ~merged
    order = cell.edges[0]                       # the nodes in order along the line
    T = np.zeros((n, k, k))
    for a in range(k):
        T[:, a, a] = keep[:, a]
    rows = np.arange(n)
    for p, b in enumerate(order):
        if not merged[:, b].any():
            continue
        sides = []
        for walk in (order[p - 1::-1] if p else (), order[p + 1:]):
            target = np.full(n, -1)
            for q in walk:                      # the nearest kept node on this side
                target = np.where((target < 0) & keep[:, q], q, target)
            sides.append(target)
        share = np.where((sides[0] >= 0) & (sides[1] >= 0), 0.5, 1.0)
        for t in sides:
            on = merged[:, b] & (t >= 0)
            T[rows[on], t[on], b] += share[on]
    return T


def _modified(T: np.ndarray | None, N: list, k: int) -> list:
    """``N~_A = sum_B T_AB N_B`` (T per segment, constants); ``T`` None: unmodified."""
    if T is None:
        return N
    out = []
    for a in range(k):
        acc = None
        for b in range(k):
            t = T[:, a, b]
            if not t.any():
                continue
            term = N[b] * at_gauss(t)
            acc = term if acc is None else acc + term
        out.append(acc if acc is not None else N[0] * 0.0)
    return out


def dual_coefficients(P: list, lo, hi, cell: CellType, T: np.ndarray | None = None,
                      n_gauss: int = N_GAUSS_ELEMENT, measure: Measure = PLANE,
                      space: DualSpace | None = None) -> dict:
    """Step 6: dual coefficients ``A~ = D~ M~^{-1}`` on the projectable part ``[lo, hi]``.

    ``D~ = diag(int N~_A dGamma)``, ``M~_AB = int N~_A N~_B dGamma`` over
    ``xi in [lo, hi]`` with ``dGamma = |x_s'(xi)| dxi`` (the current Jacobian of
    the element with coefficients ``P``, :func:`~skfem_mortar.contact.
    mortar_quadratic_segmentation.element_polynomial`), ``N~ = T N``
    (:func:`merge_matrix`; a zero row gets ``M~_AA = 1``, ``D~_AA = 0``), by an
    ``n_gauss``-point rule; arrays or jets.  ``Phi_A = sum_B A~_AB N~_B`` then
    satisfies ``int Phi_A N~_B dGamma = delta_AB int N~_A dGamma`` for that rule.
    ``measure``: ``dGamma`` times its weight ``w(x_s(xi))``
    (:mod:`~skfem_mortar.contact.measures`), so the basis is biorthogonal in ``w dGamma``.
    ``A~`` from ``D~``, ``M~`` is the space's
    (:meth:`~skfem_mortar.contact.multiplier_spaces.DualSpace.cell_coefficients`;
    default the registered ``"dual"``).

    Returns
    -------
    dict ``(A, B) -> A~_AB``, each of shape (n,).
    """
    k = cell.n_nodes
    eta, w = gauss_rule(n_gauss)
    xi, half = _segment_points(lo, hi, eta)
    PE = _expand(P)
    dG = _jacobian(PE, xi) * half * w
    if not measure.unit:
        dG = dG * measure.weight(curve(PE, xi))
    Nt = _modified(T, shape_values(cell, xi), k)
    wN = [N * dG for N in Nt]
    D = [x.sum(1) for x in wN]
    M = {(a, b): (wN[a] * Nt[b]).sum(1) for a in range(k) for b in range(a, k)}
    if T is not None:
        dead = ~T.any(axis=2)                              # merged rows
        for a in range(k):
            if dead[:, a].any():
                M[a, a] = M[a, a] + dead[:, a] * 1.0
    return (space if space is not None else _DUAL).cell_coefficients(D, M)


# -------------------------------------------------------------- one block of segments
class _Problem(NamedTuple):
    """A surface pair prepared for the blocks."""

    xs: np.ndarray
    seg_s: np.ndarray
    xm: np.ndarray
    seg_m: np.ndarray
    sg: Segmentation
    slots: SlaveSlots
    mask: np.ndarray
    area: np.ndarray
    T: np.ndarray                  # (n_el_s, k, k) modification of every slave element
    merged_any: np.ndarray         # (n_el_s,) whether T is not the identity
    rule: tuple
    n_gauss_element: int
    cells: tuple                   # the slave and master cell types
    measure: Measure               # the weight of dGamma

    @property
    def n_slots(self) -> int:
        return 3 * self.slots.k - 2

    def nv(self, partial: bool) -> int:
        return 2 * (self.n_slots + self.cells[1].n_nodes) + (4 if partial else 0)


def _prepare(xs, seg_s, xm, seg_m, segmentation, pairs, margin, reach, crosspoints,
             n_gauss, n_gauss_element, cells=None, measure: Measure = PLANE) -> _Problem:
    xs, seg_s, xm, seg_m, cells = _as_arrays(xs, seg_s, xm, seg_m, cells)
    n_s = xs.shape[1]
    mirror = mirror_of_axis(measure.axis)   # the axis of revolution: axial normals there
    sg = segmentation if segmentation is not None else segment(
        xs, seg_s, xm, seg_m, pairs=pairs, margin=margin, frozen=False, reach=reach,
        cells=cells, mirror=mirror)
    cp = np.isin(np.arange(n_s), [] if crosspoints is None else crosspoints)
    support = multiplier_support(xs, seg_s, sg, cells[0], n_gauss, measure)
    # outside plane models the scale is int |N_A| w dGamma: int N_A w dGamma of a line3
    # vertex on the axis vanishes (mortar_support.tributary_weights)
    trib = tributary_weights(xs, seg_s, cells[0], 2 * n_gauss_element - 1, measure,
                             absolute=not measure.unit)
    mask = (support > MASK_TOL * trib) & ~cp
    merged = ~mask[seg_s]
    return _Problem(xs, seg_s, xm, seg_m, sg, slave_slots(xs, seg_s, cells[0], mirror), mask,
                    support,
                    merge_matrix(merged, cells[0]), merged.any(axis=1), gauss_rule(n_gauss),
                    n_gauss_element, cells, measure)


class _Block(NamedTuple):
    g: list             # Jets (n,), first order: g_A of the element's nodes
    q: Jet | None       # sum_A lam_A g_A to second order
    D: np.ndarray       # (n, k_s, k_s) int Phi_A N_B dGamma
    M: np.ndarray       # (n, k_s, k_m) int Phi_A N_C dGamma


def _end_points(sg: Segmentation, sl: np.ndarray, Pc: list, Qc: list, Vm: list, const):
    """Steps 2, 3: the end points ``lo, hi`` of the mortar segments ``sl`` by their
    origin: a slave end is -1 or 1 (a constant), a master vertex (local variables
    ``Vm``, the master element's first two nodes) is projected onto the slave
    element in jets; frozen segmentations keep their values."""
    if sg.frozen:
        return const(sg.xi[sl, 0]), const(sg.xi[sl, 1])
    n = sl.size
    src = sg.src[sl]
    ends = []
    for c in (0, 1):
        start = np.where(src[:, 0] == c, sg.xi[sl, 0], np.where(src[:, 1] == c, sg.xi[sl, 1], 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            ends.append(project_on_slave_jet(Pc, Qc, Vm[c], start))
    lo = where(src[:, 0] == -1, const(-np.ones(n)), where(src[:, 0] == 0, ends[0], ends[1]))
    hi = where(src[:, 1] == -1, const(np.ones(n)), where(src[:, 1] == 0, ends[0], ends[1]))
    return lo, hi


def _projectable_part(exi: np.ndarray, nodes: tuple, Pc: list, Qc: list, Vb: list | None,
                      const) -> tuple:
    """Step 6: the projectable part ``[l, h]`` of the slave elements, in jets of the
    master nodes bounding it (``Vb``, None: held constant; ``nodes`` -1 at a slave end)."""
    if Vb is None:
        return const(exi[:, 0]), const(exi[:, 1])
    lo_node, hi_node = nodes
    n = exi.shape[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        pl = project_on_slave_jet(Pc, Qc, Vb[0], np.where(lo_node >= 0, exi[:, 0], 0.0))
        ph = project_on_slave_jet(Pc, Qc, Vb[1], np.where(hi_node >= 0, exi[:, 1], 0.0))
    return (where(lo_node >= 0, pl, const(-np.ones(n))),
            where(hi_node >= 0, ph, const(np.ones(n))))


def _block(P: _Problem, sl: np.ndarray, nv: int, second: bool, biorth: "DualSpace | None",
           lam: np.ndarray | None, tangential: bool = False) -> _Block:
    """Steps 1 to 7 on the mortar segments ``sl`` in jets of ``nv`` local variables
    (0: values only); ``tangential``: the tangential offsets ``r_A`` of
    :func:`tangential_evaluate` instead of the weighted gaps."""
    (cs, cm), sg = P.cells, P.sg
    k, km = cs.n_nodes, cm.n_nodes
    e, m = sg.e_s[sl], sg.e_m[sl]
    ns = P.n_slots
    pos = [P.slots.pos[:, e, j] for j in range(ns)]
    pos += [P.xm[:, P.seg_m[m, a]] for a in range(km)]
    lo_node, hi_node = sg.elem_node[e, 0], sg.elem_node[e, 1]
    partial = nv > P.nv(False)
    if partial:
        pos += [P.xm[:, np.maximum(lo_node, 0)], P.xm[:, np.maximum(hi_node, 0)]]
    V = [tuple(Jet.variable(xk[i], 2 * j + i, nv, second) if 2 * j + 1 < nv
               else Jet.constant(xk[i], nv, second) for i in (0, 1))
         for j, xk in enumerate(pos)]
    like = V[0][0]
    const = lambda v: constant_like(np.asarray(v, dtype=float), like)  # noqa: E731
    # 1. the slave normal field
    nrm = element_normals(V[:ns], cs, P.slots.wp[e], P.slots.wn[e], P.slots.mirrored_of(e))
    Pc, Qc = element_polynomial(V[:k], cs), element_polynomial(nrm, cs)
    R = element_polynomial(V[ns:ns + km], cm)
    # 2, 3. end points of the mortar segments: the master vertices projected onto e
    lo, hi = _end_points(sg, sl, Pc, Qc, V[ns:ns + 2], const)
    # 6. multiplier functions (dual: on the projectable part of e)
    T = P.T[e] if P.merged_any[e].any() else None
    A = None
    if biorth:
        part = _projectable_part(sg.elem_xi[e], (lo_node, hi_node), Pc, Qc,
                                 V[ns + km:ns + km + 2] if partial else None, const)
        A = dual_coefficients(Pc, *part, cs, T, P.n_gauss_element, P.measure, biorth)
    # 4. Gauss points on the mortar segments, 5. their projections onto the master
    eta_r, w = P.rule
    xi, half = _segment_points(lo, hi, eta_r)
    PE, QE, RE = _expand(Pc), _expand(Qc), _expand(R)
    X = curve(PE, xi)
    Nn = curve(QE, xi)
    dG = _jacobian(PE, xi) * half * w
    if not P.measure.unit:
        dG = dG * P.measure.weight(X)
    Rv = [None if r is None else (value(r[0]), value(r[1])) for r in RE]
    eta0, _ = project_on_master(Rv, (value(X[0]), value(X[1])), (value(Nn[0]), value(Nn[1])))
    eta0 = np.nan_to_num(eta0)
    eta = project_on_master_jet(RE, X, Nn, eta0)
    xm_g = curve(RE, eta)
    nl2 = Nn[0] * Nn[0] + Nn[1] * Nn[1]
    nl = nl2.sqrt() if isinstance(nl2, Jet) else np.sqrt(nl2)
    gn = ((xm_g[0] - X[0]) * Nn[0] + (xm_g[1] - X[1]) * Nn[1]) / nl
    f = gn * dG                                       # g_n dGamma
    if tangential:                                    # tau_A . (x_m - x_s) dGamma per node
        dx, dy = xm_g[0] - X[0], xm_g[1] - X[1]
        f = [(dx * at_gauss(nrm[a][1]) - dy * at_gauss(nrm[a][0])) * dG for a in range(k)]
    # 6. Phi_A at the Gauss points
    Nt = _modified(T, shape_values(cs, xi), k)
    if A is not None:
        Phi = []
        for a in range(k):
            acc = None
            for b in range(k):
                term = Nt[b] * at_gauss(A[a, b])
                acc = term if acc is None else acc + term
            Phi.append(acc)
    else:
        Phi = Nt
    # 7. g_A (first order) and sum_A lam_A g_A (second order)
    if tangential:
        g, q = _tangential_rows(Phi, f, lam, P.seg_s[e], second)
    else:
        f1 = f.first() if isinstance(f, Jet) else f
        g = [((ph.first() if isinstance(ph, Jet) else ph) * f1).sum(1) for ph in Phi]
        q = None
        if second and lam is not None:
            lam_e = lam[P.seg_s[e]]                       # (n, k)
            phl = None
            for a in range(k):
                term = Phi[a] * at_gauss(lam_e[:, a])
                phl = term if phl is None else phl + term
            q = (phl * f).sum(1)
    # values: D_AB = int Phi_A N_B dGamma, M_AC = int Phi_A N_C dGamma
    xv, dGv = value(xi), value(dG)
    Nb = shape_values(cs, xv)
    Nc = shape_values(cm, value(eta))
    ph_v = [value(ph) * dGv for ph in Phi]
    D = np.stack([np.stack([(p * N).sum(1) for N in Nb], 1) for p in ph_v], 1)
    M = np.stack([np.stack([(p * N).sum(1) for N in Nc], 1) for p in ph_v], 1)
    return _Block(g=g, q=q, D=D, M=M)


def _tangential_rows(Phi: list, f: list, lam: np.ndarray | None, rows: np.ndarray,
                     second: bool) -> tuple[list, Jet | None]:
    """``r_A = int Phi_A f_A`` (first order) and ``sum_A lam_A r_A`` (second order)
    of one block, ``f_A = tau_A . (x_m - x_s) dGamma`` at the Gauss points."""
    def first(x):
        return x.first() if isinstance(x, Jet) else x
    r = [(first(ph) * first(fa)).sum(1) for ph, fa in zip(Phi, f)]
    q = None
    if second and lam is not None:
        for a, (ph, fa) in enumerate(zip(Phi, f)):
            term = (ph * at_gauss(lam[rows[:, a]]) * fa).sum(1)
            q = term if q is None else q + term
    return r, q


def _blocks(P: _Problem, nv_on: bool, biorth: bool, second: bool):
    """Index blocks of mortar segments with their number of local variables
    (dual multipliers on partly projectable slave elements: 4 more)."""
    sg = P.sg
    if not nv_on:
        groups = [(np.arange(sg.n), 0)]
    elif biorth and not sg.frozen:
        node = sg.elem_node[sg.e_s]
        partial = (node[:, 0] >= 0) | (node[:, 1] >= 0)
        groups = [(np.flatnonzero(~partial), P.nv(False)), (np.flatnonzero(partial), P.nv(True))]
    else:
        groups = [(np.arange(sg.n), P.nv(False))]
    n_g = P.rule[0].size + (P.n_gauss_element if biorth else 0)
    for idx, nv in groups:
        chunk = max(1, _CHUNK_ENTRIES // (n_g * max(nv, 1) ** (2 if second else 1)))
        for start in range(0, idx.size, chunk):
            yield idx[start:start + chunk], nv


def _local_dofs(P: _Problem, sl: np.ndarray, nv: int) -> np.ndarray:
    """Pair dofs of the local variables of the segments ``sl`` (n, nv)."""
    sg = P.sg
    e, m = sg.e_s[sl], sg.e_m[sl]
    n_s = P.xs.shape[1]
    nodes = [2 * P.slots.nodes[e]] + [2 * n_s + 2 * P.seg_m[m]]
    if nv > P.nv(False):
        en = sg.elem_node[e]
        nodes.append(2 * n_s + 2 * np.where(en >= 0, en, P.seg_m[m, :1]))
    base = np.concatenate(nodes, axis=1)
    return (base[:, :, None] + np.arange(2)).reshape(base.shape[0], -1)[:, :nv]


def evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
             lam: np.ndarray | None = None, tangent: bool = True,
             space: "MultiplierSpace | str" = "standard", n_gauss: int = N_GAUSS, segmentation: Segmentation | None = None,
             pairs: tuple[np.ndarray, np.ndarray] | None = None, margin: float | None = None,
             crosspoints: np.ndarray | None = None, reach: float = 0.0,
             n_gauss_element: int = N_GAUSS_ELEMENT, measure: Measure = PLANE,
             **options: Any) -> ContactEval:
    """Mortar weighted gaps ``g``, ``G = dg/dx`` and ``H = sum_A lam_A d^2 g_A/dx^2``
    on curved 3-node (or 2-node) segments.

    Parameters
    ----------
    xs, xm : ndarray (2, n_s), (2, n_m)
        Current slave and master node coordinates (all surface nodes: vertices and mids).
    seg_s, seg_m : int ndarray (n, 3) or (n, 2)
        Slave and master segments, columns (start, end[, mid]), outward
        right-hand normals from start to end.
    lam : ndarray (n_s,), optional
        Multipliers; with ``tangent`` the Hessian ``H`` is returned.
    tangent : bool
        Compute ``G`` (and ``H`` if ``lam``).
    space : MultiplierSpace or str
        The multiplier space (:func:`~skfem_mortar.contact.mortar.biorthogonal`):
        ``"standard"`` (``Phi_A = N_A``) or a biorthogonal one (``"dual"``,
        :func:`dual_coefficients`).
    n_gauss : int in [1, 10]
        Gauss points per mortar segment (default :data:`N_GAUSS`, module doc).
    segmentation : Segmentation, optional
        Reuse these mortar segments (:func:`segment`); frozen (policy ``step``):
        the pair list, the end points ``xi_a, xi_b`` and the projectable parts
        are held fixed, and ``G``, ``H`` are the exact derivatives of that
        frozen ``g`` (the normals, the slave Jacobian, the dual coefficients'
        Jacobian and the Gauss-point projections still move).
    pairs, margin, reach
        Candidate pairs and the search margin, as :func:`skfem_mortar.contact.mortar.evaluate`.
    crosspoints : int array, optional
        Slave nodes without a multiplier (pinned); their shape functions are
        merged into their elements' other nodes (:func:`merge_matrix`).
    n_gauss_element : int in [1, 10]
        Points of the element rule of the dual basis and the tributary weights.
    measure : Measure
        The weight ``w(x)`` of ``dGamma`` (:mod:`~skfem_mortar.contact.measures`,
        default plane ``w = 1``): every integral (``g``, ``D``, ``M``, the supports,
        the dual basis) is taken in ``w(x_s) dGamma``, with its derivatives.  A
        measure with an axis (axisymmetric) makes the slave nodes on it take the
        mirror normal, axial (:func:`~skfem_mortar.contact.normals.mirror_of_axis`).
    **options
        ``cells``: the (slave, master) cell types, ``line2`` or ``line3`` (default:
        the lines of the connectivities' columns,
        :func:`~skfem_mortar.contact.segmentation.line_cells`).

    Returns
    -------
    ContactEval
        ``area`` is the mortar support ``int N_A dGamma``, ``mask`` the nodes whose
        support is above ``MASK_TOL`` of their tributary weight (and not
        crosspoints); ``info`` holds ``D`` (n_s, n_s), ``M`` (n_s, n_m) csr
        (``int Phi_A N_B dGamma``, ``int Phi_A N_C dGamma``), ``segmentation``
        and ``n_segments``.
    """
    return _evaluate(xs, seg_s, xm, seg_m, lam, tangent, space, n_gauss, segmentation, pairs,
                     margin, crosspoints, reach, n_gauss_element, options, False, "evaluate",
                     measure)


def tangential_evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
                        lam: np.ndarray | None = None, tangent: bool = True,
                        space: "MultiplierSpace | str" = "standard", n_gauss: int = N_GAUSS, segmentation: Segmentation | None = None,
                        pairs: tuple[np.ndarray, np.ndarray] | None = None,
                        margin: float | None = None, crosspoints: np.ndarray | None = None,
                        reach: float = 0.0, n_gauss_element: int = N_GAUSS_ELEMENT,
                        measure: Measure = PLANE, **options: Any) -> ContactEval:
    """The tangential offsets ``r_A = dot(tau_A, sum_C M_AC x_C - sum_B D_AB x_B)``,
    ``G = dr/dx`` and ``H = sum_A lam_A d^2 r_A/dx^2`` on curved segments, exact.

    The curved counterpart of :func:`skfem_mortar.contact.mortar.tangential_evaluate`
    (the configuration-dependent part of the objective slip of
    :func:`skfem_mortar.contact.slip.mortar_slip`): the same mortar segments,
    multiplier functions, Gauss points and mask as :func:`evaluate` (same
    parameters; ``lam`` the tangential multipliers), with the integrand
    ``Phi_A tau_A . (x_m(eta) - x_s(xi)) dGamma`` instead of ``Phi_A g_n dGamma``;
    ``tau_A = (n_y, -n_x)`` is the nodal normal of step 1 turned by -90 degrees,
    a jet of the element's slot nodes like the normal field.  Summed over the
    mortar segments this is ``tau_A . (M x_m - D x_s)`` with the ``D``, ``M`` of
    the same rule, exactly.

    Returns
    -------
    ContactEval
        ``g`` holds ``r_A``; ``info`` the current ``D``, ``M``, ``tangent``
        (2, n_s) the values ``tau_A``, ``segmentation`` and ``n_segments``.
    """
    return _evaluate(xs, seg_s, xm, seg_m, lam, tangent, space, n_gauss, segmentation, pairs,
                     margin, crosspoints, reach, n_gauss_element, options, True,
                     "tangential_evaluate", measure)


def _dual_space(space: "MultiplierSpace | str") -> DualSpace:
    """The biorthogonal space object that gives ``A_e`` (:func:`dual_coefficients`)."""
    s = space if isinstance(space, MultiplierSpace) else make_space(space)
    return s if callable(getattr(s, "cell_coefficients", None)) else _DUAL


def _evaluate(xs, seg_s, xm, seg_m, lam, tangent, space, n_gauss, segmentation, pairs, margin,
              crosspoints, reach, n_gauss_element, options, tangential, name,
              measure: Measure = PLANE) -> ContactEval:
    """:func:`evaluate` (``tangential`` False) or :func:`tangential_evaluate`."""
    options = dict(options)
    cells = options.pop("cells", None)
    if options:
        raise TypeError(f"unknown options for mortar_quadratic.{name}: {sorted(options)}")
    _check_rule("n_gauss", n_gauss)
    _check_rule("n_gauss_element", n_gauss_element)
    P = _prepare(xs, seg_s, xm, seg_m, segmentation, pairs, margin, reach, crosspoints,
                 n_gauss, n_gauss_element, cells, measure)
    n_s, n_m = P.xs.shape[1], P.xm.shape[1]
    k = P.slots.k
    ndof = 2 * n_s + 2 * n_m
    second = tangent and lam is not None
    lamv = None if lam is None else np.asarray(lam, dtype=float)
    g = np.zeros(n_s)
    Gt, Ht, Dt, Mt = Triplets(), Triplets(), Triplets(), Triplets()
    bi = _dual_space(space) if biorthogonal(space) else None
    for sl, nv in _blocks(P, tangent, bi, second):
        if sl.size == 0:
            continue
        blk = _block(P, sl, nv, second, bi, lamv, tangential)
        rows = P.seg_s[P.sg.e_s[sl]]                   # (n, k)
        for a in range(k):
            np.add.at(g, rows[:, a], value(blk.g[a]))
        Dt.outer(rows, rows, blk.D)
        Mt.outer(rows, P.seg_m[P.sg.e_m[sl]], blk.M)
        if tangent:
            dl = _local_dofs(P, sl, nv)
            for a in range(k):
                Gt.rows(rows[:, a], dl, blk.g[a].g.T)
            if second:
                Ht.block(dl, blk.q.hessian())
    G = Gt.csr((n_s, ndof)) if tangent else None
    H = Ht.csr((ndof, ndof)) if second else None
    D, M = Dt.csr((n_s, n_s)), Mt.csr((n_s, n_m))
    info = {"D": D, "M": M, "segmentation": P.sg, "n_segments": P.sg.n}
    if tangential:
        nrm = nodal_normals(P.xs, P.seg_s, P.cells[0], mirror_of_axis(P.measure.axis))
        info["tangent"] = np.stack([nrm[1], -nrm[0]])
    return ContactEval(g=g, G=G, H=H, area=P.area, mask=P.mask, info=info)
