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
4. per slave cell ``e`` (its integration cells side by side,
   :func:`~skfem_mortar.contact.mortar_groups.groups`: the variables
   ``[x_s, n_s, x_m of each integration cell]``): the sums ``G_B = sum_cells g~_B`` and the
   multiplier functions ``Phi_A = sum_B C_AB N_B``, ``C = T`` (standard) or ``C = A~ T`` (dual,
   ``A~ = D~_e M~_e^-1`` of the modified functions ``N~ = T N`` summed over the cell's
   integration cells: each lies in one smooth piece, so piecewise cells integrate
   exactly), ``T`` the crosspoint/boundary merge; ``g_A = sum_B C_AB G_B``;
5. :func:`~skfem_mortar.contact.mortar_groups.assemble`: ``G = G_loc J``,
   ``H = J^T H_loc J + sum_(a, i) df/dn_ai d2n_ai/dx2``, each group's repeated dofs summed,
   scattered once through :class:`~skfem_mortar.contact.scatter.Triplets`.

A slave node is masked when its support ``int N_A w dGamma`` is at most the space's
``mask_tolerance`` (:func:`~.multiplier_spaces.mask_tolerance`) of its
tributary weight (and crosspoints are): its function is merged into its neighbours'
by the one rule read from the cell's edges
(:func:`~skfem_mortar.contact.mortar_support.merge_nodes`).

The integration cells go through steps 2 to 5 in chunks of whole slave cells
(:func:`chunks`, at most :data:`CHUNK_ENTRIES` derivative entries each), appending to
one set of triplets; with more than one chunk the supports (for the mask) come first,
from a first-order pass.  With ``H`` asked, the slave cells whose nodes all carry a zero
multiplier go first order, in a pass of their own (:func:`passes`: ``H`` has no term
from them).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from .cell_map import check_connectivity
from .cells import cell_type
from ..core.errors import ContactSizeError
from .contact_eval import ContactEval, LazyInfo
from .integration_points import IntegrationCells, LocalLayout, LocalVariables
from .jets import Jet
from .line_points import LineSegmentation
from .measures import PLANE, Measure
from .mortar import biorthogonal
from .mortar_cells import cell_integrals
from .mortar_groups import Groups, group_sums, groups, scatter_groups
from .mortar_support import N_GAUSS_ELEMENT, merge_nodes, tributary_weights
from .multiplier_spaces import make_space, mask_tolerance
from .normals import NodalNormals, mirror_of_axis, nodal_normals
from .scatter import Triplets
from .segmentation import Segmentation, line_cells

__all__ = ["evaluate", "chunks", "passes", "CHUNK_ENTRIES", "GROUP_ENTRIES", "BUCKET_SLOTS"]

CHUNK_ENTRIES = 250_000
"""Derivative entries per chunk of integration cells (``nv^2`` each with Hessians):
one Hessian jet at ``n_gp`` points of a chunk takes at most ``8 n_gp CHUNK_ENTRIES``
bytes (2 MB a point: 18 MB for a 9-point quad4/quad4 chunk of 192 cells, ``nv = 36``;
a 2D line2 chunk holds 1,736 cells, so the usual 2D call is one chunk)."""


def _row(C, a: int, jets: list):
    """``sum_b C[:, a, b] jets[b]`` (``C`` values ``(n, k, k)`` or a dict of jets; None:
    the identity, ``jets[a]`` itself: no product by 1)."""
    if C is None:
        return jets[a]
    acc = None
    for b in range(len(jets)):
        c = C[a, b] if isinstance(C, dict) else C[:, a, b]
        if not isinstance(c, Jet) and not np.any(c):
            continue
        t = jets[b] * c
        acc = t if acc is None else acc + t
    return acc if acc is not None else jets[0] * 0.0


def _combine(C, jets: list) -> list:
    """``sum_b C[:, a, b] jets[b]`` for each ``a`` (``C`` values ``(n, k, k)`` or a dict of
    jets; None: the identity)."""
    return [_row(C, a, jets) for a in range(len(jets))]


def _biorthogonal(ints, grp: Groups, T: np.ndarray, space, reference=None
                  ) -> tuple[dict, np.ndarray]:
    """``A~ = D~ M~^-1`` of ``N~ = T N`` over each slave cell's integration cells (jets);
    ``reference``: the slave cell type when every cell is covered whole (the reference
    cell's mass, constant jets: :func:`_reference_mass`); ``T`` None: no node merged (the
    sums themselves, bit for bit what the identity's products by 1 and 0 give)."""
    if reference:
        nA, nAB = _reference_mass(reference, grp, ints.g)
        k = len(nA)
    else:
        k = len(ints.n_A)
        sums = group_sums(ints.n_A + list(ints.n_AB.values()), grp)
        nA, nAB = sums[:k], dict(zip(ints.n_AB, sums[k:]))
    if T is None:                       # nAB holds the upper triangle cell_coefficients reads
        A = space.cell_coefficients(nA, nAB)
        return A, _values(A, k)
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
    return A, np.matmul(_values(A, k), T)


