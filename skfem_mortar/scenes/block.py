"""Scene ``block``: a homogeneous block in uniaxial stretch (reference problem 1).

The unit square ``[0, 1]^2`` rests on frictionless supports (``u_x = 0`` on
the left, ``u_y = 0`` on the bottom); the right face is moved to
``x = stretch`` (ramped with the load factor); top and right are otherwise
traction-free. The exact solution is the affine map ``F = diag(lx, ly)`` with
``lx = stretch`` and ``ly`` from the zero lateral stress condition ``P_yy = 0``.
Every isoparametric element reproduces an affine field exactly, so on any
(distorted) mesh the computed answer equals the exact one to round-off.
``plane`` chooses plane strain (``F_zz = 1``, default) or plane stress
(``S_zz = 0``, then ``lz = ly`` by isotropy), ``kinematics`` finite strain
(default) or small strain (linear elasticity with the material's ``mu``,
``lambda``: ``ly = 1 + eps_yy``, ``P_xx = sigma_xx``), see :func:`exact_uniaxial`.

Metrics (errors relative to the exact value, or to ``mu`` where that is 0):

* ``nominal_stress``: reaction on the right face (sum of the residual over its
  x-dofs) per unit reference height, against ``P_xx``;
* ``lateral_stretch``: mean current height of the top vertices, against ``ly``;
* ``max_stress_error``: ``max |P - P_exact|_F / |P_exact|_F`` over all
  quadrature points of all elements (first Piola-Kirchhoff stress).
"""
from __future__ import annotations

import math

import numpy as np
from ..core.lazy import brentq
from skfem import MeshQuad, MeshTri

from ..bodies.materials import (PLANES, LinearElastic, Material, NeoHooke,
                                SaintVenantKirchhoff, lame_from_young)
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..bodies.solid import ELEMENTS, KINEMATICS, Solid, constitutive_law
from . import Param, Scene, Setup, grid_dofs, lame_quantities

__all__ = ["SCENE", "build", "exact_uniaxial", "svk_stretch_range", "block_mesh"]

MATERIALS = {"neo-hooke": NeoHooke, "svk": SaintVenantKirchhoff}


def svk_stretch_range(nu: float, plane: str = "strain") -> tuple[float, float]:
    """Open interval of ``stretch`` where the SVK block has a stable uniaxial state.

    The lateral Green strain is ``E_yy = -a E_xx`` with ``a = nu / (1 - nu)``
    (plane strain) or ``a = nu`` (plane stress: ``lambda* / (lambda* + 2 mu) = nu``),
    so ``ly^2 = 1 - a (lx^2 - 1)`` must be positive:
    ``lx < sqrt(1 + 1 / a)`` when ``a > 0``. In compression the nominal
    stress ``P_xx = c lx (lx^2 - 1) / 2`` has its limit point at
    ``lx = 1 / sqrt(3)``.
    """
    a = nu if plane == "stress" else nu / (1.0 - nu)
    high = math.sqrt(1.0 + 1.0 / a) if a > 0 else math.inf
    return 1.0 / math.sqrt(3.0), high


