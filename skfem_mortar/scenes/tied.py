"""Scene ``tied``: a cantilever meshed as two non-matching parts glued by a :class:`TiePair`.

The plane-strain block ``[0, L] x [0, H]`` (``L = 4``, ``H = 1``, neo-Hookean)
is clamped on its left edge (``u = 0`` at ``x = 0``) and bent by a dead shear
traction ``(0, -load)`` per unit reference length on its right edge
(``x = L``).  It is meshed in two parts, ``[0, L/2]`` with ``n_left`` and
``[L/2, L]`` with ``n_right`` elements across the height at ``refine = 1``
(each level doubles both; square elements), glued along ``x = L/2`` by a mortar
tie (``--method mortar``: standard multipliers, ``mortar-dual``: dual ones).
The slave is the right part's left edge (the finer side with the defaults).

The reference is the same block meshed in one piece with the left part's
element size, solved with the same load steps.  Metrics:

* ``tip_deflection``: minus the mean vertical displacement of the loaded edge
  (trapezoidal rule over its nodes, exact for the linear trace), against the
  one-piece block's (``tip_deflection_exact``); the relative difference is the
  discretization error of the two meshes (zero to round-off when
  ``n_left == n_right``: matching meshes, ``D = M``);
* ``energy``: the strain energy ``sum int W(F) dV`` of both parts, against the
  one-piece block's;
* ``interface_force``: the vertical resultant of the tie forces on the right
  part, ``sum_B sum_A D_AB lam_Ay``, against the load it carries, ``load H``
  (equilibrium of the right part: exact for any mesh);
* ``interface_moment``: the moment about the origin of the tie forces on the
  right part in the current configuration, against minus that of the load
  (equilibrium of moments of the right part, exact at finite rotation: the
  internal forces of a hyperelastic body have no resultant moment);
* ``traction_max``: the largest ``|lam|`` over the interface (nodal traction,
  force per unit reference length), with its one-piece counterpart: the
  interface nodal forces of the one-piece block's right half over the
  tributary lengths, at the same heights (linear interpolation).
"""
from __future__ import annotations

import numpy as np
from skfem import Basis, MeshQuad, MeshTri

from ..bodies.materials import NeoHooke
from ..bodies.solid import Solid, internal_force
from ..contact.surfaces import ContactSurface, tributary_lengths
from ..contact.tie import TiePair
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..loads.traction import Traction
from . import Param, Scene, Setup, grid_dofs, lame_quantities, positive, ratio

__all__ = ["SCENE", "build", "LENGTH", "HEIGHT"]

LENGTH, HEIGHT = 4.0, 1.0
METHODS = ("mortar", "mortar-dual")


def _part(x0: float, x1: float, ny: int, element: str, material: NeoHooke, name: str) -> Solid:
    """A rectangle ``[x0, x1] x [0, H]`` of ``ny`` square-ish elements across the height,
    tagged ``left``, ``right``, ``bottom``, ``top``."""
    nx = max(1, int(round(ny * (x1 - x0) / HEIGHT)))
    mesh_cls = MeshTri if element == "tri1" else MeshQuad
    mesh = mesh_cls.init_tensor(np.linspace(x0, x1, nx + 1),
                                np.linspace(0.0, HEIGHT, ny + 1))
    tol = 1e-9 * LENGTH
    mesh = mesh.with_boundaries({"left": lambda x: np.abs(x[0] - x0) < tol,
                                 "right": lambda x: np.abs(x[0] - x1) < tol})
    return Solid(mesh, material, element=element, name=name)


def tip_deflection(body: Solid, z: np.ndarray) -> float:
    """Minus the mean ``u_y`` of the body's ``right`` edge (trapezoidal rule)."""
    nodes = np.unique(body.mesh.facets[:, body.mesh.boundaries["right"]])
    y = body.X[1, nodes]
    o = np.argsort(y)
    uy = body.u(z)[body.node_dofs[1, nodes[o]]]
    return -float(np.trapezoid(uy, y[o]) / (y[o][-1] - y[o][0]))


def strain_energy(body: Solid, z: np.ndarray) -> float:
    """``int W(F) dV`` over the body (its quadrature rule)."""
    W = body.material.energy(body.deformation_gradient(z))
    return float(np.sum(W * body.basis.dx))


def _load_moment(body: Solid, load: Traction, z: np.ndarray) -> float:
    """Moment about the origin of the load's nodal forces at the current positions."""
    fx, fy = load.force[body.node_dofs]
    x = body.x(z)
    return float(np.sum(x[0] * fy - x[1] * fx))


