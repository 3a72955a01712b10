"""Pictures of 3D models: off-screen pyvista renders, written as PNG.

What :func:`render3d` draws (the matplotlib figure of :mod:`.plot` stays for 2D):

- each 3D body at the final state, deformed (its points moved by their
  ``displacement``), coloured by its von Mises stress, with a scalar bar that
  names the quantity and its units (:data:`~.plot_common.FIELD_WORDS`);
  quadratic cells drawn curved (VTK's nonlinear subdivision of their faces);
- the undeformed outline: the feature edges of the initial configuration
  (``z0``; the reference one for ``z0 = 0``), as grey lines (actor ``"outline"``);
- the supports: the nodes the model's ``Dirichlet`` items hold, as points
  (actor ``"supports"``), and the loads: the nodal forces of its load items
  (``phase == "loads"``) on the body at the load factor, as arrows of one
  length (they mark where and which way a load acts, not how much; actor
  ``"loads"``), both at the deformed positions;
- optionally a cut: the deformed body clipped by a plane (``cut``), so that
  the stress inside shows;
- beside it, when ``items`` hold contact pairs between 3D bodies' faces: their
  slave surfaces at the final state coloured by the contact pressure, seen from
  the master's side (actors ``"contact:<name>"``).

pyvista is imported inside the functions (:func:`~.views.prepare_offscreen`
chooses VTK's headless window where no display is there).  The returned
:class:`~.plot_common.Picture` shows inline in a notebook (a static PNG: no
server is needed).
"""
from __future__ import annotations

import os
from typing import Any, Sequence

import numpy as np

from .plot_common import FIELD_WORDS, Picture

__all__ = ["render3d", "scene3d", "CUT_AXES"]

#: named cut planes: the normal of a plane through the body's centre
CUT_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: the arrows' length as a fraction of the model's size
_ARROW_LENGTH = 0.08
#: the scalar bar: at the right, beside the model (the camera leaves it room)
_BAR = {"color": "black", "vertical": True, "fmt": "%.3g", "position_x": 0.84,
        "position_y": 0.2, "width": 0.1, "height": 0.6, "title_font_size": 18,
        "label_font_size": 16}
#: a nodal force below this fraction of the largest is round-off, not a load
_ROUND_OFF = 1e-9