def _values(A: dict, k: int) -> np.ndarray:
    """The values ``(n, k, k)`` of the jets ``A[(a, b)]``."""
    return np.stack([np.stack([A[a, b].v for b in range(k)], -1) for a in range(k)], 1)


def _reference_mass(cell, grp: Groups, g: list) -> tuple[list, dict]:
    """``int N_A`` and ``int N_A N_B`` over the reference cell (exact rule of degree
    ``2 order``) as constant jets of the groups' variables (the Jacobian of an affine
    cell is a constant factor, which ``D~ M~^-1`` cancels)."""
    X, w = cell.quadrature(2 * cell.order)
    N = cell.shape(X)                                        # (k, nq)
    n_e = grp.e_s.size
    second = (g[0][0] if isinstance(g[0], (list, tuple)) else g[0]).h is not None

    def const(v):
        return Jet.constant(np.full(n_e, float(v)), grp.nv, second)
    nA = [const(N[a] @ w) for a in range(cell.n_nodes)]
    nAB = {(a, b): const((N[a] * N[b]) @ w) for a in range(cell.n_nodes)
           for b in range(a, cell.n_nodes)}
    return nA, nAB


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


def passes(e_s: np.ndarray, seg_s: np.ndarray, lam: np.ndarray | None, nv: int,
           entries: int | None = None) -> tuple[list, bool]:
    """The passes of one call over its integration cells (slave cells ``e_s``): a list of
    ``(rows, second)`` (rows None: all; :func:`chunks` of each), and whether each pass is
    one chunk.  ``lam`` (None: no ``H``): only the slave cells with a nonzero multiplier at
    one of their nodes carry Hessians, in a first pass; the others go first order, in a
    second.  ``H = sum_A lam_A d2g_A/dx2`` has no term from them: ``g_A`` of a node ``A``
    sums the cells of the slave cells at ``A`` (merges and dual coefficients mix the nodes
    of one slave cell only), so theirs would add exact zeros (measured: 60 % of the seed
    scene's cells over its run, whose Hessians were 60 % of its kernel time)."""
    if lam is None or not e_s.size:
        subsets = [(None, lam is not None)]
    else:
        hot = (np.asarray(lam) != 0)[seg_s[e_s]].any(axis=1)   # NaN != 0: hot
        subsets = ([(None, bool(hot[0]))] if hot.all() or not hot.any() else
                   [(np.flatnonzero(hot), True), (np.flatnonzero(~hot), False)])
    plan, small = [], True
    for sel, second in subsets:
        if sel is None:                      # all cells: the chunks' rows as they are
            parts = chunks(e_s, nv, second, entries)
            rows = parts
        else:                                # chunks of the subset, back in the call's rows
            parts = chunks(e_s[sel], nv, second, entries)
            rows = [sel if r is None else sel[r] for r in parts]
        small = small and parts[0] is None
        plan += [(r, second) for r in rows]
    return plan, small


def _supports(pre: list, rows: list, n_s: int) -> np.ndarray:
    """The supports ``int N_A w dGamma`` from the passes' integrals ``pre`` (rows ``rows``
    of the call's cells, None: all), summed in the cells' order (as one pass would)."""
    if rows[0] is None:
        return np.bincount(pre[0][0].ravel(), weights=pre[0][2].support.ravel(), minlength=n_s)
    order = np.argsort(np.concatenate(rows), kind="stable")
    S = np.concatenate([p[0] for p in pre])[order]
    w = np.concatenate([p[2].support for p in pre])[order]
    return np.bincount(S.ravel(), weights=w.ravel(), minlength=n_s)


GROUP_ENTRIES = 2 ** 25
"""Most Hessian entries ``nv^2`` of one slave cell's group jets (``nv`` its variables,
``d (2 k_s + m k_m)`` for ``m`` integration cells): 2^25 is 268 MB a jet (a tri3 face under
about 480 quad4 faces; a dual space sums nine such jets).  Beyond it :func:`evaluate`
raises :class:`~skfem_mortar.core.errors.ContactSizeError` (a failed Newton iteration:
met where an iterate pushed a graded sphere through the plane, ``hertz3d`` tet1 at
refine -1, 2,160 integration cells under one slave face; before, the process ran out of
memory).  Only groups that carry Hessians are bounded; first order needs ``nv``."""


BUCKET_SLOTS = 4
"""A dual space's groups of slave cells with at most this many integration cells share
one bucket (:func:`_buckets`); more: a bucket per power of two."""


