"""Dual multipliers on tri3 and quad4 slave faces: the 4 x 4 inverse, the masking rule,
the tributary weights.

The one mortar kernel builds the dual basis of each slave face ``e`` as
``Phi_A = sum_B (A~ T)_AB N_B`` with ``A~ = D~_e M~_e^-1`` of the modified functions
``N~ = T N`` (``D~_e = diag int N~_A``, ``M~_e = int N~_A N~_B`` over the face's
integration cells, the projected part of the face), so that
``int Phi_A N~_B = delta_AB int N~_A``.  This module gives it the three pieces that
surfaces need beyond lines:

* :func:`sym_inverse` — the inverse of a symmetric ``k x k`` matrix by cofactors for
  ``k`` up to 4 (quad4), on arrays or jets, so the derivatives of ``A_e`` follow (the
  2 x 2 minors of the first two and the last two rows: 12 products, then 3 per entry);
* :func:`merge_faces` — ``T`` for faces with masked nodes (the rule below, which is
  :func:`~skfem_mortar.contact.mortar_support.merge_nodes`, one rule for every cell);
* :func:`face_tributary_weights` — ``w_A = int N_A w(x) dGamma`` over the whole slave
  surface, the scale a node's mortar support is masked against.

Fully projected faces: on a flat tri3, ``D_e = A/3 I``, ``M_e = A/12 (1 + I)``
(``1`` the matrix of ones), so ``A_e = 4 I - 1`` and ``Phi_A = 4 N_A - 1``; on a
parallelogram quad4 ``A_e`` has 4 on the diagonal, -2 to the edge neighbours and 1
to the opposite corner, ``Phi_A = 4 N_A - 2 (N_next + N_prev) + N_opposite``
(tests/test_dual3d.py).

The masking rule
----------------
A slave node whose mortar support ``int N_A w dGamma`` over the projected parts of its
faces is at most its space's ``mask_tolerance`` (1e-3 for dual multipliers, 1e-2 for
standard ones: :mod:`~skfem_mortar.contact.multiplier_spaces`, "The masked band") times
its tributary weight is masked (as in 2D: no multiplier, ``g_A = 0``).  On each face, a masked node's shape
function is given to the face's kept nodes nearest to it along the face's edges, in
equal shares: on a tri3 to the other kept corners; on a quad4 to its kept edge
neighbours, else to the opposite corner.  So ``N~_A = N_A + sum_z s_Az N_z`` for a
kept ``A`` (``sum_A s_Az = 1``) and ``N~_z = 0``: the kept ``N~`` still sum to one
on the face, so the dual functions built on them (the dual basis of the reduced node
set, ``A~`` over the projected part) sum to one too, and a masked node's ``Phi`` is
zero.  A quad4 covered along one edge only (its two far corners masked) becomes the
line2 dual basis along that edge: ``N~_0 = N_0 + N_3 = (1 - xi)/2``.  A face with
every node masked carries no multiplier.

Why the masking is not optional: over a strip of relative width ``eps`` along an
edge the far node's ``int N_z`` is ``O(eps^2)``, and the unmasked ``A_e`` grows like
``6 / eps`` on a tri3 (593 at ``eps = 0.01``) and ``12 / eps`` on a quad4; masked, the
coefficients tend to those of the edge's line2 dual basis (2 and -1, within ``2 eps``)
at every width (tests/test_dual3d.py).  The far node's support over its tributary
weight is ``3 eps^2`` (tri3) and ``eps^2`` (quad4), so the dual tolerance 1e-3 masks it
below ``eps`` = 0.018 and 0.032: the largest unmasked coefficient is then about 330 and
380 (about 1e4 under the former tolerance 1e-6, whose kept nodes read their pressure
with errors up to 1e-5).
"""
from __future__ import annotations

import numpy as np

from .cells import CellType, cell_type
from .jets import inv
from .mortar_support import edge_distances, merge_nodes

__all__ = ["sym_inverse", "merge_faces", "face_tributary_weights", "edge_distances"]


def _m(M: dict, a: int, b: int):
    return M[min(a, b), max(a, b)]


