"""Prescribed displacements: :class:`Dirichlet`, and node numbers against dof numbers.

A 2D body numbers its unknowns per node and component (``node_dofs``, shape
``(2, n_nodes)``), so node ``k`` is not dof ``k``.  ``Dirichlet(body, nodes=...)``
takes node numbers (``mesh.boundary_nodes()``, ``mesh.nodes_satisfying(...)``)
and makes the dofs (:func:`dofs_of_nodes`); ``Dirichlet(body, dofs)`` refuses
node numbers passed as dofs where it can tell (:func:`node_numbers_as_dofs`).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .item import Item

__all__ = ["Dirichlet", "dofs_of_nodes", "node_numbers_as_dofs", "dof_indices", "component_rows"]

_COMPONENTS = {0: 0, 1: 1, 2: 2, "x": 0, "y": 1, "z": 2}


def component_rows(component: int | str | None, n_comp: int) -> tuple[int, ...]:
    """The rows of ``node_dofs`` (components) that ``component`` names in a body
    with ``n_comp`` displacement components: all of them for None.

    Raises
    ------
    ValueError
        For anything but None, 0 .. n_comp - 1 or "x", "y" (and "z" in 3D),
        naming the allowed values (a bool is refused: True == 1).
    """
    allowed = [k for k, v in _COMPONENTS.items() if v < n_comp]
    if component is None:
        return tuple(range(n_comp))
    if isinstance(component, (bool, np.bool_)) or not isinstance(component, (int, str,
                                                                           np.integer)) \
            or component not in allowed:
        words = ", ".join(repr(k) for k in allowed[:-1]) + f" or {allowed[-1]!r}"
        every = "both" if n_comp == 2 else f"all {n_comp}"
        raise ValueError(f"component must be None ({every}), {words}, got {component!r}")
    return (_COMPONENTS[component],)


def dofs_of_nodes(body: Any, nodes: Any, component: int | str | None, what: str
                  ) -> np.ndarray:
    """The local dofs of ``nodes`` of ``body``, component-major
    (``node_dofs[components][:, nodes].ravel()``: every x dof, then every y dof).

    Raises
    ------
    ValueError
        For a body without ``node_dofs``, a ``component`` not in
        ``{None, 0, 1, "x", "y"}`` (and ``2, "z"`` in 3D, :func:`component_rows`), or
        nodes that are neither integers in ``[0, n_nodes)`` nor a boolean mask of
        length ``n_nodes`` (``what`` names them).
    """
    nd = getattr(body, "node_dofs", None)
    rows = component_rows(component, 2 if nd is None else np.shape(nd)[0])
    if nd is None:
        raise ValueError(f"{what}: body {body.name!r} ({type(body).__name__}) has no "
                         f"node_dofs; give dofs instead of nodes")
    nd = np.asarray(nd, dtype=np.int64)
    a = dof_indices(nodes, nd.shape[1], what)  # (the same rules: integers or a mask)
    return nd[list(rows)][:, a].ravel()


def _named_node_sets(mesh: Any) -> dict[str, np.ndarray]:
    """The vertex set of each named boundary of ``mesh``."""
    return {name: np.unique(mesh.facets[:, np.asarray(facets, dtype=np.int64)])
            for name, facets in (getattr(mesh, "boundaries", None) or {}).items()}


def _along_boundary(mesh: Any, vertices: np.ndarray) -> bool:
    """Whether each of ``vertices`` that is a corner of a boundary facet shares a
    boundary facet with another of them (a run along the boundary)."""
    ends = np.asarray(mesh.facets, dtype=np.int64)[:, mesh.boundary_facets()]
    inside = np.isin(ends, vertices)
    corners = np.isin(vertices, ends)
    linked = np.isin(vertices, ends[:, inside.all(axis=0)])
    return bool(np.all(linked | ~corners))


def node_numbers_as_dofs(body: Any, dofs: np.ndarray) -> str:
    """Why the local ``dofs`` of a body with a mesh look like node numbers
    ("" if they do not, or if the body has no mesh to tell by).

    They do when there are 3 or more, every one is a vertex number
    (``< n_nodes``) of a vertex on the boundary, read as vertices they run along
    the boundary (each shares a boundary facet with another: what
    ``mesh.nodes_satisfying`` of an edge and ``mesh.boundary_nodes()`` give;
    ``dofs_on`` of an edge plus a pin inside reads as scattered vertices), and either

    - read as dofs they hold a single component of an interior vertex
      (``mesh.boundary_nodes()``, the nodes of an edge: a support is on the
      boundary, and an interior point support holds both components), or
    - they are exactly the vertices of a named boundary (``mesh.nodes_satisfying``
      of a named edge) and read as dofs hold one component of some vertex.

    Dofs a body method gives on the boundary (``dofs_on``) reach no interior
    vertex, and ``dofs_at_nodes`` holds both components of each vertex; one
    or two numbers (a vertex's two dofs, an edge's ends) are never refused.
    Not told apart: vertex numbers that read as dofs are both components of
    boundary vertices (the first four vertices of an edge numbered from 0 are
    also both dofs of its first two): that is a support too.
    """
    mesh, nd = getattr(body, "mesh", None), getattr(body, "node_dofs", None)
    if mesh is None or nd is None or not hasattr(mesh, "boundary_nodes"):
        return ""
    given = np.unique(dofs)
    nd = np.asarray(nd, dtype=np.int64)
    if given.size < 3 or given.max() >= nd.shape[1]:
        return ""
    bnodes = np.unique(mesh.boundary_nodes())
    if not np.all(np.isin(given, bnodes)) or not _along_boundary(mesh, given):
        return ""
    held = np.isin(nd, given)                                # (d, n_nodes)
    half = held.any(axis=0) & ~held.all(axis=0)              # some components held
    inner = np.flatnonzero(half & ~np.isin(np.arange(nd.shape[1]), bnodes))
    if inner.size:
        v = int(inner[0])
        k = int(nd[np.argmax(held[:, v]), v])
        many = f"{inner.size} interior {'vertex' if inner.size == 1 else 'vertices'}"
        return (f"read as dofs they hold one component of {many} (e.g. dof {k} of "
                f"vertex {v}), while read as vertex numbers all {given.size} lie on "
                f"the boundary")
    for name, nodes in _named_node_sets(mesh).items():
        if half.any() and np.array_equal(given, nodes):
            return (f"they are exactly the vertex numbers of boundary {name!r}, and read "
                    f"as dofs they hold one component of vertex {int(np.flatnonzero(half)[0])}")
    return ""


def dof_indices(dofs: Any, n: int, what: str) -> np.ndarray:
    """Integer dof indices in ``[0, n)`` from ``dofs`` (ValueError otherwise).

    A boolean mask of length ``n`` is taken as the mask it is (its True
    entries); any other boolean array, non-integer numbers, or indices
    outside ``[0, n)`` are refused.
    """
    a = np.asarray(dofs)
    if a.dtype == bool:
        if a.shape != (n,):
            raise ValueError(f"{what}: a boolean mask must have shape ({n},), got {a.shape}")
        return np.flatnonzero(a)
    a = a.ravel()
    if a.size and not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{what} must be integers in [0, {n}), got {a.dtype} values")
    a = a.astype(np.int64)
    if a.size and (a.min() < 0 or a.max() >= n):
        raise ValueError(f"{what} must lie in [0, {n}), got values in [{a.min()}, {a.max()}]")
    return a


def _check_repeats(value: np.ndarray, inverse: np.ndarray, first: np.ndarray,
                   dofs: np.ndarray) -> None:
    """A dof listed twice must be given the same value both times."""
    kept = value[first][inverse.ravel()]  # the value of each dof's first listing
    clash = value != kept
    if np.any(clash):
        k = int(np.flatnonzero(clash)[0])
        raise ValueError(f"dof {dofs[k]} is listed twice with different values "
                         f"({kept[k]} and {value[k]})")


def _node_values(value: np.ndarray, n_dofs: int, component: int | str | None,
                 n_comp: int = 2) -> np.ndarray:
    """Values given per node as ``(components, nodes)`` (an x row, a y row, ...),
    flat in the order of the dofs; ValueError naming ``value`` for any other
    shape (a node-major ``(nodes, components)`` array would interleave x and y)."""
    k = len(component_rows(component, n_comp))
    want = (k, n_dofs // k)
    if value.shape != want:
        raise ValueError(f"value given per node must have shape {want} (one row per "
                         f"component, one column per node; transpose a (nodes, "
                         f"components) array), got shape {value.shape}")
    return value.ravel()


def _given_dofs(body: Item, dofs: Any, nodes: Any, component: int | str | None,
                boundary: Any = None) -> np.ndarray:
    """The local dofs of a :class:`Dirichlet`: ``dofs`` checked (and refused
    when they look like node numbers), the dofs of ``nodes``, or those of a
    ``boundary`` (``body.dofs_on(boundary, component)``)."""
    if isinstance(dofs, str):      # Dirichlet(body, "bottom"): a tag where dofs go
        raise ValueError(f"Dirichlet on body {body.name!r}: dofs must be dof numbers, got the "
                         f"string {dofs!r}; a boundary tag goes to boundary=: "
                         f"Dirichlet({body.name}, boundary={dofs!r})")
    given = sum(a is not None for a in (dofs, nodes, boundary))
    if given != 1:
        raise ValueError(f"Dirichlet on body {body.name!r}: give either dofs (e.g. "
                         f"body.dofs_on('top')) or nodes= (vertex numbers) or boundary= "
                         f"(a boundary tag), not {'neither' if given == 0 else 'both'}")
    if boundary is not None:
        if not hasattr(body, "dofs_on"):
            raise ValueError(f"boundary: body {body.name!r} ({type(body).__name__}) has no "
                             f"boundaries (dofs_on); give dofs instead")
        if component is not None:   # the allowed values, in the body's dimension
            component_rows(component, int(np.shape(body.node_dofs)[0]))
        return np.asarray(body.dofs_on(boundary, component), dtype=np.int64)
    if nodes is not None:
        return dofs_of_nodes(body, nodes, component, f"nodes of body {body.name!r}")
    if component is not None:
        raise ValueError(f"component={component!r} goes with nodes= or boundary=, not with "
                         f"dofs (body.dofs_on(..., component) gives the dofs of one "
                         f"component)")
    given = np.asarray(dofs)
    out = dof_indices(dofs, body.n_dofs, f"dofs of body {body.name!r}")
    why = "" if given.dtype == bool else node_numbers_as_dofs(body, out)
    if why:
        raise ValueError(f"dofs of body {body.name!r} look like node numbers: {why}. Node k "
                         f"has the dofs body.node_dofs[:, k]: give the nodes as "
                         f"Dirichlet(body, nodes=..., component=None|'x'|'y'|...), or dofs from "
                         f"body.dofs_on(boundary) / body.dofs_at_nodes(nodes) (dofs that are "
                         f"meant, read so, pass as a boolean mask over the body's dofs)")
    return out


class Dirichlet(Item):
    """Prescribed values of global unknowns, ramped with the load factor.

    ``value(load_factor) = ramp * load_factor * value + (1 - ramp) * value``, or,
    when ``value`` is a callable, ``value(load_factor)`` itself (a load path,
    e.g. press a die down, then slide it).

    Parameters
    ----------
    body : Item
        The body whose unknowns are prescribed.
    dofs : array of int or bool, optional
        Dof indices *local to the body's block*, as the body's methods give
        them (``body.dofs_on("top")``, ``cable.support_dofs()``), or a boolean
        mask of them.  Node numbers are not dofs (node ``k`` has the dofs
        ``body.node_dofs[:, k]``): integers that look like the node numbers
        of a boundary (:func:`node_numbers_as_dofs`) are refused; give those
        as ``nodes``.
    value : float, array or callable
        Final prescribed value(s) (displacement), or a function of the load
        factor returning a scalar or one value per dof (in the order of
        ``dofs``; with ``nodes``: every x value, then every y value (then z in 3D)).
    ramp : bool
        Scale the value with the load factor (default) or hold it fixed.
    nodes : array of int or bool, optional (keyword only)
        Instead of ``dofs``: vertex numbers of the body (``mesh.boundary_nodes()``,
        ``mesh.nodes_satisfying(...)``) or a boolean mask of its vertices,
        with ``component``.
    boundary : str, array of int or callable, optional (keyword only)
        Instead of ``dofs``: a boundary of the body (a tag of
        ``mesh.boundaries``, facet indices, or a test of facet midpoints), all its
        dofs (vertex, edge and face nodes) of ``component``:
        ``body.dofs_on(boundary, component)``.
    component : {None, 0, 1, "x", "y"}, and 2, "z" in 3D (keyword only)
        With ``nodes`` or ``boundary``: every component (None, default) or one.

    Raises
    ------
    ValueError
        Neither or both of ``dofs`` and ``nodes``, ``component`` without
        ``nodes``, indices out of range, node numbers given as ``dofs``,
        non-finite values.
    """

    def __init__(self, body: Item, dofs: np.ndarray | None = None,
                 value: float | np.ndarray = 0.0, ramp: bool = True, name: str = "", *,
                 nodes: np.ndarray | None = None, component: int | str | None = None,
                 boundary: str | np.ndarray | Any = None):
        if not isinstance(body, Item) or body.dof_kind != "u":
            raise ValueError(f"body must be a body of the model (a Solid, Cable, ...), "
                             f"got {type(body).__name__}")
        self.body = body
        dofs = _given_dofs(body, dofs, nodes, component, boundary)
        self.local_dofs, self._order, inverse = np.unique(dofs, return_index=True,
                                                          return_inverse=True)
        self.path = value if callable(value) else None
        if self.path is not None:
            value = np.asarray(self.path(0.0), dtype=float)
        value = np.asarray(value, dtype=float)
        if nodes is not None and value.ndim > 1:  # (components, nodes): x row, y row
            value = _node_values(value, dofs.size, component,
                                 int(np.shape(getattr(body, "node_dofs", np.zeros((2, 0))))[0]))
        if value.ndim and value.shape != dofs.shape:
            raise ValueError(f"value must be a scalar or one value per dof ({dofs.size}), "
                             f"got shape {value.shape}")
        if not np.all(np.isfinite(value)):
            raise ValueError(f"value must be finite (dirichlet on body {body.name!r})")
        if value.ndim:  # keep values aligned with the sorted unique dofs
            _check_repeats(value, inverse, self._order, dofs)
            value = value[self._order]
        self.value = value
        self.ramp = ramp
        self.name = name or f"dirichlet_{body.name}"

    def prescribed(self, load_factor: float) -> tuple[np.ndarray, np.ndarray]:
        if self.path is not None:
            vals = np.asarray(self.path(load_factor), dtype=float)
            vals = vals.ravel()[self._order] if vals.ndim else vals
            if not np.all(np.isfinite(vals)):
                raise ValueError(f"{self.name}: the prescribed path gave non-finite values "
                                 f"at load factor {load_factor}")
            return (self.body.offset + self.local_dofs,
                    np.broadcast_to(vals, self.local_dofs.shape).astype(float))
        scale = load_factor if self.ramp else 1.0
        vals = np.broadcast_to(scale * self.value, self.local_dofs.shape).astype(float)
        return self.body.offset + self.local_dofs, vals
