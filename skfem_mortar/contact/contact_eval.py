"""The result of a contact discretization: gaps and their derivatives.

The kernel of a contact discretization (NTS, mortar) is a pure function of
the current coordinates of a slave and a master surface::

    evaluate(xs, seg_s, xm, seg_m, lam=None, tangent=True, **options) -> ContactEval,

and :class:`ContactEval` is what it returns (also what a
:class:`~skfem_mortar.contact.discretization.ContactDiscretization` returns to the pair).  Local dof order of the surface
pair: slave node k -> 2k (x), 2k + 1 (y); master node j -> 2 n_s + 2j,
2 n_s + 2j + 1; in 3D (``d = 3`` coordinates per node) slave node k -> 3k + c,
master node j -> 3 n_s + 3j + c.

:func:`node_gap_eval` assembles the :class:`ContactEval` of a node-to-segment kernel
from per-node gradients and Hessians (NTS on line cells and on faces alike).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

__all__ = ["ContactEval", "LazyInfo", "node_gap_eval"]


@dataclass
class ContactEval:
    """Gaps of the slave nodes and their first and second derivatives.

    Attributes
    ----------
    g : ndarray (n_s,)
        Gap of each slave node, ``g > 0`` open (NTS: the normal gap g_N;
        mortar: the weighted gap g~_A).  Meaningless where ``mask`` is False.
    G : csr_matrix (n_s, 2 n_s + 2 n_m)
        ``dg/dx`` in the local dof order of the pair.
    H : csr_matrix (2 n_s + 2 n_m, 2 n_s + 2 n_m) or None
        ``sum_A lam_A d^2 g_A / dx^2``; only when ``lam`` was given and a tangent asked.
    area : ndarray (n_s,)
        Tributary length of each slave node (half the lengths of its slave
        segments), used to turn a nodal force into a traction.
    mask : ndarray (n_s,) of bool
        Slave nodes that have a master partner; the others are kept inactive.
    info : dict
        Extra per-node arrays for output and tests (e.g. NTS ``xi``, ``segment``).
    """

    g: np.ndarray
    G: sp.csr_matrix | None
    H: sp.csr_matrix | None
    area: np.ndarray
    mask: np.ndarray
    info: dict = field(default_factory=dict)


class LazyInfo(dict):
    """A :class:`ContactEval`'s ``info`` whose costly entries are made when first read:
    ``lazy`` maps a key to a function of no arguments that makes its value (the mortar
    kernel's ``D`` and ``M``, read by ties, friction and the outputs, not by a Newton
    step).  ``info[key]``, ``key in info``, ``get`` and :meth:`copy` see them; ``keys``
    and ``items`` list the entries made so far."""

    def __init__(self, *args, lazy: dict | None = None, **kwargs):
        super().__init__(*args, **kwargs)
        self._lazy = dict(lazy or {})

    def __missing__(self, key):
        make = self._lazy.pop(key, None)
        if make is None:
            raise KeyError(key)
        value = self[key] = make()
        return value

    def __contains__(self, key) -> bool:
        return super().__contains__(key) or key in self._lazy

    def get(self, key, default=None):
        return self[key] if key in self else default

    def copy(self) -> "LazyInfo":
        """A shallow copy with the entries not made yet (each copy makes its own)."""
        return LazyInfo(self, lazy=self._lazy)



def node_gap_eval(g: np.ndarray, k: np.ndarray, m: np.ndarray, dg: np.ndarray,
                  h: np.ndarray | None, lam: np.ndarray | None, n_m: int, d: int,
                  area: np.ndarray, mask: np.ndarray, info: dict) -> ContactEval:
    """The :class:`ContactEval` of gaps that each depend on one slave node and one
    master cell: ``g (n_s,)``; the nodes ``k (n,)`` with a master, the nodes ``m (n,
    n_nodes)`` of their cells, ``dg (n, nv)`` and ``h (nv, nv, n)`` (or None) the gaps'
    gradients and Hessians in the local order ``[x_k, x_{m_1}, ..., x_{m_n}]`` (``d``
    coordinates each); ``H = sum_k lam_k d^2 g_k``.  ``G`` is ``(n_s, d (n_s + n_m))``."""
    from .scatter import Triplets
    n_s = g.size
    dofs = np.column_stack([d * k + c for c in range(d)]
                           + [d * n_s + d * m[:, a] + c for a in range(m.shape[1])
                              for c in range(d)])
    ndof = d * n_s + d * n_m
    Gt = Triplets()
    Gt.rows(k, dofs, dg)
    H = None
    if h is not None:
        Ht = Triplets()
        Ht.block(dofs, h * lam[k])
        H = Ht.csr((ndof, ndof))
    return ContactEval(g=g, G=Gt.csr((n_s, ndof)), H=H, area=area, mask=mask, info=info)