def _edge_traction(body: Solid, z: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The one-piece reference traction on the plane ``x = L/2`` at heights ``y``: the
    internal nodal forces ``int Grad v : P dV`` of the elements right of it at its
    nodes (the force the left half exerts on the right half there), over the nodes'
    tributary lengths (a lumped traction), linearly interpolated, (2, n)."""
    mesh = body.mesh
    right = np.flatnonzero(mesh.p[0, mesh.t].mean(axis=0) > 0.5 * LENGTH)
    basis = Basis(mesh, body.basis.elem, elements=right,
                  quadrature=(body.basis.X, body.basis.W))
    P = body.material.stress(body.deformation_gradient(z)[:, :, right])
    r = internal_force.assemble(basis, P=P)
    nodes = np.flatnonzero(np.abs(mesh.p[0] - 0.5 * LENGTH) < 1e-9 * LENGTH)
    nodes = nodes[np.argsort(mesh.p[1, nodes])]
    seg = np.c_[np.arange(nodes.size - 1), np.arange(1, nodes.size)]
    t = r[body.node_dofs[:, nodes]] / tributary_lengths(mesh.p[:, nodes], seg)
    ys = mesh.p[1, nodes]
    return np.vstack([np.interp(y, ys, t[0]), np.interp(y, ys, t[1])])


def _model(parts: list[Solid], load: float, items: list) -> tuple[Model, Traction]:
    tip = parts[-1]
    traction = Traction(tip, "right", (0.0, -load), name="shear")
    model = Model([*parts, *items, traction,
                   Dirichlet(parts[0], parts[0].dofs_on("left"), 0.0, name="clamp")])
    return model, traction


def build(params: dict, method: str | None = None) -> Setup:
    """The two glued parts, the clamp, the tip load and the tie; the metrics solve the
    one-piece block too."""
    method = method or METHODS[0]
    material = NeoHooke(E=float(params["E"]), nu=float(params["nu"]))
    level = 2 ** (int(params["refine"]) - 1)
    ny_l, ny_r = int(params["n_left"]) * level, int(params["n_right"]) * level
    element, load = params["element"], float(params["load"])
    left = _part(0.0, 0.5 * LENGTH, ny_l, element, material, "left")
    right = _part(0.5 * LENGTH, LENGTH, ny_r, element, material, "right")
    tie = TiePair(ContactSurface.from_solid(right, "left", name="right_interface"),
                  ContactSurface.from_solid(left, "right", name="left_interface"),
                  dual=(method == "mortar-dual"), name="tie")
    model, traction = _model([left, right], load, [tie])

    def metrics(result) -> dict:
        from ..solver.stepping import solve  # the scenes build, the solver solves

        z = result.z
        one = _part(0.0, LENGTH, ny_l, element, material, "one_piece")
        ref_model, _ = _model([one], load, [])
        ref = solve(ref_model, n_steps=max(1, len(result.steps)))
        d, d_ex = tip_deflection(right, z), tip_deflection(one, ref.z)
        e = strain_energy(left, z) + strain_energy(right, z)
        e_ex = strain_energy(one, ref.z)
        fs, _ = tie.forces(z)
        xs = tie.slave.x(z)
        force, force_ex = float(fs[1].sum()), load * HEIGHT
        moment = float(np.sum(xs[0] * fs[1] - xs[1] * fs[0]))
        moment_ex = -_load_moment(right, traction, z)
        lam = tie.traction(z)
        t_ref = _edge_traction(one, ref.z, tie.slave.X[1])
        t_max, t_max_ex = float(np.hypot(*lam).max()), float(np.hypot(*t_ref).max())
        scale = np.abs(t_ref).max()
        return {
            "tip_deflection": d, "tip_deflection_exact": d_ex,
            "tip_deflection_error": abs(d - d_ex) / abs(d_ex),
            "energy": e, "energy_exact": e_ex, "energy_error": abs(e - e_ex) / abs(e_ex),
            "interface_force": force, "interface_force_exact": force_ex,
            "interface_force_error": abs(force - force_ex) / abs(force_ex),
            "interface_moment": moment, "interface_moment_exact": moment_ex,
            "interface_moment_error": abs(moment - moment_ex) / abs(moment_ex),
            "traction_max": t_max, "traction_max_exact": t_max_ex,
            "traction_max_error": abs(t_max - t_max_ex) / t_max_ex,
            "traction_error": float(np.abs(lam - t_ref)[:, tie.tied].max() / scale),
            "n_tied": int(tie.tied.sum()),
        }

    return Setup(model=model, metrics=metrics, outputs=[left, right, *tie.outputs()])


def estimate_dofs(params: dict) -> int:
    """Dofs of the two parts and of the one-piece reference (square elements)."""
    level = 2 ** (int(params["refine"]) - 1)
    nl, nr = int(params["n_left"]) * level, int(params["n_right"]) * level
    half = int(round(0.5 * LENGTH / HEIGHT))
    return grid_dofs(half * nl, nl) + grid_dofs(half * nr, nr) + grid_dofs(2 * half * nl, nl)


def derived(params: dict) -> list:
    """The Lame parameters, the load, and the strain scale ``load L^2 / (E H^2)`` (the
    linear beam's largest bending strain over 6) at most 0.05: beyond, the
    cantilever folds onto itself."""
    E, load = float(params["E"]), float(params["load"])
    return [*lame_quantities(E, float(params["nu"])), positive("load", load, "load"),
            ratio("the strain scale load L^2 / (E H^2)", load * LENGTH ** 2 / (E * HEIGHT ** 2),
                  ("load", "E"), 0.0, 0.05)]


SCENE = Scene(
    name="tied",
    summary="A cantilever meshed as two non-matching parts glued by mortar tying, "
            "against the same block meshed in one piece.",
    params=(
        Param("E", 1000.0, "Young's modulus (both parts)", float, low=0.0, low_inclusive=False),
        Param("nu", 0.3, "Poisson's ratio (both parts)", float, low=0.0, high=0.5,
              low_inclusive=False, high_inclusive=False),
        Param("load", 2.0, "dead shear traction on the right edge (force per unit "
              "reference length, downwards)", float, low=0.0, low_inclusive=False),
        Param("refine", 2, "refinement level: 1 is the base mesh, each level halves h", int,
              low=1, high=8),
        Param("n_left", 4, "elements across the height of the left part at refine = 1",
              int, low=1, high=1000),
        Param("n_right", 6, "elements across the height of the right part (the slave) at "
              "refine = 1", int, low=1, high=1000),
        Param("element", "quad1", "linear element", str, choices=("tri1", "quad1")),
    ),
    build=build,
    methods=METHODS,
    default_steps=4,
    estimate_dofs=estimate_dofs,
    sizes=("refine", "n_left", "n_right"),
    derived=derived,
)
