"""Contact surfaces: nodes + connectivity + a cell type (:mod:`.cells`).

In 2D a surface is an oriented chain of line cells; in 3D a set of surface cells
(``tri3``, ``quad4``) running counter-clockwise seen from outside
(:meth:`ContactSurface.from_solid` of a tetrahedral or hexahedral solid: NTS and
mortar contact, and tying, between them).  The cell type is an attribute, :attr:`ContactSurface.cell`.

A :class:`ContactSurface` holds ``n`` surface nodes and ``segments`` (n_seg, 2)
indices into them, ordered along one chain (open or closed) and oriented so
that the OUTWARD unit normal of a segment with tangent ``t = x_2 - x_1`` is its
right-hand normal::

    n = (t_y, -t_x) / |t| .

A counter-clockwise boundary of a solid is oriented this way.  Surfaces are
built from a :class:`~skfem_mortar.bodies.solid.Solid`'s tagged boundary facets
(:meth:`ContactSurface.from_solid`), from a cable
(:meth:`ContactSurface.from_cable`, the side chosen by the user), or are rigid
(:class:`RigidPlane`, :class:`RigidCircle`: fixed coordinates, no unknowns).
Quadratic solids (tri2, quad2) give 3-node segments ``(start, end, mid)``
(``segments`` of shape ``(n_seg, 3)``, :attr:`ContactSurface.order` 2): the
facet's mid node (its P2 facet dofs) is a surface node too, and the segment is
the curve ``x(xi) = N_1 x_start + N_2 x_end + N_3 x_mid``, ``xi in [-1, 1]``,
``N_1 = xi (xi - 1)/2``, ``N_2 = xi (xi + 1)/2``, ``N_3 = 1 - xi^2``, its outward
normal the right-hand normal of ``dx/dxi``.  The ends of a line cell are its
corners (:attr:`CellType.corners`: columns 0 and 1 for line2 and line3), what walks
the chain reads.
"""
from __future__ import annotations

from typing import Any, Callable, NamedTuple

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..bodies.cable import MAX_ELEMENTS
from ..bodies.checks import check_boundary_facets
from ..bodies.solid import boundary_facets
from ..core.validate import count, flag, real
from ..core.validate_arrays import index_array, real_array
from ..core.chain import segment_lengths, segment_normals, segments_at_nodes, tributary_lengths
from .boundary_cells import boundary_cells, closed_surface
from .cell_map import (cell_measures, cell_normals, cell_points, check_connectivity,
                       output_cells, reversal)
from .cells import CellType, cell_type
from .surface_kinds import CURVE, FACE, entry

__all__ = ["ContactSurface", "RigidPlane", "RigidCircle", "chain_segments",
           "segment_lengths", "segment_normals", "tributary_lengths", "segments_at_nodes",
           "LINEAR_TRACE", "QUADRATIC_TRACE", "TRACE_3D", "check_geometry", "AXIS_TOL",
           "Layout", "LAYOUTS"]

#: the most segments a rigid surface is built with (:class:`RigidPlane`,
#: :class:`RigidCircle`): as many as the finest cable has elements
MAX_SEGMENTS = MAX_ELEMENTS

#: solid elements whose boundary trace is linear between facet vertices: tri1,
#: quad1 and the mixed "mini" triangle (P1 + bubble, the bubble vanishes on facets)
LINEAR_TRACE = ("tri1", "quad1", "mini")
#: solid elements whose boundary trace is the 3-node Lagrange line (P2 on the facet)
QUADRATIC_TRACE = ("tri2", "quad2")
#: 3D solid elements whose boundary trace is a linear surface cell (tri3 on tetrahedra,
#: quad4 on hexahedra; the mixed "tet-mini"'s bubble vanishes on facets)
TRACE_3D = ("tet1", "tet-mini", "hex1", "hex1-md")


