"""What a 3D solid writes per node: its displacement and the Cauchy stress.

The displacement is the field's value at every node of the output mesh (vertices,
and for quadratic elements the edge, face and interior nodes).  The stress is
discontinuous between elements; at a node it is the volume-weighted mean of the
element averages ``sigma_e = int_e sigma dV / V_e`` over the elements holding the
node,

    sigma(n) = sum_{e ∋ n} V_e sigma_e / sum_{e ∋ n} V_e ,

exact for a homogeneous state and first-order accurate otherwise (the pictures'
smooth field; the element averages themselves are what the solid integrates).
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["nodal_output", "STRESS_NAMES"]

#: the six Cauchy components written, (name, i, j)
STRESS_NAMES = (("sigma_xx", 0, 0), ("sigma_yy", 1, 1), ("sigma_zz", 2, 2),
                ("sigma_xy", 0, 1), ("sigma_yz", 1, 2), ("sigma_xz", 0, 2))


def nodal_output(solid: Any, z: np.ndarray) -> dict[str, np.ndarray]:
    """Point data of a 3D ``solid`` at the global unknowns ``z``: ``displacement``
    ``(N, 3)``, the six Cauchy components and ``von_mises`` ``(N,)`` on the ``N``
    nodes of its :meth:`~skfem_mortar.bodies.solid.Solid.output_mesh` (module
    docstring)."""
    points, conn = solid._output_nodes()
    ndofs = solid._nodes[2]                                    # (3, N) local dofs
    u = np.asarray(solid.u(z), dtype=float)
    out: dict[str, np.ndarray] = {"displacement": u[ndofs].T.copy()}
    F = solid.deformation_gradient(z)
    sigma, _ = solid.material.cauchy(F)
    vm = solid.material.von_mises(F)
    dx = np.asarray(solid.basis.dx)
    vol = dx.sum(axis=1)                                       # V_e
    n = points.shape[1]
    weight = np.bincount(conn.ravel(), weights=np.broadcast_to(vol, conn.shape).ravel(),
                         minlength=n)

    def at_nodes(q: np.ndarray) -> np.ndarray:   # sum_e V_e q_e / sum_e V_e
        qe = np.sum(q * dx, axis=-1)                           # V_e q_e
        return np.bincount(conn.ravel(), weights=np.broadcast_to(qe, conn.shape).ravel(),
                           minlength=n) / weight

    for name, i, j in STRESS_NAMES:
        out[name] = at_nodes(sigma[i, j])
    out["von_mises"] = at_nodes(vm)
    return out
