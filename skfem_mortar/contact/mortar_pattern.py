"""The mortar method's reserved tangent pattern, for any dimension and cell type.

The weighted gap ``g_A`` sums over the integration cells of the slave cells at ``A``;
a cell's integrals depend on its nodes, on the nodal normals of its nodes (each an
average over the cells at that node: :func:`~skfem_mortar.contact.normals.nodal_normals`,
so over the nodes of every slave cell that shares a node with it) and on the master
cell it is paired with.  So row ``A`` of ``G`` (and of ``H``'s rows, the same
couplings) holds:

* ``A``'s own dofs;
* for each slave cell ``e`` at ``A``: the nodes of every slave cell sharing a node with
  ``e`` (``e``'s nodal-normal stencil; line2 chains: the nodes ``p, a, b, n`` of ``e =
  (a, b)`` and its neighbours), every cell, held pair or not (local, cheap: the slave
  part never grows, so against a rigid master the pattern repeats from the first
  iteration on);
* the nodes of the master cells held with ``e`` (the reservation's pairs).

Each node has ``d`` dofs, ``d`` the coordinates' rows; slave node ``A``'s are
``d A + c``, master node ``C``'s ``d n_s + d C + c``.  With ``Q`` the slave cells'
node incidence (``n_cell x n_s``) and ``P`` the held pairs' master node incidence
(``n_cell x n_m``), the node pattern is ``[I + Q^T (Q Q^T) Q, Q^T P]``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .discretization import pattern_matrix

__all__ = ["stencil_pattern"]


def _incidence(owner: np.ndarray, nodes: np.ndarray, shape: tuple[int, int]) -> sp.csr_matrix:
    """0/1 ``(n_cell, n_nodes)`` with ones at ``(owner[i], nodes[i, j])``."""
    k = nodes.shape[1] if nodes.ndim == 2 else 1
    return sp.csr_matrix((np.ones(nodes.size), (np.repeat(owner, k), nodes.ravel())),
                         shape=shape)


def stencil_pattern(seg_s: np.ndarray, n_s: int, seg_m: np.ndarray, n_m: int,
                    e_s: np.ndarray, e_m: np.ndarray, d: int) -> sp.csr_matrix:
    """The pattern ``(n_s, d (n_s + n_m))`` of the module docstring: slave cells
    ``seg_s``, master cells ``seg_m``, held pairs ``(e_s, e_m)``, ``d`` dofs a node.

    Parameters
    ----------
    seg_s, seg_m : int ndarray (n_cell, k_s), (n_cell_m, k_m)
    n_s, n_m : int
        Slave and master node counts.
    e_s, e_m : int ndarray (n_held,)
        The held (reserved) cell pairs.
    d : int
        Dofs a node (the coordinates' rows).

    Returns
    -------
    scipy.sparse.csr_matrix
        0/1, sorted, no duplicates (:func:`~.discretization.pattern_matrix`).
    """
    seg_s = np.asarray(seg_s, dtype=np.int64)
    n_cell = seg_s.shape[0]
    Q = _incidence(np.arange(n_cell), seg_s, (n_cell, n_s))
    stencil = (Q @ Q.T) @ Q                                   # cell -> its stencil's nodes
    slave = (Q.T @ stencil).tocoo()                           # node A -> nodes
    P = _incidence(np.asarray(e_s, dtype=np.int64),
                   np.asarray(seg_m, dtype=np.int64)[np.asarray(e_m, dtype=np.int64)],
                   (n_cell, n_m))
    master = (Q.T @ P).tocoo()
    own = np.arange(n_s)
    rows = np.concatenate([slave.row, master.row, own])
    nodes = np.concatenate([slave.col, n_s + master.col, own])
    c = np.arange(d)
    return pattern_matrix(np.repeat(rows, d), (d * nodes[:, None] + c).ravel(),
                          (n_s, d * (n_s + n_m)))
