"""Mortar contact kernel in 2D: weighted gaps, their exact first and second derivatives.

Frictionless mortar contact of linear 2-node surface elements.  A slave node A
carries a multiplier ``lam_A`` with the shape function ``Phi_A`` (standard:
``Phi_A = N_A``; dual: biorthogonal to ``N_A``); the slave surface is
``x_s = sum_B N_B x_B`` and the master surface ``x_m = sum_C N_C x_C``.  The
contact work is ``sum_A lam_A g_A`` with the weighted gap

    g_A = - sum_B n_AB . x_B + sum_C n_AC . x_C                      (weighted_gap)
        = int_Gc Phi_A(xi1) (x_m(xi2) - x_s(xi1)) . n(xi1) dGamma,

    n_AB = int_Gc Phi_A(xi1) N_B(xi1) n dGamma,   D_AB = int_Gc Phi_A(xi1) N_B(xi1) dGamma,
    n_AC = int_Gc Phi_A(xi1) N_C(xi2) n dGamma,   M_AC = int_Gc Phi_A(xi1) N_C(xi2) dGamma,

with ``n = n~ / |n~|``, ``n~(xi1) = N_1 n_a + N_2 n_b`` the interpolated
averaged nodal normal of the slave surface (outward from the slave body), so
``g > 0`` is open.  ``n_AB = D_AB n`` and ``n_AC = M_AC n`` only where ``n`` is
constant along the element (a flat slave surface).

The algorithm, one function per step, each vectorized over mortar segments
and Gauss points and each working on plain arrays and on jets:

1. slave normal field: :func:`nodal_normals`, :func:`slave_element`
   (``n_A = normalize(nu_prev + nu_next)``, ``n~(xi) = N_1 n_a + N_2 n_b``);
2. projections along it: :func:`project_on_slave` (master nodes onto slave
   elements), :func:`project_on_master` (slave Gauss points onto master elements);
3. segmentation: :func:`segment` (which slave/master element pairs overlap and
   where) and :func:`segment_end_points` (``xi_a, xi_b`` of each mortar segment);
4. the Gauss rule on ``eta in [-1, 1]`` mapped onto each segment:
   :func:`gauss_rule`, :func:`segment_quadrature`
   (``xi1 = (1 - eta)/2 xi_a + (1 + eta)/2 xi_b``,
   ``dGamma = |x_b - x_a|/2 (xi_b - xi_a)/2 w_k``);
5. multiplier shape functions ``Phi_A = sum_B c_AB N_B``:
   :func:`multiplier_coefficients` (identity, or dual ``A_e = D_e M_e^-1``
   from :func:`dual_coefficients`; crosspoints merged);
6. the mortar integrals ``n_AB, n_AC, D_AB, M_AC``: :func:`mortar_integrals`;
7. the weighted gap from them by the identity above: :func:`weighted_gap`;
8. its exact derivatives ``G = dg/dx``, ``H = sum_A lam_A d^2 g_A/dx^2``:
   :func:`gap_jets`.

Step 8 differentiates the equivalent one-integrand form
``int Phi_A g_n dGamma`` with ``g_n = (x_m - x_s) . n = alpha |n~|``
(:class:`MasterProjection`: ``x_s + alpha n~`` is on the master line), which
equals the identity Gauss point by Gauss point.  Every segment contribution is
a composition of the steps above in the local node coordinates (4 slave nodes:
previous, a, b, next, because the nodal normals of a and b involve the
neighbouring segments; the 2 master nodes; for dual multipliers also the 2
master nodes bounding the projectable part of the slave element), evaluated in
forward-mode jets (:class:`~skfem_mortar.contact.jets.Jet`), so ``G`` and ``H`` are exact,
including the derivatives of the nodal normals, the segment end points, the
slave Jacobian, the Gauss point projections and the dual coefficients.

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

from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp

from .contact_eval import ContactEval
from .multiplier_spaces import MultiplierSpace, make_space
from .cells import cell_type
from .measures import PLANE, Measure
from .normals import mirror_of_axis
from .mortar_support import multiplier_support, tributary_weights
from .scatter import Triplets
from .jets import Jet, at_gauss, constant_like, sqrt, value, where
from .segmentation import Segmentation, check_kernel_cells, line_cells
from .mortar_segmentation import (nodal_normals,
                                  normal_length, project_on_master, project_on_slave,
                                  segment, segment_end_points, slave_element)

__all__ = ["evaluate", "segment", "Segmentation", "dual_coefficients", "MASK_TOL",
           "nodal_normals", "slave_element", "project_on_slave", "project_on_master",
           "segment_end_points", "gauss_rule", "Quadrature", "segment_quadrature",
           "multiplier_coefficients", "biorthogonal", "multiplier_shape_functions", "MortarIntegrals",
           "mortar_integrals", "weighted_gap", "gap_jets", "assemble_local",
           "integrals", "SurfaceIntegrals"]

MASK_TOL = 1e-6
"""Slave nodes whose mortar support is below this fraction of their tributary length
are masked out and merged into their neighbours like crosspoints (see
:func:`evaluate`, Notes)."""
_CHUNK_ENTRIES = 200_000  # Hessian entries per block of segments: 1.6 MB arrays stay in cache


# ------------------------------------------------------------ step 4: Gauss rule
def gauss_rule(n_gauss: int) -> tuple[np.ndarray, np.ndarray]:
    """Step 4: the Gauss-Legendre points ``eta_k`` and weights ``w_k`` on [-1, 1].

    ``sum_k w_k p(eta_k) = int_{-1}^{1} p(eta) d eta`` exactly for polynomials
    of degree ``2 n_gauss - 1``.  Computed once per ``n_gauss`` (numpy's
    ``leggauss`` solves an eigenproblem: a fixed cost of every kernel call);
    the arrays are read-only.
    """
    rule = _GAUSS.get(n_gauss)
    if rule is None:
        rule = np.polynomial.legendre.leggauss(n_gauss)
        for a in rule:
            a.flags.writeable = False
        rule = _GAUSS[n_gauss] = (rule[0], rule[1])
    return rule


_GAUSS: dict[int, tuple[np.ndarray, np.ndarray]] = {}


class Quadrature(NamedTuple):
    """Step 4: the Gauss points of mortar segments, ``dGamma_k = jac * w_k``.

    Attributes
    ----------
    xi : ndarray or Jet (n, n_gauss)
        Slave parameter ``xi1(eta_k) = (1 - eta_k)/2 xi_a + (1 + eta_k)/2 xi_b``.
    jac : ndarray or Jet (n,)
        ``|x_b - x_a| / 2 * (xi_b - xi_a) / 2``: the slave Jacobian ``dGamma/dxi``
        times ``dxi/deta`` (constant along a segment of a linear element).
    w : ndarray (n_gauss,)
        The weights ``w_k``.
    mw : ndarray or Jet (n, n_gauss) or None
        The measure's weight ``w(x_s(xi1_k))`` at the Gauss points
        (:mod:`~skfem_mortar.contact.measures`); None: 1 (plane, no product).
    """

    xi: Any
    jac: Any
    w: np.ndarray
    mw: Any = None

    def dgamma(self, f):
        """``f dGamma`` at the Gauss points: ``f * jac * w_k`` (times ``mw``)."""
        out = f * at_gauss(self.jac) * self.w
        return out if self.mw is None else out * self.mw

    def weights(self) -> np.ndarray:
        """The values ``dGamma_k = jac w_k`` (times ``mw``) (n, n_gauss)."""
        out = value(self.jac)[:, None] * self.w
        return out if self.mw is None else out * value(self.mw)


def segment_quadrature(el, xi_a, xi_b, eta: np.ndarray, w: np.ndarray,
                       measure: Measure = PLANE) -> Quadrature:
    """Step 4: the Gauss rule ``(eta, w)`` mapped onto the mortar segments ``[xi_a, xi_b]``.

    ``xi1 = (1 - eta)/2 xi_a + (1 + eta)/2 xi_b`` and
    ``dGamma = |x_b - x_a| / 2 * (xi_b - xi_a) / 2 * w`` with ``|x_b - x_a| / 2 = |dx|``
    of the slave element ``el`` (:class:`~skfem_mortar.contact.mortar_segmentation.SlaveElement`),
    times the measure's weight ``w(x_s(xi1))``, ``x_s = x0 + xi1 dx`` (unless
    ``measure.unit``).
    """
    d1x, d1y = el.dx
    jac = sqrt(d1x * d1x + d1y * d1y) * ((xi_b - xi_a) * 0.5)
    xi = at_gauss(xi_a) * ((1.0 - eta) * 0.5) + at_gauss(xi_b) * ((1.0 + eta) * 0.5)
    mw = None
    if not measure.unit:
        mw = measure.weight(tuple(at_gauss(c) + at_gauss(d) * xi for c, d in zip(el.x0, el.dx)))
    return Quadrature(xi=xi, jac=jac, w=w, mw=mw)


# ------------------------------------------------ step 5: multiplier shape functions
def dual_coefficients(lo, hi, weights=None):
    """Step 5: dual shape function coefficients ``A_e = D_e M_e^{-1}`` on the projectable part.

    With ``D_e = diag(int N_A)`` and ``M_e = int N_A N_B`` over ``xi in [lo, hi]``
    (the slave Jacobian cancels), ``Phi_A = sum_B A_AB N_B`` satisfies
    ``int Phi_A N_B = delta_AB int N_A`` on that part (Popp et al. 2013).  On the
    full element ``A = [[2, -1], [-1, 2]]``.  Works on arrays and on jets.

    ``weights = (w_a, w_b)``: the measure's weight at the element's nodes
    (:mod:`~skfem_mortar.contact.measures`, linear in ``x``, so
    ``w(xi) = N_1 w_a + N_2 w_b`` on the element); then ``D_e = diag(int N_A w)``,
    ``M_e = int N_A N_B w`` (:func:`_weighted_dual`), biorthogonal in ``w dGamma``.

    Returns
    -------
    (a11, a12, a21, a22)
    """
    if weights is not None:
        return _weighted_dual(lo, hi, *weights)

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


def _weighted_dual(lo, hi, wa, wb):
    """:func:`dual_coefficients` in ``w dGamma`` with ``w = N_1 w_a + N_2 w_b``: the
    integrands are cubic in ``xi``, so the 2-point Gauss rule on ``[lo, hi]`` is exact
    (the constant Jacobian and ``(hi - lo)/2`` cancel in ``D_e M_e^{-1}``)."""
    eta, w = gauss_rule(2)
    xi = at_gauss(lo) * ((1.0 - eta) * 0.5) + at_gauss(hi) * ((1.0 + eta) * 0.5)
    n1, n2 = (1.0 - xi) * 0.5, (1.0 + xi) * 0.5
    ww = (at_gauss(wa) * n1 + at_gauss(wb) * n2) * w
    d1, d2 = (n1 * ww).sum(1), (n2 * ww).sum(1)
    m11, m12, m22 = (n1 * n1 * ww).sum(1), (n1 * n2 * ww).sum(1), (n2 * n2 * ww).sum(1)
    det = m11 * m22 - m12 * m12
    det_inv = det.inv() if isinstance(det, Jet) else 1.0 / det
    return (d1 * m22 * det_inv, -(d1 * m12) * det_inv,
            -(d2 * m12) * det_inv, d2 * m11 * det_inv)


def biorthogonal(space: "MultiplierSpace | str" = "standard") -> bool:
    """Step 5: whether the multiplier space ``space`` builds ``Phi_A`` from each slave
    cell's ``D_e``, ``M_e``.

    ``space`` is a :class:`~skfem_mortar.contact.multiplier_spaces.MultiplierSpace` or
    a registered name.  A space with ``coefficients(D_e, M_e)`` (``A_e = D_e M_e^-1``,
    biorthogonal: ``int Phi_A N_B = delta_AB int N_A``) gets the coefficients of
    :func:`dual_coefficients` on the projectable part of each cell, differentiated;
    any other traction space ``Phi_A = N_A``.

    Raises
    ------
    ValueError
        When ``space`` is not a registered name or its ``kind`` is not ``"traction"``.
    """
    s = space if isinstance(space, MultiplierSpace) else make_space(space)
    if s.kind != "traction":
        raise ValueError(f"space must be a traction multiplier space for the mortar kernels, "
                         f"got {s.name!r} (kind {s.kind!r})")
    return callable(getattr(s, "coefficients", None))


def multiplier_coefficients(like, biorthogonal: bool = False, part=None, merged=None,
                            weights=None) -> list:
    """Step 5: coefficients ``c`` of ``Phi_a = c11 N1 + c12 N2``, ``Phi_b = c21 N1 + c22 N2``.

    Standard multipliers: ``c = I`` (``Phi_A = N_A``).  Dual: ``c = A_e``
    (:func:`dual_coefficients`) on the projectable part ``part = (l, h)`` of
    the slave element.  ``merged = (merged_a, merged_b)`` (bool arrays): a
    crosspoint or masked node is merged into its neighbour: its ``Phi = 0`` and
    the neighbour's ``Phi = 1`` on that element.  ``weights``: the measure's nodal
    weights of :func:`dual_coefficients` (None: plane).  ``like`` (an array or jet of
    shape (n,)) sets the kind and the length of the result.

    Returns
    -------
    [c11, c12, c21, c22]
    """
    n = value(like).shape[0]
    one, zero = constant_like(np.ones(n), like), constant_like(np.zeros(n), like)
    c = list(dual_coefficients(*part, weights)) if biorthogonal else [one, zero, zero, one]
    if merged is not None:
        cpa, cpb = merged
        if cpa.any() or cpb.any():
            c[0] = where(cpa, zero, where(cpb, one, c[0]))
            c[1] = where(cpa, zero, where(cpb, one, c[1]))
            c[2] = where(cpb, zero, where(cpa, one, c[2]))
            c[3] = where(cpb, zero, where(cpa, one, c[3]))
    return c


def multiplier_shape_functions(c) -> tuple:
    """Step 5: ``Phi_A = K0_A + K1_A xi`` from the coefficients ``c``.

    ``K0_a = (c11 + c12)/2``, ``K1_a = (c12 - c11)/2`` and likewise for ``b``
    (``N_1 = (1 - xi)/2``, ``N_2 = (1 + xi)/2``).

    Returns
    -------
    (K0_a, K1_a, K0_b, K1_b), each of the kind of ``c``, shape (n,).
    """
    return (c[0] + c[1]) * 0.5, (c[1] - c[0]) * 0.5, (c[2] + c[3]) * 0.5, (c[3] - c[2]) * 0.5


# ------------------------------------------------------- step 6: mortar integrals
class MortarIntegrals(NamedTuple):
    """Step 6: the mortar integrals of each mortar segment (values).

    Local nodes: ``A, B`` in ``(a, b)`` (the slave element), ``C`` in
    ``(m1, m2)`` (the master element); the last axis of ``n_AB, n_AC`` is the
    vector component.

    Attributes
    ----------
    n_AB, n_AC : ndarray (n, 2, 2, 2) or None
        ``int Phi_A N_B n dGamma``, ``int Phi_A N_C n dGamma``.
    D, M : ndarray (n, 2, 2)
        ``int Phi_A N_B dGamma``, ``int Phi_A N_C dGamma``.
    area : ndarray (n, 2)
        ``int N_A dGamma`` (the mortar support of the slave node).
    """

    n_AB: np.ndarray
    n_AC: np.ndarray
    D: np.ndarray
    M: np.ndarray
    area: np.ndarray


def mortar_integrals(K, xi: np.ndarray, s: np.ndarray, dgamma: np.ndarray, normal=None
                     ) -> MortarIntegrals:
    """Step 6: ``n_AB, n_AC, D_AB, M_AC`` by the Gauss rule on each mortar segment.

    ``D_AB = sum_k Phi_A N_B(xi1_k) dGamma_k``,
    ``M_AC = sum_k Phi_A N_C(xi2_k) dGamma_k``,
    ``n_AB = sum_k Phi_A N_B(xi1_k) n_k dGamma_k``,
    ``n_AC = sum_k Phi_A N_C(xi2_k) n_k dGamma_k``, with ``N_B = ((1 - xi1)/2,
    (1 + xi1)/2)``, ``N_C = (1 - s, s)`` at the projected master point and ``n``
    the unit normal ``n~ / |n~|``.

    Parameters
    ----------
    K : (K0_a, K1_a, K0_b, K1_b)
        Multiplier shape functions (:func:`multiplier_shape_functions`), values (n,).
    xi, s : ndarray (n, n_gauss)
        Slave parameter and master parameter of the Gauss points.
    dgamma : ndarray (n, n_gauss)
        ``dGamma_k`` (:meth:`Quadrature.weights`).
    normal : (nx, ny), ndarrays (n, n_gauss), optional
        Unit normal at the Gauss points; without it ``n_AB``, ``n_AC`` are None
        (:func:`evaluate` needs only ``D``, ``M`` and the supports).
    """
    ka0, ka1, kb0, kb1 = (value(k)[:, None] for k in K)
    n1, n2 = (1.0 - xi) * 0.5, (1.0 + xi) * 0.5
    phi = (ka0 + ka1 * xi, kb0 + kb1 * xi)
    wB = np.stack([np.stack([p * n1 * dgamma, p * n2 * dgamma], 1) for p in phi], 1)
    wC = np.stack([np.stack([p * (1 - s) * dgamma, p * s * dgamma], 1) for p in phi], 1)
    n_AB = n_AC = None
    if normal is not None:
        nvec = np.stack(normal, -1)                                # (n, n_gauss, 2)
        n_AB = np.einsum("nabk,nki->nabi", wB, nvec)
        n_AC = np.einsum("nack,nki->naci", wC, nvec)
    return MortarIntegrals(n_AB=n_AB, n_AC=n_AC, D=wB.sum(-1), M=wC.sum(-1),
                           area=np.stack([(n1 * dgamma).sum(1), (n2 * dgamma).sum(1)], 1))


# --------------------------------------------------------- step 7: weighted gap
def weighted_gap(n_AB: np.ndarray, n_AC: np.ndarray, x_B: np.ndarray, x_C: np.ndarray
                 ) -> np.ndarray:
    """Step 7: the weighted gap of each slave node.

    ``g_A = - sum_B n_AB . x_B + sum_C n_AC . x_C``.

    Parameters
    ----------
    n_AB, n_AC : ndarray (..., nA, nB, 2), (..., nA, nC, 2)
        The vector mortar integrals (:func:`mortar_integrals`, per segment, or
        assembled).
    x_B, x_C : ndarray (..., nB, 2), (..., nC, 2)
        Slave and master node coordinates.

    Returns
    -------
    g : ndarray (..., nA)
    """
    return (np.einsum("...abi,...bi->...a", n_AC, x_C)
            - np.einsum("...abi,...bi->...a", n_AB, x_B))


# ------------------------------------------------------- step 8: exact derivatives
def gap_jets(K, gn: Jet, quad: Quadrature, lam_ab=None):
    """Step 8: jets of ``g_A = int Phi_A g_n dGamma`` over each mortar segment.

    ``g_n = (x_m - x_s) . n = alpha |n~|`` at the Gauss points (steps 2 and 4),
    ``Phi_A = K0_A + K1_A xi1`` (step 5): by the identity of step 7 the same
    ``g_A``, written as one integrand so that its derivatives need no product
    rule over ``n_AB``, ``n_AC``.

    Returns
    -------
    g_a, g_b : Jet (n,), first order (the rows of ``G``).
    q : Jet (n,) or None
        ``lam_a g_a + lam_b g_b`` to second order (``H``), when ``lam_ab`` is given.
    """
    E = at_gauss
    ka0, ka1, kb0, kb1 = K
    f = quad.dgamma(gn)                              # g_n dGamma
    f1, x1 = f.first(), quad.xi.first()              # first derivatives suffice for G
    ga = ((E(ka0.first()) + E(ka1.first()) * x1) * f1).sum(1)
    gb = ((E(kb0.first()) + E(kb1.first()) * x1) * f1).sum(1)
    q = None
    if lam_ab is not None:                           # sum_A lam_A g_A with its Hessian
        la, lb = lam_ab
        q = ((E(ka0 * la + kb0 * lb) + E(ka1 * la + kb1 * lb) * quad.xi) * f).sum(1)
    return ga, gb, q


# -------------------------------------------------------------- one block of segments
class _Local(NamedTuple):
    """Nodes of each mortar segment: slave p, a, b, n; master m1, m2; lo, hi
    (the master nodes bounding the projectable part of the slave element, -1 for a slave end)."""

    p: np.ndarray
    a: np.ndarray
    b: np.ndarray
    n: np.ndarray
    m1: np.ndarray
    m2: np.ndarray
    lo: np.ndarray
    hi: np.ndarray

    @staticmethod
    def of(sg: Segmentation, seg_s, seg_m, pnode, nnode) -> "_Local":
        e, m = sg.e_s, sg.e_m
        a, b = seg_s[e, 0], seg_s[e, 1]
        return _Local(pnode[a], a, b, nnode[b], seg_m[m, 0], seg_m[m, 1],
                      sg.elem_node[e, 0], sg.elem_node[e, 1])

    def take(self, sl) -> "_Local":
        return _Local(*(q[sl] for q in self))


def _embed(j: Jet, idx: np.ndarray, offset: int, nv: int, second: bool = True) -> Jet:
    """Entries ``idx`` of a 6-variable node jet, placed at variables ``offset..offset+5``
    (without its Hessian unless ``second``)."""
    v = j.v[idx]
    if nv == 0:
        return Jet(v, np.zeros((0, v.size)), None)
    g = np.zeros((nv, v.size))
    g[offset:offset + 6] = j.g[:, idx]
    h = None
    if second and j.h is not None:
        h = np.zeros((nv, nv, v.size))
        h[offset:offset + 6, offset:offset + 6] = j.h[:, :, idx]
    return Jet(v, g, h)


class _Block(NamedTuple):
    """What one block of mortar segments contributes."""

    ints: MortarIntegrals          # step 6
    g: np.ndarray | None           # (n, 2) weighted gaps of the nodes a, b by step 7 (vector)
    ga: Jet                        # step 8: weighted gaps of a, b (first order) ...
    gb: Jet
    q: Jet | None                  # ... and lam_a g_a + lam_b g_b to second order


class _Fields(NamedTuple):
    """Steps 1 to 5 on a block of mortar segments (jets): what steps 6 to 8 integrate."""

    na: tuple                      # nodal normals of a and b (jets)
    nb: tuple
    el: Any                        # SlaveElement
    K: tuple                       # multiplier shape functions
    quad: Quadrature               # Gauss points
    proj: Any                      # MasterProjection of the Gauss points


def _segment_fields(xs, xm, loc: _Local, sg: Segmentation, sl, nv: int, second: bool,
                    biorth: bool, merged: np.ndarray, rule, nrm,
                    measure: Measure = PLANE) -> _Fields:
    """Steps 1 to 5 (and the projections of step 2) on the mortar segments ``sl``
    in jets of ``nv`` local variables (see :func:`_block`), every integral in the
    measure's ``w(x) dGamma``."""
    p, a, b, n, m1, m2, lo_node, hi_node = loc
    e = sg.e_s[sl]
    pos = [xs[:, p], xs[:, a], xs[:, b], xs[:, n], xm[:, m1], xm[:, m2]]
    if nv > 12:
        pos += [xm[:, np.maximum(lo_node, 0)], xm[:, np.maximum(hi_node, 0)]]
    V = [tuple(Jet.variable(xk[i], 2 * k + i, nv, second) if 2 * k + 1 < nv
               else Jet.constant(xk[i], nv, second) for i in (0, 1))
         for k, xk in enumerate(pos)]
    Xa, Xb, M1, M2 = V[1], V[2], V[4], V[5]
    # 1. nodal normals: node jets in (prev, node, next) placed at slots (p, a, b) / (a, b, n)
    na = (_embed(nrm[0], a, 0, nv, second), _embed(nrm[1], a, 0, nv, second))
    nb = (_embed(nrm[0], b, 2, nv, second), _embed(nrm[1], b, 2, nv, second))
    el = slave_element(Xa, Xb, na, nb)
    const = lambda v: constant_like(v, Xa[0])  # noqa: E731
    # 2, 3. segment end points on the slave element (master nodes projected onto it)
    if sg.frozen:
        lo, hi = const(sg.xi[sl, 0]), const(sg.xi[sl, 1])
    else:
        lo, hi = segment_end_points(el, M1, M2, sg.src[sl])
    # 5. multiplier shape functions (dual: on the projectable part [l, h] of the element)
    part = None
    if biorth:
        exi = sg.elem_xi[e]
        if sg.frozen or nv <= 12:
            part = const(exi[:, 0]), const(exi[:, 1])
        else:
            part = (where(lo_node >= 0, project_on_slave(el, V[6])[0], const(-np.ones(e.size))),
                    where(hi_node >= 0, project_on_slave(el, V[7])[0], const(np.ones(e.size))))
    wab = None if measure.unit or not biorth else (measure.weight(Xa), measure.weight(Xb))
    K = multiplier_shape_functions(multiplier_coefficients(Xa[0], biorth, part, merged[sl].T,
                                                           wab))
    # 4. Gauss points; 2. their projections onto the master element
    quad = segment_quadrature(el, lo, hi, *rule, measure)
    proj = project_on_master(el, M1, M2)
    return _Fields(na=na, nb=nb, el=el, K=K, quad=quad, proj=proj)


