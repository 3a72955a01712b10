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
by the one rule read from the cell's edges
(:func:`~skfem_mortar.contact.mortar_support.merge_nodes`).

The integration cells go through steps 2 to 5 in chunks of whole slave cells
(:func:`chunks`, at most :data:`CHUNK_ENTRIES` derivative entries each), appending to
one set of triplets; with more than one chunk the supports (for the mask) come first,
from a first-order pass.
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
from .mortar_support import N_GAUSS_ELEMENT, merge_nodes, tributary_weights
from .multiplier_spaces import make_space
from .normals import NodalNormals, mirror_of_axis, nodal_normals
from .scatter import Triplets
from .segmentation import Segmentation, line_cells

__all__ = ["Groups", "groups", "group_sum", "group_sums", "assemble", "evaluate", "chunks", "CHUNK_ENTRIES"]

CHUNK_ENTRIES = 250_000
"""Derivative entries per chunk of integration cells (``nv^2`` each with Hessians):
one Hessian jet at ``n_gp`` points of a chunk takes at most ``8 n_gp CHUNK_ENTRIES``
bytes (2 MB a point: 18 MB for a 9-point quad4/quad4 chunk of 192 cells, ``nv = 36``;
a 2D line2 chunk holds 1,736 cells, so the usual 2D call is one chunk)."""


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
    return group_sums([j], grp)[0]


def group_sums(jets: list, grp: Groups) -> list:
    """:func:`group_sum` of several cell jets of one kind at once (one scatter per slot)."""
    n_e, nv = grp.e_s.size, grp.nv
    second = jets[0].h is not None
    if grp.m == 1 and np.array_equal(grp.cell, np.arange(jets[0].v.size)):   # one cell a group
        idx = np.argsort(grp.index(0))
        return [Jet(j.v, j.g[idx], j.h[np.ix_(idx, idx)] if second else None) for j in jets]
    G = np.stack([j.g for j in jets])
    H = np.stack([j.h for j in jets]) if second else None
    g = np.zeros((len(jets), nv, n_e))
    h = np.zeros((len(jets), nv, nv, n_e)) if second else None
    for s in range(grp.m):
        sel = np.flatnonzero(grp.slot == s)
        rows, idx = grp.cell[sel], grp.index(s)
        g[:, idx[:, None], rows] += G[:, :, sel]
        if second:
            h[:, idx[:, None, None], idx[:, None], rows] += H[:, :, :, sel]
    return [Jet(np.bincount(grp.cell, weights=j.v, minlength=n_e), g[i],
                None if h is None else h[i]) for i, j in enumerate(jets)]


def _extended(grp: Groups, conn_s, conn_m, e_m, normals: NodalNormals, n_s: int):
    """Dofs ``(n_e, n_ext)`` (-1 where unused) of the extended variables
    ``[x_s, the normals' neighbourhoods, x_m of each slot]`` and the normals' block of
    ``J``, ``Jn (n_e, k_s d, k_s K d)`` (block diagonal: ``dn_a/dx`` of each slave node;
    ``J`` is the identity on ``x_s`` and ``x_m``)."""
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
    Jn = np.zeros((n_e, k_s, d, k_s, K * d))
    dn = normals.dn[:, S].reshape(d, n_e, k_s, K * d)                # (d, n_e, k_s, K d)
    for a in range(k_s):
        Jn[:, a, :, a] = dn[:, :, a].transpose(1, 0, 2)
    return dofs, Jn.reshape(n_e, k_s * d, k_s * K * d), S


def _parts(nv: int, lay: LocalLayout, K: int) -> tuple:
    """Group variables on ``x_s, x_m`` (``P``) and on ``n_s`` (``N``); where ``P`` and
    the normals' neighbourhoods (``B``) sit among the extended ones."""
    xs = lay.k_s * lay.d
    nbh = K * xs
    P = np.r_[0:xs, 2 * xs:nv]
    return P, np.arange(xs, 2 * xs), np.r_[0:xs, xs + nbh:nv - xs + nbh], slice(xs, xs + nbh)


def _chain_gradient(g: np.ndarray, Jn: np.ndarray, parts: tuple) -> np.ndarray:
    """``G = G_loc J``, ``(n_e, n_ext)``, from ``g (nv, n_e)`` (``J``'s identity blocks
    copied, the normals' block a batched product)."""
    P, N, Pe, B = parts
    out = np.empty((g.shape[1], Pe.size + Jn.shape[2]))
    out[:, Pe] = g[P].T
    out[:, B] = np.matmul(g[N].T[:, None, :], Jn)[:, 0]
    return out


