"""Scene ``mindlin``: Cattaneo-Mindlin partial slip of a cylinder on a block of the same material.

The lower half of a cylinder of radius ``R`` (centre ``(0, R)``, touching
``y = 0`` at the origin; :func:`graded_half_disk`) rests on a block
``[-W, W] x [-W, 0]`` (``W = 30 a``, its bottom clamped, :func:`graded_full_block`)
of the same linear-elastic material (small strain, plane strain), with
Coulomb friction ``mu`` between the cylinder's arc (slave) and the block's
top (master).  Both bodies have the same ``E`` and ``nu``: the Dundurs
constant ``beta`` vanishes, so the normal and the tangential problems
decouple (the tangential tractions do not change the pressure) and Hertz
theory holds with ``E* = E / (2 (1 - nu^2))``.

Loading, by displacement control of the cylinder's flat top ``y = R`` (every
node of it moves by the same ``(u_x, u_y)``: the top stays straight and level,
so the cylinder cannot rotate):

* ``t <= t_press``: the top moves down by ``press t / t_press``; the depth
  ``press`` is chosen for the target line load ``load`` by the approach of
  linear theory (:func:`approach`; the measured force ``P`` is 0.3 % below
  the target at the defaults) and then held;
* ``t > t_press``: the top moves along ``x`` by ``U = shift mu press (t -
  t_press) / (1 - t_press)``.  The tangential force ``Q`` rises monotonically
  from 0 (measured at the defaults: ``Q / (mu P) = 0.70`` at ``shift = 1.1``;
  the contact slides as a whole, ``Q = mu P``, from ``shift`` about 1.7).

Friction acts from ``t_press`` on (``pressing='frictionless'``, the default:
``Coulomb(mu, start=t_press)``): theory's pressing is shear-free (``beta =
0``), and pressing with friction in finite steps (``pressing='frictional'``)
locks in the slip each node makes within the step it touches down in as stick
traction (up to 0.2 ``mu p0`` at ``n_a = 12`` with 4 pressing steps), which
then stays in the stick core as its error.

Why displacement control: the top's reactions supply the moment ``Q R`` of
the tangential force, so the pressure stays Hertz's (a uniform traction on the
top could not, and a load-controlled rigid top would need a multipoint
constraint, which the package does not have); with ``beta = 0`` the normal
force stays at its pressed value while ``U`` grows (``P_drift``, measured
1e-4 to 3e-4: the interface tilts by the antisymmetric normal displacements
the shear causes in each body, and the contact lives on the current
configuration).  Friction carries history: the scene never takes the one-step
path.

``P`` and ``Q`` are the measured contact forces per unit thickness in the
contact's local frame (the sums of the nodal normal and tangential forces,
:func:`contact_reading`: the forces of linear theory, ``Q = mu P`` exactly
when every node slides; the global resultant, ``contact_force_x`` and
``_y``, differs by the tilt, 0.4 % of ``Q``), and the formulas are evaluated
at them::

    a = sqrt(4 P R / (pi E*)),  p0 = 2 P / (pi a),  p(x) = p0 sqrt(1 - x^2 / a^2),
    c = a sqrt(1 - Q / (mu P)),
    q(x) = mu p0 sqrt(1 - x^2 / a^2)                               c <= |x| <= a,
    q(x) = mu p0 [sqrt(1 - x^2 / a^2) - (c / a) sqrt(1 - x^2 / c^2)]    |x| < c,

with ``q`` the shear traction the cylinder exerts on the block along ``+x``
(the direction of ``Q``).  The nodal tractions are read as linear theory reads
them (as ``hertz``'s ``*_ref`` metrics): per unit reference length at the
slave nodes' reference positions, ``x`` measured from the centre of the
pressure (its pressure-weighted mean).

Meshes: the hertz scene's graded quarter disk and block
(:func:`~skfem_mortar.scenes.hertz.graded_quarter_disk`,
:func:`~skfem_mortar.scenes.hertz.graded_block`) mirrored about ``x = 0``,
element edges about ``h0 = a_est / n_a`` within ``FINE_ZONE a_est`` of the
origin (``a_est`` the half-width at the target load), growing by 0.3 times the
distance beyond; the contact surfaces are the arc and the block's top within
``CONTACT_ZONE a_est`` of the axis.  The cylinder's mesh is moved along ``x``
by ``OFFSET h0``: mirrored meshes put a slave node on a master node at the
first touch (and all along the surfaces, node above node). That case converges
(``tests/test_coincident_nodes.py``), but standard mortar with friction then cuts
its steps (24 for 16); the offset keeps the scene's stepping regular.

Accuracy (``benchmarks/friction/mindlin_refinement.py``, ``docs/friction.md``):
the stick zone's edges are read from the nodes, within ``h0 / 2`` each; in the
slip zones ``q = mu p`` at every node, so there the shear's error is ``mu``
times the pressure's (the floor).  In the stick core the shear's error is at
the floor (dual: ``shear_core_error`` 0.050, 0.010, 0.003 at ``n_a = 6, 12,
24`` against the pressure's 0.019, 0.011, 0.007); the largest nodal error sits
next to ``|x| = c``, where ``q`` has a square-root cusp, and the L2 error it
dominates falls like ``h`` (dual 0.094, 0.038, 0.021 against the pressure's
0.048, 0.013, 0.011).

Metrics
-------
``time``, ``normal_force``, ``tangential_force`` : lists (0 at the start)
    The load factor and the contact's normal and tangential forces ``P``,
    ``Q`` per step (local frame, :func:`contact_reading`).
``P``, ``Q``, ``Q_ratio``
    The last step's forces and ``Q / (mu P)``.
``P_drift``
    ``max |P_k - P_press| / P_press`` over the shifting steps (``P_press`` the
    force at the end of the pressing).
``half_width``, ``half_width_exact``, ``half_width_error``
    The contact half-width from the nodal pressures (half the distance between
    the midpoints beyond the last node in compression on either side), Hertz's
    ``a`` at ``P``, the relative error.
``stick_half_width``, ``stick_half_width_exact``, ``stick_half_width_error``
    The same from the stick/slip statuses (half the distance between the
    midpoints beyond the last sticking node on either side), ``c`` at ``P``
    and ``Q``, the relative error.
``shear_error``, ``shear_l2_error``
    ``max |q - q(x)| / (mu p0)`` over the slave nodes with ``|x| <= 1.5 a``,
    and the relative L2 error of ``q`` over ``[-1.5 a, 1.5 a]`` (trapezoidal
    rule on the nodes).
``pressure_error``, ``pressure_l2_error``
    The same for the pressure against Hertz (over ``p0``): the half-space floor
    of the shear errors on the same mesh.
``shear_core_error``, ``pressure_core_error``
    ``max |q - q(x)| / (mu p0)`` over the nodes with ``|x| < 0.8 c``, and
    ``max |p - p(x)| / p0`` over those with ``|x| < 0.8 a`` (away from the
    square-root cusps).
``stick_centre``
    The middle of the stick zone over ``a`` (Mindlin: 0).
``contact_centre``, ``contact_force_x``, ``contact_force_y``
    The pressure's centre (reference ``x``) and the contact's resultant on the
    cylinder in the global frame.
``n_stick``, ``n_slip``
    Contact nodes sticking and sliding at the end.
``element_size``, ``P_target``, ``newton_iterations``
    The fine zone's element size ``h0``, the target load, the Newton
    iterations per step.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from skfem import MeshTri

from ..bodies.materials import LinearElastic
from ..bodies.solid import Solid
from ..contact.friction import SLIP, STICK, Coulomb
from ..contact.pair import ContactPair
from ..contact.surfaces import ContactSurface, tributary_lengths
from ..core.dirichlet import Dirichlet
from ..core.model import Model
from . import MAX_STEPS, METHODS, Param, Scene, Setup, lame_quantities, positive, ratio
from .hertz import A_OVER_R, graded_block, graded_quarter_disk, hertz_exact
from .slide import SCENE as _SLIDE  # the friction coefficient and t_press parameters

__all__ = ["SCENE", "build", "mindlin_exact", "mirrored", "graded_half_disk",
           "graded_full_block", "approach", "contact_reading", "FINE_ZONE", "DEPTH",
           "CONTACT_ZONE", "OFFSET"]

FINE_ZONE = 1.5   # in units of a_est: the fine zone (a margin for P off its target)
DEPTH = 30.0      # the block's half-width and depth in units of a_est
CONTACT_ZONE = 4.0  # the contact surfaces: |x| < CONTACT_ZONE a_est (nothing else touches)
#: the core of a zone: |x| < CORE c (stick zone), |x| < CORE a (contact zone)
CORE = 0.8
#: the cylinder's mesh is moved along x by OFFSET h0 (see the module docstring)
OFFSET = 0.25


def mindlin_exact(x: np.ndarray, a: float, p0: float, mu: float, c: float) -> np.ndarray:
    """Cattaneo-Mindlin shear traction ``q(x)`` (along the tangential load) of
    the half-width ``a``, peak pressure ``p0`` and stick half-width ``c``:
    ``mu p0 sqrt(1 - x^2/a^2)`` in the slip zones, minus
    ``mu p0 (c/a) sqrt(1 - x^2/c^2)`` in the stick zone ``|x| < c``, 0 outside."""
    x = np.asarray(x, dtype=float)
    q = mu * p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))
    if c > 0:
        q = q - mu * p0 * (c / a) * np.sqrt(np.clip(1.0 - (x / c) ** 2, 0.0, None))
    return q


def mirrored(mesh: MeshTri, boundaries: dict) -> MeshTri:
    """``mesh`` (in ``x >= 0``) and its mirror image about ``x = 0``, the nodes on
    ``x = 0`` shared; ``boundaries`` the named facet tests of the whole mesh."""
    p, t = mesh.p, mesh.t
    tol = 1e-12 * np.abs(p).max()
    on_axis = np.abs(p[0]) <= tol
    off = np.flatnonzero(~on_axis)
    image = np.arange(p.shape[1])
    image[off] = p.shape[1] + np.arange(off.size)
    P = np.hstack([p, np.vstack([-p[0, off], p[1, off]])])
    T = np.hstack([t, image[t][[0, 2, 1]]])   # mirrored triangles counter-clockwise again
    return MeshTri(P, np.ascontiguousarray(T)).with_boundaries(boundaries)


def graded_half_disk(R: float, h0: float, fine: float, contact: float) -> MeshTri:
    """The lower half disk ``y <= R`` of the circle of radius ``R`` about ``(0, R)``,
    graded towards the origin (the mirrored
    :func:`~skfem_mortar.scenes.hertz.graded_quarter_disk`); boundaries
    ``top`` (``y = R``), ``arc`` and ``contact`` (the arc within ``|x| < contact``)."""
    tol = 1e-9 * R
    return mirrored(graded_quarter_disk(R, h0, fine), {
        "top": lambda x: x[1] > R - tol, "arc": lambda x: x[1] < R - tol,
        "contact": lambda x: (x[1] < R - tol) & (np.abs(x[0]) < contact)})


def graded_full_block(W: float, h0: float, fine: float, contact: float) -> MeshTri:
    """The block ``[-W, W] x [-W, 0]`` graded towards the origin (the mirrored
    :func:`~skfem_mortar.scenes.hertz.graded_block`); boundaries ``top``,
    ``bottom``, ``left``, ``right`` and ``contact`` (the top within ``|x| < contact``)."""
    tol = 1e-9 * W
    return mirrored(graded_block(W, h0, fine), {
        "top": lambda x: x[1] > -tol, "bottom": lambda x: x[1] < -W + tol,
        "left": lambda x: x[0] < -W + tol, "right": lambda x: x[0] > W - tol,
        "contact": lambda x: (x[1] > -tol) & (np.abs(x[0]) < contact)})


def approach(load: float, radius: float, E: float, nu: float, depth: float) -> float:
    """Estimated downward displacement of the cylinder's top that presses it by
    ``load``: the plane-strain approach of linear theory (Johnson, *Contact
    Mechanics*, ch. 5, the two-dimensional contact of cylinders), the half cylinder's compression between its contact and
    its centre plus the block's between its surface and the depth ``depth``,

        delta = P (1 - nu^2) / (pi E) [(2 ln(4 R / a) - 1) + (2 ln(2 d / a) - nu / (1 - nu))],

    with Hertz's ``a`` at ``P``.  An estimate (the block is finite, its bottom
    clamped): the scene measures the force it gets."""
    a = hertz_exact(radius, load, E, nu, E, nu)["half_width"]
    k = load * (1 - nu * nu) / (math.pi * E)
    return k * ((2 * math.log(4 * radius / a) - 1) + (2 * math.log(2 * depth / a) - nu / (1 - nu)))


def _path(press: float, shift: float, t_press: float):
    """The top's displacement ``(u_x(t), u_y(t))``: down by ``press`` over ``t <= t_press``,
    then along ``x`` by ``shift`` over the rest."""
    def ux(t):
        return shift * max(t - t_press, 0.0) / (1.0 - t_press)

    def uy(t):
        return -press * min(t / t_press, 1.0)
    return ux, uy


def contact_reading(pair: ContactPair, z: np.ndarray) -> dict:
    """The contact as linear theory reads it, per slave node sorted by reference ``x``.

    ``X`` the reference positions; ``p`` and ``q`` the pressure and the shear
    traction the cylinder exerts on the block along ``+x`` (``q = -t_t
    sign(tau_x)``, ``t_t`` the traction on the slave along its tangent ``tau``),
    both per unit reference length (``p D_A / L_A``, ``D_A`` the method's
    current tributary length, ``L_A`` the reference one); ``status`` the
    stick/slip/open codes; ``P = sum p_A D_A`` and ``Q = sum q_A D_A`` the
    normal and tangential resultants in the contact's local frame (the sums of
    the nodal normal and tangential forces: linear theory's ``P`` and ``Q``,
    whose ratio is exactly ``mu`` where every node slides).
    """
    d = pair.tangential_data(z)
    p, _, ev = pair.pressure_and_gap(z)
    q = -d["tangential_traction"] * np.sign(d["tangent"][0])
    D = ev.area
    w = D / tributary_lengths(pair.slave.X, pair.slave.segments)
    X = pair.slave.X[0]
    order = np.argsort(X)
    return {"X": X[order], "p": (p * w)[order], "q": (q * w)[order],
            "status": d["status"][order], "P": float(np.sum(p * D)),
            "Q": float(np.sum(q * D))}


def _edges(x: np.ndarray, inside: np.ndarray) -> tuple[float, float]:
    """The midpoints beyond the outermost nodes of ``inside`` on either side (``x``
    sorted): the ends of a zone read from the nodes (``(0, 0)`` if it is empty)."""
    k = np.flatnonzero(inside)
    if k.size == 0:
        return 0.0, 0.0
    lo, hi = k.min(), k.max()
    return (float(0.5 * (x[lo] + x[max(lo - 1, 0)])),
            float(0.5 * (x[hi] + x[min(hi + 1, len(x) - 1)])))


def _errors(x: np.ndarray, v: np.ndarray, exact: np.ndarray, scale: float,
            span: float) -> tuple[float, float]:
    """``max |v - exact| / scale`` and the relative L2 error over ``|x| <= span``."""
    sel = np.abs(x) <= span
    e = v[sel] - exact[sel]
    l2 = math.sqrt(np.trapezoid(e ** 2, x[sel]) / np.trapezoid(exact[sel] ** 2, x[sel]))
    return float(np.abs(e).max() / scale), l2


def build(params: dict, method: str | None = None) -> Setup:
    """Half cylinder, block, friction pair, the press-and-shift path of the top; metrics."""
    method = method or "nts"
    R, P_target = float(params["radius"]), float(params["load"])
    E, nu, mu = float(params["E"]), float(params["nu"]), float(params["mu"])
    t_press = float(params["t_press"])
    frictionless_press = params["pressing"] == "frictionless"
    ex = hertz_exact(R, P_target, E, nu, E, nu)
    a_est = ex["half_width"]
    if a_est > A_OVER_R[1] * R:
        raise ValueError(f"load must keep the contact half-width a = {a_est:.4g} below "
                         f"{A_OVER_R[1]} radius (Hertz theory needs a << R); lower load or "
                         f"raise E")
    h0 = a_est / int(params["n_a"])
    W = DEPTH * a_est
    press = approach(P_target, R, E, nu, W)
    shift = float(params["shift"]) * mu * press
    material = LinearElastic(E=E, nu=nu)
    # the cylinder's mesh moved by OFFSET h0 along x: the mirrored meshes would put
    # slave and master nodes at the same x (node on node: it converges since the
    # segmentation snaps such projections, but standard mortar with friction cuts steps)
    disk = graded_half_disk(R, h0, FINE_ZONE * a_est, CONTACT_ZONE * a_est)
    disk = replace(disk, doflocs=disk.doflocs + np.array([[OFFSET * h0], [0.0]]))
    cyl = Solid(disk, material, name="cylinder", kinematics="small")
    block = Solid(graded_full_block(W, h0, FINE_ZONE * a_est, CONTACT_ZONE * a_est), material, name="block",
                  kinematics="small")
    ux, uy = _path(press, shift, t_press)
    top_x, top_y = cyl.dofs_on("top", "x"), cyl.dofs_on("top", "y")
    pair = ContactPair(ContactSurface.from_solid(cyl, "contact", name="cylinder_arc"),
                       ContactSurface.from_solid(block, "contact", name="block_top"), method,
                       name="contact",
                       friction=Coulomb(mu, start=t_press if frictionless_press else 0.0))
    model = Model([cyl, block, pair,
                   Dirichlet(block, block.dofs_on("bottom"), 0.0, name="block_bottom"),
                   Dirichlet(cyl, top_x, value=ux, name="shift"),
                   Dirichlet(cyl, top_y, value=uy, name="press")])

    def metrics(result) -> dict:
        t = [float(lf) for lf in result.load_factors]
        readings = [contact_reading(pair, z) for z in result.states[1:]]
        Pk = np.array([0.0] + [r["P"] for r in readings])
        Qk = np.array([0.0] + [r["Q"] for r in readings])
        P, Q = float(Pk[-1]), float(Qk[-1])
        # the drift of P over the shifting steps, from the force at the end of pressing
        shifted = np.flatnonzero(np.asarray(t) >= t_press * (1 - 1e-12))
        P_press = Pk[shifted[0]] if shifted.size else P
        drift = float(np.max(np.abs(Pk[shifted] - P_press)) / P_press) if shifted.size else 0.0
        ref = readings[-1]
        X, p, q, st = ref["X"], ref["p"], ref["q"], ref["status"]
        xc = float(np.trapezoid(p * X, X) / np.trapezoid(p, X))   # the centre of the pressure
        x = X - xc
        h = hertz_exact(R, P, E, nu, E, nu)
        a, p0 = h["half_width"], h["peak_pressure"]
        c = a * math.sqrt(max(1.0 - Q / (mu * P), 0.0))
        half = float(0.5 * np.diff(_edges(x, p > 1e-8 * p.max()))[0])
        stick_ends = _edges(x, st == STICK)
        stick = 0.5 * (stick_ends[1] - stick_ends[0])
        qe = mindlin_exact(x, a, p0, mu, c)
        pe = p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))
        q_max, q_l2 = _errors(x, q, qe, mu * p0, 1.5 * a)
        p_max, p_l2 = _errors(x, p, pe, p0, 1.5 * a)
        core = np.abs(x) < CORE * c   # the stick zone off its edges' square-root cusps
        q_core = float(np.abs(q - qe)[core].max() / (mu * p0)) if core.any() else 0.0
        inner = np.abs(x) < CORE * a
        p_core = float(np.abs(p - pe)[inner].max() / p0)
        F = pair.total_force(result.z)   # in the global frame: the interface tilts
        return {"time": t, "normal_force": Pk.tolist(), "tangential_force": Qk.tolist(),
                "P": P, "Q": Q, "Q_ratio": Q / (mu * P), "P_drift": drift,
                "P_target": P_target, "contact_centre": xc,
                "contact_force_x": float(F[0]), "contact_force_y": float(F[1]),
                "half_width": half, "half_width_exact": a,
                "half_width_error": abs(half - a) / a,
                "stick_half_width": stick, "stick_half_width_exact": c,
                "stick_half_width_error": abs(stick - c) / c if c > 0 else stick / a,
                "stick_centre": 0.5 * (stick_ends[0] + stick_ends[1]) / a,
                "shear_error": q_max, "shear_l2_error": q_l2,
                "pressure_error": p_max, "pressure_l2_error": p_l2,
                "shear_core_error": q_core, "pressure_core_error": p_core,
                "n_stick": int(np.sum(st == STICK)), "n_slip": int(np.sum(st == SLIP)),
                "element_size": h0,
                "newton_iterations": [int(s.newton_iterations) for s in result.steps]}

    return Setup(model=model, metrics=metrics, n_steps=int(params["n_steps"]))


def derived(params: dict) -> list:
    """Radius, load, the Lame parameters, ``E*`` and ``a / R`` (Hertz needs ``a << R``)."""
    R, P = float(params["radius"]), float(params["load"])
    E, nu = float(params["E"]), float(params["nu"])
    out = [positive("radius", R, "radius"), positive("load", P, "load"),
           *lame_quantities(E, nu, "E", "nu", "the bodies")]
    if not all(d.ok() for d in out):
        return out
    ex = hertz_exact(R, P, E, nu, E, nu)
    return out + [positive("E*", ex["E_star"], "E", "nu"),
                  ratio("the contact half-width over the radius a / R", ex["half_width"] / R,
                        ("load", "radius", "E", "nu"), *A_OVER_R)]


SCENE = Scene(
    name="mindlin",
    summary="Cattaneo-Mindlin: a half cylinder pressed on a block of the same material "
            "(Coulomb friction), then shifted tangentially under displacement control: a "
            "central stick zone |x| < a sqrt(1 - Q / (mu P)) between two slip zones.",
    params=(
        _SLIDE.param("mu"),
        Param("radius", 8.0, "cylinder radius R", float, low=0.0, low_inclusive=False),
        Param("load", 3.2, "target line load P per unit thickness (sets the press depth; "
              "the metrics use the measured force)", float, low=0.0, low_inclusive=False),
        Param("shift", 1.1, "the top's final tangential displacement over mu times the "
              "press depth (Q / (mu P) about 0.7 at 1.1; gross sliding, Q = mu P, from about "
              "1.7)", float, low=0.0, low_inclusive=False, high=10.0),
        Param("E", 200.0, "Young's modulus of both bodies", float, low=0.0,
              low_inclusive=False),
        Param("nu", 0.3, "Poisson's ratio of both bodies", float, low=0.0,
              low_inclusive=False, high=0.5, high_inclusive=False),
        Param("n_a", 12, "elements per contact half-width a in the fine zone", int, low=4,
              high=240),
        replace(_SLIDE.param("t_press"),
                doc="load factor at which pressing ends and shifting starts"),
        Param("pressing", "frictionless", "friction while pressing: 'frictionless' (friction "
              "acts from t_press on: Mindlin's shear-free pressing) or 'frictional' (from the "
              "start: the slip of each node within the step it touches down in stays locked "
              "as stick traction, an error of the load step)", str,
              choices=("frictionless", "frictional")),
        Param("n_steps", 16, "load steps (press and shift together)", int, low=2,
              high=MAX_STEPS),
    ),
    build=build,
    methods=METHODS,
    default_steps=16,
    derived=derived,
)