def _buckets(e_s: np.ndarray) -> list:
    """A chunk's rows split by the number of integration cells of their slave cell:
    a dual space's groups hold ``m`` slots, the most of any slave cell among them, so
    one slave cell under 31 master cells made every group's jets 132 variables wide
    (hertz refine=3).  Buckets: at most :data:`BUCKET_SLOTS` cells, then 5-8, 9-16, ...;
    ``[None]``: one bucket, all rows (the integrals are made for the whole chunk, only
    the groups are split, so the chunk's memory is as without buckets)."""
    if not e_s.size:
        return [None]
    count = np.bincount(e_s)[e_s]
    bucket = np.ceil(np.log2(np.maximum(count, BUCKET_SLOTS))).astype(np.int64)
    if np.all(bucket == bucket[0]):
        return [None]
    return [np.flatnonzero(bucket == b) for b in np.unique(bucket)]


def _rows(r, ic: IntegrationCells, S, loc, ints) -> tuple:
    """Rows ``r`` (None: all) of one chunk's cells, slave nodes and integrals (jets, lists
    and dicts of jets, arrays by their first axis)."""
    if r is None:
        return ic, S, loc, ints

    def take(x):
        if x is None:
            return None
        if isinstance(x, Jet):
            return x.take(r)
        if isinstance(x, (list, tuple)):
            return [take(y) for y in x]
        if isinstance(x, dict):
            return {key: take(y) for key, y in x.items()}
        return x[r]
    return (_take(ic, r), S[r], loc,
            ints._replace(**{f: take(getattr(ints, f)) for f in ints._fields}))


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
    plan, small = passes(ic.e_s, seg_s, lam if second else None, LocalLayout.of(cells).n_loc,
                         chunk_entries)
    whole = getattr(points, "whole_cells", None)
    whole = whole(ic) if whole is not None and biorth and measure.unit else None
    reference = whole is not None and bool(whole.all()) and ic.e_s.size > 0
    mass = biorth and not reference          # the reference cell's mass: no mass jets
    pre = None
    if small:                                # every pass one chunk: their integrals first
        pre = [surf.integrals(points, _take(ic, rows), sec, mass, integrand)
               for rows, sec in plan]
        support = _supports(pre, [rows for rows, _ in plan], n_s)
    else:
        support = _support(surf, points, ic, n_s, chunk_entries)
    trib = tributary_weights(xs, seg_s, cells[0], 2 * N_GAUSS_ELEMENT - 1, measure,
                             absolute=not measure.unit)
    cp = np.isin(np.arange(n_s), [] if crosspoints is None else crosspoints)
    mask = (support > mask_tolerance(space, cells[0].dim) * trib) & ~cp
    space = make_space(space) if isinstance(space, str) and biorth else space
    acc = (np.zeros(n_s), Triplets(), Triplets(), Triplets(), Triplets())
    n = xs.shape[0] * (n_s + n_m)
    shapes = ((n_s, n), (n, n), (n_s, n_s), (n_s, n_m))
    summed: list = [None] * 4
    for i, (rows, sec) in enumerate(plan):
        sub = _take(ic, rows)
        S, loc, ints = pre[i] if small else surf.integrals(points, sub, sec, mass, integrand)
        for r in _buckets(sub.e_s) if biorth else [None]:
            _chunk(surf, *_rows(r, sub, S, loc, ints), mask, space if biorth else None, lam,
                   tangent, acc, reference)
        if not small or i == len(plan) - 1:  # small: one sum (a csr conversion) at the end
            _sum_chunk(acc[1:], shapes, summed, last=i == len(plan) - 1, lazy=(2, 3))
    G, H = (sp.csr_matrix(shape) if m is None else m for m, shape in zip(summed[:2], shapes))
    info = LazyInfo({"segmentation": ic.data[0] if isinstance(ic.data, tuple) else ic.data,
                     "n_segments": ic.e_s.size, "normals": nn},
                    lazy={"D": _last_sum(acc[3], shapes[2], summed[2]),
                          "M": _last_sum(acc[4], shapes[3], summed[3])})
    return ContactEval(g=acc[0], G=G if tangent else None, H=H if second else None,
                       area=support, mask=mask, info=info)