def chain_segments(seg: np.ndarray, n_nodes: int | None = None) -> tuple[np.ndarray, bool]:
    """Order directed segments into one simple chain.

    Parameters
    ----------
    seg : int ndarray (n_seg, 2)
        Directed segments (start node, end node), in any order.
    n_nodes : int, optional
        Number of nodes the indices refer to.

    Returns
    -------
    order : int ndarray (n_seg,)
        Permutation putting the segments in chain order (end of one = start of the next).
    closed : bool
        Whether the chain is a closed loop.

    Raises
    ------
    ValueError
        When the segments are not one simple chain: a node starts or ends more
        than one segment (a branch, or inconsistent orientation), a segment is
        degenerate, or the segments form several pieces.
    """
    seg = np.asarray(seg, dtype=np.int64).reshape(-1, 2)
    if not seg.size:
        raise ValueError("segments must not be empty")
    if np.any(seg[:, 0] == seg[:, 1]):
        raise ValueError("segments must join two different nodes")
    n = int(seg.max()) + 1 if n_nodes is None else int(n_nodes)
    out_deg = np.bincount(seg[:, 0], minlength=n)
    in_deg = np.bincount(seg[:, 1], minlength=n)
    if out_deg.max() > 1 or in_deg.max() > 1:
        raise ValueError("segments do not form a simple chain: a node starts or ends "
                         "more than one segment (branching or inconsistently oriented surface)")
    used = (out_deg + in_deg) > 0
    graph = sp.coo_matrix((np.ones(len(seg)), (seg[:, 0], seg[:, 1])), shape=(n, n))
    n_comp, labels = connected_components(graph, directed=False)
    if len(np.unique(labels[used])) != 1:
        raise ValueError("segments do not form a simple chain: they form "
                         f"{len(np.unique(labels[used]))} separate pieces")
    starts = np.flatnonzero(used & (in_deg == 0))
    closed = starts.size == 0
    # successor of each segment: the segment starting where it ends
    _, seg_of_start = segments_at_nodes(seg, n)
    nxt = seg_of_start[seg[:, 1]]
    first = 0 if closed else int(seg_of_start[starts[0]])
    # rank along the chain by pointer doubling (vectorized, O(n log n))
    m = len(seg)
    nxt_c = np.where(nxt < 0, np.arange(m), nxt)
    if closed:
        nxt_c = nxt_c.copy()
        prev_first = np.flatnonzero(nxt == first)
        nxt_c[prev_first] = prev_first  # cut the loop before the first segment
    dist = np.where(nxt_c == np.arange(m), 0, 1).astype(np.int64)
    jump = nxt_c.copy()
    for _ in range(int(np.ceil(np.log2(max(m, 2)))) + 1):
        dist = dist + dist[jump]
        jump = jump[jump]
    # dist = number of segments after each one; the chain order is by decreasing dist
    order = np.argsort(-dist, kind="stable")
    if order[0] != first or np.any(np.diff(dist[order]) != -1):
        raise ValueError("segments do not form a simple chain")
    return order, bool(closed)


