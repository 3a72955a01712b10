"""Scene ``slide``: a block pressed on a rigid plane with Coulomb friction, then pushed along it.

A linear-elastic (small-strain) block ``[0, W] x [0, H]`` (``W = 2``,
``H = 0.5``) rests on the rigid plane ``y = 0`` (its bottom the slave, Coulomb
friction ``mu``).  For load factors ``t <= t_press`` a uniform traction on its
top presses it with the total normal force ``N t / t_press`` (per unit
thickness), held after that.  Then the block is pushed tangentially:

* ``control = "displacement"``: the top's ``x`` displacement rises to
  ``slide`` (uniform, ramped over ``t_press < t <= 1``).  The shear traction
  is largest at the edges, so slip starts there and spreads inwards (partial
  slip) until every contact node slides (gross sliding); from then on the
  tangential force is exactly ``mu N``;
* ``control = "load"``: a uniform tangential traction on the top rises to the
  total ``Q``.  Below ``mu N`` the block sticks (the edges may slip) and the
  contact carries exactly ``Q``; above it there is no equilibrium, and the
  solve ends in a :class:`~skfem_mortar.core.errors.ConvergenceError` whose
  message names the cause (every contact node slides: the load exceeds the
  friction bound).  The first step starts from the multipliers of the
  uniform pressure ``N / W``, so that friction holds the block from the first
  iteration (no support takes the tangential load).

Metrics
-------
``time``, ``normal_force``, ``tangential_force`` : lists (0 at the start): the
    load factor, the applied normal force and what pushes the block (the
    support's reaction under displacement control, the applied load under load
    control), which by the block's equilibrium the contact carries; per unit
    thickness.
``contact_normal_force``, ``contact_tangential_force`` : the force the plane
    exerts on the block at the end (``F_y`` and ``-F_x``,
    :meth:`~skfem_mortar.contact.pair.ContactPair.total_force`).
``tangential_ratio``
    ``contact_tangential_force / (mu N)``.
``tangential_ratio_error``
    ``|contact_tangential_force - exact| / (mu N)``, the exact force ``mu N``
    (displacement control, sliding at the end) or the applied load (load control).
``max_tangential_ratio``
    The largest ``tangential_force / (mu N)`` of the steps.
``n_stick``, ``n_slip``
    Contact nodes sticking and sliding at the end (per step: ``n_stick``,
    ``n_slip`` in each step record's ``info``).
``newton_iterations``
    Per step.

NTS on the flat plane gives ``mu N`` to round-off once sliding; mortar's
traction acts along the slave's averaged nodal tangent, so where the slave
surface is not flat (an edge lifted by the push's moment) its resultant
departs from ``mu N`` by the tilt of those tangents (``docs/friction.md``).
"""
from __future__ import annotations

import numpy as np
from skfem import MeshTri

from ..bodies.materials import LinearElastic
from ..bodies.solid import Solid
from ..contact.friction import SLIP, STICK, Coulomb
from ..contact.pair import ContactPair
from ..contact.surfaces import ContactSurface, RigidPlane
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..loads.traction import Traction
from . import (MAX_STEPS, METHODS, Param, Scene, Setup, grid_dofs, lame_quantities, positive,
               press_then_slide, ratio)

__all__ = ["SCENE", "build", "block_mesh", "WIDTH", "HEIGHT"]

WIDTH, HEIGHT = 2.0, 0.5


