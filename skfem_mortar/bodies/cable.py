"""Cables: polylines of 2-node string elements in the plane (axial force only).

A :class:`Cable` is a body (``dof_kind == "u"``) whose unknowns are the
displacements of its nodes.  Each element ``e = (i, j)`` has the current
chord ``d = x_j - x_i``, length ``l = |d|``, unit tangent ``t = d / l`` and
the stretch ``lambda = l / L0`` against its rest length ``L0``.  With the axial
force ``N(lambda)`` of a :class:`CableLaw`, the internal virtual work
``N dl`` gives the element forces and the tangent

    f_j = -f_i = N t ,
    K_jj = K_ii = -K_ij = -K_ji = N'(lambda) / L0  t t^T + N / l (I - t t^T) .

Everything is vectorized over the elements; the tangent is returned as COO
triplets.  Construction helpers build a cable between two supports
(:meth:`Cable.between`), a closed ring (:meth:`Cable.ring`) and a polyline
through given points (:meth:`Cable.from_points`).
"""
from __future__ import annotations

import numpy as np
from ..core.lazy import brentq

from .cable_laws import LAWS, CableLaw, get_law, newton_rtol  # noqa: F401 (public here too)
from ..core.errors import InversionError
from ..core.item import Contribution, Item
from ..core.chain import segment_lengths
from ..core.validate import count, flag, real
from ..core.validate_arrays import index_array, real_array

__all__ = ["CableLaw", "LAWS", "get_law", "Cable", "newton_rtol", "side_sign", "MAX_ELEMENTS"]

#: the most elements :meth:`Cable.between` and :meth:`Cable.ring` build: one
#: assembly of a model holding the cable peaks near 2.2 kB per element
#: (measured at 1e6 elements), so about 22 GB at this bound (the scenes stop
#: at 1e6); above it the count is a typo, refused before anything is allocated
MAX_ELEMENTS = 10_000_000


def element_count(value: object, low: int) -> int:
    """``n_elements`` checked: an integer (``2.5`` refused, not truncated) in
    ``[low, MAX_ELEMENTS]``, ValueError naming it, the bound and why otherwise."""
    n = count("n_elements", value, low)
    if n > MAX_ELEMENTS:
        raise ValueError(f"n_elements must be at most MAX_ELEMENTS = {MAX_ELEMENTS} (one "
                         f"assembly takes about 2.2 kB per element: 22 GB there), got {n}")
    return n


def _per_element(name: str, value: object, n_el: int) -> np.ndarray:
    """A finite value > 0 per element from a number or an array of ``n_el`` numbers."""
    a = real_array(name, value, 0.0, low_open=True)
    if a.ndim > 1 or (a.ndim == 1 and a.shape[0] != n_el):
        raise ValueError(f"{name} must be a number or one number per element, shape "
                         f"({n_el},), got shape {a.shape}")
    return np.broadcast_to(a, (n_el,)).copy()


def node_chain(X: np.ndarray, elements: np.ndarray | None, closed: bool
               ) -> tuple[np.ndarray, np.ndarray]:
    """The checked nodes ``X (2, n)`` and 2-node ``elements (n_el, 2)`` of a chain
    (a cable's, a membrane's meridian); ``elements=None``: the nodes in order,
    closed into a loop if ``closed``.  ValueError naming ``X`` or ``elements``."""
    X = real_array("X", X)
    if X.ndim != 2 or X.shape[0] != 2 or X.shape[1] < 2:
        raise ValueError(f"X must have shape (2, n_nodes) with n_nodes >= 2, got {X.shape}")
    n = X.shape[1]
    if elements is None:
        k = np.arange(n)
        elements = np.column_stack([k, np.roll(k, -1)]) if closed else \
            np.column_stack([k[:-1], k[1:]])
    elements = index_array("elements", elements, n)
    if elements.ndim != 2 or elements.shape[1] != 2 or len(elements) == 0:
        raise ValueError(f"elements must have shape (n_el, 2) with n_el >= 1, "
                         f"got {elements.shape}")
    _refuse_duplicates(elements)
    return X, elements