def _chain_hessian(f: Jet, Jn: np.ndarray, S: np.ndarray, normals: NodalNormals,
                   parts: tuple) -> np.ndarray:
    """``J^T H_loc J + sum_(a, i) df/dn_ai d2n_ai/dx2``: ``(n_e, n_ext, n_ext)``, by
    blocks: ``H_PP``, ``H_PN Jn``, ``Jn^T H_NN Jn`` (``J`` the identity on ``P``)."""
    P, N, Pe, B = parts
    Hl = f.hessian().transpose(2, 0, 1)                              # (n_e, nv, nv)
    n_e, nb = Jn.shape[0], Jn.shape[2]
    H = np.empty((n_e, Pe.size + nb, Pe.size + nb))
    H[:, Pe[:, None], Pe] = Hl[:, P[:, None], P]
    HPB = np.matmul(Hl[:, P[:, None], N], Jn)
    H[:, Pe[:, None], np.arange(B.start, B.stop)] = HPB
    H[:, B, Pe] = HPB.transpose(0, 2, 1)
    HBB = np.matmul(Jn.transpose(0, 2, 1), np.matmul(Hl[:, N[:, None], N], Jn))
    K = normals.nodes.shape[1]
    d = normals.n.shape[0]
    dfn = f.g[N].T.reshape(n_e, -1, d)                               # df/dn_ai
    for a in range(S.shape[1]):
        sl = slice(a * K * d, (a + 1) * K * d)
        d2 = normals.d2n[:, S[:, a]].reshape(d, n_e, K * d, K * d)
        HBB[:, sl, sl] += np.einsum("ni,inrs->nrs", dfn[:, a], d2)
    H[:, B, B] = HBB
    return H


def _scatter(g: list, grp: Groups, conn_s, conn_m, e_m, normals: NodalNormals, n_s: int,
             lam, tangent: bool, out: np.ndarray, trip: Triplets, th: Triplets,
             q: Jet | None = None) -> None:
    """:func:`assemble`'s work, added to ``out`` and appended to ``trip`` (G), ``th`` (H);
    ``q``: ``sum_A lam_A g_A`` if made already (then ``g`` may be first order)."""
    lay = grp.layout
    S = conn_s[grp.e_s]
    for a in range(lay.k_s):
        np.add.at(out, S[:, a], g[a].v)
    if not tangent or not grp.e_s.size:      # no cells in this call: nothing to scatter
        return
    ext, Jn, S = _extended(grp, conn_s, conn_m, e_m, normals, n_s)
    parts = _parts(grp.nv, lay, normals.nodes.shape[1])
    dofs, rank = _distinct(ext)
    used = dofs >= 0
    safe = np.where(used, dofs, 0)
    for a in range(lay.k_s):
        trip.rows(S[:, a], safe, _on_distinct(_chain_gradient(g[a].g, Jn, parts), rank,
                                              dofs.shape[1]), used)
    if q is None and lam is not None and g[0].h is not None:
        lam = np.asarray(lam, dtype=float)
        q = g[0] * lam[S[:, 0]]
        for a in range(1, lay.k_s):
            q = q + g[a] * lam[S[:, a]]
    if q is not None:
        H = _on_distinct(_chain_hessian(q, Jn, S, normals, parts), rank, dofs.shape[1])
        if not used.all():
            H *= used[:, :, None]
            H *= used[:, None, :]
        th.block(safe, H.transpose(1, 2, 0))