def _block(xs, xm, loc: _Local, sg: Segmentation, sl, nv: int, second: bool, biorth: bool,
           merged: np.ndarray, rule, nrm, lam_ab=None, vector: bool = False,
           measure: Measure = PLANE) -> _Block:
    """Steps 1 to 8 on the mortar segments ``sl`` in jets of ``nv`` local variables.

    Local variables: ``x`` and ``y`` of the slave nodes p, a, b, n, the master
    nodes m1, m2 and (``nv = 16``) the two master nodes bounding the projectable
    part of the slave element; ``nv = 0``: values only.  ``vector``: also the
    vector integrals ``n_AB``, ``n_AC`` and the weighted gaps from them (step 7).
    ``measure``: the weight ``w(x)`` of every ``dGamma``.
    """
    _, a, b, _, m1, m2, _, _ = loc
    f = _segment_fields(xs, xm, loc, sg, sl, nv, second, biorth, merged, rule, nrm, measure)
    el, K, quad, proj = f.el, f.K, f.quad, f.proj
    # 8. g_n = alpha |n~| = (x_m - x_s) . n and the weighted gaps with their derivatives
    gn = proj.alpha(quad.xi) * normal_length(el, quad.xi)
    ga, gb, q = gap_jets(K, gn, quad, lam_ab if second else None)
    # 6. mortar integrals (values), with the unit normal n~/|n~| at the Gauss points
    xv = quad.xi.v
    normal = None
    if vector:
        nt = tuple(value(c)[:, None] + value(d)[:, None] * xv for c, d in zip(el.n0, el.dn))
        nl = np.sqrt(nt[0] * nt[0] + nt[1] * nt[1])
        normal = (nt[0] / nl, nt[1] / nl)
    ints = mortar_integrals(K, xv, proj.s(xv), quad.weights(), normal)
    # 7. weighted gaps of the nodes a, b by the identity
    g = None
    if vector:
        g = weighted_gap(ints.n_AB, ints.n_AC, np.stack([xs[:, a].T, xs[:, b].T], 1),
                         np.stack([xm[:, m1].T, xm[:, m2].T], 1))
    return _Block(ints=ints, g=g, ga=ga, gb=gb, q=q)