def _refuse_duplicates(elements: np.ndarray) -> None:
    """ValueError naming the first two elements that join the same two nodes (either
    order: the pair's stiffness would count twice) or an element joining a node to itself."""
    same = np.flatnonzero(elements[:, 0] == elements[:, 1])
    if same.size:
        raise ValueError(f"elements must join two different nodes: element "
                         f"{int(same[0])} joins node {int(elements[same[0], 0])} to itself")
    key = np.sort(elements, axis=1)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    dup = np.flatnonzero(first[inverse] != np.arange(len(elements)))
    if dup.size:
        k = int(dup[0])
        j = int(first[inverse[k]])
        raise ValueError(f"elements must list each node pair once (a duplicate doubles "
                         f"its stiffness): elements {j} and {k} both join nodes "
                         f"{tuple(int(i) for i in elements[j])} ({dup.size} duplicate(s))")


def side_sign(side: str | int, name: str = "side") -> int:
    """+1 for "left" (normal = tangent turned by +90 degrees), -1 for "right"
    (the integers +1 and -1 too; a bool or a float is refused, naming ``name``)."""
    if isinstance(side, str) and side in ("left", "right"):
        return 1 if side == "left" else -1
    if isinstance(side, (int, np.integer)) and not isinstance(side, (bool, np.bool_)) \
            and side in (1, -1):
        return int(side)
    raise ValueError(f"{name} must be 'left' or 'right' (or +1 / -1), got {side!r}")