def sym_inverse(M: dict, k: int) -> dict:
    """Inverse of the symmetric ``k x k`` matrix given by its upper triangle
    ``M[(a, b)]``, ``a <= b`` (arrays or jets of one shape), by cofactors: returns the
    upper triangle of the inverse.  ``k`` = 1 to 4 (else ValueError naming ``k``).

    For ``k = 4``, with the 2 x 2 minors ``s`` of rows 0, 1 and ``c`` of rows 2, 3::

        det = s01 c23 - s02 c13 + s03 c12 + s12 c03 - s13 c02 + s23 c01,

    and each cofactor three products of a row entry and a minor.
    """
    if k == 1:
        return {(0, 0): inv(M[0, 0])}
    if k == 2:
        a, b, d = M[0, 0], M[0, 1], M[1, 1]
        r = inv(a * d - b * b)
        return {(0, 0): d * r, (0, 1): -(b * r), (1, 1): a * r}
    if k == 3:
        a, b, c, d, e, f = M[0, 0], M[0, 1], M[0, 2], M[1, 1], M[1, 2], M[2, 2]
        C = {(0, 0): d * f - e * e, (0, 1): c * e - b * f, (0, 2): b * e - c * d,
             (1, 1): a * f - c * c, (1, 2): b * c - a * e, (2, 2): a * d - b * b}
        r = inv(a * C[0, 0] + b * C[0, 1] + c * C[0, 2])
        return {key: v * r for key, v in C.items()}
    if k != 4:
        raise ValueError(f"k must be 1, 2, 3 or 4 (the cofactor inverse of tri3 and quad4 "
                         f"faces and of line cells), got {k}")
    m = {(a, b): _m(M, a, b) for a in range(4) for b in range(4)}
    s = {(i, j): m[0, i] * m[1, j] - m[1, i] * m[0, j] for i in range(4) for j in range(i + 1, 4)}
    c = {(i, j): m[2, i] * m[3, j] - m[3, i] * m[2, j] for i in range(4) for j in range(i + 1, 4)}
    det = (s[0, 1] * c[2, 3] - s[0, 2] * c[1, 3] + s[0, 3] * c[1, 2]
           + s[1, 2] * c[0, 3] - s[1, 3] * c[0, 2] + s[2, 3] * c[0, 1])
    r = inv(det)
    C = {(0, 0): m[1, 1] * c[2, 3] - m[1, 2] * c[1, 3] + m[1, 3] * c[1, 2],
         (0, 1): m[0, 2] * c[1, 3] - m[0, 1] * c[2, 3] - m[0, 3] * c[1, 2],
         (0, 2): m[3, 1] * s[2, 3] - m[3, 2] * s[1, 3] + m[3, 3] * s[1, 2],
         (0, 3): m[2, 2] * s[1, 3] - m[2, 1] * s[2, 3] - m[2, 3] * s[1, 2],
         (1, 1): m[0, 0] * c[2, 3] - m[0, 2] * c[0, 3] + m[0, 3] * c[0, 2],
         (1, 2): m[3, 2] * s[0, 3] - m[3, 0] * s[2, 3] - m[3, 3] * s[0, 2],
         (1, 3): m[2, 0] * s[2, 3] - m[2, 2] * s[0, 3] + m[2, 3] * s[0, 2],
         (2, 2): m[3, 0] * s[1, 3] - m[3, 1] * s[0, 3] + m[3, 3] * s[0, 1],
         (2, 3): m[2, 1] * s[0, 3] - m[2, 0] * s[1, 3] - m[2, 3] * s[0, 1],
         (3, 3): m[2, 0] * s[1, 2] - m[2, 1] * s[0, 2] + m[2, 2] * s[0, 1]}
    return {key: v * r for key, v in C.items()}


def merge_faces(merged: np.ndarray, cell: "str | CellType") -> np.ndarray:
    """The masking rule's ``T`` (module docstring): ``N~_A = sum_B T_AB N_B`` per face.

    ``merged`` (n, k) bool: the face's masked (or otherwise multiplier-less) nodes.
    Kept nodes keep their function; a merged node's goes to the kept nodes nearest to
    it along the face's edges (:func:`edge_distances`), in equal shares; merged rows
    are zero.  ``sum_A T_AB = 1`` for every ``B`` unless the whole face is merged.

    Returns
    -------
    T : ndarray (n, k, k)
    """
    cell = cell_type(cell)
    merged = np.asarray(merged, dtype=bool)
    if merged.ndim != 2 or merged.shape[1] != cell.n_nodes or cell.dim != 2:
        raise ValueError(f"merged must have the columns of the face cell {cell.name} "
                         f"({cell.n_nodes} nodes), got shape {merged.shape}")
    return merge_nodes(merged, cell)


def face_tributary_weights(xs: np.ndarray, seg: np.ndarray, cell: "str | CellType",
                           degree: int = 4, measure=None, absolute: bool = False
                           ) -> np.ndarray:
    """``w_A = int N_A w(x) dGamma`` over the whole slave surface of tri3 or quad4
    faces, ``(n_s,)``: the face's rule of ``degree`` (one more for a measure with a
    weight) on ``N_A |T_1 x T_2|``; ``absolute``: ``int |N_A| w dGamma``.  A flat tri3 of
    area ``A`` gives ``A/3`` to each corner, a parallelogram quad4 ``A/4``."""
    cell = cell_type(cell)
    xs = np.asarray(xs, dtype=float)
    seg = np.asarray(seg, dtype=np.int64)
    unit = measure is None or measure.unit
    pts, w = cell.quadrature(degree + (0 if unit else 1))
    N, dN = cell.shape(pts), cell.dshape(pts)                  # (k, q), (k, 2, q)
    X = xs[:, seg]                                             # (3, n, k)
    T = np.einsum("dnk,kaq->adnq", X, dN)
    dG = np.linalg.norm(np.cross(T[0], T[1], axis=0), axis=0) * w
    if not unit:
        dG = dG * measure.weight(np.einsum("dnk,kq->dnq", X, N))
    f = np.abs(N) if absolute else N
    out = np.zeros(xs.shape[1])
    for a in range(cell.n_nodes):
        np.add.at(out, seg[:, a], dG @ f[a])
    return out