def exact_uniaxial(material: Material, stretch: float) -> tuple[float, float]:
    """Lateral stretch ``ly`` and nominal stress ``P_xx`` of the uniaxial state of
    ``material`` in its plane (``material.plane``).

    With ``lambda_p`` the in-plane Lame constant (``lambda`` in plane strain,
    ``lambda* = 2 lambda mu / (lambda + 2 mu)`` in plane stress):

    Neo-Hooke: ``mu (ly^2 - 1) + lambda ln(lx ly^k) = 0`` with ``k = 1`` (plane
    strain) or ``k = 2`` (plane stress, ``lz = ly``), solved with brentq on the
    branch through ``ly = 1`` at ``lx = 1``; ``P_xx = mu (lx - 1/lx) + lambda
    ln(lx ly^k) / lx``.
    SVK: ``S_yy = 0`` gives ``E_yy = -lambda_p E_xx / (lambda_p + 2 mu)``,
    ``ly = sqrt(1 + 2 E_yy)``, ``P_xx = lx (lambda_p (E_xx + E_yy) + 2 mu E_xx)``.
    Linear elasticity (small strain): ``eps_xx = lx - 1``,
    ``eps_yy = -lambda_p eps_xx / (lambda_p + 2 mu)``, ``ly = 1 + eps_yy``,
    ``P_xx = sigma_xx = lambda_p (eps_xx + eps_yy) + 2 mu eps_xx``.

    Raises
    ------
    ValueError
        If no such state exists (naming ``stretch`` and the allowed range).
    """
    mu, lam, lx = material.mu, material.lmbda, float(stretch)
    lam_p = material.lmbda_plane
    if not lx > 0.0:
        raise ValueError(f"stretch must be > 0 (got {stretch})")
    if isinstance(material, LinearElastic):
        exx = lx - 1.0
        eyy = -lam_p * exx / (lam_p + 2.0 * mu)
        return 1.0 + eyy, lam_p * (exx + eyy) + 2.0 * mu * exx
    if isinstance(material, SaintVenantKirchhoff):
        low, high = svk_stretch_range(material.nu, material.plane)
        if not low < lx < high:
            raise ValueError(
                f"stretch must lie in ({low:.6g}, {high:.6g}) for the svk material with "
                f"nu = {material.nu:.6g} in plane {material.plane} (below: past the "
                f"compressive limit point 1/sqrt(3); above: no real lateral stretch), "
                f"got {lx}")
        exx = 0.5 * (lx * lx - 1.0)
        eyy = -lam_p * exx / (lam_p + 2.0 * mu)
        ly = math.sqrt(1.0 + 2.0 * eyy)
        return ly, lx * (lam_p * (exx + eyy) + 2.0 * mu * exx)
    if not isinstance(material, NeoHooke):
        raise ValueError(f"material must be NeoHooke, SaintVenantKirchhoff or LinearElastic, "
                         f"got {material!r}")
    k = 2 if material.plane == "stress" else 1

    def g(ly: float) -> float:
        return mu * (ly * ly - 1.0) + lam * math.log(lx * ly ** k)

    g1 = g(1.0)
    if g1 == 0.0:
        ly = 1.0
    elif g1 < 0.0:            # root above 1; g grows like mu ly^2
        hi = 2.0
        while g(hi) < 0.0:
            hi *= 2.0
        ly = brentq(g, 1.0, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    else:                      # root below 1
        # g is increasing for ly^2 > -k lambda / (2 mu) (always when lambda >= 0)
        lo = math.sqrt(-k * lam / (2.0 * mu)) if lam < 0.0 else 0.5
        if lam >= 0.0:
            while g(lo) > 0.0:
                lo *= 0.5
        elif g(lo) > 0.0:
            raise ValueError(f"stretch = {lx} has no uniaxial neo-Hookean state for "
                             f"nu = {material.nu:.6g}; use a larger stretch")
        ly = brentq(g, lo, 1.0, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    return ly, mu * (lx - 1.0 / lx) + lam * math.log(lx * ly ** k) / lx


def block_mesh(kind: str, refine: int, distort: float, seed: int = 0):
    """Unit square mesh with tags left/right/bottom/top, interior vertices moved.

    Each interior vertex moves by a random vector of length at most
    ``distort * h`` (``h = 2**-refine``, uniform in the disk; fixed ``seed``).
    With ``distort < 0.3`` no element can invert: two vertices of an element
    approach each other by at most ``0.6 h``, less than the smallest height
    ``h / sqrt(2)`` of the triangles (``h`` for the squares).
    """
    mesh = (MeshTri() if kind == "tri" else MeshQuad()).refined(int(refine))
    if distort > 0.0:
        h = 2.0 ** -int(refine)
        p = mesh.p.copy()
        inner = np.setdiff1d(np.arange(mesh.nvertices), mesh.boundary_nodes())
        rng = np.random.default_rng(seed)
        r = distort * h * np.sqrt(rng.random(inner.size))
        phi = 2.0 * np.pi * rng.random(inner.size)
        p[:, inner] += r * np.array([np.cos(phi), np.sin(phi)])
        mesh = type(mesh)(p, mesh.t)
    return mesh.with_defaults()


def _check(params: dict) -> None:
    lame_from_young(params["E"], params["nu"])  # E > 0, -1 < nu < 0.5
    if params["material"] not in MATERIALS:
        raise ValueError(f"material must be one of {sorted(MATERIALS)}, got {params['material']!r}")
    if params["element"] not in ELEMENTS:
        raise ValueError(f"element must be one of {sorted(ELEMENTS)}, got {params['element']!r}")
    if not float(params["stretch"]) > 0.0:
        raise ValueError(f"stretch must be > 0, got {params['stretch']}")
    if int(params["refine"]) != params["refine"] or params["refine"] < 0:
        raise ValueError(f"refine must be an integer >= 0, got {params['refine']}")
    if not 0.0 <= params["distort"] < 0.3:
        raise ValueError(f"distort must lie in [0, 0.3), got {params['distort']}")


def _relative(q: float, q_exact: float, scale: float) -> float:
    """``|q - q_exact| / |q_exact|``, or divided by ``scale`` when ``q_exact == 0``."""
    return abs(q - q_exact) / (abs(q_exact) if q_exact != 0.0 else scale)


def build(params: dict, method: str | None = None) -> Setup:
    """Model, metrics and outputs of the block (``method`` is unused: no contact)."""
    _check(params)
    material = MATERIALS[params["material"]](E=params["E"], nu=params["nu"])
    kinematics, plane = params.get("kinematics", "finite"), params.get("plane", "strain")
    law, _ = constitutive_law(material, kinematics, plane)
    stretch = float(params["stretch"])
    ly_exact, pxx_exact = exact_uniaxial(law, stretch)  # raises on invalid SVK range
    element = params["element"]
    mesh = block_mesh(element[:-1], params["refine"], params["distort"])
    solid = Solid(mesh, material, element, name="block", kinematics=kinematics, plane=plane)
    right = solid.dofs_on("right", "x")
    model = Model([
        solid,
        Dirichlet(solid, solid.dofs_on("left", "x"), 0.0, name="left_x"),
        Dirichlet(solid, solid.dofs_on("bottom", "y"), 0.0, name="bottom_y"),
        Dirichlet(solid, right, stretch - 1.0, name="right_x"),
    ])
    top_nodes = np.unique(mesh.facets[:, mesh.boundaries["top"]])
    height = 1.0

    def metrics(result) -> dict:
        z = result.z
        s = solid.reaction(result.residual(), right) / height
        ly = float(np.mean(solid.x(z)[1, top_nodes])) / height
        P = solid.material.stress(solid.deformation_gradient(z))
        P_ex = np.zeros((2, 2, 1, 1))
        P_ex[0, 0] = pxx_exact
        dev = np.sqrt(np.sum((P - P_ex) ** 2, axis=(0, 1)))
        return {
            "nominal_stress": s,
            "nominal_stress_exact": pxx_exact,
            "nominal_stress_error": _relative(s, pxx_exact, material.mu),
            "lateral_stretch": ly,
            "lateral_stretch_exact": ly_exact,
            "lateral_stretch_error": _relative(ly, ly_exact, 1.0),
            "max_stress_error": float(dev.max()) / (abs(pxx_exact) if pxx_exact else material.mu),
        }

    return Setup(model=model, metrics=metrics)


def estimate_dofs(params: dict) -> int:
    """Dofs of the refined unit square (no mesh built)."""
    n = 2 ** int(params["refine"])
    return grid_dofs(n, n, order=2 if params["element"].endswith("2") else 1)


def derived(params: dict) -> list:
    """The Lame parameters of ``E`` and ``nu`` (in the scale window)."""
    return lame_quantities(float(params["E"]), float(params["nu"]))


SCENE = Scene(
    name="block",
    summary="Block in uniaxial stretch on frictionless supports (plane strain or stress, "
            "finite or small strain): homogeneous, exact to round-off on any mesh "
            "(reference problem 1).",
    params=(
        Param("E", 1.0, "Young's modulus", float, low=0.0, low_inclusive=False),
        Param("nu", 0.3, "Poisson's ratio", float, low=-1.0, high=0.5,
              low_inclusive=False, high_inclusive=False),
        Param("stretch", 2.0, "prescribed stretch lx of the block (< 1 compresses)", float,
              low=0.1, high=10.0),
        Param("material", "neo-hooke", "hyperelastic law", str, choices=tuple(MATERIALS)),
        Param("element", "tri1", "displacement element", str, choices=tuple(ELEMENTS)),
        Param("refine", 3, "uniform refinements of the unit square", int, low=0, high=12),
        Param("distort", 0.2, "random interior vertex shift, as a fraction of h", float,
              low=0.0, high=0.3, high_inclusive=False),
        Param("kinematics", "finite", "finite strain (the hyperelastic law) or small strain "
              "(linear elasticity with its mu, lambda)", str, choices=KINEMATICS),
        Param("plane", "strain", "plane strain (F_zz = 1) or plane stress (S_zz = 0)", str,
              choices=PLANES),
    ),
    build=build,
    methods=(None,),
    default_steps=5,
    estimate_dofs=estimate_dofs,
    sizes=("refine",),
    derived=derived,
)
