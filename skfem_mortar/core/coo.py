"""COO indices of element matrices: the one copy of "every local dof against every other"."""
from __future__ import annotations

import numpy as np

__all__ = ["element_coo"]


def element_coo(dofs: np.ndarray, elements_last: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Global rows and columns of element matrices, raveled like the matrices.

    ``dofs`` (n_el, n_loc) global indices: ``rows[e, l, m] = dofs[e, l]`` and
    ``cols[e, l, m] = dofs[e, m]``, for element matrices ``k`` (n_el, n_loc, n_loc).
    With ``elements_last``, ``dofs`` is (n_loc, n_el) and the matrices
    (n_loc, n_loc, n_el): ``rows[l, m, e] = dofs[l, e]``, ``cols[l, m, e] = dofs[m, e]``.
    """
    d = np.asarray(dofs)
    if elements_last:
        n, n_el = d.shape
        return (np.broadcast_to(d[:, None, :], (n, n, n_el)).ravel(),
                np.broadcast_to(d[None, :, :], (n, n, n_el)).ravel())
    n_el, n = d.shape
    return (np.broadcast_to(d[:, :, None], (n_el, n, n)).ravel(),
            np.broadcast_to(d[:, None, :], (n_el, n, n)).ravel())
