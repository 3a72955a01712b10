"""What a 3D solid writes per node: its displacement and the Cauchy stress.

The displacement is the field's value at every node of the output mesh (vertices,
and for quadratic elements the edge, face and interior nodes).  The stress is
discontinuous between elements; at a node it is the volume-weighted mean of the
element averages ``sigma_e = int_e sigma dV / V_e`` over the elements holding the
node,

    sigma(n) = sum_{e ∋ n} V_e sigma_e / sum_{e ∋ n} V_e ,

exact for a homogeneous state and first-order accurate otherwise (the pictures'
smooth field; the element averages themselves are what the solid integrates).
``sigma = P F^T / J`` from the solid's :meth:`~skfem_mortar.bodies.solid.Solid.first_piola`
(``sigma = P`` at small strain), and von Mises

    sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2
         + 3 (s_xy^2 + s_yz^2 + s_xz^2)) .
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .deformation import checked_det

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
    F, P = solid.first_piola(z)
    if solid.kinematics == "small":
        sigma = P                                              # sigma itself
    else:
        sigma = np.einsum("iJ...,kJ...->ik...", P, F) / checked_det(F)
    vm = np.sqrt(0.5 * ((sigma[0, 0] - sigma[1, 1]) ** 2 + (sigma[1, 1] - sigma[2, 2]) ** 2
                        + (sigma[2, 2] - sigma[0, 0]) ** 2)
                 + 3.0 * (sigma[0, 1] ** 2 + sigma[1, 2] ** 2 + sigma[0, 2] ** 2))
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
