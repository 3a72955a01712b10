"""Central-difference tangents of an item's residual, shared by the tests."""
import numpy as np


def dense(c, n):
    """Residual vector and dense tangent of one item's Contribution on n unknowns."""
    R = np.bincount(c.r_index, weights=c.r_value, minlength=n)
    K = np.zeros((n, n))
    np.add.at(K, (c.k_rows, c.k_cols), c.k_vals)
    return R, K


def fd_tangent(item, z, lf, n=None, h=1e-6):
    """Central differences of the residual: truncation error O(h^2 R_xxx) and
    round-off O(eps |R| / h) ~ 1e-10 (relative) for unit-size geometry."""
    n = len(z) if n is None else n
    K = np.zeros((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = h
        rp = dense(item.assemble(z + e, lf, tangent=False), n)[0]
        rm = dense(item.assemble(z - e, lf, tangent=False), n)[0]
        K[:, k] = (rp - rm) / (2 * h)
    return K
