"""Scene ``patch``: the contact patch test (benchmarks section 5).

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
"""
from __future__ import annotations

import numpy as np
from skfem import MeshQuad, MeshTri

from ..contact import ContactPair
from ..contact_output import ContactOutput
from ..loads import FollowerPressure
from ..materials import NeoHooke
from ..model import Dirichlet, Model
from ..solid import Solid
from ..surfaces import ContactSurface
from . import METHODS, Param, Scene, Setup

__all__ = ["SCENE", "build"]

WIDTH, HEIGHT = 1.0, 0.5


def _block(y0: float, nx: int, element: str, E: float, nu: float, name: str) -> Solid:
    ny = max(1, (nx + 1) // 2)
    xs = np.linspace(0.0, WIDTH, nx + 1)
    ys = np.linspace(y0, y0 + HEIGHT, ny + 1)
    mesh_cls = MeshTri if element == "tri1" else MeshQuad
    mesh = mesh_cls.init_tensor(xs, ys).with_defaults()
    return Solid(mesh, NeoHooke(E=E, nu=nu), element=element, name=name)


def _corner(body: Solid, x: float, y: float) -> int:
    d = np.hypot(body.X[0] - x, body.X[1] - y)
    return int(np.argmin(d))


def build(params: dict, method: str | None = None) -> Setup:
    """Two blocks, pressure, supports and the contact pair; metric: the pressure error."""
    q, nu = float(params["pressure"]), float(params["nu"])
    method = method or "nts"
    element = params["element"]
    bottom = _block(0.0, int(params["n_bottom"]), element, float(params["E_bottom"]), nu,
                    "bottom")
    top = _block(HEIGHT, int(params["n_top"]), element, float(params["E_top"]), nu, "top")
    slave = ContactSurface.from_solid(top, "bottom", name="top_bottom")
    master = ContactSurface.from_solid(bottom, "top", name="bottom_top")
    pair = ContactPair(slave, master, method, name="contact")
    model = Model([
        top, bottom, pair,
        FollowerPressure(top, q, facets="top", side="inward", name="pressure"),
        Dirichlet(bottom, bottom.dofs_on("bottom", "y"), 0.0, name="support_y"),
        Dirichlet(bottom, bottom.dofs_at_nodes([_corner(bottom, 0.0, 0.0)], "x"), 0.0,
                  name="support_x"),
        Dirichlet(top, top.dofs_at_nodes([_corner(top, 0.0, 2 * HEIGHT)], "x"), 0.0,
                  name="top_x"),
    ])

    def metrics(result) -> dict:
        d = pair.contact_data(result.z)
        p = d["pressure"]
        err = float(np.max(np.abs(p - q)) / q)
        return {"pressure_error": err, "pressure_min": float(p.min()),
                "pressure_max": float(p.max()), "pressure_exact": q,
                "n_active": int(pair.active.sum()),
                "max_abs_gap": float(np.nanmax(np.abs(d["gap"])))}

    return Setup(model=model, metrics=metrics, outputs=[top, bottom, ContactOutput(pair)], contact=pair.contact_data)


SCENE = Scene(
    name="patch",
    summary="Contact patch test: two stacked blocks under a uniform pressure, exact "
            "contact pressure q everywhere (benchmarks section 5).",
    params=(
        Param("pressure", 1e4, "Cauchy pressure q on the top face", float,
              low=0.0, low_inclusive=False),
        Param("E_top", 1e6, "Young's modulus of the upper block", float,
              low=0.0, low_inclusive=False),
        Param("E_bottom", 1e6, "Young's modulus of the lower block", float,
              low=0.0, low_inclusive=False),
        Param("nu", 0.0, "Poisson's ratio of both blocks (0: the test is exact)", float,
              low=0.0, high=0.5, high_inclusive=False),
        Param("n_top", 5, "elements along the width of the upper (slave) block", int, low=1),
        Param("n_bottom", 4, "elements along the width of the lower (master) block", int,
              low=1),
        Param("element", "quad1", "linear element (straight contact segments)", str,
              choices=("tri1", "quad1")),
    ),
    build=build,
    methods=METHODS,
    default_steps=1,
)