# -------------------------------------------------------------------- evaluate
def _as_arrays(xs, seg_s, xm, seg_m, cells=None):
    """The coordinates and connectivities as arrays; ``cells``, when given, must be
    ``line2`` (the cells this kernel evaluates)."""
    if cells is not None:
        check_kernel_cells(line_cells(seg_s, seg_m, cells), ("line2",), "the linear mortar kernel")
    return (np.asarray(xs, dtype=float).reshape(2, -1), np.asarray(seg_s, dtype=np.int64).reshape(-1, 2),
            np.asarray(xm, dtype=float).reshape(2, -1), np.asarray(seg_m, dtype=np.int64).reshape(-1, 2))


def assemble_local(values: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                   shape: tuple[int, int]) -> sp.csr_matrix:
    """Sum per-segment 2x2 blocks ``values[k, i, j]`` into ``[rows[k, i], cols[k, j]]``.

    With vector blocks ``values[k, i, j, c]`` (``n_AB``, ``n_AC``) the column is
    ``2 cols[k, j] + c`` (the dof order ``x, y`` of each node) and the result
    has ``2 shape[1]`` columns, so that ``n_AB @ x.T.ravel() = sum_B n_AB . x_B``.
    """
    if values.ndim == 4:
        cols = (2 * cols[:, :, None] + np.arange(2)).reshape(-1, 4)
        values = values.reshape(-1, 2, 4)
        shape = (shape[0], 2 * shape[1])
    r = np.repeat(rows, values.shape[2], axis=1)
    c = np.tile(cols, (1, 2))
    return sp.coo_matrix((values.ravel(), (r.ravel(), c.ravel())), shape=shape).tocsr()


