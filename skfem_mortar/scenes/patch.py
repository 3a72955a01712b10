"""Scene ``patch``: the contact patch test (reference problem 5).

Two elastic blocks of width 1 and height 0.5 stacked on the flat interface
``y = 0.5`` (Crisfield 2000), the lower one on frictionless supports
(``u_y = 0`` on its bottom, ``u_x = 0`` at its bottom-left corner), the upper
one loaded by a uniform Cauchy pressure ``q`` on its top face (a follower
pressure on the current face), its horizontal rigid-body motion fixed by
``u_x = 0`` at its top-left corner; its vertical position is held by contact
alone.  The slave surface is the bottom of the upper block, the master the top
of the lower one.  The initial gap is zero and every node with gap <= 0 starts
active.  The exact solution is uniform: contact pressure ``q`` at every slave
node and ``sigma_yy = -q`` in both blocks.  It holds at finite strain when the
widths are equal and aligned and both blocks expand laterally alike: ``nu = 0``
in both (the default); with ``nu > 0`` and different moduli the interface
slides and the test is no longer exact.

Matching meshes (``n_top == n_bottom``) pass with every method; on
non-matching meshes single-pass NTS does not (its error is reported, not
hidden), mortar does.

Offset and overlap (``offset``, ``top_width``): the upper block spans
``[offset, offset + top_width]``, the lower one ``[0, 1]``; they touch on the
overlapped part ``[max(0, offset), min(1, offset + top_width)]``.  The parts of
the interface that face nothing are loaded by the same pressure ``q`` directly:
the overhang of the upper block's bottom face pushed up, the uncovered part of
the lower block's top face pushed down (consistent nodal forces of the uniform
traction ``q`` over the uncovered part of each facet, integrated exactly, also
on a facet cut by the end of the other surface; dead loads, exact because with
``nu = 0`` both faces keep their length and direction).  Every face of both
blocks then carries ``q`` and the uniform state stays exact: contact pressure
``q`` on the overlapped part, ``sigma_yy = -q`` everywhere.  The end of each
surface generally falls inside an element of the other, so this tests the
partial elements at the surface ends: a slave element that reaches beyond the
master (``offset < 0`` or ``offset + top_width > 1``) and a master element
that reaches beyond the slave.  With mortar the contact traction is
``lam_h = sum_A Phi_A lam_A`` on the overlap, and ``lam_h = q`` holds when every
slave node whose multiplier support meets the overlap carries ``lam_A = q``
(the ``Phi_A`` sum to one there, for standard and dual multipliers), including
the outer node of a partially overlapped slave element; slave nodes without a
master partner carry no load.  The defaults (``offset = 0``,
``top_width = 1``) are the aligned test of reference problem 5.  At least two
nodes of the upper block's bottom face (its vertices, and the mid nodes of
quadratic elements) must lie over the lower block: the upper block is held
vertically by contact alone and would rotate about a single node (with offset 0,
``top_width <= n_top``, ``2 n_top`` for quadratic elements); other offsets and
widths are refused up front (:func:`derived`), naming the range that works.
``segmentation`` (mortar only) rebuilds the mortar segments every Newton
iteration or once per load step; nothing slides here, so both give the same.

``kinematics="small"`` makes both blocks linear elastic (small strain; the
contact still acts on the current configuration): with ``nu = 0`` the
uniform state is exact as well.  ``thickness`` is the model's reference
thickness ``H`` (``Model(..., thickness=H)``): the pressures stay ``q``, the
forces are totals over ``H`` (the point loads on the uncovered parts are
given as ``q H`` times their length).

Metrics: ``pressure_error`` (largest nodal deviation from ``q`` over the
overlap, relative), ``contact_force`` (the slave's contact resultant, total
over ``H``) against ``q H`` times the overlap, and ``support_reaction`` (the
vertical reaction of the lower block's support, from the residual) against
``q H`` times the width of the lower block, each with ``_exact`` and ``_error``.
"""
from __future__ import annotations

import math

import numpy as np
from skfem import MeshQuad, MeshTri

