"""The fixed CSR pattern of the tangent and its reuse.

:class:`_Pattern` is the union of the items' sorted triplet keys
``row * n + col``, where each triplet goes and the cached gather of the free
block; :func:`_unique_keys`, :func:`_element_keys`, :func:`_union` and
:func:`_merge` find and join the keys.  Used by
:meth:`skfem_mortar.core.model.Model._tangent` and
:meth:`~skfem_mortar.core.model.Model.free_block`.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .coo import element_coo
from .item import Contribution


def _cat(arrays: list[np.ndarray], dtype) -> np.ndarray:
    return np.concatenate(arrays) if arrays else np.zeros(0, dtype=dtype)


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a is b or (a.shape == b.shape and np.array_equal(a, b))


def _unique_keys(rows: np.ndarray, cols: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Sorted unique keys ``row * n + col`` of triplets and the place of each
    triplet among them (``keys[inv] == row * n + col``).

    Our own counting sort instead of ``np.argsort`` of the keys: scipy's
    ``coo_tocsr`` buckets the triplet numbers by row (linear) and
    ``csr_sort_indices`` sorts each short row; the duplicates are then
    neighbours in each row, so no key of a triplet is formed (measured at
    6.1e6 triplets of hertz ``refine=3``: 0.30 s against 0.46 s for the
    same sort forming a key per triplet); ``np.unique`` where scipy's
    kernels are not there."""
    try:
        from scipy.sparse import _sparsetools
        coo_tocsr, sort_rows = _sparsetools.coo_tocsr, _sparsetools.csr_sort_indices
    except (ImportError, AttributeError):  # pragma: no cover (a scipy without them)
        keys, inv = np.unique(rows.astype(np.int64) * n + cols, return_inverse=True)
        return keys, inv.ravel()
    m = rows.size
    itype = np.int32 if max(n, m) < 2**31 - 1 else np.int64
    indptr = np.empty(n + 1, dtype=itype)
    indices = np.empty(m, dtype=itype)
    ids = np.empty(m, dtype=np.int64)  # each triplet's number, in row-major order
    coo_tocsr(n, n, m, rows.astype(itype, copy=False), cols.astype(itype, copy=False),
              np.arange(m, dtype=np.int64), indptr, indices, ids)
    sort_rows(n, indptr, indices, ids)
    new = np.empty(m, dtype=bool)  # a triplet that starts a key
    new[:1] = True
    np.not_equal(indices[1:], indices[:-1], out=new[1:])
    starts = indptr[:-1]
    new[starts[starts < m]] = True
    # (a cumsum of int8 is 7x faster than one of bool, which goes through a cast)
    count = np.cumsum(new.view(np.int8), dtype=np.int64)
    inv = np.empty(m, dtype=np.int64)
    inv[ids] = count - 1
    per_row = np.diff(np.concatenate([[0], count])[indptr.astype(np.int64)])
    keys = np.repeat(np.arange(n, dtype=np.int64) * n, per_row) + indices[new]
    return keys, inv


