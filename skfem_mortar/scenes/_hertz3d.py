"""The parts of scene ``hertz3d``: Hertz contact of a sphere, a quarter (or a half) in 3D
(private until the 3D contact pair registers the scene).

The quarter ``X, Y >= 0`` of the hemisphere of ``hertz_axi`` (radius ``R``, centre
``(0, 0, R)``, touching ``Z = 0`` at the origin), pressed by the total force ``F``
(``load``, over the whole sphere) as a uniform dead traction on its flat top
``Z = R``: the model's share of it (``F / 4`` on the quarter) over the top's area
(a polygon, 0.4 to 0.7 % short of ``pi R^2 / 4``; the force is exact, and
the top is ``R``, 40 ``a`` by default, from the contact), on a rigid plane ``Z = 0``
or on the quarter of ``hertz_axi``'s elastic cylinder (radius and height
``W = 30 a``, its bottom clamped) (``base``).  The symmetry planes ``X = 0`` and
``Y = 0`` are rollers (``u_x = 0``, ``u_y = 0`` on them) on both bodies, declared as
such so that the contact surfaces read them
(:func:`~skfem_mortar.scenes._contact3d.symmetry_planes`).  ``model=half`` is the
half ``Y >= 0``: the quarter's mesh and its mirror image across ``X = 0`` (an
exactly symmetric mesh), the roller on ``Y = 0``
only and ``u_x = 0`` on the sphere's axis ``X = Y = 0`` (the ``x`` translation and
the rotation about ``y``, which frictionless contact does not hold); it carries
``F / 2`` and equals the quarter on a symmetric mesh.

Meshes (:func:`~skfem_mortar.scenes._contact3d.graded_octant`,
:func:`~skfem_mortar.scenes._contact3d.graded_quarter_cylinder`): a structured grid
of the cube, cells of edge ``h0`` within ``1.2 a`` of the contact point
(``h0 = (a / 30) 2^-refine``, as ``hertz_axi``), growing by
:data:`~skfem_mortar.scenes._contact3d.GROWTH` a cell beyond, mapped smoothly onto
the body: ``hex1`` (the default) its hexahedra, ``tet1`` each split into six Kuhn
tetrahedra, every other layer in depth mirrored.  The grid is structured because
the nodal pressure of linear elements (the nodal reaction over its tributary area)
depends on the node's patch: on the meshes graded by bisection that this scene had
before, the patches under the contact came in several kinds and the nodal
pressures scattered by +-10 % about Hertz at ``refine = -2``, so the largest of
them was 8.5 % high while the fitted radius was within 0.8 %.  On the structured
grid every surface node off the symmetry planes has the same patch; the nodes on
the planes (whose mirrored patch is another kind: Kuhn tetrahedra have no mirror
symmetry) read a few per cent low, the axis node most (``benchmarks/hertz3d_series.py``
has the numbers).  Hexahedra have one patch kind everywhere (every patch is
mirror-symmetric), so their nodal pressures lie within 0.8 % of Hertz's profile at
``refine = -2`` (tet1: 5.7 %) and the largest of them approaches the finite
hemisphere's answer at every level, which the Kuhn patch bias keeps tet1's from doing
(+1.6 % off the planes at -1): hence ``hex1`` is the default.  Standard mortar
multipliers amplify that bias (the consistent ``D`` is inverted against the nodal
reactions): at ``refine = -2`` its fitted radius is 2.1 % from Hertz's on hex1 and
28 % on tet1.

Under the contact the base's graded grid (of cell ``h0`` there, ``base_h = 1``) and the
sphere's nearly coincide: their surface nodes within ``1.5 a`` lie within
``3e-4 h0`` of each other in ``(X, Y)`` and the triangles' diagonals agree, so the
interface is matching and mortar-dual reads NTS's pressures.  ``base_h`` scales the
base's cells (``base_h h0``), making the interface non-matching.  ``slave=cap`` makes
the sphere's contact surface its faces within ``a +`` :data:`CAP_CELLS` ``h0`` of the
axis instead of its whole curved boundary: the answer is the same (the faces beyond never touch)
with far fewer mortar face pairs (the search pairs the graded far faces, whose boxes
are large, with the base's top).

Hertz (:func:`~skfem_mortar.scenes.hertz_axi.hertz_sphere`)::

    a = (3 F R / (4 E*))^(1/3),   p0 = 3 F / (2 pi a^2) .

Readings (:func:`hertz_metrics`, as ``hertz_axi``'s): ``peak_pressure`` (the largest
nodal pressure), ``contact_radius`` (the least-squares fit of
``p^2 = p0^2 (1 - r^2 / a^2)`` over the nodes in compression with
``r = sqrt(x^2 + y^2) < 0.8 a``, :func:`~skfem_mortar.scenes._axi.fit_ellipse`;
``peak_pressure_fit`` the fitted ``p0``), each with ``_exact`` and ``_error``,
``pressure_profile_error`` (the largest ``|p_A - p0 sqrt(1 - r_A^2 / a^2)| / p0`` over
the nodes in that window: the nodal pressures' scatter about Hertz's profile), and
``contact_force`` (the slave's resultant times the symmetry factor 4 or 2)
against ``F``.  The fit runs over the whole sphere's nodes (a node on one symmetry
plane stands for two, one off both for four), so a quarter and a half on mirrored
meshes fit the same points.  The registration (the contact pair) waits for the 3D pair.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..bodies.solid import Solid
from ..core.dirichlet import Dirichlet
from ..loads.traction import Traction
from . import Param, hertz_axi
from ._axi import fit_ellipse
from ._contact3d import (cylinder_planes, graded_axis, graded_octant, graded_quarter_cylinder,
                         mirrored, nodes_on_plane, octant_axes, octant_planes, plane_on_lines,
                         tagged)
from ._scene3d import make_solid, memory_quantity
from .hertz import A_OVER_R
from .hertz_axi import FIT_WINDOW, hertz_sphere

__all__ = ["PARAMS", "HertzParts", "build_bodies", "exact_hertz3d", "hertz_metrics",
           "multiplicity", "derived", "estimate_dofs", "FINE_ZONE", "SYMMETRY"]

#: the zone of ``h0``-sized elements, in units of ``a`` (as ``hertz_axi``)
FINE_ZONE = 1.2

#: the rigid plane's extent from the axis, in units of ``a``
RIGID_SIZE = 3.0

#: ``slave=cap``: the sphere's faces whose centre lies within ``a + CAP_CELLS h0`` of the
#: axis (Hertz's contact ends at ``a``; a discrete contact zone reaches at most about
#: one cell beyond it)
CAP_CELLS = 2.0

#: the symmetry planes ``(axis, value)`` and the share of the sphere of each model
SYMMETRY = {"quarter": ([(0, 0.0), (1, 0.0)], 4.0), "half": ([(1, 0.0)], 2.0)}


@dataclass
class HertzParts:
    """The bodies and items of ``hertz3d`` without the contact pair.

    Attributes
    ----------
    sphere : Solid
    base : Solid or None
        The elastic base (None on a rigid plane).
    items : list
        The bodies, the load, the rollers (and the base's clamp).
    slave : tuple (Solid, str)
        The sphere and its boundary ``sphere`` (``slave=sphere``) or ``cap`` (its
        faces within ``a +`` :data:`CAP_CELLS` ``h0`` of the axis, ``slave=cap``).
    master : tuple (Solid, str) or dict
        The base and ``top``, or the rigid plane ``Z = 0`` (outward normal ``+z``) over
        ``RIGID_SIZE a`` from the axis: ``{"X": (3, n), "faces": (n_faces, 4)}``
        (:func:`~skfem_mortar.scenes._contact3d.plane_on_lines`, faces about
        ``1.5 h0 base_h`` a side; the half's is the quarter's and its mirror image).
    symmetry : list of (int, float)
        The symmetry planes ``X[axis] = value`` the rollers declare.
    share : float
        The sphere over the model (4 quarter, 2 half).
    h0 : float
        The element size under the contact.
    """

    sphere: Solid
    base: Solid | None
    items: list
    slave: tuple
    master: tuple | dict
    symmetry: list
    share: float
    h0: float


def exact_hertz3d(params: dict) -> dict:
    """:func:`~skfem_mortar.scenes.hertz_axi.hertz_sphere` of ``params``."""
    rigid = params["base"] == "rigid"
    return hertz_sphere(float(params["radius"]), float(params["load"]), float(params["E"]),
                        float(params["nu"]), None if rigid else float(params["E_base"]),
                        float(params["nu_base"]))


def _model_mesh(mesh, planes, names, curved: str, model: str, tol: float):
    """``mesh`` (a quarter) as the ``model``'s: the half mirrors it across ``X = 0``."""
    if model == "quarter":
        return mesh
    half = mirrored(mesh, 0)
    keep = [(pl, nm) for pl, nm in zip(planes, names) if nm != "x0"]
    return tagged(half, [k[0] for k in keep], [k[1] for k in keep], curved, tol)


def _rollers(body: Solid, model: str, name: str) -> list:
    """``u_x = 0`` on ``x0`` and ``u_y = 0`` on ``y0`` (quarter), or ``u_y = 0`` on ``y0``
    and ``u_x = 0`` on the axis ``X = Y = 0`` (half)."""
    items = [Dirichlet(body, boundary="y0", component=1, name=f"{name}_symmetry_y0")]
    if model == "quarter":
        return [Dirichlet(body, boundary="x0", component=0, name=f"{name}_symmetry_x0")
                ] + items
    tol = 1e-9 * float(np.ptp(body.X))
    axis = np.intersect1d(nodes_on_plane(body.mesh, 0, 0.0, tol),
                          nodes_on_plane(body.mesh, 1, 0.0, tol))
    return items + [Dirichlet(body, nodes=axis, component=0, name=f"{name}_axis_x")]


def _with_cap(mesh, radius: float):
    """``mesh`` with the boundary ``cap``: its ``sphere`` faces whose centre lies within
    ``radius`` of the axis ``X = Y = 0``."""
    faces = np.asarray(mesh.boundaries["sphere"])
    centre = mesh.p[:2, mesh.facets[:, faces]].mean(axis=1)
    return mesh.with_boundaries({"cap": faces[np.hypot(*centre) < radius]})


def build_bodies(params: dict) -> HertzParts:
    """The sphere, its load and rollers, the base (or the rigid plane's data) of
    ``params`` (:data:`PARAMS`)."""
    R, F, model = float(params["radius"]), float(params["load"]), params["model"]
    ex = exact_hertz3d(params)
    a = ex["contact_radius"]
    # a float refine (not the scene's parameter, an integer) gives the levels between
    h0 = a / 30.0 * 2.0 ** (-float(params["refine"]))
    element = params["element"]
    planes, names = octant_planes(R)
    mesh = _model_mesh(graded_octant(R, h0, FINE_ZONE * a, element), planes, names,
                       "sphere", model, 1e-9 * R)
    slave = params.get("slave", "sphere")
    if slave == "cap":
        mesh = _with_cap(mesh, a + CAP_CELLS * h0)
    sphere = make_solid(mesh, {**params, "law": "neo-hooke"}, "sphere")
    symmetry, share = SYMMETRY[model]
    # the flat top is a polygon short of the disc by the chords' segments: the
    # traction is the model's share of F over the polygon's area (a unit traction's total)
    top_area = float(Traction(sphere, "top", [0.0, 0.0, 1.0]).force.sum())
    items = [sphere, Traction(sphere, "top", [0.0, 0.0, -F / (share * top_area)],
                              name="load"), *_rollers(sphere, model, "sphere")]
    if params["base"] == "rigid":
        # the half's plane is the quarter's and its mirror image (its touch tests and
        # projections then mirror the quarter's)
        hb = float(params.get("base_h", 1.0)) * h0
        lines = np.linspace(0.0, RIGID_SIZE * a, int(np.ceil(RIGID_SIZE * a / (1.5 * hb))) + 1)
        xs = lines if model == "quarter" else np.concatenate([-lines[:0:-1], lines])
        X, faces = plane_on_lines(xs, lines, 0.0)
        plane = {"X": X, "faces": faces}
        return HertzParts(sphere, None, items, (sphere, slave), plane, symmetry, share, h0)
    W = 30.0 * a
    planes, names = cylinder_planes(W)
    hb = float(params.get("base_h", 1.0)) * h0
    mesh = _model_mesh(graded_quarter_cylinder(W, hb, FINE_ZONE * a, element), planes, names,
                       "side", model, 1e-9 * W)
    base = make_solid(mesh, {**params, "law": "neo-hooke", "E": params["E_base"],
                             "nu": params["nu_base"]}, "base")
    items += [base, Dirichlet(base, boundary="bottom", name="base_bottom"),
              *_rollers(base, model, "base")]
    return HertzParts(sphere, base, items, (sphere, slave), (base, "top"), symmetry,
                      share, h0)


def multiplicity(x: np.ndarray, symmetry: list) -> np.ndarray:
    """How many nodes of the whole sphere each node ``x`` (3, n) of the model stands for:
    2 per symmetry plane ``(axis, value)`` it is not on (within ``1e-9`` of the
    largest ``|x|``), so the quarter's interior nodes count 4, those on one plane 2,
    those on the axis 1."""
    tol = 1e-9 * float(np.abs(x).max())
    m = np.ones(x.shape[1], dtype=np.int64)
    for axis, value in symmetry:
        m *= np.where(np.abs(x[axis] - value) <= tol, 1, 2)
    return m


def hertz_metrics(exact: dict, x: np.ndarray, pressure: np.ndarray, force_z: float,
                  symmetry: list, load: float) -> dict:
    """The readings of the module docstring from the slave nodes' current positions
    ``x`` (3, n), their nodal ``pressure`` and the slave's contact resultant
    ``force_z`` (upwards, on the model's part of the sphere) of a model with the
    ``symmetry`` planes: the fit runs over the whole sphere's nodes (each node
    repeated by its :func:`multiplicity`), so the quarter and the half fit alike."""
    m = multiplicity(x, symmetry)
    r = np.repeat(np.hypot(x[0], x[1]), m)
    p = np.repeat(np.asarray(pressure, dtype=float), m)
    a, p0 = exact["contact_radius"], exact["peak_pressure"]
    fit_p0, fit_a = fit_ellipse(r, p, FIT_WINDOW * a)
    force = 2.0 ** len(symmetry) * float(force_z)
    window = r < FIT_WINDOW * a
    hertz = p0 * np.sqrt(1.0 - (r[window] / a) ** 2)
    out = {"peak_pressure_fit": fit_p0, "contact_force": force, "load": load,
           "contact_force_error": abs(force - load) / load, "E_star": exact["E_star"],
           "pressure_profile_error": float(np.max(np.abs(p[window] - hertz), initial=0.0)
                                           ) / p0}
    for key, val in (("peak_pressure", float(np.nanmax(p))), ("contact_radius", fit_a)):
        out.update({key: val, f"{key}_exact": exact[key],
                    f"{key}_error": abs(val - exact[key]) / exact[key]})
    return out


#: ``hertz_axi``'s parameters by name: the same names, ranges and defaults
_AXI = {p.name: p for p in hertz_axi.SCENE.params}


def estimate_dofs(params: dict) -> int:
    """Displacement dofs, counted from the grids' axes (no mesh built): 3 per node of
    the sphere's grid (and of the base's), the same for tet1 and hex1 (the quarter;
    the half has the mirrored nodes too).  The grids depend on ``a / R`` alone; a
    ratio outside the range that :func:`derived` refuses (``A_OVER_R``), or none
    (a load or modulus out of range), is counted at the nearest end (the finer grid
    without one), so that the refusal names the parameter, not ``refine``."""
    try:
        ratio = exact_hertz3d(params)["contact_radius"] / float(params["radius"])
    except (ArithmeticError, ValueError):
        ratio = A_OVER_R[0]
    ratio = float(np.clip(ratio, *A_OVER_R)) if np.isfinite(ratio) else A_OVER_R[0]
    h0, fine = ratio / 30.0 * 2.0 ** (-int(params["refine"])), FINE_ZONE * ratio
    plane, depth = octant_axes(1.0, h0, fine)               # in units of R
    nodes = plane.size ** 2 * depth.size
    if params["base"] != "rigid":                           # in units of W = 30 a
        hb = float(params.get("base_h", 1.0)) * h0
        nodes += graded_axis(hb / (30.0 * ratio), fine / (30.0 * ratio)).size ** 3
    return int(3 * nodes * (1 if params.get("model", "quarter") == "quarter" else 2))


def derived(params: dict) -> list:
    """``hertz_axi``'s derived quantities (radius, load, Lame parameters, E*, a / R: the
    same parameter names) and the run's estimated memory."""
    return [*hertz_axi.derived(params), memory_quantity(estimate_dofs(params), "refine")]

PARAMS = (
    *(_AXI[k] for k in ("radius", "load", "E", "nu", "E_base", "nu_base", "base")),
    Param("refine", -2, "mesh level: element size (a/30) 2^-refine under the contact (as "
          "hertz_axi; -2: a/7.5, 2.5e4 dofs in the quarter sphere; -1: 1e5)", int,
          low=-3, high=-1),
    Param("element", "hex1", "bodies' element on their structured graded grid: hex1 (its "
          "hexahedra: nodal pressures within 1 % of Hertz) or tet1 (six Kuhn tetrahedra "
          "a cell: a few per cent of patch bias)", str,
          choices=("tet1", "hex1")),
    Param("model", "quarter", "the quarter (two symmetry planes) or the half (one)", str,
          choices=("quarter", "half")),
    *(_AXI[k] for k in ("segmentation", "kinematics")),
    Param("base_h", 1.0, "the base's element size under the contact over the sphere's h0 "
          "(elastic base; the rigid plane's faces are 1.5 h0 base_h): at 1 the two graded "
          "grids nearly coincide there (matching meshes), other values make them "
          "non-matching", float, low=0.25, high=4.0),
    Param("slave", "sphere", "the sphere's contact surface: its whole curved boundary, or "
          "the cap of faces within a + 2 h0 of the axis (the faces that can touch: the "
          "same answer with fewer mortar face pairs)", str, choices=("sphere", "cap")),
)