class Cable(Item):
    """A cable (string) body: 2-node elements with axial force only.

    Parameters
    ----------
    X : array (2, n_nodes)
        Node coordinates of the start configuration (dim-first, like skfem).
    elements : int array (n_el, 2), optional
        Node pairs ordered along the chain.  Default: ``(k, k+1)`` for an open
        polyline, plus ``(n-1, 0)`` when ``closed``.
    EA : float or array (n_el,)
        Axial stiffness, > 0.
    law : {"linear", "svk", "hencky"} or CableLaw
        Axial law N(lambda).
    tension_only : bool
        If True a slack element (lambda < 1) carries no force, ``N = 0``.
    closed : bool
        Whether the polyline is a closed ring (only used for the default
        ``elements``).
    rest_length : float or array (n_el,), optional
        Stress-free lengths ``L0``.  Default: the element lengths in ``X``
        (then ``X`` is stress free).  A start geometry that differs from the
        stress-free one (e.g. the small sag of :meth:`between`) sets them.
    slack_stiffness : float
        Regularization of the tangent of slack elements when ``tension_only``
        (see Notes), >= 0.  Default 1.
    tension_floor : float
        Tangent-only floor ``N_f`` (a force, >= 0) of the geometric stiffness:
        the tangent uses ``max(N, load_factor * N_f) / l (I - t t^T)`` (see
        Notes).  Default 0 (exact tangent everywhere).
    name : str

    Raises
    ------
    ValueError
        Naming the parameter: a number that is not a finite real number in its
        range (a string such as ``"1"``, a bool, NaN or infinity), a flag that is
        not a bool, node indices that are not integers in ``[0, n_nodes)``, an
        element listed twice (the same node pair in either order: its stiffness
        would count twice), ``EA`` or ``rest_length`` of the wrong length.

    Notes
    -----
    *Slack elements.*  With ``tension_only`` a slack element has ``N = 0`` and
    an exactly zero derivative, so a partly slack cable has a singular
    tangent (its nodes can move freely).  The residual is kept exact, but the
    tangent of a slack element is replaced by
    ``slack_stiffness * EA / L0 * t t^T``, the axial stiffness it has when just
    taut (all laws have ``N'(1) = EA``).  Newton then takes bounded steps
    through slack states (a secant-like predictor), and since only the
    tangent changes, a converged state solves the exact tension-only
    equations.  Where every element is taut at the solution the tangent is
    exact there and convergence quadratic.  ``slack_stiffness=0`` gives the
    exact (singular) derivative, used by the finite-difference tests.

    *Unstressed starts.*  At a stress-free start (``N = 0``) the tangent has no
    geometric stiffness ``N / l``; under a pressure the equilibrium tension is
    ``T ~ p r``, so the short-wave transverse modes of a fine cable are
    under-stiffened by a factor ``T / (p l^2)`` and the first Newton step
    throws them far off (measured on ``cable_arc``, svk and hencky laws, 1e3
    to 1e4 elements: 15-25 iterations in the first step, and step cuts; 4
    iterations with the floor below).  A
    ``tension_floor`` ``N_f`` replaces ``N`` by ``max(N, lf N_f)`` in the
    geometric stiffness of the *tangent only*.  The residual is unchanged, so
    a converged state solves the exact equations; wherever the tension at the
    solution exceeds ``lf N_f`` the tangent is exact there and convergence
    quadratic.  Scenes with a pressure ``p`` on a cable of half-span or
    radius ``a`` (tension at least ``lf p a``) use ``N_f = 0.1 p a``.
    """

    dof_kind = "u"
    geometries = ("plane",)
    #: what to use instead in another geometry (the model's refusal says it)
    geometry_advice = {"axisymmetric": (
        "a Cable is a plane string; in an axisymmetric model use Membrane "
        "(skfem_mortar.bodies.membrane), the membrane of revolution (meridian nodes "
        "(R, Z), laws 'neo-hooke' and 'svk')")}
    loaded = False  # its residual does not depend on the load factor
    phase = "bulk"

    def __init__(self, X: np.ndarray, elements: np.ndarray | None = None, *,
                 EA: float | np.ndarray = 1.0, law: str | CableLaw = "linear",
                 tension_only: bool = False, closed: bool = False,
                 rest_length: float | np.ndarray | None = None,
                 slack_stiffness: float = 1.0, tension_floor: float = 0.0,
                 name: str = "cable"):
        closed = flag("closed", closed)
        X, elements = node_chain(X, elements, closed)
        n = X.shape[1]
        self.X = X
        self.elements = elements
        self.closed = closed
        self.law = get_law(law)
        self.tension_only = flag("tension_only", tension_only)
        # finite: an infinite slack tangent makes every slack row inf (the solve NaN)
        self.slack_stiffness = real("slack_stiffness", slack_stiffness, 0.0)
        self.tension_floor = real("tension_floor", tension_floor, 0.0)
        n_el = len(elements)
        self.EA = _per_element("EA", EA, n_el)
        chord = segment_lengths(X, elements)
        if np.any(chord <= 1e-12 * max(float(np.max(chord)), np.finfo(float).tiny)):
            k = int(np.argmin(chord))
            ends = tuple(int(i) for i in elements[k])
            raise ValueError(f"X: element {k} joins coincident nodes {ends}; "
                             f"every element must have a length > 0")
        self._dX = X[:, elements[:, 1]] - X[:, elements[:, 0]]
        if rest_length is None:
            rest_length = chord
        self.rest_length = _per_element("rest_length", rest_length, n_el)
        self.name = name
        self.n_nodes = n
        self.n_dofs = 2 * n
        # interleaved like skfem's ElementVector: node k -> dofs (2k, 2k+1)
        self.node_dofs = np.arange(2 * n, dtype=np.int64).reshape(n, 2).T.copy()

    # -- construction helpers ----------------------------------------------
    @classmethod
    def from_points(cls, points: np.ndarray, *, closed: bool = False, **kw) -> "Cable":
        """A polyline through ``points`` (n, 2) (or (2, n); a (2, 2) array is read
        as two points, row-wise), stress free as given; ``kw`` as for :class:`Cable`."""
        P = real_array("points", points)
        if P.ndim == 2 and P.shape[1] == 2 and P.shape[0] != 2:
            P = P.T
        elif P.ndim == 2 and P.shape == (2, 2):
            P = P.T  # two points given row-wise
        return cls(P, closed=flag("closed", closed), **kw)

    @classmethod
    def ring(cls, radius0: float, n_elements: int, *,
             center: tuple[float, float] = (0.0, 0.0), **kw) -> "Cable":
        """A closed ring, nodes counter-clockwise on the circle of radius ``radius0``.

        Stress free as built (rest lengths ``2 radius0 sin(pi / n)``).  The
        outward normal is on the *right* of the chain direction.
        """
        radius0 = real("radius0", radius0, 0.0, low_open=True)
        n = element_count(n_elements, 3)
        center = _point("center", center)
        phi = 2.0 * np.pi * np.arange(n) / n
        X = np.vstack([center[0] + radius0 * np.cos(phi),
                       center[1] + radius0 * np.sin(phi)])
        return cls(X, closed=True, **kw)

    @classmethod
    def between(cls, start: np.ndarray | tuple[float, float],
                end: np.ndarray | tuple[float, float], length0: float, n_elements: int, *,
                bulge: str | int = "left", start_sag: float = 0.05,
                span_rtol: float = 1e-9, **kw) -> "Cable":
        """An open cable of reference length ``length0`` from ``start`` to ``end``.

        The start geometry (the nodes in ``X``) is well posed in all cases:

        * ``length0 > span``: the stress-free arc, ``n`` equal chords of length
          ``length0 / n`` inscribed in a circle through both supports, bulging to
          ``bulge`` (the side the pressure pushes to).  Chord half-angle alpha
          solves ``span / c = sin(n alpha) / sin(alpha)``.
        * ``length0 == span`` (within ``span_rtol``): a straight stress-free
          cable has no transverse stiffness, its first tangent is singular.
          Regularization: the nodes start on a shallow circular arc of height
          ``start_sag * span`` bulging to ``bulge`` while the rest lengths stay
          ``length0 / n``, so the start is slightly stretched (stretch
          ``1 + (8/3) start_sag^2`` to leading order) and has a transverse
          geometric stiffness ``N / l``.  Only the starting point of Newton
          changes, not the equations (the supports are pinned at the same
          points), so the converged answer does not depend on ``start_sag``.
          A stress-free arc flatter than ``start_sag * span`` (``length0`` below
          about ``span (1 + (8/3) start_sag^2)``) is nearly as degenerate (its
          first Newton steps overshoot, and with the hencky law may land on
          the far equilibrium branch) and starts the same way.
        * ``length0 < span``: straight, pre-stretched (rest length ``length0 / n``).

        Supports: pin both ends with ``Dirichlet(cable, cable.support_dofs())``.

        Raises
        ------
        ValueError
            Naming the parameter: ``start``, ``end`` not two distinct points of finite
            numbers, ``length0`` not a finite number > 0, ``n_elements`` not an integer
            in ``[1, MAX_ELEMENTS]`` (checked before anything is allocated),
            ``start_sag`` outside ``(0, 0.5]``, ``bulge`` not a side.
        """
        n = element_count(n_elements, 1)
        p0, p1 = _point("start", start), _point("end", end)
        span = float(np.hypot(*(p1 - p0)))
        if not span > 0:
            raise ValueError(f"start and end must differ, got {p0.tolist()} twice")
        length0 = real("length0", length0, 0.0, low_open=True)
        start_sag = real("start_sag", start_sag, 0.0, 0.5, low_open=True)
        span_rtol = real("span_rtol", span_rtol, 0.0, 1.0)
        sign = side_sign(bulge, "bulge")
        rest = length0 / n
        X = None
        if length0 > span * (1.0 + span_rtol):
            X = _arc_equal_chords(p0, p1, rest, n, sign)
            t = (p1 - p0) / span
            height = np.max(sign * (t[0] * (X[1] - p0[1]) - t[1] * (X[0] - p0[0])))
            if n > 1 and height < start_sag * span:
                X = None        # too flat: regularized like the straight start
        if X is None and length0 >= span * (1.0 - span_rtol):
            X = _arc_by_height(p0, p1, start_sag * span, n, sign)
        elif X is None:
            s = np.linspace(0.0, 1.0, n + 1)
            X = p0[:, None] + (p1 - p0)[:, None] * s
        return cls(X, closed=False, rest_length=rest, **kw)

    # -- kinematics --------------------------------------------------------
    def u(self, z: np.ndarray) -> np.ndarray:
        """Nodal displacements (2, n_nodes)."""
        return np.asarray(z)[self.offset + self.node_dofs]

    def x(self, z: np.ndarray) -> np.ndarray:
        """Current node coordinates (2, n_nodes)."""
        return self.X + self.u(z)

    def support_dofs(self, nodes: np.ndarray | list[int] | None = None) -> np.ndarray:
        """Local dofs (x and y) of ``nodes``; default both ends of an open cable."""
        if nodes is None:
            if self.closed:
                raise ValueError("a closed ring has no end nodes: pass nodes explicitly")
            nodes = [self.elements[0, 0], self.elements[-1, 1]]
        nodes = np.atleast_1d(index_array("nodes", nodes, self.n_nodes))
        return self.node_dofs[:, nodes].T.ravel()

    def element_dofs(self) -> np.ndarray:
        """Local dofs (n_el, 4) ordered ``[x_i, y_i, x_j, y_j]``."""
        i, j = self.elements[:, 0], self.elements[:, 1]
        nd = self.node_dofs
        return np.column_stack([nd[0, i], nd[1, i], nd[0, j], nd[1, j]])

    def _geometry(self, z: np.ndarray):
        # chord = reference chord + displacement difference: no round-off of
        # the absolute positions X + u enters the (short) chords of a fine cable
        # (hence not segment_lengths(self.x(z), ...))
        u = self.u(z)
        i, j = self.elements[:, 0], self.elements[:, 1]
        d = self._dX + (u[:, j] - u[:, i])
        length = np.hypot(d[0], d[1])
        if not np.all(np.isfinite(length)):
            raise InversionError(f"{self.name}: non-finite node coordinates")
        if np.any(length <= 1e-14 * self.rest_length):
            raise InversionError(f"{self.name}: an element collapsed to zero length")
        return d, length

    def _force(self, stretch: np.ndarray):
        """Axial force, its derivative, and the tangent's derivative (regularized)."""
        N = self.law.force(stretch, self.EA)
        dN = self.law.stiffness(stretch, self.EA)
        dN_tangent = dN
        if self.tension_only:
            slack = stretch < 1.0
            N = np.where(slack, 0.0, N)
            dN = np.where(slack, 0.0, dN)
            dN_tangent = np.where(slack, self.slack_stiffness * self.EA, dN)
        return N, dN, dN_tangent

    def stretch(self, z: np.ndarray) -> np.ndarray:
        """Element stretch ``lambda = l / L0`` (n_el,)."""
        return self._geometry(z)[1] / self.rest_length

    def tension(self, z: np.ndarray) -> np.ndarray:
        """Element axial force ``N(lambda)`` (n_el,)."""
        return self._force(self.stretch(z))[0]

    # -- assembly ----------------------------------------------------------
    def assemble(self, z: np.ndarray, load_factor: float,
                 tangent: bool = True) -> Contribution:
        """Internal forces ``f_j = -f_i = N t`` and tangent (see module docstring;
        regularizations of slack elements and of unstressed states in the class Notes)."""
        d, length = self._geometry(z)
        N, _, dN_t = self._force(length / self.rest_length)
        if not np.all(np.isfinite(N)):
            raise InversionError(f"{self.name}: non-finite axial force")
        t = d / length                                   # (2, n_el)
        f = (N * t).T                                    # force on node j
        r = np.hstack([-f, f])                           # (n_el, 4)
        dofs = self.offset + self.element_dofs()
        if not tangent:
            return Contribution.from_dofs(dofs, r)
        tt = np.einsum("ie,je->eij", t, t)               # (n_el, 2, 2)
        kmat = (dN_t / self.rest_length)[:, None, None]
        N_geo = N if self.tension_floor == 0.0 else \
            np.maximum(N, load_factor * self.tension_floor)
        kgeo = (N_geo / length)[:, None, None]
        Kjj = kmat * tt + kgeo * (np.eye(2) - tt)
        k = np.empty((len(N), 4, 4))
        k[:, :2, :2] = Kjj
        k[:, 2:, 2:] = Kjj
        k[:, :2, 2:] = -Kjj
        k[:, 2:, :2] = -Kjj
        return Contribution.from_dofs(dofs, r, k)

    # -- output ------------------------------------------------------------
    def output_mesh(self):
        """Points (n, 2) of the start geometry and the polyline cells ("line")."""
        return self.X.T.copy(), [("line", self.elements.copy())]

    def output_data(self, z: np.ndarray):
        """Point data ``displacement``; cell data ``tension`` and ``stretch``."""
        stretch = self.stretch(z)
        return ({"displacement": self.u(z).T.copy()},
                {"tension": [self._force(stretch)[0]], "stretch": [stretch]})

    def __repr__(self) -> str:
        """One line: name, law, open or closed, sizes."""
        kind = "closed" if self.closed else "open"
        slack = ", tension only" if self.tension_only else ""
        return (f"Cable({self.name!r}, law {self.law.name}{slack}, {kind}: {self.n_nodes} nodes, "
                f"{len(self.elements)} elements, {self.n_dofs} dofs)")