def _distinct(ext: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each group's distinct dofs ``(n_e, u)`` (-1 where unused) and the place
    ``rank (n_e, n_ext)`` of each extended variable among them.

    A dof appears several times among a group's extended variables (a slave node in
    ``x_s`` and in its own and its neighbours' normal stencils); summed onto its distinct
    dofs (:func:`_on_distinct`) a line2 cell's ``H`` block is 12 x 12 instead of 20 x 20,
    so fewer triplets are kept.  The unused variables (-1) share one place."""
    n_e, n = ext.shape
    key = np.where(ext >= 0, ext, np.iinfo(np.int64).max)
    order = np.argsort(key, axis=1, kind="stable")
    sk = np.take_along_axis(key, order, 1)
    new = np.ones(sk.shape, dtype=bool)
    new[:, 1:] = sk[:, 1:] != sk[:, :-1]
    rank = np.empty(sk.shape, dtype=np.int64)
    np.put_along_axis(rank, order, np.cumsum(new, axis=1) - 1, 1)
    u = int(rank.max()) + 1 if rank.size else 1
    dofs = np.full((n_e, u), -1, dtype=ext.dtype)
    dofs[np.arange(n_e)[:, None], rank] = np.where(ext >= 0, ext, -1)
    return dofs, rank


def _on_distinct(a: np.ndarray, rank: np.ndarray, u: int) -> np.ndarray:
    """A gradient ``(n_e, n_ext)`` or Hessian ``(n_e, n_ext, n_ext)`` of the extended
    variables summed onto the distinct dofs (:func:`_distinct`): ``(n_e, u)`` or
    ``(n_e, u, u)``, ``a_u = sum_(rank_i = u) a_i`` (each axis; one bincount, the terms
    of a place added in the order of the variables)."""
    n_e = rank.shape[0]
    at = np.arange(n_e)[:, None] * u + rank                        # (n_e, n_ext)
    if a.ndim == 3:                    # in place: one index array the size of ``a``
        row = at
        at = np.empty(a.shape, dtype=np.int64)
        np.multiply(row[:, :, None], u, out=at)
        at += rank[:, None, :]
    out = np.bincount(at.ravel(), weights=a.ravel(), minlength=n_e * u ** (a.ndim - 1))
    return out.reshape((n_e,) + (u,) * (a.ndim - 1))


def assemble(g: list, grp: Groups, conn_s, conn_m, e_m, normals: NodalNormals, n_s: int,
             n_m: int, lam: np.ndarray | None = None, tangent: bool = True):
    """``g (n_s,)``, ``G = dg/dx`` and ``H = sum_A lam_A d2g_A/dx2`` from the group jets
    ``g[a]`` (slave node ``a`` of each group), the nodal normals chained in (module
    docstring); dofs: slave node ``A`` ``d A + c``, master node ``C`` ``d n_s + d C + c``."""
    out, trip, th = np.zeros(n_s), Triplets(), Triplets()
    _scatter(g, grp, conn_s, conn_m, e_m, normals, n_s, lam, tangent, out, trip, th)
    if not tangent:
        return out, None, None
    n = grp.layout.d * (n_s + n_m)
    H = th.csr((n, n)) if lam is not None and g[0].h is not None else None
    return out, trip.csr((n_s, n)), H


def _row(C, a: int, jets: list):
    """``sum_b C[:, a, b] jets[b]`` (``C`` values ``(n, k, k)`` or a dict of jets)."""
    acc = None
    for b in range(len(jets)):
        c = C[a, b] if isinstance(C, dict) else C[:, a, b]
        if not isinstance(c, Jet) and not np.any(c):
            continue
        t = jets[b] * c
        acc = t if acc is None else acc + t
    return acc if acc is not None else jets[0] * 0.0


def _combine(C, jets: list) -> list:
    """``sum_b C[:, a, b] jets[b]`` for each ``a`` (``C`` values ``(n, k, k)`` or a dict of jets)."""
    return [_row(C, a, jets) for a in range(len(jets))]


def _biorthogonal(ints, grp: Groups, T: np.ndarray, space) -> tuple[dict, np.ndarray]:
    """``A~ = D~ M~^-1`` of ``N~ = T N`` over each slave cell's integration cells (jets)."""
    k = len(ints.n_A)
    sums = group_sums(ints.n_A + list(ints.n_AB.values()), grp)
    nA, nAB = sums[:k], dict(zip(ints.n_AB, sums[k:]))
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
    return A, np.matmul(Av, T)


def chunks(e_s: np.ndarray, nv: int, second: bool, entries: int | None = None) -> list:
    """Rows of the integration cells in chunks of whole slave cells (each in the rows'
    own order) such that a chunk holds at most ``entries`` (default
    :data:`CHUNK_ENTRIES`) derivative entries, ``nv^2`` per integration cell with
    Hessians (``nv`` without), and at least one slave cell; ``[None]``: one chunk, all rows.
    """
    per = max(1, int(CHUNK_ENTRIES if entries is None else entries) // (nv * nv if second
                                                                        else nv))
    if e_s.size <= per:
        return [None]
    order = np.argsort(e_s, kind="stable")
    es = e_s[order]
    starts = np.append(np.flatnonzero(np.r_[True, es[1:] != es[:-1]]), es.size)
    out, lo = [], 0
    while lo < es.size:
        j = np.searchsorted(starts, lo + per, side="right") - 1   # last start <= lo + per
        hi = starts[j] if starts[j] > lo else starts[np.searchsorted(starts, lo, "right")]
        out.append(np.sort(order[lo:hi]))
        lo = hi
    return out