def _blocks(nseg: int, nv: int, n_gauss: int, second: bool, loc: _Local,
            hessian: np.ndarray | None = None):
    """Index blocks of mortar segments with their number of local variables and
    whether they carry second derivatives.

    Dual multipliers on partially projectable slave elements depend on the
    master nodes bounding the projectable part: 16 local variables there, 12
    elsewhere.  With ``second``, only the segments where ``hessian`` is True
    (default: all) carry second derivatives: a segment whose nodes ``a``,
    ``b`` both have ``lam = 0`` adds exactly nothing to ``H = sum_A lam_A
    d2 g_A``, and its jets without Hessians cost about a third.  Blocks bound
    the memory of the Hessian arrays; each is vectorized.
    """
    groups = [(np.arange(nseg), nv)]
    if nv == 16:
        partial = (loc.lo >= 0) | (loc.hi >= 0)
        groups = [(np.flatnonzero(~partial), 12), (np.flatnonzero(partial), 16)]
    for idx, nv_g in groups:
        parts = [(idx, second)]
        if second and hessian is not None:
            parts = [(idx[hessian[idx]], True), (idx[~hessian[idx]], False)]
        for sub, sec in parts:
            chunk = max(1, _CHUNK_ENTRIES // (n_gauss * max(nv_g, 1) ** (2 if sec else 1)))
            for start in range(0, sub.size, chunk):
                yield sub[start:start + chunk], nv_g, sec


def _cat(L, n, dtype=float, shape=(0,)):
    return np.concatenate(L) if n else np.zeros(shape, dtype=dtype)


class _Problem(NamedTuple):
    """A surface pair prepared for the blocks: segments, mask, nodal normals, local nodes."""

    xs: np.ndarray
    xm: np.ndarray
    n_s: int
    n_m: int
    sg: Segmentation
    mask: np.ndarray
    merged: np.ndarray
    nrm: tuple
    loc: _Local
    rule: tuple
    second: bool
    measure: Measure

    @staticmethod
    def of(xs, seg_s, xm, seg_m, segmentation, pairs, margin, reach, crosspoints, n_gauss,
           nodal_jets: int, second: bool, cells=None, measure: Measure = PLANE) -> "_Problem":
        xs, seg_s, xm, seg_m = _as_arrays(xs, seg_s, xm, seg_m, cells)
        n_s = xs.shape[1]
        mirror = mirror_of_axis(measure.axis)   # the axis of revolution: axial normals there
        sg = segmentation if segmentation is not None else segment(
            xs, seg_s, xm, seg_m, pairs=pairs, margin=margin, frozen=False, reach=reach,
            mirror=mirror)
        # a node supported over a sliver only is masked and merged like a crosspoint,
        # so that the multiplier functions still sum to one there (evaluate, Notes)
        cp_nodes = np.zeros(n_s, bool)
        if crosspoints is not None:
            cp_nodes[np.asarray(crosspoints, dtype=np.int64)] = True
        line2 = cell_type("line2")          # the cells of this kernel (_as_arrays)
        support = multiplier_support(xs, seg_s, sg, line2, 1, measure)  # N_A |dx/dxi|: degree 1
        trib = tributary_weights(xs, seg_s, line2, 1, measure)
        mask = (support > MASK_TOL * trib) & ~cp_nodes
        nrm, pnode, nnode = nodal_normals(xs, seg_s, second, nodal_jets, mirror)
        loc = _Local.of(sg, seg_s, seg_m, pnode, nnode)
        merged = (cp_nodes | ~mask)[np.stack([loc.a, loc.b], 1)]
        return _Problem(xs, xm, n_s, xm.shape[1], sg, mask, merged, nrm, loc,
                        gauss_rule(n_gauss), second, measure)

    def block(self, ls: _Local, sl, nv: int, biorth: bool, lam_ab, vector: bool = False,
              second: bool | None = None) -> _Block:
        return _block(self.xs, self.xm, ls, self.sg, sl, nv,
                      self.second if second is None else second, biorth, self.merged,
                      self.rule, self.nrm, lam_ab, vector, self.measure)

    def assemble(self, order: list, out: list) -> MortarIntegrals:
        """Steps 6 assembled: the blocks' integrals summed into (n_s, .) arrays and csr,
        in the order of the segments whatever the blocks (so the sums are the same
        to the last bit however the segments were blocked)."""
        n = self.sg.n
        o = _cat(order, n, np.int64)            # the segment of each block-order value
        at = np.empty_like(o)
        at[o] = np.arange(n)                    # the block-order place of each segment
        sl_nodes = np.stack([self.loc.a, self.loc.b], 1)
        ms_nodes = np.stack([self.loc.m1, self.loc.m2], 1)
        area_seg = _cat([x.area for x in out], n, shape=(0, 2))[at]
        area = np.zeros(self.n_s)
        np.add.at(area, sl_nodes[:, 0], area_seg[:, 0])
        np.add.at(area, sl_nodes[:, 1], area_seg[:, 1])

        def glob(name, cols, n_cols, shape):
            vals = [getattr(x, name) for x in out]
            if vals and vals[0] is None:
                return None
            return assemble_local(_cat(vals, n, shape=shape)[at], sl_nodes, cols,
                                  (self.n_s, n_cols))
        return MortarIntegrals(
            n_AB=glob("n_AB", sl_nodes, self.n_s, (0, 2, 2, 2)),
            n_AC=glob("n_AC", ms_nodes, self.n_m, (0, 2, 2, 2)),
            D=glob("D", sl_nodes, self.n_s, (0, 2, 2)), M=glob("M", ms_nodes, self.n_m, (0, 2, 2)),
            area=area)


def _jet_rows(P: "_Problem", tangent: bool, biorth: bool, n_gauss: int, lam, block
              ) -> tuple[np.ndarray, Any, Any, "MortarIntegrals"]:
    """Per-node rows summed over the mortar segments of ``P``, block by block.

    ``block(ls, sl, nv, lam_ab, second)`` returns a :class:`_Block` whose ``ga``,
    ``gb`` are the jets of the rows of the nodes a, b of each segment and ``q``
    (with ``second``) their ``lam``-weighted sum to second order; segments whose
    nodes a, b both have ``lam = 0`` are evaluated to first order only (their
    part of ``H`` is zero, see :func:`_blocks`).  Returns the values (n_s,), their
    first derivatives ``G`` (csr, local dofs), ``sum_A lam_A`` times their
    second derivatives ``H`` (csr, or None) and the assembled integrals.
    ``g``, ``G`` and the integrals are summed in the order of the segments,
    whatever the blocks: the same to the last bit whether or not ``H`` split
    them (a kept evaluation answers for a new one, ``Mortar.evaluate``).
    """
    n_s, sg, loc, second = P.n_s, P.sg, P.loc, P.second
    ndof = 2 * n_s + 2 * P.n_m
    nv = (16 if (biorth and not sg.frozen) else 12) if tangent else 0
    lamv = None if lam is None else np.asarray(lam, dtype=float)
    itype = np.int32 if ndof < 2**31 - 1 else np.int64   # halves the COO index memory
    # local dofs of each segment: nodes p, a, b, n (slave), m1, m2, lo, hi (master)
    nodes = [2 * loc.p, 2 * loc.a, 2 * loc.b, 2 * loc.n, 2 * n_s + 2 * loc.m1,
             2 * n_s + 2 * loc.m2, 2 * n_s + 2 * np.where(loc.lo >= 0, loc.lo, loc.m1),
             2 * n_s + 2 * np.where(loc.hi >= 0, loc.hi, loc.m1)]
    dofs = np.stack([d + k for d in nodes for k in (0, 1)], 1)[:, :nv].astype(itype)

    hessian = None if lamv is None else (lamv[loc.a] != 0.0) | (lamv[loc.b] != 0.0)
    ga, gb = np.zeros(sg.n), np.zeros(sg.n)                 # per segment, for a and b
    GA, GB = np.zeros((sg.n, nv)), np.zeros((sg.n, nv))     # their first derivatives
    nvs = np.zeros(sg.n, dtype=np.int64)                     # local variables of each
    Ht, out, order = Triplets(itype), [], []
    for sl, nv_g, sec in _blocks(sg.n, nv, n_gauss, second, loc, hessian):
        order.append(sl)
        ls = loc.take(sl)
        lam_ab = (lamv[ls.a], lamv[ls.b]) if sec and lamv is not None else None
        blk = block(ls, sl, nv_g, lam_ab, sec)
        out.append(blk.ints)
        ga[sl], gb[sl] = blk.ga.v, blk.gb.v
        if tangent:
            GA[sl, :nv_g], GB[sl, :nv_g], nvs[sl] = blk.ga.g.T, blk.gb.g.T, nv_g
            if sec:
                Ht.block(dofs[sl, :nv_g], blk.q.hessian())
    g = np.zeros(n_s)
    np.add.at(g, loc.a, ga)
    np.add.at(g, loc.b, gb)
    G = H = None
    if tangent:
        used = np.arange(nv) < nvs[:, None]                  # (n_seg, nv)
        Gt = Triplets(itype)
        Gt.rows(loc.a, dofs, GA, used)
        Gt.rows(loc.b, dofs, GB, used)
        G = Gt.csr((n_s, ndof))
        if second:  # no block with second derivatives where every lam is 0
            H = Ht.csr((ndof, ndof))
    return g, G, H, P.assemble(order, out)


def evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
             lam: np.ndarray | None = None, tangent: bool = True,
             space: "MultiplierSpace | str" = "standard",
             n_gauss: int = 2, segmentation: Segmentation | None = None,
             pairs: tuple[np.ndarray, np.ndarray] | None = None, margin: float | None = None,
             crosspoints: np.ndarray | None = None, reach: float = 0.0,
             cells: tuple | None = None, measure: Measure = PLANE,
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
    space : MultiplierSpace or str
        The multiplier space (:func:`biorthogonal`): ``"standard"`` (``Phi_A = N_A``)
        or a biorthogonal one (``"dual"``).  Biorthogonal coefficients are
        computed on the projectable part of each slave
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
        :func:`~skfem_mortar.contact.mortar_segmentation.segment` (default: local, the
        two element lengths).
    crosspoints : int array, optional
        Slave nodes (e.g. on a Dirichlet boundary) whose multiplier is merged
        into the neighbour: on their element the neighbour's multiplier shape
        function becomes 1 and theirs 0; they are never in ``mask``.
    cells : (slave, master) cell types, optional
        Both ``line2`` (checked; the cells of this kernel).
    measure : Measure
        The weight ``w(x)`` of ``dGamma`` (:mod:`~skfem_mortar.contact.measures`,
        default plane ``w = 1``): every integral (``g``, ``D``, ``M``, the supports,
        the dual basis) is taken in ``w(x_s) dGamma`` at the current slave point,
        with its derivatives.  A measure with an axis (axisymmetric) makes the
        slave nodes on it take the mirror normal, axial
        (:func:`~skfem_mortar.contact.normals.mirror_of_axis`).

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
    P = _Problem.of(xs, seg_s, xm, seg_m, segmentation, pairs, margin, reach, crosspoints,
                    n_gauss, nodal_jets=(6 if tangent else 0), second=tangent and lam is not None,
                    cells=cells, measure=measure)
    bi = biorthogonal(space)
    g, G, H, A = _jet_rows(P, tangent, bi, n_gauss, lam,
                           lambda ls, sl, nv_g, lam_ab, sec: P.block(ls, sl, nv_g, bi, lam_ab,
                                                                     second=sec))
    sg = P.sg
    return ContactEval(g=g, G=G, H=H, area=A.area, mask=P.mask,
                       info={"D": A.D, "M": A.M, "segmentation": sg, "n_segments": sg.n})


class SurfaceIntegrals(NamedTuple):
    """The mortar integrals of a surface pair, assembled (see :func:`integrals`).

    Attributes
    ----------
    n_AB : csr (n_s, 2 n_s)
        ``int Phi_A N_B n dGamma``, component ``i`` of node ``B`` in column ``2 B + i``.
    n_AC : csr (n_s, 2 n_m)
        ``int Phi_A N_C n dGamma``, likewise.
    D, M : csr (n_s, n_s), (n_s, n_m)
        ``int Phi_A N_B dGamma``, ``int Phi_A N_C dGamma``.
    g : ndarray (n_s,)
        ``-n_AB @ x_s + n_AC @ x_m`` (:func:`weighted_gap`, per segment, summed).
    area, mask : ndarray (n_s,)
        As in :func:`evaluate`.
    """

    n_AB: sp.csr_matrix
    n_AC: sp.csr_matrix
    D: sp.csr_matrix
    M: sp.csr_matrix
    g: np.ndarray
    area: np.ndarray
    mask: np.ndarray


def integrals(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
              space: "MultiplierSpace | str" = "standard", n_gauss: int = 2,
              segmentation: Segmentation | None = None,
              pairs: tuple[np.ndarray, np.ndarray] | None = None, margin: float | None = None,
              crosspoints: np.ndarray | None = None, reach: float = 0.0,
              measure: Measure = PLANE) -> SurfaceIntegrals:
    """The vector mortar integrals ``n_AB``, ``n_AC``, with ``D``, ``M`` and the weighted gap.

    Steps 1 to 7 of the module doc, values only, on the same mortar segments,
    multiplier functions and mask as :func:`evaluate` (same parameters).  The
    weighted gap is assembled by the identity ``g_A = -sum_B n_AB . x_B +
    sum_C n_AC . x_C``; :func:`evaluate` integrates the same ``g_A`` as one
    integrand ``int Phi_A g_n dGamma`` (equal Gauss point by Gauss point, to
    round-off), which is what its exact derivatives differentiate.
    """
    P = _Problem.of(xs, seg_s, xm, seg_m, segmentation, pairs, margin, reach, crosspoints,
                    n_gauss, nodal_jets=0, second=False, measure=measure)
    g = np.zeros(P.n_s)
    bi = biorthogonal(space)
    out, order = [], []
    for sl, _, _ in _blocks(P.sg.n, 0, n_gauss, False, P.loc):
        ls = P.loc.take(sl)
        blk = P.block(ls, sl, 0, bi, None, vector=True)
        order.append(sl)
        out.append(blk.ints)
        np.add.at(g, ls.a, blk.g[:, 0])
        np.add.at(g, ls.b, blk.g[:, 1])
    A = P.assemble(order, out)
    return SurfaceIntegrals(n_AB=A.n_AB, n_AC=A.n_AC, D=A.D, M=A.M, g=g, area=A.area,
                            mask=P.mask)