# -- start geometries ---------------------------------------------------------
def _point(name: str, value: object) -> np.ndarray:
    """A point (x, y) of finite real numbers, ValueError naming ``name`` otherwise."""
    a = real_array(name, value)
    if a.shape != (2,):
        raise ValueError(f"{name} must be a point (x, y), got shape {a.shape}")
    return a


def _arc_points(p0, p1, radius, half_angle, n, sign):
    """n+1 points on a circular arc from p0 to p1 with central half-angle
    ``half_angle`` (in (0, pi)), bulging to the side ``sign`` (+1 left)."""
    t = (p1 - p0) / np.hypot(*(p1 - p0))
    m = sign * np.array([-t[1], t[0]])
    mid = 0.5 * (p0 + p1)
    center = mid - m * radius * np.cos(half_angle)
    phi = np.linspace(-half_angle, half_angle, n + 1)
    pts = center[:, None] + radius * (np.outer(t, np.sin(phi)) + np.outer(m, np.cos(phi)))
    pts[:, 0], pts[:, -1] = p0, p1
    return pts


def _arc_equal_chords(p0, p1, chord, n, sign):
    """n equal chords of length ``chord`` inscribed in a circle through p0, p1.

    The chord half-angle alpha in (0, pi/n) solves
    ``span / chord = sin(n alpha) / sin(alpha)`` (decreasing from n to 0).
    """
    span = np.hypot(*(p1 - p0))
    target = span / chord
    if n == 1 or target >= n:
        s = np.linspace(0.0, 1.0, n + 1)
        return p0[:, None] + (p1 - p0)[:, None] * s
    g = lambda a: np.sin(n * a) / np.sin(a) - target
    hi = np.pi / n
    alpha = brentq(g, 1e-15 * hi, hi * (1 - 1e-15), xtol=1e-15 * hi, rtol=4 * np.finfo(float).eps)
    radius = chord / (2.0 * np.sin(alpha))
    return _arc_points(p0, p1, radius, n * alpha, n, sign)


def _arc_by_height(p0, p1, height, n, sign):
    """n+1 points equally spaced in angle on the arc of the given apex height."""
    half = 0.5 * np.hypot(*(p1 - p0))
    radius = (half ** 2 + height ** 2) / (2.0 * height)
    half_angle = np.arcsin(min(1.0, half / radius))
    if height > half:
        half_angle = np.pi - half_angle
    return _arc_points(p0, p1, radius, half_angle, n, sign)
