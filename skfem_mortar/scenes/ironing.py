"""Scene ``ironing``: a stiff half-ring die pressed into a soft block, then slid.

Finite sliding (reference problem 7; Puso and Laursen 2004; Yastrebov 2013,
"shallow ironing"):
a neo-Hookean block ``[0, W] x [0, H]`` (``W = 9``, ``H = 3``, ``E = 1``,
``nu = 0.3``) clamped on its bottom, and a deformable die, the lower half of a
ring of outer radius ``R = 3`` and inner radius ``0.933 R = 2.8``
(``E_die = 1000``, ``nu = 0.3``), whose lowest point touches the block's top at
``x = x_start``.  The die is driven by a load path prescribed on its inner arc
(every node moves alike, a rigid translation of the inner boundary): for load
factors ``t <= t_press`` it goes down by ``press t / t_press``, after that it
slides to the right by ``slide (t - t_press) / (1 - t_press)`` at the full
depth.  The slave surface is the block's top by default (``slave=die``: the
die's outer arc), the master the other one.  ``mu > 0`` gives the pair
Coulomb friction ``mu`` (``docs/friction.md``); ``mu = 0`` (the default)
builds none.

The scaled-down default mesh (``n_block`` elements along the block's width,
``n_block / 3`` through its height, ``n_die`` along the die's arc, quad1) runs
in a few seconds per method; the default slide (3) keeps the contact zone on
the block (the benchmark's slide 10 needs a longer block).

There is no closed form.  The checks (:mod:`tests.test_ironing`) are the
qualitative claims of the benchmark: the reaction forces are smooth in time
(NTS shows steps as slave nodes pass master segment ends, mortar should not),
the normal force settles while sliding, Newton does not stall.

Metrics
-------
``time``, ``normal_force``, ``tangential_force`` : lists, one value per load
    step (with 0 at the start): the load factor, and the force the die's
    driver exerts on the die, normal (``-R_y``, > 0 pressing) and tangential
    (``R_x``, > 0 pushing it forward).
``normal_force_mean``, ``normal_force_variation`` : over the sliding steps
    after the first quarter of the slide (the start-up transient): the mean,
    and ``(max - min) / mean``.
``tangential_force_mean`` :
    likewise.
``force_ratio_mean``, ``force_ratio_spread``, ``force_ratio_steps`` : the ratio
    ``tangential_force / normal_force`` in steady sliding, over the steps of the
    last third of the slide (with friction the die first sticks and shears the
    block, over about half of the default slide): its mean, its ``max - min``,
    and the first and last step of that window (step ``k`` ends at ``time[k]``;
    at the defaults steps 30 to 40 of 40).  Frictionless it is the die's
    geometric resistance (the block's bulge ahead of it, which changes sign as
    the die passes the block's middle); with friction it is about ``mu`` more
    (a little more: the contact leans on the die's front face).
``n_stick``, ``n_slip`` : with friction, the slave nodes sticking and sliding
    at the end.
``normal_force_roughness`` : ``max |F_{k+1} - 2 F_k + F_{k-1}| / mean`` over the
    same window, the largest second difference of the history: for a smooth
    history it is O(dt^2), a step of size ``s`` gives at least ``s / mean``.
``max_newton_iterations``, ``step_cuts`` :
    Newton effort.
``max_penetration`` : the largest penetration (negative gap, as a length) of
    an active slave node at the end, over the die's outer radius.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from skfem import MeshQuad

from ..contact.friction import SLIP, STICK, Coulomb
from ..contact.pair import ContactPair
from ..bodies.materials import NeoHooke
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..bodies.solid import Solid
from ..contact.surfaces import ContactSurface
from . import (MAX_STEPS, METHODS, Param, Scene, Setup, grid_dofs, lame_quantities,
               press_then_slide, ratio)

__all__ = ["SCENE", "build", "die_mesh", "block_mesh", "plot_history"]

WIDTH, HEIGHT = 9.0, 3.0
RADIUS, INNER = 3.0, 2.8


def block_mesh(n: int) -> MeshQuad:
    """Quad mesh of the block ``[0, 9] x [0, 3]``, ``n x max(1, n // 3)`` elements;
    boundaries ``top``, ``bottom``."""
    ny = max(1, n // 3)
    mesh = MeshQuad.init_tensor(np.linspace(0.0, WIDTH, n + 1), np.linspace(0.0, HEIGHT, ny + 1))
    tol = 1e-9 * WIDTH
    return mesh.with_boundaries({"top": lambda x: x[1] > HEIGHT - tol,
                                 "bottom": lambda x: x[1] < tol})


def die_mesh(n: int, x_center: float, y_center: float, n_radial: int = 1) -> MeshQuad:
    """Quad mesh of the lower half ring (angles pi to 2 pi), ``n`` elements along
    the arc, ``n_radial`` through the thickness; boundaries ``outer``, ``inner``.

    Built as a tensor mesh in ``(r, theta)`` (that order keeps the elements
    counter-clockwise: ``det d(x, y)/d(r, theta) = r > 0``) and mapped.
    """
    m = MeshQuad.init_tensor(np.linspace(INNER, RADIUS, n_radial + 1),
                             np.linspace(np.pi, 2.0 * np.pi, n + 1))
    r, th = m.p
    p = np.vstack([x_center + r * np.cos(th), y_center + r * np.sin(th)])
    mesh = MeshQuad(p, m.t)
    # boundary facets whose two vertices both lie on a circle (the facet midpoints of
    # a polygonal arc lie inside it, so skfem's midpoint test does not apply)
    bf = mesh.boundary_facets()
    rv = r[mesh.facets[:, bf]]
    tol = 1e-9 * RADIUS
    return mesh.with_boundaries({"outer": bf[np.all(rv > RADIUS - tol, axis=0)],
                                 "inner": bf[np.all(rv < INNER + tol, axis=0)]})


def build(params: dict, method: str | None = None) -> Setup:
    """Block, die, the die's load path, the contact pair; reaction-force metrics."""
    method = method or "mortar"
    press, slide = float(params["press"]), float(params["slide"])
    t_press, x0 = float(params["t_press"]), float(params["x_start"])
    if x0 - RADIUS < -WIDTH or x0 + slide > WIDTH + RADIUS:
        raise ValueError("x_start and slide must keep the die over the block")
    block = Solid(block_mesh(int(params["n_block"])),
                  NeoHooke(E=float(params["E_block"]), nu=float(params["nu"])),
                  element="quad1", name="block")
    die = Solid(die_mesh(int(params["n_die"]), x0, HEIGHT + RADIUS),
                NeoHooke(E=float(params["E_die"]), nu=float(params["nu"])),
                element="quad1", name="die")
    die_s = ContactSurface.from_solid(die, "outer", name="die_outer")
    block_s = ContactSurface.from_solid(block, "top", name="block_top")
    slave, master = (die_s, block_s) if params["slave"] == "die" else (block_s, die_s)
    mu = float(params["mu"])
    pair = ContactPair(slave, master, method, name="contact",
                       friction=Coulomb(mu) if mu > 0.0 else None)
    uy, ux = press_then_slide(t_press, -press, slide)  # the inner arc's displacement
    dx = die.dofs_on("inner", "x")
    dy = die.dofs_on("inner", "y")
    model = Model([block, die, pair,
                   Dirichlet(block, block.dofs_on("bottom"), 0.0, name="clamp"),
                   Dirichlet(die, dx, value=lambda t: ux(t), name="drive_x"),
                   Dirichlet(die, dy, value=lambda t: uy(t), name="drive_y")])

    def metrics(result) -> dict:
        t = result.load_factors
        fn, ft = np.zeros(len(t)), np.zeros(len(t))
        for k in range(1, len(t)):
            R, _, _ = model.assemble(result.states[k], t[k], tangent=False)
            fn[k] = -die.reaction(R, dy)
            ft[k] = die.reaction(R, dx)
        slide_steps = t > t_press + 0.25 * (1.0 - t_press) - 1e-12
        out = {"time": t.tolist(), "normal_force": fn.tolist(),
               "tangential_force": ft.tolist(),
               "max_newton_iterations": max((s.newton_iterations for s in result.steps),
                                            default=0),
               "step_cuts": int(sum(s.cuts for s in result.steps))}
        if np.count_nonzero(slide_steps) >= 3:
            w = fn[slide_steps]
            mean = float(np.mean(w))
            out["normal_force_mean"] = mean
            out["normal_force_variation"] = float((w.max() - w.min()) / abs(mean))
            out["normal_force_roughness"] = float(np.max(np.abs(np.diff(w, 2))) / abs(mean))
            out["tangential_force_mean"] = float(np.mean(ft[slide_steps]))
        # steady sliding: the last third of the slide (with friction the die sticks
        # and shears the block first, over about half of the default slide)
        steady = np.flatnonzero(t > t_press + (2.0 / 3.0) * (1.0 - t_press) - 1e-12)
        if steady.size:  # index k: the state after step k
            q = ft[steady] / fn[steady]
            out["force_ratio_mean"] = float(np.mean(q))
            out["force_ratio_spread"] = float(np.ptp(q))
            out["force_ratio_steps"] = [int(steady[0]), int(steady[-1])]
        d = pair.contact_data(result.z)
        act = pair.active[d["node"]]  # the rows of d follow the surface
        gap = np.where(np.isfinite(d["gap"]), d["gap"], 0.0)
        out["max_penetration"] = float(max(0.0, -gap[act].min(initial=0.0)) / RADIUS)
        out["n_active"] = int(act.sum())
        if pair.friction is not None:  # the last step's statuses (checkpointed)
            status = pair.statuses.converged
            out["n_stick"] = int(np.sum(status == STICK))
            out["n_slip"] = int(np.sum(status == SLIP))
        return out

    return Setup(model=model, metrics=metrics,
                 n_steps=int(params["n_steps"]),
                 plots=lambda metrics, out: plot_history(
                     metrics, Path(out) / "reactions.png", title=f"ironing ({method})"))


def plot_history(metrics: dict, path: str | Path, title: str = "") -> Path:
    """Normal and tangential reaction of the die against the load factor, as a PNG.

    ``metrics`` is the ``metrics`` object of an ``ironing`` run (one dict, or a
    dict ``{label: metrics}`` to compare methods on one figure).
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = metrics if "time" not in metrics else {"": metrics}
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    for label, m in runs.items():
        ax[0].plot(m["time"], m["normal_force"], ".-", label=label or None)
        ax[1].plot(m["time"], m["tangential_force"], ".-", label=label or None)
    ax[0].set_title("normal force on the die")
    ax[1].set_title("tangential force on the die")
    for a in ax:
        a.set_xlabel("load factor (press, then slide)")
        a.grid(True, alpha=0.3)
    if len(runs) > 1 or "" not in runs:
        ax[0].legend()
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def estimate_dofs(params: dict) -> int:
    """Dofs of the block (``n x n // 3``) and the die (``n_die x 1``)."""
    n = int(params["n_block"])
    return grid_dofs(n, max(1, n // 3)) + grid_dofs(int(params["n_die"]), 1)


def derived(params: dict) -> list:
    """Both bodies' Lame parameters, their stiffness ratio in ``[1e-12, 1e12]`` (the
    tangent's condition number grows with it) and at least one load step of pressing."""
    nu = float(params["nu"])
    Eb, Ed = float(params["E_block"]), float(params["E_die"])
    return [*lame_quantities(Eb, nu, "E_block", "nu", "the block"),
            *lame_quantities(Ed, nu, "E_die", "nu", "the die"),
            ratio("E_die / E_block", Ed / Eb, ("E_die", "E_block"), 1e-12, 1e12),
            ratio("the pressing steps t_press n_steps", float(params["t_press"])
                  * int(params["n_steps"]), ("t_press", "n_steps"), 1.0, float(MAX_STEPS))]


SCENE = Scene(
    name="ironing",
    summary="Ironing: a stiff half-ring die pressed 1.4 into a soft neo-Hookean block, "
            "then slid along it (finite sliding, reference problem 7).",
    params=(
        Param("press", 1.4, "depth the die's inner arc is pressed down", float,
              low=0.0, low_inclusive=False, high=2.5),
        Param("slide", 3.0, "distance the die then slides to the right", float,
              low=0.0, high=10.0),
        Param("x_start", 3.0, "x of the die's lowest point at the start", float,
              low=0.0, high=WIDTH),
        Param("t_press", 0.25, "load factor at which pressing ends and sliding starts",
              float, low=0.0, low_inclusive=False, high=1.0, high_inclusive=False),
        Param("n_steps", 40, "load steps (press and slide together)", int, low=2,
              high=MAX_STEPS),
        Param("E_block", 1.0, "Young's modulus of the block", float, low=0.0,
              low_inclusive=False),
        Param("E_die", 1000.0, "Young's modulus of the die", float, low=0.0,
              low_inclusive=False),
        Param("nu", 0.3, "Poisson's ratio of both bodies", float, low=0.0, high=0.5,
              high_inclusive=False),
        Param("n_block", 45, "elements along the block's width (n/3 through its height)",
              int, low=3, high=100_000),
        Param("n_die", 48, "elements along the die's half-ring arc", int, low=4,
              high=1_000_000),
        Param("mu", 0.0, "Coulomb friction coefficient (0: frictionless, no friction built)",
              float, low=0.0, high=2.0),
        Param("slave", "block", "which surface carries the multipliers", str,
              choices=("die", "block")),
    ),
    build=build,
    methods=METHODS,
    default_steps=40,
    estimate_dofs=estimate_dofs,
    sizes=("n_block", "n_die"),
    derived=derived,
)