def _cut_plane(cut: Any, center: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """``(normal, origin)`` of ``cut``: None, an axis name of :data:`CUT_AXES` (a plane
    through ``center``), or ``(normal, origin)`` of 3 numbers each."""
    if cut is None:
        return None
    if isinstance(cut, str):
        if cut not in CUT_AXES:
            raise ValueError(f"cut must be None, one of {sorted(CUT_AXES)} or (normal, "
                             f"origin), got {cut!r}")
        return np.array(CUT_AXES[cut]), np.asarray(center, dtype=float)
    try:
        normal, origin = (np.asarray(v, dtype=float) for v in cut)
    except (TypeError, ValueError):
        raise ValueError(f"cut must be None, one of {sorted(CUT_AXES)} or (normal, origin), "
                         f"got {cut!r}") from None
    if normal.shape != (3,) or origin.shape != (3,) or not (
            np.all(np.isfinite(normal)) and np.all(np.isfinite(origin))
            and np.linalg.norm(normal) > 0):
        raise ValueError(f"cut must be (normal, origin): two finite 3-vectors, the normal "
                         f"not zero, got {cut!r}")
    return normal, origin


def _node_of_dofs(body: Any, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The output node (row of ``points``) and the component of each local dof of
    ``body``: a dof sits where its node is (``basis.doflocs``)."""
    locs = np.asarray(body.basis.doflocs, dtype=float).T            # (n_dofs, 3)
    both = np.concatenate([np.asarray(points, dtype=float), locs])
    _, inverse = np.unique(both, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    where = np.full(inverse.max() + 1, -1, dtype=np.int64)
    where[inverse[:len(points)]] = np.arange(len(points))
    return where[inverse[len(points):]], np.asarray(body.dof_component, dtype=np.int64)


def _marks(body: Any, items: Sequence, load_factor: float, z: np.ndarray,
           points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The held nodes, and the loaded nodes with their nodal forces ``(n, 3)``."""
    from ..core.dirichlet import Dirichlet

    node, comp = _node_of_dofs(body, points)
    n = len(points)
    held = np.zeros(n, dtype=bool)
    force = np.zeros((n, 3))
    lo, hi = body.offset, body.offset + body.n_dofs
    for it in items:
        if isinstance(it, Dirichlet) and it.body is body:
            dofs, _ = it.prescribed(load_factor)
            held[node[np.asarray(dofs) - lo]] = True
        elif getattr(it, "phase", None) == "loads" and getattr(it, "body", None) is body:
            c = it.assemble(np.asarray(z, dtype=float), load_factor, tangent=False)
            idx = np.asarray(c.r_index)
            on = (idx >= lo) & (idx < hi)
            local = idx[on] - lo
            np.add.at(force, (node[local], comp[local]), -np.asarray(c.r_value)[on])
    size = np.linalg.norm(force, axis=1)
    loaded = np.flatnonzero(size > _ROUND_OFF * size.max(initial=0.0))
    return np.flatnonzero(held), loaded, force[loaded]


def scene3d(bodies: Sequence, z0: np.ndarray, z1: np.ndarray, *, items: Sequence = (),
            load_factor: float = 1.0, cut: Any = None, title: str = "",
            window_size: tuple[int, int] = (1200, 900)) -> Any:
    """The :class:`pyvista.Plotter` (off screen, not shown) of :func:`render3d`.

    Its actors are named ``"body:<name>"``, ``"outline:<name>"``,
    ``"supports:<name>"`` and ``"loads:<name>"``; its scalar bar is titled with
    the field's words (quantity and units).
    """
    from .io import frame_mesh
    from .views import prepare_offscreen

    if not (len(window_size) == 2 and all(int(v) >= 200 for v in window_size)):
        raise ValueError(f"window_size must be two integers >= 200, got {window_size!r}")
    prepare_offscreen()
    import pyvista as pv

    pairs = _face_pairs(items)
    plotter = pv.Plotter(off_screen=True, window_size=[int(v) for v in window_size],
                         shape=(1, 2) if pairs else (1, 1))
    plotter.set_background("white")
    words = FIELD_WORDS["von_mises"]
    grids = []
    for body in bodies:
        points, cells = body.output_mesh()
        pdata, cdata = body.output_data(z1)
        grid = pv.from_meshio(frame_mesh(points, cells, pdata, cdata))
        grid0 = grid.copy()
        u = np.asarray(pdata["displacement"], dtype=float)
        grid.points = np.asarray(points, dtype=float) + u
        grid0.points = np.asarray(points, dtype=float) + np.asarray(
            body.output_data(z0)[0]["displacement"], dtype=float)
        grids.append((body, grid, grid0, np.asarray(points, dtype=float), u))
    if not grids:
        raise ValueError("bodies must hold at least one 3D body to draw")
    every = np.concatenate([g.points for _, g, _, _, _ in grids]
                           + [g0.points for _, _, g0, _, _ in grids])
    size = float(np.linalg.norm(every.max(axis=0) - every.min(axis=0))) or 1.0
    vm = np.concatenate([np.asarray(g.point_data["von_mises"]) for _, g, _, _, _ in grids])
    clim = [float(vm.min()), float(vm.max())]
    if clim[1] - clim[0] <= 1e-12 * max(abs(clim[1]), 1e-300):   # one value: a band around it
        clim = [clim[0] - 0.5 * abs(clim[0]) - 1e-12, clim[1] + 0.5 * abs(clim[1]) + 1e-12]
    plane = _cut_plane(cut, 0.5 * (every.max(axis=0) + every.min(axis=0)))
    for body, grid, grid0, points, u in grids:
        shown = grid if plane is None else grid.clip(normal=plane[0], origin=plane[1])
        plotter.add_mesh(shown, scalars="von_mises", cmap="viridis", clim=clim,
                         name=f"body:{body.name}", show_edges=True, edge_color="#404040",
                         scalar_bar_args=_BAR | {"title": words.replace(" (", "\n(")})
        surface = grid0.extract_surface(nonlinear_subdivision=2, algorithm="dataset_surface")
        outline = surface.extract_feature_edges(feature_angle=30.0, boundary_edges=True,
                                                non_manifold_edges=False, manifold_edges=False)
        plotter.add_mesh(outline, color="#808080", line_width=1.5, name=f"outline:{body.name}")
        held, loaded, force = _marks(body, items, load_factor, z1, points)
        if held.size:
            plotter.add_points(points[held] + u[held], color="#d62728", point_size=9,
                               render_points_as_spheres=True, name=f"supports:{body.name}")
        if loaded.size:
            d = force / np.linalg.norm(force, axis=1)[:, None]
            tip = points[loaded] + u[loaded]
            plotter.add_arrows(tip - _ARROW_LENGTH * size * d, d, mag=_ARROW_LENGTH * size,
                               color="#1f77b4", name=f"loads:{body.name}")
    if title:
        plotter.add_text(title, font_size=12, color="black", name="title")
    plotter.view_isometric()
    plotter.reset_camera()
    plotter.camera.zoom(0.85)
    if pairs:
        plotter.subplot(0, 1)
        _pressure_view(plotter, pairs, z1)
        plotter.subplot(0, 0)
    return plotter


def _face_pairs(items: Sequence) -> list:
    """The contact pairs among ``items`` whose slave is a 3D body's faces."""
    return [it for it in items if hasattr(it, "contact_data")
            and getattr(getattr(getattr(it, "slave", None), "cell", None), "dim", 0) == 2]


def _slave_pressure(pair: Any, z1: np.ndarray) -> tuple:
    """A pair's slave node positions ``(3, n)``, faces ``(n_f, k)``, nodal contact
    pressures at ``z1`` (0 where a node has none) and which faces carry pressure."""
    data = pair.contact_data(z1)
    p = np.zeros(pair.slave.n_nodes)
    p[data["node"]] = np.nan_to_num(data["pressure"])
    faces = np.asarray(pair.slave.segments)
    loaded = p[faces].max(axis=1) > 0 if len(faces) else np.zeros(0, dtype=bool)
    return np.asarray(pair.slave.x(z1), dtype=float), faces, p, loaded


def _focus(surfaces: Sequence) -> np.ndarray | None:
    """The box ``(3, 2)`` around the faces that carry pressure, grown by half its
    extent on every side (None where no face does)."""
    pts = np.hstack([np.zeros((3, 0))]
                    + [x[:, f[loaded].ravel()] for x, f, _, loaded in surfaces])
    if not pts.size:
        return None
    lo, hi = pts.min(axis=1), pts.max(axis=1)
    pad = 0.5 * (hi - lo).max()
    return np.column_stack([lo - pad, hi + pad])


def _pressure_view(plotter: Any, pairs: Sequence, z1: np.ndarray) -> None:
    """The slave surfaces of ``pairs`` at ``z1`` coloured by the contact pressure (actors
    ``"contact:<name>"``), seen from the side their master is on (against the mean
    outward normal of the faces that carry pressure, or of all where none does).
    Where some faces carry pressure, the view shows the faces whose centre lies in
    the box around them grown by half its extent (:func:`_focus`): a small contact
    zone on a large surface fills the view."""
    import pyvista as pv

    surfaces = [_slave_pressure(pair, z1) for pair in pairs]
    box = _focus(surfaces)
    normal = np.zeros(3)
    for pair, (x, faces, p, loaded) in zip(pairs, surfaces):
        n, a = pair.slave.normals(z1)
        if box is not None and len(faces):
            centre = x[:, faces].mean(axis=2)
            shown = np.all((centre >= box[:, :1]) & (centre <= box[:, 1:]), axis=0)
            faces, n, a = faces[shown], n[:, loaded], a[loaded]
        cells = np.hstack([np.full((len(faces), 1), faces.shape[1]), faces]).ravel()
        mesh = pv.PolyData(x.T, cells)
        mesh.point_data["contact pressure"] = p
        plotter.add_mesh(mesh, scalars="contact pressure", cmap="magma", show_edges=True,
                         edge_color="#404040", name=f"contact:{pair.name}",
                         scalar_bar_args=_BAR | {"title": "pressure\n(force/length²)"})
        normal += (n * a).sum(axis=1)
    plotter.add_text("slave surface", font_size=12, color="black", name="contact_title")
    if np.linalg.norm(normal) > 0:
        normal /= np.linalg.norm(normal)
        plotter.view_vector(normal, viewup=np.eye(3)[int(np.argmin(np.abs(normal)))])
    plotter.reset_camera()
    plotter.camera.zoom(0.85)


def render3d(bodies: Sequence, z0: np.ndarray, z1: np.ndarray, path: str | os.PathLike, *,
             items: Sequence = (), load_factor: float = 1.0, cut: Any = None,
             title: str = "", window_size: tuple[int, int] = (1200, 900)) -> Picture:
    """The 3D model at ``z1`` as a PNG at ``path`` (module docstring), written atomically.

    Parameters
    ----------
    bodies : sequence of Output
        The 3D bodies (their ``output_mesh``/``output_data``: ``displacement``
        and ``von_mises`` per node).
    z0, z1 : ndarray
        The initial unknowns (the outline is drawn at them: the undeformed body
        for ``z0 = 0``) and the drawn state.
    items : sequence of Item
        The model's items: supports and loads are taken from them.
    load_factor : float
        The load factor of ``z1``.
    cut : None, "x", "y", "z" or (normal, origin)
        Clip the deformed bodies by a plane (through the model's centre for an
        axis name), keeping the side the normal points away from.
    title : str
    window_size : (int, int)
        Width and height in pixels, each at least 200.

    Returns
    -------
    Picture
        The PNG's path (shown inline by a notebook).

    Raises
    ------
    ValueError
        For a bad ``cut`` or ``window_size``, or no body.
    """
    from .io import atomic_path

    plotter = scene3d(bodies, z0, z1, items=items, load_factor=load_factor, cut=cut,
                      title=title, window_size=window_size)
    path = os.fspath(path)
    try:
        with atomic_path(path, suffix=".png") as tmp:
            plotter.screenshot(str(tmp))
    finally:
        plotter.close()
    return Picture(path)