from ..contact.pair import ContactPair
from ..loads.pressure import FollowerPressure
from ..bodies.materials import NeoHooke
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from ..bodies.solid import KINEMATICS, Solid
from ..contact.surfaces import ContactSurface
from ..loads.traction import PointLoad
from . import (METHODS, Derived, Param, Scene, Setup, grid_dofs, lame_quantities, positive,
               ratio)

__all__ = ["SCENE", "build"]

WIDTH, HEIGHT = 1.0, 0.5


def _block(x0: float, width: float, y0: float, nx: int, element: str, E: float, nu: float,
           name: str, kinematics: str = "finite") -> Solid:
    ny = max(1, (nx + 1) // 2)
    xs = np.linspace(x0, x0 + width, nx + 1)
    ys = np.linspace(y0, y0 + HEIGHT, ny + 1)
    mesh_cls = MeshTri if element.startswith("tri") else MeshQuad
    mesh = mesh_cls.init_tensor(xs, ys).with_defaults()
    return Solid(mesh, NeoHooke(E=E, nu=nu), element=element, name=name,
                 kinematics=kinematics)


def _corner(body: Solid, x: float, y: float) -> int:
    d = np.hypot(body.X[0] - x, body.X[1] - y)
    return int(np.argmin(d))


#: ``int N_k dxi`` from -1 to ``xi`` of the facet shape functions (linear: the two
#: ends; quadratic: the ends and the mid node), in the order (left, right[, mid])
_PRIMITIVES = {
    1: (lambda x: (2 * x - x * x) / 4.0 + 0.75, lambda x: (2 * x + x * x) / 4.0 + 0.25),
    2: (lambda x: x ** 3 / 6.0 - x * x / 4.0 + 5.0 / 12.0,
        lambda x: x ** 3 / 6.0 + x * x / 4.0 - 1.0 / 12.0,
        lambda x: x - x ** 3 / 3.0 + 2.0 / 3.0)}


def uncovered_load(body: Solid, boundary: str, lo: float, hi: float, traction: float,
                   name: str) -> PointLoad | None:
    """Consistent nodal forces of the uniform traction ``(0, traction)`` on the part of a
    horizontal face outside ``[lo, hi]`` (None if the face lies inside).

    For a straight facet ``[x0, x1]`` with ``x = x0 + (1 + xi) (x1 - x0) / 2`` and a loaded
    piece ``[c0, c1]`` of it, ``f_k = t (x1 - x0) / 2 int_xi(c0)^xi(c1) N_k dxi`` with the
    facet's shape functions (linear: ``(1 - xi)/2, (1 + xi)/2``; quadratic:
    ``xi (xi - 1)/2, xi (xi + 1)/2, 1 - xi^2`` on the ends and the mid node), integrated
    exactly (a facet cut by ``lo`` or ``hi`` gets its loaded part only).
    """
    mesh = body.mesh
    facets = mesh.boundaries[boundary]
    ends = mesh.facets[:, facets]                                # (2, n_f)
    x = mesh.p[0, ends]
    swap = x[0] > x[1]
    ends = np.where(swap, ends[::-1], ends)
    x0, x1 = np.minimum(*x), np.maximum(*x)
    quadratic = body.element.endswith("2")
    prims = _PRIMITIVES[2 if quadratic else 1]
    dofs = [body.node_dofs[1, ends[0]], body.node_dofs[1, ends[1]]]
    if quadratic:
        dofs.append(body.basis.facet_dofs[1, facets])
    f = np.zeros((len(prims), x0.size))
    for c0, c1 in ((x0, np.minimum(x1, lo)), (np.maximum(x0, hi), x1)):  # two pieces per facet
        c1 = np.maximum(c0, c1)
        xi0, xi1 = (2.0 * (c - x0) / (x1 - x0) - 1.0 for c in (c0, c1))
        for k, prim in enumerate(prims):
            f[k] += traction * 0.5 * (x1 - x0) * (prim(xi1) - prim(xi0))
    total = np.zeros(body.n_dofs)
    for k, d in enumerate(dofs):
        np.add.at(total, d, f[k])
    loaded = np.flatnonzero(total)
    if loaded.size == 0:
        return None
    return PointLoad(body, loaded, total[loaded], name=name)


def build(params: dict, method: str | None = None) -> Setup:
    """Two blocks, pressure, supports and the contact pair; metric: the pressure error."""
    q, nu = float(params["pressure"]), float(params["nu"])
    s, wt = float(params["offset"]), float(params["top_width"])
    lo, hi = max(0.0, s), min(WIDTH, s + wt)   # an overlap of two nodes at least (derived)
    method = method or "nts"
    element = params["element"]
    kin = params.get("kinematics", "finite")
    H = float(params.get("thickness", 1.0))
    bottom = _block(0.0, WIDTH, 0.0, int(params["n_bottom"]), element,
                    float(params["E_bottom"]), nu, "bottom", kin)
    top = _block(s, wt, HEIGHT, int(params["n_top"]), element, float(params["E_top"]), nu,
                 "top", kin)
    slave = ContactSurface.from_solid(top, "bottom", name="top_bottom")
    master = ContactSurface.from_solid(bottom, "top", name="bottom_top")
    options = {} if method == "nts" else {"segmentation": params["segmentation"]}
    pair = ContactPair(slave, master, method, name="contact", **options)
    items = [
        top, bottom, pair,
        FollowerPressure(top, q, facets="top", side="inward", name="pressure"),
        Dirichlet(bottom, bottom.dofs_on("bottom", "y"), 0.0, name="support_y"),
        Dirichlet(bottom, bottom.dofs_at_nodes([_corner(bottom, 0.0, 0.0)], "x"), 0.0,
                  name="support_x"),
        Dirichlet(top, top.dofs_at_nodes([_corner(top, s, 2 * HEIGHT)], "x"), 0.0,
                  name="top_x"),
    ]
    # the parts of the interface facing nothing carry q directly (module doc); point
    # loads are totals, so over the thickness H
    items += [ld for ld in (uncovered_load(top, "bottom", lo, hi, q * H, "overhang_load"),
                            uncovered_load(bottom, "top", lo, hi, -q * H, "uncovered_load"))
              if ld is not None]
    model = Model(items, thickness=H)
    support = bottom.dofs_on("bottom", "y")
    xs0 = slave.X[0]
    tol = 1e-12 * WIDTH
    inside = (xs0 >= lo - tol) & (xs0 <= hi + tol)

    def metrics(result) -> dict:
        d = pair.contact_data(result.z)
        p, ins = d["pressure"], inside[d["node"]]  # rows along the surface
        err = float(np.max(np.abs(p[ins] - q)) / q)
        free = ~np.isfinite(d["gap"])  # no master partner: must carry nothing
        out = {"pressure_error": err, "pressure_min": float(p[ins].min()),
               "pressure_max": float(p[ins].max()), "pressure_exact": q,
               "n_overlap": int(inside.sum()),
               "unsupported_pressure": float(np.max(np.abs(p[free]), initial=0.0) / q),
               "n_active": int(pair.active.sum()),
               "max_abs_gap": float(np.nanmax(np.abs(d["gap"])))}
        # totals over the thickness H: the pair's resultant and the reaction are
        forces = {"contact_force": (float(pair.total_force(result.z)[1]),
                                    q * H * (hi - lo)),
                  "support_reaction": (bottom.reaction(result.residual(), support),
                                       q * H * WIDTH)}
        for key, (val, exact) in forces.items():
            out.update({key: val, f"{key}_exact": exact,
                        f"{key}_error": abs(val - exact) / exact})
        return out

    return Setup(model=model, metrics=metrics)


def estimate_dofs(params: dict) -> int:
    """Dofs of both blocks' tensor meshes (``n x max(1, (n + 1) // 2)`` elements each)."""
    order = 2 if params["element"].endswith("2") else 1
    return sum(grid_dofs(n, max(1, (n + 1) // 2), order)
               for n in (int(params["n_top"]), int(params["n_bottom"])))


def nodes_over_base(params: dict) -> int:
    """How many nodes of the upper block's bottom face (vertices, and mid nodes of
    quadratic elements) lie over the lower block ``[0, WIDTH]``."""
    s, wt = float(params["offset"]), float(params["top_width"])
    n = int(params["n_top"]) * (2 if params["element"].endswith("2") else 1)
    x = s + wt * np.arange(n + 1) / n
    tol = 1e-12 * WIDTH
    return int(np.count_nonzero((x >= -tol) & (x <= WIDTH + tol)))


def derived(params: dict) -> list:
    """Both blocks' Lame parameters, the pressure, the strain scale ``pressure / E``
    of each block at most 10 (beyond, the block is crushed flat), and the overlap:
    at least two of the upper block's bottom nodes over the lower block (the upper
    block is held vertically by contact alone: on one node it would rotate freely,
    "rigid modes held by nothing") and an overlap of at least 1e-3 of the width."""
    q, nu = float(params["pressure"]), float(params["nu"])
    s, wt = float(params["offset"]), float(params["top_width"])
    overlap = min(WIDTH, s + wt) - max(0.0, s)
    out = [Derived("the upper block's bottom nodes over the lower block",
                   nodes_over_base(params), ("top_width", "offset", "n_top"), 2, math.inf),
           ratio("the overlap of the blocks / the width", overlap / WIDTH,
                 ("offset", "top_width"), 1e-3, 1.0),
           positive("pressure", q, "pressure"),
           positive("the total load pressure thickness", q * float(params["thickness"]),
                    "pressure", "thickness")]
    for name in ("E_top", "E_bottom"):
        E = float(params[name])
        out += lame_quantities(E, nu, name, "nu", name[2:] + " block")
        out.append(ratio(f"the strain scale pressure / {name}", q / E, ("pressure", name),
                         0.0, 10.0))
    return out


SCENE = Scene(
    name="patch",
    summary="Contact patch test: two stacked blocks under a uniform pressure, exact "
            "contact pressure q everywhere (reference problem 5).",
    params=(
        Param("pressure", 1e4, "Cauchy pressure q on the top face", float,
              low=0.0, low_inclusive=False),
        Param("E_top", 1e6, "Young's modulus of the upper block", float,
              low=0.0, low_inclusive=False),
        Param("E_bottom", 1e6, "Young's modulus of the lower block", float,
              low=0.0, low_inclusive=False),
        Param("nu", 0.0, "Poisson's ratio of both blocks (0: the test is exact)", float,
              low=0.0, high=0.5, high_inclusive=False),
        Param("n_top", 5, "elements along the width of the upper (slave) block", int, low=1,
              high=100_000),
        Param("n_bottom", 4, "elements along the width of the lower (master) block", int,
              low=1, high=100_000),
        Param("element", "quad1", "element of both blocks: linear (straight 2-node contact "
              "segments) or quadratic (3-node segments, the facets' mid nodes in contact)", str,
              choices=("tri1", "quad1", "tri2", "quad2")),
        Param("offset", 0.0, "x of the upper block's left edge (the lower block spans "
              "[0, 1]); != 0 shifts the slave against the master; at least two nodes of "
              "the upper block's bottom must lie over the lower block", float,
              low=-WIDTH, high=WIDTH, low_inclusive=False, high_inclusive=False),
        Param("top_width", WIDTH, "width of the upper (slave) block; > 1 makes the slave "
              "surface longer than the master; at least two nodes of its bottom must lie "
              "over the lower block (offset 0: top_width <= n_top, or 2 n_top for "
              "quadratic elements)", float, low=0.0, high=10.0,
              low_inclusive=False),
        Param("segmentation", "iteration", "mortar only: rebuild the mortar segments every "
              "Newton iteration, or once per load step (frozen during the step)", str,
              choices=("iteration", "step")),
        Param("kinematics", "finite", "both blocks: finite strain (neo-Hooke) or small "
              "strain (linear elasticity; contact on the current configuration)", str,
              choices=KINEMATICS),
        Param("thickness", 1.0, "reference thickness H: forces are totals over H, "
              "pressures per unit thickness", float, low=0.0, low_inclusive=False),
    ),
    build=build,
    methods=METHODS,
    default_steps=1,
    estimate_dofs=estimate_dofs,
    sizes=("n_top", "n_bottom"),
    derived=derived,
)
