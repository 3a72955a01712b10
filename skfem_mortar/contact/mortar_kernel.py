"""The one mortar kernel's evaluation: multiplier functions per slave cell, nodal normals
chained in, one scatter.

:func:`evaluate` runs, for any segmentation that keeps the contract of
:mod:`~skfem_mortar.contact.integration_points` (2D lines by default,
:class:`~skfem_mortar.contact.line_points.LineSegmentation`):

1. averaged nodal normals with their first and second derivatives over the
   neighbouring nodes (:func:`~skfem_mortar.contact.normals.nodal_normals`, mirror
   normals on an axis);
2. the integration cells (values), their local variables ``[x_s, x_m, n_s]`` and their
   points (jets);
3. per integration cell, with ``Phi_A = N_A``: ``g~_A``, ``D``, ``M`` and, for a dual space,
   ``int N_A`` and ``int N_A N_B`` (:func:`~skfem_mortar.contact.mortar_cells.cell_integrals`);
4. per slave cell ``e`` (its integration cells side by side, :func:`groups`: the variables
   ``[x_s, n_s, x_m of each integration cell]``): the sums ``G_B = sum_cells g~_B`` and the
   multiplier functions ``Phi_A = sum_B C_AB N_B``, ``C = T`` (standard) or ``C = A~ T`` (dual,
   ``A~ = D~_e M~_e^-1`` of the modified functions ``N~ = T N`` summed over the cell's
   integration cells: each lies in one smooth piece, so piecewise cells integrate
   exactly), ``T`` the crosspoint/boundary merge; ``g_A = sum_B C_AB G_B``;
5. :func:`assemble`: ``G = G_loc J``, ``H = J^T H_loc J + sum_(a, i) df/dn_ai d2n_ai/dx2``,
   scattered once through :class:`~skfem_mortar.contact.scatter.Triplets`.

A slave node is masked when its support ``int N_A w dGamma`` is below ``MASK_TOL`` of its
tributary weight (and crosspoints are): its function is merged into its neighbours'
(:func:`~skfem_mortar.contact.mortar_quadratic.merge_matrix`).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from .cell_map import check_connectivity
from .cells import cell_type
from .contact_eval import ContactEval
from .integration_points import IntegrationCells, LocalLayout, LocalVariables
from .jets import Jet
from .line_points import LineSegmentation
from .measures import PLANE, Measure
from .mortar import MASK_TOL, biorthogonal
from .mortar_cells import cell_integrals
from .mortar_quadratic import N_GAUSS_ELEMENT, merge_matrix
from .mortar_support import tributary_weights
from .multiplier_spaces import make_space
from .normals import NodalNormals, mirror_of_axis, nodal_normals
from .scatter import Triplets
from .segmentation import Segmentation, line_cells

__all__ = ["Groups", "groups", "group_sum", "assemble", "evaluate"]


class Groups(NamedTuple):
    """The integration cells of each slave cell side by side.

    ``cell (n,)``: the group (slave cell) of each integration cell, ``slot (n,)`` its
    place in it, ``e_s (n_e,)`` the slave cell of each group, ``m`` the most cells of one,
    ``layout`` the cells' :class:`LocalLayout`.  Group variables:
    ``[x_s (k_s d), n_s (k_s d), x_m of slot 0, ..., slot m-1 (k_m d each)]``.
    """

    cell: np.ndarray
    slot: np.ndarray
    e_s: np.ndarray
    m: int
    layout: LocalLayout

    @property
    def nv(self) -> int:
        lay = self.layout
        return lay.d * (2 * lay.k_s + self.m * lay.k_m)

    def index(self, slot: int) -> np.ndarray:
        """The group variable of each local variable of a cell in ``slot``."""
        lay = self.layout
        xs = lay.k_s * lay.d
        xm = lay.k_m * lay.d
        return np.concatenate([np.arange(xs), 2 * xs + slot * xm + np.arange(xm),
                               xs + np.arange(xs)])


def groups(e_s: np.ndarray, layout: LocalLayout, each: bool = False) -> Groups:
    """:class:`Groups` of the integration cells' slave cells ``e_s``; ``each``: every
    integration cell its own group (what functions constant on a slave cell need, the
    standard space's ``Phi = T N``: smaller jets than a whole slave cell's)."""
    if each:
        return Groups(np.arange(e_s.size), np.zeros(e_s.size, dtype=np.int64),
                      np.asarray(e_s), 1, layout)
    e, cell = np.unique(e_s, return_inverse=True)
    order = np.argsort(cell, kind="stable")
    first = np.searchsorted(cell[order], np.arange(e.size))
    slot = np.empty(e_s.size, dtype=np.int64)
    slot[order] = np.arange(e_s.size) - first[cell[order]]
    return Groups(cell, slot, e, int(slot.max()) + 1 if slot.size else 1, layout)


def group_sum(j: Jet, grp: Groups) -> Jet:
    """``sum`` of a cell jet ``(n,)`` over each group, in the group variables: ``(n_e,)``."""
    n_e, nv = grp.e_s.size, grp.nv
    if grp.m == 1 and np.array_equal(grp.cell, np.arange(j.v.size)):   # one cell per group
        idx = np.argsort(grp.index(0))
        return Jet(j.v, j.g[idx], None if j.h is None else j.h[np.ix_(idx, idx)])
    v = np.bincount(grp.cell, weights=j.v, minlength=n_e)
    g = np.zeros((nv, n_e))
    h = None if j.h is None else np.zeros((nv, nv, n_e))
    for s in range(grp.m):
        sel = np.flatnonzero(grp.slot == s)
        rows, idx = grp.cell[sel], grp.index(s)
        g[np.ix_(idx, rows)] += j.g[:, sel]
        if h is not None:
            h[np.ix_(idx, idx, rows)] += j.h[:, :, sel]
    return Jet(v, g, h)


def _extended(grp: Groups, conn_s, conn_m, e_m, normals: NodalNormals, n_s: int):
    """Dofs ``(n_e, n_ext)`` (-1 where unused) of the extended variables
    ``[x_s, the normals' neighbourhoods, x_m of each slot]`` and ``J (n_e, nv, n_ext)``."""
    lay = grp.layout
    d, k_s, k_m = lay.d, lay.k_s, lay.k_m
    n_e, c = grp.e_s.size, np.arange(d)
    S = conn_s[grp.e_s]
    K = normals.nodes.shape[1]
    nb = normals.nodes[S]                                            # (n_e, k_s, K)
    Mn = np.full((n_e, grp.m, k_m), -1)
    Mn[grp.cell, grp.slot] = conn_m[e_m]
    dofs = np.concatenate([(S[:, :, None] * d + c).reshape(n_e, -1),
                           np.where(nb[..., None] >= 0, nb[..., None] * d + c, -1).reshape(n_e, -1),
                           np.where(Mn[..., None] >= 0, d * n_s + Mn[..., None] * d + c,
                                    -1).reshape(n_e, -1)], axis=1)
    xs, nbh = k_s * d, k_s * K * d
    J = np.zeros((n_e, grp.nv, dofs.shape[1]))
    J[:, np.arange(xs), np.arange(xs)] = 1.0
    xm = np.arange(grp.m * k_m * d)
    J[:, 2 * xs + xm, xs + nbh + xm] = 1.0
    dn = normals.dn[:, S]                                            # (d, n_e, k_s, K, d)
    for a in range(k_s):
        for i in range(d):
            J[:, xs + a * d + i, xs + a * K * d:xs + (a + 1) * K * d] = dn[i, :, a].reshape(n_e, -1)
    return dofs, J, S


def _chain_hessian(f: Jet, J: np.ndarray, S: np.ndarray, normals: NodalNormals,
                   lay: LocalLayout) -> np.ndarray:
    """``J^T H_loc J + sum_(a, i) df/dn_ai d2n_ai/dx2``: ``(n_ext, n_ext, n_e)``."""
    Hl = np.ascontiguousarray(f.hessian().transpose(2, 0, 1))     # (n_e, nv, nv)
    H = np.matmul(np.matmul(J.transpose(0, 2, 1), Hl), J).transpose(1, 2, 0)
    K, d, xs = normals.nodes.shape[1], lay.d, lay.k_s * lay.d
    for a in range(lay.k_s):
        sl = slice(xs + a * K * d, xs + (a + 1) * K * d)
        for i in range(d):
            d2 = normals.d2n[i, S[:, a]].reshape(-1, K * d, K * d)
            H[sl, sl] += np.einsum("n,nrs->rsn", f.g[xs + a * d + i], d2)
    return H


def assemble(g: list, grp: Groups, conn_s, conn_m, e_m, normals: NodalNormals, n_s: int,
             n_m: int, lam: np.ndarray | None = None, tangent: bool = True):
    """``g (n_s,)``, ``G = dg/dx`` and ``H = sum_A lam_A d2g_A/dx2`` from the group jets
    ``g[a]`` (slave node ``a`` of each group), the nodal normals chained in (module
    docstring); dofs: slave node ``A`` ``d A + c``, master node ``C`` ``d n_s + d C + c``."""
    lay = grp.layout
    S = conn_s[grp.e_s]
    out = np.zeros(n_s)
    for a in range(lay.k_s):
        np.add.at(out, S[:, a], g[a].v)
    if not tangent:
        return out, None, None
    dofs, J, S = _extended(grp, conn_s, conn_m, e_m, normals, n_s)
    used = dofs >= 0
    safe = np.where(used, dofs, 0)
    shape = (n_s, lay.d * (n_s + n_m))
    trip = Triplets()
    for a in range(lay.k_s):
        trip.rows(S[:, a], safe, np.einsum("pn,npr->nr", g[a].g, J), used)
    H = None
    if lam is not None and g[0].h is not None:
        lam = np.asarray(lam, dtype=float)
        f = g[0] * lam[S[:, 0]]
        for a in range(1, lay.k_s):
            f = f + g[a] * lam[S[:, a]]
        Hl = _chain_hessian(f, J, S, normals, lay) * (used[:, :, None] & used[:, None, :]
                                                      ).transpose(1, 2, 0)
        th = Triplets()
        th.block(safe, Hl)
        H = th.csr((shape[1], shape[1]))
    return out, trip.csr(shape), H


def _combine(C, jets: list) -> list:
    """``sum_b C[:, a, b] jets[b]`` for each ``a`` (``C`` values ``(n, k, k)`` or a dict of jets)."""
    k = len(jets)
    out = []
    for a in range(k):
        acc = None
        for b in range(k):
            c = C[a, b] if isinstance(C, dict) else C[:, a, b]
            if not isinstance(c, Jet) and not np.any(c):
                continue
            t = jets[b] * c
            acc = t if acc is None else acc + t
        out.append(acc if acc is not None else jets[0] * 0.0)
    return out


def _biorthogonal(ints, grp: Groups, T: np.ndarray, space) -> tuple[dict, np.ndarray]:
    """``A~ = D~ M~^-1`` of ``N~ = T N`` over each slave cell's integration cells (jets)."""
    k = len(ints.n_A)
    nA = [group_sum(j, grp) for j in ints.n_A]
    nAB = {key: group_sum(j, grp) for key, j in ints.n_AB.items()}
    full = {(a, b): nAB[min(a, b), max(a, b)] for a in range(k) for b in range(k)}
    D = _combine(T, nA)
    M = {}
    dead = ~T.any(axis=2)
    for a in range(k):
        for b in range(a, k):
            acc = None
            for c in range(k):
                for e in range(k):
                    t = T[:, a, c] * T[:, b, e]
                    if np.any(t):
                        term = full[c, e] * t
                        acc = term if acc is None else acc + term
            M[a, b] = acc if acc is not None else nA[0] * 0.0
        if dead[:, a].any():
            M[a, a] = M[a, a] + dead[:, a] * 1.0
    A = space.cell_coefficients(D, M)
    Av = np.stack([np.stack([A[a, b].v for b in range(k)], -1) for a in range(k)], 1)
    return A, np.einsum("nab,nbc->nac", Av, T)


def evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
             lam: np.ndarray | None = None, tangent: bool = True, space="standard",
             n_gauss: int = 2, segmentation: Segmentation | None = None,
             pairs=None, margin: float | None = None, crosspoints=None, reach: float = 0.0,
             measure: Measure = PLANE, cells=None, points=None) -> ContactEval:
    """Mortar weighted gaps ``g``, ``G = dg/dx``, ``H = sum_A lam_A d2g_A/dx2`` by the one
    kernel (module docstring), the interface of ``mortar_quadratic.evaluate``.

    ``points``: the segmentation's side of the contract (default the line segmentation of
    ``cells`` with ``n_gauss`` points, ``pairs``, ``margin``, ``reach``); ``segmentation``:
    integration cells to reuse (frozen: their end points held).  Returns
    :class:`ContactEval` with ``area`` the supports, ``mask``, and ``D``, ``M`` in ``info``.
    """
    xs, xm = np.asarray(xs, dtype=float), np.asarray(xm, dtype=float)
    seg_s, seg_m = np.asarray(seg_s, dtype=np.int64), np.asarray(seg_m, dtype=np.int64)
    if cells is None:                       # the 2D array interface: lines by columns
        cells = line_cells(seg_s, seg_m)
    cells = tuple(cell_type(c) for c in cells)
    seg_s = check_connectivity(seg_s, cells[0], xs.shape[1])
    seg_m = check_connectivity(seg_m, cells[1], xm.shape[1])
    mirror = mirror_of_axis(measure.axis)
    second = tangent and lam is not None
    nn = nodal_normals(xs, seg_s, cells[0], order=2 if second else 1, mirror=mirror)
    if points is None:
        points = LineSegmentation(cells, n_gauss, pairs=pairs, margin=margin, reach=reach,
                                  frozen=False, **({"mirror": mirror} if mirror else {}))
    ic = (IntegrationCells(segmentation.e_s, segmentation.e_m, segmentation)
          if segmentation is not None else
          points.integration_cells(xs, seg_s, xm, seg_m, nn.n))
    S = seg_s[ic.e_s]
    loc = LocalVariables.of(xs.T[S], xm.T[seg_m[ic.e_m]], nn.n.T[S], second)
    pts = points.integration_points(ic, loc)
    biorth = biorthogonal(space)
    ints = cell_integrals(pts, loc, cells, measure, mass=biorth)
    n_s, n_m = xs.shape[1], xm.shape[1]
    support = np.bincount(S.ravel(), weights=ints.support.ravel(), minlength=n_s)
    trib = tributary_weights(xs, seg_s, cells[0], 2 * N_GAUSS_ELEMENT - 1, measure,
                             absolute=not measure.unit)
    cp = np.isin(np.arange(n_s), [] if crosspoints is None else crosspoints)
    mask = (support > MASK_TOL * trib) & ~cp
    grp = groups(ic.e_s, loc.layout, each=not biorth)
    merged = ~mask[seg_s[grp.e_s]]
    k = seg_s.shape[1]
    T = (merge_matrix(merged, cells[0]) if merged.any()      # (line cells only, so far)
         else np.broadcast_to(np.eye(k), (grp.e_s.size, k, k)))
    Gs = _combine(T, [group_sum(j, grp) for j in ints.g])
    C = T
    if biorth:
        A, C = _biorthogonal(ints, grp, T, make_space(space) if isinstance(space, str) else space)
        Gs = _combine(A, Gs)
    g, G, H = assemble(Gs, grp, seg_s, seg_m, ic.e_m, nn, n_s, n_m, lam, tangent)
    Ci = C[grp.cell]
    D = _csr(np.einsum("nab,nbc->nac", Ci, ints.D), S, S, (n_s, n_s))
    M = _csr(np.einsum("nab,nbc->nac", Ci, ints.M), S, seg_m[ic.e_m], (n_s, n_m))
    info = {"D": D, "M": M, "segmentation": ic.data, "n_segments": ic.e_s.size}
    return ContactEval(g=g, G=G, H=H, area=support, mask=mask, info=info)


def _csr(vals: np.ndarray, rows: np.ndarray, cols: np.ndarray, shape) -> sp.csr_matrix:
    t = Triplets()
    t.outer(rows, cols, vals)
    return t.csr(shape)