def _sum_chunk(trips: tuple, shapes: tuple, summed: list, last: bool = False,
               lazy: tuple = ()) -> None:
    """The chunks' triplets summed into csr and emptied once they hold at least half as
    many entries as the running sum (and at the ``last`` chunk): the peak memory is a
    chunk's triplets and about twice the running sums, not every chunk's triplets
    (measured: 2.5 GB at 400 hertz3d faces before, flat at 0.58 GB after), and each entry
    of the sum is copied a bounded number of times on average (a sum at every chunk copies
    the whole running sum each time: quadratic in the chunks).  Half: a triplet takes 24
    bytes, a csr entry 12, and with the repeated dofs summed before the scatter
    (:mod:`~.mortar_groups`) a chunk adds few duplicates, so the held triplets would otherwise
    grow to twice the sum's bytes (test_memory3d's mortar peak 38.6 -> 39.1 MiB at four
    times the faces; 38.6 with half).  The ``lazy`` ones' last sum is left to
    :func:`_last_sum`."""
    for k, (t, shape) in enumerate(zip(trips, shapes)):
        if last and k in lazy:
            continue
        if t.r and (last or summed[k] is None or 2 * sum(v.size for v in t.v) >= summed[k].nnz):
            m = t.csr(shape)
            summed[k] = m if summed[k] is None else summed[k] + m
            t.r.clear(), t.c.clear(), t.v.clear()


def _last_sum(t: Triplets, shape: tuple, prev):
    """:func:`_sum_chunk`'s last sum of ``t`` onto ``prev`` (None: nothing summed yet), as
    a function made when called: ``D`` and ``M`` (:class:`~.contact_eval.LazyInfo`), which a
    Newton step does not read (two of a small call's four sparse conversions)."""
    def make() -> sp.csr_matrix:
        if not t.r:
            return sp.csr_matrix(shape) if prev is None else prev
        m = t.csr(shape)
        return m if prev is None else prev + m
    return make


def _support(surf: _Surfaces, points, ic: IntegrationCells, n_s: int, entries) -> np.ndarray:
    """The nodes' supports ``int N_A w dGamma`` (D's row sums) by a first-order pass in
    chunks (the mask needs them before any chunk is combined)."""
    support = np.zeros(n_s)
    for rows in chunks(ic.e_s, LocalLayout.of(surf.cells).n_loc, False, entries):
        S, _, ints = surf.integrals(points, _take(ic, rows), False, False)
        support += np.bincount(S.ravel(), weights=ints.support.ravel(), minlength=n_s)
    return support


def _check_size(grp: Groups, second: bool) -> None:
    """:class:`~skfem_mortar.core.errors.ContactSizeError` if the groups' Hessian jets
    (``second``) would exceed :data:`GROUP_ENTRIES` entries a group."""
    if second and grp.nv ** 2 > GROUP_ENTRIES:
        raise ContactSizeError(
            f"a slave cell lies under {grp.m} master cells: its jets would take "
            f"{8 * grp.nv ** 2 / 2 ** 20:.3g} MB each (more than GROUP_ENTRIES = {GROUP_ENTRIES} "
            f"entries); an iterate far from the solution, or a slave surface far coarser than "
            f"its master (make the finer surface the slave)")


def _chunk(surf: _Surfaces, ic: IntegrationCells, S, loc, ints, mask, space, lam, tangent,
           acc, reference: bool = False) -> None:
    """One chunk of whole slave cells: groups, merge ``T``, (dual) ``A~``, ``g_A``, the
    scatter of ``g``, ``G``, ``H``, ``D``, ``M`` into ``acc``."""
    grp = groups(ic.e_s, loc.layout, each=space is None)
    seg_s = surf.seg_s
    merged = ~mask[seg_s[grp.e_s]]
    k = seg_s.shape[1]
    T = merge_nodes(merged, surf.cells[0]) if merged.any() else None   # None: identity
    rowwise = isinstance(ints.g[0], (list, tuple))
    _check_size(grp, (ints.g[0][0] if rowwise else ints.g[0]).h is not None)
    if rowwise:                       # f[A][B] (the slip's): g_A = sum_B C_AB f[A][B]
        sums = [group_sums(row, grp) for row in ints.g]
        Gs = ([_combine(T, row) for row in sums] if space is not None
              else [_row(T, a, row) for a, row in enumerate(sums)])
    else:
        Gs = _combine(T, group_sums(ints.g, grp))
    C, q = T, None
    if space is not None and rowwise:
        A, C = _biorthogonal(ints, grp, T, space, reference and surf.cells[0])
        Gs = [_row(A, a, row) for a, row in enumerate(Gs)]
    elif space is not None:
        A, C = _biorthogonal(ints, grp, T, space, reference and surf.cells[0])
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
    scatter_groups(Gs, grp, seg_s, surf.seg_m, ic.e_m, surf.nn, n_s, lam, tangent, out, trip, th,
                   q)
    D, M = ints.D, ints.M               # C None: the identity
    if C is not None:
        Ci = C[grp.cell]
        D, M = np.einsum("nab,nbc->nac", Ci, D), np.einsum("nab,nbc->nac", Ci, M)
    tD.outer(S, S, D)
    tM.outer(S, surf.seg_m[ic.e_m], M)