def block_mesh(n: int) -> MeshTri:
    """Triangles of ``[0, W] x [0, H]``, ``n x max(1, n // 4)`` cells; boundaries
    ``top``, ``bottom``."""
    ny = max(1, n // 4)
    m = MeshTri.init_tensor(np.linspace(0.0, WIDTH, n + 1), np.linspace(0.0, HEIGHT, ny + 1))
    tol = 1e-9 * WIDTH
    return m.with_boundaries({"top": lambda x: x[1] > HEIGHT - tol,
                              "bottom": lambda x: x[1] < tol})


class _PathTraction(Traction):
    """A :class:`~skfem_mortar.loads.traction.Traction` times ``path(load_factor)``."""

    def __init__(self, body, boundary, traction, path, name=""):
        super().__init__(body, boundary, traction, name=name)
        self.path = path

    def assemble(self, z, load_factor, tangent=True):
        return super().assemble(z, self.path(load_factor), tangent)


def build(params: dict, method: str | None = None) -> Setup:
    """Block, plane, friction pair, the press and push paths; force metrics."""
    method = method or "nts"
    mu, N, t_press = float(params["mu"]), float(params["N"]), float(params["t_press"])
    control = params["control"]
    block = Solid(block_mesh(int(params["n"])),
                  LinearElastic(E=float(params["E"]), nu=float(params["nu"])), name="block")
    plane = RigidPlane((0.5 * WIDTH, 0.0), (0.0, 1.0), length=10.0 * WIDTH, name="plane")
    pair = ContactPair(ContactSurface.from_solid(block, "bottom"), plane, method,
                       name="contact", friction=Coulomb(mu))

    press, push = press_then_slide(t_press)
    items = [block, pair, _PathTraction(block, "top", (0.0, -N / WIDTH), press, name="press")]
    top_x = block.dofs_on("top", "x")
    solve_options: dict = {}
    if control == "displacement":
        slide = float(params["slide"])
        items.append(Dirichlet(block, top_x, value=lambda t: slide * push(t), name="push"))
    else:
        Q = float(params["Q"])
        items.append(_PathTraction(block, "top", (Q / WIDTH, 0.0), push, name="push"))
    model = Model(items)
    if control == "load":
        # start from the uniform pressure: friction holds the block from the first iteration
        z0 = np.zeros(model.n)
        area = np.diff(np.sort(pair.slave.X[0]))
        trib = np.r_[area, 0.0] / 2 + np.r_[0.0, area] / 2
        order = np.argsort(np.argsort(pair.slave.X[0]))
        p = N / WIDTH
        z0[pair._normal] = pair.space.multipliers(p, trib[order])  # the traction p as multipliers
        solve_options["z0"] = z0

    def metrics(result) -> dict:
        t = result.load_factors
        if control == "displacement":  # the support's reaction, step by step
            pushed = [0.0] + [block.reaction(model.assemble(z, lf, tangent=False)[0], top_x)
                              for z, lf in zip(result.states[1:], t[1:])]
        else:
            pushed = [float(params["Q"]) * push(float(lf)) for lf in t]
        F = pair.total_force(result.z)  # the converged state's contact resultant
        status = pair.statuses.converged  # the last step's (checkpointed: also on resume)
        # the exact resultant at the end: mu N once sliding, the load below the bound
        exact = mu * N if control == "displacement" else min(pushed[-1], mu * N)
        steps = result.steps
        return {"time": t.tolist(), "normal_force": [N * press(float(lf)) for lf in t],
                "tangential_force": [float(v) for v in pushed],
                "contact_normal_force": float(F[1]), "contact_tangential_force": float(-F[0]),
                "tangential_ratio": float(-F[0] / (mu * N)),
                "tangential_ratio_error": float(abs(-F[0] - exact) / (mu * N)),
                "max_tangential_ratio": float(max(pushed) / (mu * N)),
                "n_stick": int(np.sum(status == STICK)), "n_slip": int(np.sum(status == SLIP)),
                "newton_iterations": [int(s.newton_iterations) for s in steps]}

    return Setup(model=model, metrics=metrics, n_steps=int(params["n_steps"]),
                 solve_options=solve_options)


def estimate_dofs(params: dict) -> int:
    """Dofs of the ``n x n // 4`` block."""
    n = int(params["n"])
    return grid_dofs(n, max(1, n // 4))


def derived(params: dict) -> list:
    """The block's Lame parameters, the friction bound ``mu N``, and the loads over
    the stiffness ``N / E``, ``Q / E`` in ``[1e-12, 0.1]`` (small strain: the
    block's mean strains)."""
    E = float(params["E"])
    return [*lame_quantities(E, float(params["nu"]), "E", "nu", "the block"),
            positive("the friction bound mu N", float(params["mu"]) * float(params["N"]),
                     "mu", "N"),
            ratio("the normal strain N / E", float(params["N"]) / E, ("N", "E"), 1e-12, 0.1),
            ratio("the shear strain Q / E", float(params["Q"]) / E, ("Q", "E"), 1e-12, 0.1)]


SCENE = Scene(
    name="slide",
    summary="Slide: a block pressed by N on a rigid plane with Coulomb friction, then pushed "
            "along it (partial slip from the edges, gross sliding at mu N; load control "
            "below mu N).",
    params=(
        Param("mu", 0.3, "Coulomb friction coefficient", float, low=0.0, low_inclusive=False,
              high=2.0),
        Param("N", 0.02, "normal force pressing the block (per unit thickness)", float,
              low=0.0, low_inclusive=False),
        Param("control", "displacement", "push by a displacement of the top or by a load",
              str, choices=("displacement", "load")),
        Param("slide", 0.02, "tangential displacement of the top (displacement control)",
              float, low=0.0, low_inclusive=False, high=0.5),
        Param("Q", 0.005, "tangential force on the top (load control, per unit thickness)",
              float, low=0.0, low_inclusive=False),
        Param("t_press", 0.25, "load factor at which pressing ends and pushing starts",
              float, low=0.0, low_inclusive=False, high=1.0, high_inclusive=False),
        Param("E", 1.0, "Young's modulus of the block", float, low=0.0, low_inclusive=False),
        Param("nu", 0.3, "Poisson's ratio of the block", float, low=0.0, low_inclusive=False,
              high=0.5, high_inclusive=False),
        Param("n", 20, "elements along the block's width (n/4 through its height)", int,
              low=4, high=100_000),
        Param("n_steps", 20, "load steps (press and push together)", int, low=2,
              high=MAX_STEPS),
    ),
    build=build,
    methods=METHODS,
    default_steps=20,
    estimate_dofs=estimate_dofs,
    sizes=("n",),
    derived=derived,
)
