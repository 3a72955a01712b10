"""The one mortar kernel's groups: each slave cell's integration cells side by side,
their sums, and the one scatter of the group jets with the nodal normals chained in.

* :class:`Groups` / :func:`groups`: per slave cell ``e`` its integration cells in slots,
  the group variables ``[x_s, n_s, x_m of each slot]``; :func:`group_sums` adds cell jets
  into them;
* :func:`scatter_groups` / :func:`assemble`: ``G = G_loc J``,
  ``H = J^T H_loc J + sum_(a, i) df/dn_ai d2n_ai/dx2`` (``J`` the identity on ``x_s`` and
  ``x_m``, the nodal normals' derivatives on ``n_s``), each group's repeated dofs summed
  onto its distinct dofs (:func:`_distinct`) before the triplets are kept
  (:class:`~skfem_mortar.contact.scatter.Triplets`).

Used by :mod:`~skfem_mortar.contact.mortar_kernel`.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .integration_points import LocalLayout
from .jets import Jet
from .normals import NodalNormals
from .scatter import Triplets

__all__ = ["Groups", "groups", "group_sum", "group_sums", "scatter_groups", "assemble"]


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
    J = len(jets)
    G = np.stack([j.g for j in jets])
    nl = G.shape[1]
    H = np.stack([j.h for j in jets]).reshape(J, nl * nl, -1) if second else None
    g = np.zeros((J, nv, n_e))
    h = np.zeros((J, nv * nv, n_e)) if second else None   # (nv, nv) flat: one index a slot
    for s in range(grp.m):
        sel = np.flatnonzero(grp.slot == s)
        rows, idx = grp.cell[sel], grp.index(s)
        g[:, idx[:, None], rows] += G[:, :, sel]
        if second:
            h[:, (idx[:, None] * nv + idx).ravel()[:, None], rows] += H[:, :, sel]
    return [Jet(np.bincount(grp.cell, weights=j.v, minlength=n_e), g[i],
                None if h is None else h[i].reshape(nv, nv, n_e)) for i, j in enumerate(jets)]


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


def scatter_groups(g: list, grp: Groups, conn_s, conn_m, e_m, normals: NodalNormals, n_s: int,
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
    scatter_groups(g, grp, conn_s, conn_m, e_m, normals, n_s, lam, tangent, out, trip, th)
    if not tangent:
        return out, None, None
    n = grp.layout.d * (n_s + n_m)
    H = th.csr((n, n)) if lam is not None and g[0].h is not None else None
    return out, trip.csr((n_s, n)), H