def _take(ic: IntegrationCells, rows) -> IntegrationCells:
    """Rows ``rows`` of ``ic`` (None: all), its data ``(whole, rows)`` as the contract
    keeps it (or None)."""
    if rows is None:
        return ic
    if ic.data is None:
        return IntegrationCells(ic.e_s[rows], ic.e_m[rows])
    if not (isinstance(ic.data, tuple) and len(ic.data) == 2):
        raise ValueError("IntegrationCells.data must be (whole, rows) or None to be taken "
                         f"in chunks, got {type(ic.data).__name__}")
    whole, r = ic.data
    return IntegrationCells(ic.e_s[rows], ic.e_m[rows], (whole, r[rows]))


class _Surfaces(NamedTuple):
    """One call's surfaces: coordinates, connectivities, cells, normals, measure."""

    xs: np.ndarray
    seg_s: np.ndarray
    xm: np.ndarray
    seg_m: np.ndarray
    cells: tuple
    nn: NodalNormals
    measure: Measure

    def integrals(self, points, ic: IntegrationCells, second: bool, mass: bool,
                  integrand=None):
        """Rows ``S`` (slave nodes) and :func:`cell_integrals` of the cells ``ic``."""
        S = self.seg_s[ic.e_s]
        loc = LocalVariables.of(self.xs.T[S], self.xm.T[self.seg_m[ic.e_m]], self.nn.n.T[S],
                                second)
        pts = points.integration_points(ic, loc)
        ints = cell_integrals(pts, loc, self.cells, self.measure, mass=mass,
                              integrand=integrand)
        return S, loc, _widened(ints, loc.layout.n_loc)


def _widened(ints, nv: int):
    """The integrals' jets in all ``nv`` local variables (a jet made from points that
    hold fewer, the leading ones, has fewer: :meth:`~.jets.Jet.widen`)."""
    def wide(j):
        if isinstance(j, (list, tuple)):
            return [wide(x) for x in j]
        return j.widen(nv)
    return ints._replace(g=wide(ints.g), n_A=None if ints.n_A is None else wide(ints.n_A),
                         n_AB=None if ints.n_AB is None else
                         {key: j.widen(nv) for key, j in ints.n_AB.items()})


def _mirror(measure: Measure, mirror, d: int) -> tuple:
    """The nodal normals' mirror: the measure's axis and ``mirror`` together."""
    return tuple(mirror_of_axis(measure.axis, d)) + tuple(() if mirror is None else mirror)


def evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
             lam: np.ndarray | None = None, tangent: bool = True, space="standard",
             n_gauss: int | None = None, segmentation: Segmentation | None = None,
             pairs=None, margin: float | None = None, crosspoints=None, reach: float = 0.0,
             measure: Measure = PLANE, cells=None, points=None, integrand=None,
             mirror=None, chunk_entries: int | None = None) -> ContactEval:
    """Mortar weighted gaps ``g``, ``G = dg/dx``, ``H = sum_A lam_A d2g_A/dx2`` by the one
    kernel (module docstring), for every pair of line cells (line2/line2 too).

    ``points``: the segmentation's side of the contract (default the line segmentation of
    ``cells`` with ``n_gauss`` points, default one more than the cells' highest order,
    ``pairs``, ``margin``, ``reach``; on curved cells a dual space's mass integrals take
    ``max(n_gauss, N_GAUSS_ELEMENT)`` points per integration cell); ``segmentation``:
    integration cells to reuse (frozen: their end points held).  ``integrand``: what
    replaces the weighted gap's integrand (:func:`~.mortar_cells.cell_integrals`; groups,
    merge, dual combination, chained normals and scatter stay), so ``g, G, H`` are that
    integrand's.  ``mirror``: symmetry lines or planes ``(e, c)``, ``e . x = c``, for the
    nodal normals (:func:`~.normals.nodal_normals`), with the measure's axis if it has one
    (both are used).  ``chunk_entries``: the memory bound of :func:`chunks` (default the
    points' ``chunk_entries`` if they have one, else :data:`CHUNK_ENTRIES`).  Returns
    :class:`ContactEval` with ``area`` the supports, ``mask``, and ``D``, ``M`` in ``info``.
    """
    xs, xm = np.asarray(xs, dtype=float), np.asarray(xm, dtype=float)
    seg_s, seg_m = np.asarray(seg_s, dtype=np.int64), np.asarray(seg_m, dtype=np.int64)
    if cells is None:                       # the 2D array interface: lines by columns
        cells = line_cells(seg_s, seg_m)
    cells = tuple(cell_type(c) for c in cells)
    seg_s = check_connectivity(seg_s, cells[0], xs.shape[1])
    seg_m = check_connectivity(seg_m, cells[1], xm.shape[1])
    mirror = _mirror(measure, mirror, xs.shape[0])
    second = tangent and lam is not None
    nn = nodal_normals(xs, seg_s, cells[0], order=2 if second else 1, mirror=mirror)
    biorth = biorthogonal(space)
    if points is None:
        order = max(c.order for c in cells)
        n_gauss = 1 + order if n_gauss is None else n_gauss
        points = LineSegmentation(cells, n_gauss, n_mass=max(n_gauss, N_GAUSS_ELEMENT)
                                  if biorth and order > 1 else None, pairs=pairs, margin=margin, reach=reach,
                                  frozen=False, **({"mirror": mirror} if mirror else {}))
    ic = (IntegrationCells(segmentation.e_s, segmentation.e_m,
                           (segmentation, np.arange(segmentation.n)))
          if segmentation is not None else
          points.integration_cells(xs, seg_s, xm, seg_m, nn.n))
    surf = _Surfaces(xs, seg_s, xm, seg_m, cells, nn, measure)
    n_s, n_m = xs.shape[1], xm.shape[1]
    if chunk_entries is None:               # the segmentation's own bound, if it states one
        chunk_entries = getattr(points, "chunk_entries", None)
    parts = chunks(ic.e_s, LocalLayout.of(cells).n_loc, second, chunk_entries)
    first = None
    if parts[0] is None:
        first = surf.integrals(points, ic, second, biorth, integrand)
        support = np.bincount(first[0].ravel(), weights=first[2].support.ravel(),
                              minlength=n_s)
    else:
        support = _support(surf, points, ic, n_s, chunk_entries)
    trib = tributary_weights(xs, seg_s, cells[0], 2 * N_GAUSS_ELEMENT - 1, measure,
                             absolute=not measure.unit)
    cp = np.isin(np.arange(n_s), [] if crosspoints is None else crosspoints)
    mask = (support > MASK_TOL * trib) & ~cp
    space = make_space(space) if isinstance(space, str) and biorth else space
    acc = (np.zeros(n_s), Triplets(), Triplets(), Triplets(), Triplets())
    n = xs.shape[0] * (n_s + n_m)
    shapes = ((n_s, n), (n, n), (n_s, n_s), (n_s, n_m))
    summed: list = [None] * 4
    for i, rows in enumerate(parts):
        sub = _take(ic, rows)
        S, loc, ints = first if rows is None else surf.integrals(points, sub, second, biorth,
                                                                  integrand)
        _chunk(surf, sub, S, loc, ints, mask, space if biorth else None, lam, tangent, acc)
        _sum_chunk(acc[1:], shapes, summed, last=i == len(parts) - 1)
    G, H, D, M = (sp.csr_matrix(shape) if m is None else m for m, shape in zip(summed, shapes))
    info = {"D": D, "M": M, "segmentation": ic.data[0] if isinstance(ic.data, tuple) else ic.data,
            "n_segments": ic.e_s.size, "normals": nn}
    return ContactEval(g=acc[0], G=G if tangent else None, H=H if second else None,
                       area=support, mask=mask, info=info)


