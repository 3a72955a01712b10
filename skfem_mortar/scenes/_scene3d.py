"""What the 3D scenes share: their element and law parameters, the body, the L2
error of a displacement field, and the memory estimate that refuses a size the
machine cannot hold (:func:`memory_quantity`)."""
from __future__ import annotations

import math
import os
from typing import Callable

import numpy as np
from skfem.quadrature import get_quadrature

from ..bodies.materials import LinearElastic, NeoHooke, SaintVenantKirchhoff
from ..bodies.solid import Solid
from . import MAX_DOFS_ENV, MEMORY_SHARE, Derived, Param, _total_memory

__all__ = ["ELEMENTS_3D", "LAWS", "element_param", "law_params", "make_solid",
           "displacement", "l2_error", "peak_memory_gb", "memory_quantity"]

#: the 3D elements of the scenes (the solids' names)
ELEMENTS_3D = ("tet1", "tet2", "hex1", "hex2", "p2p1", "hex1-md")

#: law name -> material class (``linear``: small strain only)
LAWS = {"neo-hooke": NeoHooke, "svk": SaintVenantKirchhoff, "linear": LinearElastic}

#: peak memory of a 3D run (bytes) = BASE + PER_DOF n + FILL n^(4/3), ``n`` the
#: displacement dofs: the interpreter and its imports (BASE), the assembly's element
#: arrays, COO triplets and tangent (PER_DOF: hex1 has 576 tangent entries and 8 x 81
#: A entries per cell of 3 dofs) and the direct solver's factor (FILL: nested
#: dissection of a 3D mesh fills ``O(n^(4/3))``).  Fitted to the peak resident memory
#: of ``bench --scene block3d`` (hex1, small strain, the default direct path: 1.4, 2.9,
#: 5.6, 9.9 GB at 4.7e4, 1.1e5, 2.1e5, 3.5e5 dofs), the fit raised to lie 2 % to 10 %
#: above each of them (19 % at 1.5e4 dofs; 28 kB per dof at 3.5e5, where the 2D rule's
#: 8 kB would allow 3.5 times too many)
BASE, PER_DOF, FILL = 150e6, 27_000.0, 50.0


def element_param(default: str = "hex1") -> Param:
    """The ``element`` parameter of a 3D scene."""
    return Param("element", default, "3D element: linear or quadratic tetrahedra (tet1, "
                 "tet2) or hexahedra (hex1, hex2), Taylor-Hood P2-P1 tetrahedra (p2p1) or "
                 "mean-dilatation hexahedra (hex1-md), the last two nearly incompressible "
                 "without locking", str, choices=ELEMENTS_3D)


def law_params(default_kinematics: str = "small") -> tuple[Param, ...]:
    """The ``E``, ``nu``, ``law`` and ``kinematics`` parameters of a 3D scene."""
    return (Param("E", 1.0, "Young's modulus", float, low=0.0, low_inclusive=False),
            Param("nu", 0.3, "Poisson's ratio", float, low=-1.0, high=0.5,
                  low_inclusive=False, high_inclusive=False),
            Param("law", "neo-hooke", "hyperelastic law (small strain: its linearization, "
                  "linear elasticity; 'linear' needs kinematics=small)", str,
                  choices=tuple(LAWS)),
            Param("kinematics", default_kinematics, "finite strain (the law) or small "
                  "strain (linear elasticity with the law's mu, lambda)", str,
                  choices=("finite", "small")))


def make_solid(mesh, params: dict, name: str) -> Solid:
    """The scene's body on ``mesh``: ``params["law"]`` of ``E``, ``nu`` in ``kinematics``
    on ``params["element"]`` (ValueError for ``law=linear`` at finite strain)."""
    law, kinematics = params["law"], params["kinematics"]
    if law == "linear" and kinematics != "small":
        raise ValueError(f"law 'linear' needs kinematics='small' (it is the small-strain "
                         f"law), got kinematics={kinematics!r}")
    material = LAWS[law](E=float(params["E"]), nu=float(params["nu"]))
    return Solid(mesh, material, params["element"], name=name, kinematics=kinematics)


def displacement(solid: Solid, z: np.ndarray) -> np.ndarray:
    """The body's displacement dofs in ``z`` (a mixed body's pressures left out)."""
    return np.asarray(solid.u(z))[:int(solid.basis.N)]


def l2_error(solid: Solid, exact: Callable[[np.ndarray], np.ndarray],
             intorder: int | None = None) -> Callable[[np.ndarray], float]:
    """``z -> ||u_h - u||_L2 / ||u||_L2`` over the body's reference domain, ``u = exact(X)``
    (``(3, ...)`` from reference points ``(3, ...)``), by a quadrature of ``intorder``
    (default twice the element's degree plus 2: the error is a polynomial of twice
    the degree times smooth factors, integrated to well below its size).

    The shape functions' values on the reference cell are those on every cell
    (Lagrange elements), so ``u_h`` at the points is ``sum_i N_i(xi_q) u_(i, c)``:
    no gradients of the basis are built (scikit-fem's vector basis would build all
    of them, 4 s for 200 hex2 cells)."""
    vector = solid.basis.elem
    scalar, dim = vector.elem, int(vector.dim)
    order = 2 * scalar.maxdeg + 2 if intorder is None else int(intorder)
    xi, w = get_quadrature(solid.mesh.elem.refdom, order)
    phi = np.array([np.asarray(scalar.lbasis(xi, i)[0]) for i in range(len(scalar.doflocs))])
    mapping = solid.mesh._mapping()
    dx = np.abs(mapping.detDF(xi)) * w                                    # (n_el, n_qp)
    ue = np.asarray(exact(np.asarray(mapping.F(xi))))                    # (dim, n_el, n_qp)
    norm2 = float(np.sum(np.sum(ue ** 2, axis=0) * dx))
    edofs = np.asarray(solid.basis.element_dofs)                          # (dim n_loc, n_el)

    def error(z: np.ndarray) -> float:
        ul = displacement(solid, z)[edofs]
        uh = np.stack([np.einsum("iq,ie->eq", phi, ul[c::dim]) for c in range(dim)])
        return math.sqrt(float(np.sum(np.sum((uh - ue) ** 2, axis=0) * dx)) / norm2)
    return error


def peak_memory_gb(n_dofs: int) -> float:
    """The estimated peak memory of a run on ``n_dofs`` displacement dofs, in GB
    (:data:`BASE`, :data:`PER_DOF`, :data:`FILL`)."""
    n = float(n_dofs)
    return (BASE + PER_DOF * n + FILL * n ** (4.0 / 3.0)) / 1e9


def memory_limit_gb() -> float:
    """The memory a run may be estimated to use: ``MEMORY_SHARE`` of the machine's
    (unlimited when ``SKFEM_MORTAR_MAX_DOFS`` is set: the user's own bound then holds)."""
    ram = _total_memory()
    if os.environ.get(MAX_DOFS_ENV, "").strip() or ram is None:
        return math.inf
    return MEMORY_SHARE * ram / 1e9


def memory_quantity(n_dofs: int, *sizes: str) -> Derived:
    """The estimated peak memory of a run as a derived quantity of the size parameters
    ``sizes``, at most :func:`memory_limit_gb` (above, the scene refuses the size,
    naming it, the estimate and the limit)."""
    return Derived(f"the estimated peak memory in GB of a run on {n_dofs:.3g} dofs "
                   f"(3D: the direct solver's fill grows as dofs^(4/3); {MAX_DOFS_ENV} "
                   f"lifts the bound)", peak_memory_gb(n_dofs), tuple(sizes), 0.0,
                   memory_limit_gb())