def _item_keys(c: Contribution, n: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_unique_keys` of an item's triplets, per node when it says how
    they were made (:attr:`Contribution.k_elements`)."""
    if c.k_elements is not None:
        return _element_keys(np.asarray(c.k_elements, dtype=np.int64), n)
    return _unique_keys(c.k_rows, c.k_cols, n)


def _element_keys(D: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_unique_keys` of ``element_coo(D, elements_last=True)``.

    Vector elements number their local dofs ``2 a + i`` and the global ones
    ``r0 + 2 s + i`` (``s`` the node, ``i`` the component): then the keys
    are those of the nodes' element triplets (a quarter as many) with each
    node pair ``(p, q)`` spread into its 2 x 2 dof pairs, row ``r0 + 2 p + i``
    holding the columns ``r0 + 2 q + k`` of the node row ``p`` in order.
    Other numberings go to :func:`_unique_keys`."""
    r = D[0::2]
    r0 = int(r.min()) if r.size else 0
    if (not r.size or D.shape[0] % 2 or not np.array_equal(D[1::2], r + 1)
            or np.any((r - r0) % 2)):
        return _unique_keys(*element_coo(D, elements_last=True), n)
    S = (r - r0) // 2                                    # (n_nodes_loc, n_el) nodes
    nn = int(S.max()) + 1
    node_keys, node_inv = _unique_keys(*element_coo(S, elements_last=True), nn)
    p, q = np.divmod(node_keys, nn)
    count = np.bincount(p, minlength=nn)
    first = np.cumsum(count) - count                     # each node row's first key
    # the dof key of node key t, components i, k: 2 t + 2 first[p] + 2 i count[p] + k
    at = 2 * np.arange(p.size) + 2 * first[p]
    keys = np.empty(4 * p.size, dtype=np.int64)
    for i in (0, 1):
        for k in (0, 1):
            keys[at + 2 * i * count[p] + k] = (r0 + 2 * p + i) * n + r0 + 2 * q + k
    b, e = S.shape
    base = 2 * node_inv.reshape(b, b, e) + (2 * first[S])[:, None, :]      # (a, b, e)
    inv = np.empty((b, 2, b, 2, e), dtype=np.int64)  # local dofs (2 a + i, 2 b + k)
    for i in (0, 1):
        shift = (2 * i * count[S])[:, None, :]
        for k in (0, 1):
            np.add(base, shift + k, out=inv[:, i, :, k, :])
    return keys, inv.reshape(-1)


def _union(sorted_keys: list[np.ndarray]) -> tuple[np.ndarray, list[np.ndarray]]:
    """The sorted union of sorted unique key arrays, and the place of each
    array's keys in it.

    The keys the largest array lacks are inserted into it (a search of the
    others in it; their own union by :func:`_merge`), so the usual case, a
    body's pattern and a contact pair's few keys, costs a copy of the body's
    keys, not a sort of all of them."""
    if not sorted_keys:
        return np.zeros(0, dtype=np.int64), []
    big = int(np.argmax([k.size for k in sorted_keys]))
    base = sorted_keys[big]
    rest = _merge([k for i, k in enumerate(sorted_keys) if i != big])
    pos = np.searchsorted(base, rest)
    found = pos < base.size
    found[found] = base[pos[found]] == rest[found]
    at = pos[~found]
    union = np.insert(base, at, rest[~found])
    places = []
    for i, k in enumerate(sorted_keys):
        if i != big:
            places.append(np.searchsorted(union, k))
        elif at.size:  # the places the inserted keys leave free
            free = np.ones(union.size, dtype=bool)
            free[at + np.arange(at.size)] = False
            places.append(np.flatnonzero(free))
        else:
            places.append(np.arange(base.size))
    return union, places


def _merge(sorted_keys: list[np.ndarray]) -> np.ndarray:
    """The sorted union of sorted unique key arrays (a stable sort merges the
    runs; ``np.unique`` hashes, which measured ten times slower here)."""
    if len(sorted_keys) <= 1:
        return sorted_keys[0] if sorted_keys else np.zeros(0, dtype=np.int64)
    k = np.sort(np.concatenate(sorted_keys), kind="stable")
    new = np.ones(k.size, dtype=bool)
    new[1:] = k[1:] != k[:-1]
    return k[new]


def _readonly(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


class _Pattern:
    """A fixed CSR pattern of the triplets of some items, where each triplet goes,
    and the gathers of its free block.

    Each item's sorted unique keys ``row * n + col`` (and the place of each of
    its triplets among them) are computed once per index arrays (taken from
    ``previous`` when the arrays are the same); the pattern is their union,
    ``indices`` and ``indptr`` read-only.  ``where[j]`` holds the place of the
    triplets of the ``j``-th item (of the first among its own keys, which
    ``_spread`` places): kept per item, so that neither the places nor the
    values are concatenated (:meth:`matrix`).
    """

    def __init__(self, items: tuple[int, ...], parts: list[Contribution], n: int,
                 previous: "_Pattern | None" = None):
        self.items = items
        self.idx = [(p.k_rows, p.k_cols) for p in parts]
        known = {} if previous is None else dict(zip(previous.items, zip(previous.idx,
                                                                        previous.local)))
        self.local = []
        for i, p in zip(items, parts):
            old = known.get(i)
            if old is not None and _same(old[0][0], p.k_rows) and _same(old[0][1], p.k_cols):
                self.local.append(old[1])
            else:
                self.local.append(_item_keys(p, n))
        keys, places = _union([uk for uk, _ in self.local])
        # the first item's values are summed among its own keys and then spread
        # to their places (no gather of a place per triplet: at hertz refine=3,
        # 6e6 triplets, that measured 0.2 s a build); the others' places per triplet
        self._spread = None if places[0].size == keys.size else places[0]
        self.where = [self.local[0][1]] + [pl[inv] for pl, (_, inv)
                                           in zip(places[1:], self.local[1:])]
        self.nnz = keys.size
        itype = np.int32 if n < 2**31 else np.int64
        # each row's first key by a search, not a division of every key (3x faster)
        indptr = np.searchsorted(keys, np.arange(n + 1, dtype=np.int64) * n)
        row_keys = np.repeat(np.arange(n, dtype=np.int64) * n, np.diff(indptr))
        self.indices = _readonly(np.subtract(keys, row_keys).astype(itype))
        self.indptr = _readonly(indptr.astype(itype))
        self.n = n
        self.last: sp.csr_matrix | None = None  # the last matrix made
        self._free: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None

    def matrix(self, vals: list[np.ndarray]) -> sp.csr_matrix:
        """The matrix of the items' values ``vals`` (one array per item).

        The sum of the triplets in their order, as one ``bincount`` of all
        of them would add them: the first item's by ``bincount`` (among its
        own keys, spread to theirs), every further item's added in order by
        ``np.add.at`` (the same sums, to the last bit, without concatenating
        the values)."""
        if self._spread is None:
            data = np.bincount(self.where[0], weights=vals[0], minlength=self.nnz)
        else:
            data = np.zeros(self.nnz)
            data[self._spread] = np.bincount(self.where[0], weights=vals[0],
                                             minlength=self._spread.size)
        for where, v in zip(self.where[1:], vals[1:]):
            np.add.at(data, where, v)
        K = sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))
        K.has_sorted_indices = True
        self.last = K
        return K

    def restrict(self, K: sp.csr_matrix, free: np.ndarray) -> sp.csr_matrix:
        """``K[free][:, free]`` of a matrix of this pattern, by a cached gather."""
        if self._free is None or not np.array_equal(self._free[0], free):
            M = sp.csr_matrix((np.arange(1.0, self.nnz + 1.0), self.indices, self.indptr),
                              shape=(self.n, self.n))[free][:, free]
            M.sort_indices()
            self._free = (free.copy(), M.data.astype(np.int64) - 1,
                          _readonly(M.indices), _readonly(M.indptr))
        _, gather, indices, indptr = self._free
        Kf = sp.csr_matrix((K.data[gather], indices, indptr), shape=(free.size, free.size))
        Kf.has_sorted_indices = True
        return Kf