class ContactSurface:
    """Contact cells on a body (or rigid): nodes + connectivity + a cell type.

    In 2D an oriented chain of line cells (straight 2-node segments, ``line2``, or
    curved 3-node ones, ``line3``); in 3D surface cells (``tri3``, ``quad4``) oriented
    counter-clockwise seen from outside.  The cell type is carried explicitly
    (:attr:`cell`); nothing later reads it from the connectivity's column count.

    Parameters
    ----------
    body : Item or None
        The body owning the nodes (with ``x(z)``, ``node_dofs``, ``offset``),
        or None for a rigid surface.
    nodes : int ndarray (n,)
        Body node index of each surface node (ignored for a rigid surface); with
        ``local_dofs``, -1 marks a node that is not a body vertex (a facet's mid node).
    segments : int ndarray (n_seg, cell.n_nodes)
        Indices into the surface nodes (line cells: ``(start, end[, mid])``); line
        cells are reordered into chain order (by their ends, :attr:`CellType.corners`).
    X : ndarray (d, n), optional
        Fixed coordinates of a rigid surface; with ``local_dofs``, the reference
        coordinates of the surface nodes of a body.
    name : str
    local_dofs : int ndarray (d, n), optional
        The dofs of each surface node in the body's block (default
        ``body.node_dofs[:, nodes]``: the vertices'), for surfaces with nodes
        that are not vertices (:meth:`from_solid` of a quadratic solid).
    cell : str or CellType, optional
        The cell type (:mod:`~skfem_mortar.contact.cells`).  Default, read once here
        from the ``segments`` argument as given: ``"line2"`` for two columns (or a
        flat list of pairs), ``"line3"`` for three; required in 3D.
    """

    def __init__(self, body: Any, nodes: np.ndarray | None, segments: np.ndarray,
                 X: np.ndarray | None = None, name: str = "surface",
                 local_dofs: np.ndarray | None = None, cell: "str | CellType | None" = None):
        self.body = body
        self.name = name
        if body is None:
            if X is None:
                raise ValueError("X (d, n) is required for a rigid surface")
            self._X = real_array("X (the rigid surface's coordinates)", X)
            if self._X.ndim != 2 or self._X.shape[0] not in (2, 3):
                raise ValueError(f"X must have shape (d, n) with d = 2 or 3, got {self._X.shape}")
            n = self._X.shape[1]
            self.nodes = None
            self._local = None
            self._vertices = False
        else:
            self._vertices = local_dofs is None
            d = np.shape(body.X)[0]
            if local_dofs is None:
                self.nodes = index_array("nodes", nodes, body.n_nodes).ravel()
                n = self.nodes.size
                self._local = np.asarray(body.node_dofs)[:, self.nodes]
                self._X = np.asarray(body.X, dtype=float)[:, self.nodes]
            else:   # -1 marks a node that is not a vertex
                self.nodes = np.asarray(nodes, dtype=np.int64).ravel()
                n = self.nodes.size
                self._local = index_array("local_dofs", local_dofs, body.n_dofs).reshape(d, n)
                self._X = real_array("X", X).reshape(d, n)
        self.cell = _given_cell(cell, segments, self._X.shape[0])
        segments = index_array("segments", segments, n)
        segments = check_connectivity(segments if segments.ndim == 2 else
                                      segments.reshape(-1, self.cell.n_nodes), self.cell, n)
        layout = entry(LAYOUTS, self.cell, "ContactSurface")
        self.segments, self.closed = layout.arrange(segments, self.cell, n)
        if np.any(cell_measures(self._X, self.segments, self.cell) <= 0):
            raise ValueError(f"surface has a {layout.zero}")

    # -- geometry ----------------------------------------------------------
    @property
    def n_nodes(self) -> int:
        return int(self._X.shape[1])

    @property
    def dim(self) -> int:
        """The space dimension ``d`` (2 or 3): coordinates per node."""
        return int(self._X.shape[0])

    @property
    def order(self) -> int:
        """The cell type's Lagrange order: 1 for straight 2-node segments (and other
        linear cells), 2 for curved 3-node ones."""
        return int(self.cell.order)

    @property
    def rigid(self) -> bool:
        return self.body is None

    @property
    def X(self) -> np.ndarray:
        """Reference coordinates (d, n)."""
        return self._X

    def x(self, z: np.ndarray) -> np.ndarray:
        """Current coordinates ``(d, n)`` of the surface nodes."""
        if self.body is None:
            return self._X
        if self._vertices:
            return self.body.x(z)[:, self.nodes]
        return self._X + np.asarray(z)[self.body.offset + self._local]

    def dofs(self) -> np.ndarray | None:
        """Global indices ``(d, n)`` into z of the nodes' unknowns, or None (rigid)."""
        if self.body is None:
            return None
        return self.body.offset + self._local

    def normals(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Outward unit normals (d, n_seg) at the cells' reference centres (a 3-node
        segment's mid node, ``xi = 0``) and the cells' lengths or areas, in the current
        configuration (:func:`~skfem_mortar.contact.cell_map.cell_normals`)."""
        return cell_normals(self.x(z), self.segments, self.cell)

    def interpolate(self, values: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """Nodal ``values (k, n)`` (coordinates, pressures) at the reference points
        ``xi (dim, q)`` of every cell: ``(k, n_seg, q)``, with the cell's own shape
        functions (:func:`~skfem_mortar.contact.cell_map.cell_points`)."""
        return cell_points(values, self.segments, self.cell, xi)

    def output_cells(self) -> list[tuple[str, np.ndarray]]:
        """The cell blocks that write the surface (meshio type, connectivity into the
        surface nodes; :func:`~skfem_mortar.contact.cell_map.output_cells`)."""
        return output_cells(self.segments, self.cell)

    def reversed(self, name: str = "") -> "ContactSurface":
        """The same surface turned over (its normals flipped): every cell's nodes
        permuted by :func:`~skfem_mortar.contact.cell_map.reversal` (segments
        ``(end, start[, mid])``, a chain run the other way), the same nodes and dofs."""
        seg = self.segments[:, list(reversal(self.cell))]
        out = ContactSurface.__new__(ContactSurface)
        out.__dict__.update(self.__dict__)
        out.name = name or self.name
        out.segments = np.ascontiguousarray(entry(LAYOUTS, self.cell, "reversed").turned(seg))
        return out

    # -- construction --------------------------------------------------------
    @classmethod
    def from_solid(cls, solid: Any, boundary: str | np.ndarray, name: str = "") -> "ContactSurface":
        """The surface made of a solid's boundary facets, oriented outward.

        Each facet is oriented so that its normal points away from the element it
        bounds (:func:`~skfem_mortar.contact.boundary_cells.boundary_cells`); in 2D
        the facets are then chained.

        Linear elements (tri1, quad1, MINI) give 2-node segments between the facet
        vertices; quadratic ones (tri2, quad2) 3-node segments ``(start, end, mid)``
        whose mid node is the facet's P2 node (``nodes`` -1 there: it is not a
        vertex), so that the surface is the facet trace of the body's
        displacement field.  Linear 3D elements (:data:`TRACE_3D`) give tri3 or quad4
        cells, for contact (nts, mortar, mortar-dual) and tying between 3D bodies.

        Parameters
        ----------
        solid : Solid
        boundary : str or int ndarray
            A tag of ``solid.mesh.boundaries`` or facet indices.
        """
        if not (hasattr(solid, "mesh") and hasattr(solid, "X") and hasattr(solid, "node_dofs")):
            raise ValueError(f"solid must be a Solid (a body with an skfem mesh), got "
                             f"{type(solid).__name__}")
        mesh = solid.mesh
        element = getattr(solid, "element", "tri1")
        if element not in LINEAR_TRACE + QUADRATIC_TRACE + TRACE_3D:
            raise ValueError(f"contact surfaces need elements whose boundary trace is a "
                             f"Lagrange line, linear {LINEAR_TRACE} or quadratic "
                             f"{QUADRATIC_TRACE}, or a linear surface cell {TRACE_3D}, "
                             f"got element {element!r}")
        facets = boundary_facets(mesh, boundary,
                                 "boundary must be one of the mesh tags {known}, got {tag!r}")
        check_boundary_facets(mesh, facets, boundary)
        ends, cell = boundary_cells(mesh, facets)
        nodes, local = np.unique(ends, return_inverse=True)
        local = local.reshape(ends.shape)
        name = name or f"{solid.name}_{boundary if isinstance(boundary, str) else 'surface'}"
        if element not in QUADRATIC_TRACE:
            return cls(solid, nodes, local, name=name, cell=cell)
        # 3-node segments: the vertices, then one mid node per facet (its P2 facet
        # dofs, at the basis' dof location: on the curve of an isoparametric mesh)
        mid_dofs = np.asarray(solid.basis.facet_dofs)[:, facets]          # (2, n_f)
        n_v, n_f = nodes.size, facets.size
        segments = np.column_stack([local, n_v + np.arange(n_f)])
        X = np.hstack([np.asarray(solid.X, dtype=float)[:, nodes],
                       np.asarray(solid.basis.doflocs, dtype=float)[:, mid_dofs[0]]])
        local_dofs = np.hstack([np.asarray(solid.node_dofs)[:, nodes], mid_dofs])
        return cls(solid, np.r_[nodes, np.full(n_f, -1)], segments, X=X, name=name,
                   local_dofs=local_dofs, cell="line3")

    @classmethod
    def from_cable(cls, cable: Any, side: str = "left", name: str = "") -> "ContactSurface":
        """The surface of a cable seen from one side.

        Parameters
        ----------
        cable : Cable
            With ``elements`` (n_el, 2) node pairs along the cable.
        side : {"left", "right"}
            Side of the cable (walking from its first to its last node) whose
            normal is the outward normal of the surface.  "right" keeps the
            element order (right-hand normal); "left" flips it.
        """
        if not (hasattr(cable, "elements") and hasattr(cable, "closed")):
            raise ValueError(f"cable must be a Cable, got {type(cable).__name__}")
        if not isinstance(side, str) or side not in ("left", "right"):
            raise ValueError(f"side must be 'left' or 'right', got {side!r}")
        el = np.asarray(cable.elements, dtype=np.int64).reshape(-1, 2)
        if side == "left":
            el = el[:, ::-1]
        nodes, local = np.unique(el, return_inverse=True)
        return cls(cable, nodes, local.reshape(-1, 2), name=name or f"{cable.name}_{side}",
                   cell="line2")


def _chained(segments: np.ndarray, cell: CellType, n: int) -> tuple[np.ndarray, bool]:
    """Line cells in chain order (by their ends, the cell's corners) and whether the
    chain is closed (:func:`chain_segments`)."""
    order, closed = chain_segments(segments[:, list(cell.corners)], n)
    return segments[order], closed


class Layout(NamedTuple):
    """How the cells of a surface kind (:mod:`.surface_kinds`) are laid out.

    ``arrange(segments, cell, n)`` the cells in the surface's order and whether the
    surface is closed; ``turned(segments)`` the order of the cells of the surface
    turned over (their nodes already permuted by
    :func:`~skfem_mortar.contact.cell_map.reversal`); ``zero`` what a cell of zero
    measure is called in the error.
    """
    arrange: Callable[[np.ndarray, CellType, int], tuple[np.ndarray, bool]]
    turned: Callable[[np.ndarray], np.ndarray]
    zero: str


#: the layout of each surface kind: curves are one chain, run the other way when
#: turned over; the faces of a 3D body stay in their order
LAYOUTS = {
    CURVE: Layout(arrange=_chained, turned=lambda seg: seg[::-1],
                  zero="segment of zero length"),
    FACE: Layout(arrange=lambda seg, c, n: (seg, closed_surface(seg, c, n)),
                 turned=lambda seg: seg, zero="cell of zero area")}


def _given_cell(cell: Any, segments: Any, d: int) -> CellType:
    """The surface's cell type: ``cell`` as given, else the 2D default read from the
    ``segments`` argument as the user passed it (two columns or a flat list of pairs:
    line2; three columns: line3).  ValueError in 3D without ``cell``, or when the cell's
    dimension is not ``d - 1``."""
    if cell is None:
        if d != 2:
            raise ValueError("cell is required for a surface in 3D (tri3 or quad4)")
        given = np.shape(segments)
        cell = "line3" if len(given) == 2 and given[1] == 3 else "line2"
    cell = cell_type(cell)
    if cell.dim != d - 1:
        raise ValueError(f"cell {cell.name!r} (dim {cell.dim}) does not bound a body in "
                         f"{d} dimensions: a surface in {d}D needs cells of dim {d - 1}")
    return cell


def _vector2(v: Any, name: str) -> np.ndarray:
    """A finite 2-vector (ValueError naming ``name`` otherwise)."""
    a = real_array(name, v)
    if a.shape != (2,):
        raise ValueError(f"{name} must be a 2-vector (x, y), got {v!r}")
    return a


def _segment_count(value: Any, low: int) -> int:
    """``n_segments`` checked: an integer in ``[low, MAX_SEGMENTS]`` (ValueError naming
    it, the bound and why otherwise), before any coordinate is allocated."""
    n = count("n_segments", value, low)
    if n > MAX_SEGMENTS:
        raise ValueError(f"n_segments must be at most MAX_SEGMENTS = {MAX_SEGMENTS} (a "
                         f"rigid surface as fine as the finest cable, MAX_ELEMENTS), got {n}")
    return n


class RigidPlane(ContactSurface):
    """A rigid straight line through ``point`` with outward unit normal ``normal``.

    Represented by ``n_segments`` equal segments (default one) of total
    length ``length`` centred on ``point``, from ``point - (length/2) t`` to
    ``point + (length/2) t`` with ``t = (-n_y, n_x)`` (so that its right-hand
    normal is ``n``).  Mortar projects the master nodes onto the slave
    elements along the slave's normal field; a node very far away (one long
    segment) may have no projection onto a slave element whose normal field
    turns (grazing contact, see docs/robustness.md): more segments, of about
    the slave's size over the contact zone, avoid it.
    """

    def __init__(self, point: tuple[float, float], normal: tuple[float, float],
                 length: float = 1e3, name: str = "plane", n_segments: int = 1):
        point, normal = _vector2(point, "point"), _vector2(normal, "normal")
        nn = np.linalg.norm(normal)
        if not np.isfinite(nn) or nn == 0:
            raise ValueError("normal must be a finite non-zero vector")
        length = real("length", length, 0.0, low_open=True)
        n_segments = _segment_count(n_segments, 1)
        normal = normal / nn
        t = np.array([-normal[1], normal[0]])
        s = np.linspace(-0.5 * length, 0.5 * length, n_segments + 1)
        X = point[:, None] + t[:, None] * s
        seg = np.column_stack([np.arange(n_segments), np.arange(1, n_segments + 1)])
        super().__init__(None, None, seg, X=X, name=name)
        self.point, self.normal = point, normal


class RigidCircle(ContactSurface):
    """A rigid circle (or arc) as a fine polygon, outward normal pointing away from the centre
    (a body pressed onto it from outside), or towards it with ``inside=True`` (a hole, a
    body pressed onto it from inside).

    Parameters
    ----------
    center : (2,)
    radius : float (> 0)
    n_segments : int (>= 3)
    arc : (theta0, theta1), optional
        Angles (radians, counter-clockwise) of the arc; default the full circle.
    inside : bool
        The contacting body is inside the circle: the segments run clockwise,
        so that the right-hand normal points to the centre (default False).
    """

    def __init__(self, center: tuple[float, float], radius: float, n_segments: int = 256,
                 arc: tuple[float, float] | None = None, name: str = "circle",
                 inside: bool = False):
        radius = real("radius", radius, 0.0, low_open=True)
        n_segments = _segment_count(n_segments, 3)
        center = _vector2(center, "center")
        inside = flag("inside", inside)
        if arc is None:
            th = np.linspace(0.0, 2 * np.pi, n_segments, endpoint=False)
            seg = np.column_stack([np.arange(n_segments), np.roll(np.arange(n_segments), -1)])
        else:
            th0, th1 = _vector2(arc, "arc")
            if not th1 > th0:
                raise ValueError(f"arc must be (theta0, theta1) with theta1 > theta0, "
                                 f"got {arc!r}")
            th = np.linspace(th0, th1, n_segments + 1)
            seg = np.column_stack([np.arange(n_segments), np.arange(1, n_segments + 1)])
        X = center[:, None] + radius * np.vstack([np.cos(th), np.sin(th)])
        # counter-clockwise nodes: right-hand normal points outward; reversed
        # segments (clockwise) for a body inside the circle: normal to the centre
        super().__init__(None, None, seg[:, ::-1] if inside else seg, X=X, name=name)
        self.center, self.radius, self.inside = center, float(radius), bool(inside)


#: a rigid master of an axisymmetric model is on the axis constraint when its line's
#: normal is within this of axial or radial (a unit vector's components), or its
#: circle's centre within this times its radius of the axis: round-off of the
#: coordinates the user computed (1e-16 relative) far below, any real tilt or
#: offset (a degree is 1.7e-2) far above
AXIS_TOL = 1e-9


def check_geometry(surface: Any, geometry: str, role: str = "master") -> None:
    """Refuse a rigid surface that has no form in the model's ``geometry``.

    In an axisymmetric model ``(r, z) = (x, y)`` a rigid surface is revolved about
    the axis ``r = 0``: a :class:`RigidPlane` only normal to the axis (a plate,
    ``z = const``) or parallel to it at ``r > 0`` (a cylinder about the axis, ``r =
    const``), a :class:`RigidCircle` only centred on the axis (a sphere), any other
    rigid surface only in ``r >= 0`` (its profile of revolution).  Tolerance
    :data:`AXIS_TOL`.  Deformable surfaces are checked by their bodies, plane models
    take any surface.

    Raises
    ------
    ValueError
        Naming ``role``, the surface and the constraint it breaks.
    """
    if geometry != "axisymmetric" or not getattr(surface, "rigid", False):
        return
    what = f"{role} {surface.name!r}"
    if isinstance(surface, RigidPlane):
        nr, nz = surface.normal
        if abs(nr) <= AXIS_TOL or (abs(nz) <= AXIS_TOL and surface.point[0] > 0):
            return
        raise ValueError(f"{what}: a rigid line in an axisymmetric model must be normal to "
                         f"the axis (a plate z = const: normal (0, +-1)) or parallel to it at "
                         f"r > 0 (a cylinder about the axis: normal (+-1, 0), point with r > 0), "
                         f"got normal ({nr:.6g}, {nz:.6g}) through point "
                         f"({surface.point[0]:.6g}, {surface.point[1]:.6g})")
    if isinstance(surface, RigidCircle):
        if abs(surface.center[0]) <= AXIS_TOL * surface.radius:
            return
        raise ValueError(f"{what}: a rigid circle in an axisymmetric model must have its "
                         f"centre on the axis (r = 0: a sphere), got center "
                         f"({surface.center[0]:.6g}, {surface.center[1]:.6g})")
    r_min = float(np.min(surface.X[0]))
    if r_min < 0:
        raise ValueError(f"{what}: a rigid surface in an axisymmetric model lies in r >= 0 "
                         f"(its profile revolved about the axis r = 0), and its smallest r is "
                         f"{r_min:.6g}")