def _sum_chunk(trips: tuple, shapes: tuple, summed: list, last: bool = False) -> None:
    """The chunks' triplets summed into csr and emptied once they hold at least half as
    many entries as the running sum (and at the ``last`` chunk): the peak memory is a
    chunk's triplets and about twice the running sums, not every chunk's triplets
    (measured: 2.5 GB at 400 hertz3d faces before, flat at 0.58 GB after), and each entry
    of the sum is copied a bounded number of times on average (a sum at every chunk copies
    the whole running sum each time: quadratic in the chunks).  Half: a triplet takes 24
    bytes, a csr entry 12, and with the repeated dofs summed before the scatter
    (:func:`_distinct`) a chunk adds few duplicates, so the held triplets would otherwise
    grow to twice the sum's bytes (test_memory3d's mortar peak 38.6 -> 39.1 MiB at four
    times the faces; 38.6 with half)."""
    for k, (t, shape) in enumerate(zip(trips, shapes)):
        if t.r and (last or summed[k] is None or 2 * sum(v.size for v in t.v) >= summed[k].nnz):
            m = t.csr(shape)
            summed[k] = m if summed[k] is None else summed[k] + m
            t.r.clear(), t.c.clear(), t.v.clear()


def _support(surf: _Surfaces, points, ic: IntegrationCells, n_s: int, entries) -> np.ndarray:
    """The nodes' supports ``int N_A w dGamma`` (D's row sums) by a first-order pass in
    chunks (the mask needs them before any chunk is combined)."""
    support = np.zeros(n_s)
    for rows in chunks(ic.e_s, LocalLayout.of(surf.cells).n_loc, False, entries):
        S, _, ints = surf.integrals(points, _take(ic, rows), False, False)
        support += np.bincount(S.ravel(), weights=ints.support.ravel(), minlength=n_s)
    return support


def _chunk(surf: _Surfaces, ic: IntegrationCells, S, loc, ints, mask, space, lam, tangent,
           acc) -> None:
    """One chunk of whole slave cells: groups, merge ``T``, (dual) ``A~``, ``g_A``, the
    scatter of ``g``, ``G``, ``H``, ``D``, ``M`` into ``acc``."""
    grp = groups(ic.e_s, loc.layout, each=space is None)
    seg_s = surf.seg_s
    merged = ~mask[seg_s[grp.e_s]]
    k = seg_s.shape[1]
    T = (merge_nodes(merged, surf.cells[0]) if merged.any()
         else np.broadcast_to(np.eye(k), (grp.e_s.size, k, k)))
    rowwise = isinstance(ints.g[0], (list, tuple))
    if rowwise:                       # f[A][B] (the slip's): g_A = sum_B C_AB f[A][B]
        sums = [group_sums(row, grp) for row in ints.g]
        Gs = ([_combine(T, row) for row in sums] if space is not None
              else [_row(T, a, row) for a, row in enumerate(sums)])
    else:
        Gs = _combine(T, group_sums(ints.g, grp))
    C, q = T, None
    if space is not None and rowwise:
        A, C = _biorthogonal(ints, grp, T, space)
        Gs = [_row(A, a, row) for a, row in enumerate(Gs)]
    elif space is not None:
        A, C = _biorthogonal(ints, grp, T, space)
        if lam is not None and Gs[0].h is not None:
            # q = sum_A lam_A sum_B A_AB G_B = sum_B mu_B G_B, mu_B = sum_A lam_A A_AB: k
            # second-order products instead of k^2; g_A themselves to first order
            lamS = np.asarray(lam, dtype=float)[seg_s[grp.e_s]]
            mu = [sum((A[a, b] * lamS[:, a] for a in range(1, k)), A[0, b] * lamS[:, 0])
                  for b in range(k)]
            q = sum((mu[b] * Gs[b] for b in range(1, k)), mu[0] * Gs[0])
            A = {key: a.first() for key, a in A.items()}
            Gs = [j.first() for j in Gs]
        Gs = _combine(A, Gs)
    out, trip, th, tD, tM = acc
    n_s = surf.xs.shape[1]
    _scatter(Gs, grp, seg_s, surf.seg_m, ic.e_m, surf.nn, n_s, lam, tangent, out, trip, th, q)
    Ci = C[grp.cell]
    tD.outer(S, S, np.einsum("nab,nbc->nac", Ci, ints.D))
    tM.outer(S, surf.seg_m[ic.e_m], np.einsum("nab,nbc->nac", Ci, ints.M))


