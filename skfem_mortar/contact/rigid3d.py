"""Rigid masters of 3D models: a plane, a sphere and a cylinder, each an exact surface
that NTS projects onto (:func:`exact_gaps`), with a face mesh for the outputs and the
preflight's facing test (:class:`RigidSurface3D`).

Gaps of a slave node ``x`` (positive open; ``s = +1`` for a body outside the sphere or
cylinder, ``-1`` inside) and their derivatives (the master has no dofs, so only
``x`` varies)::

    plane     g = n . (x - p)                     dg/dx = n          d2g/dx2 = 0
    sphere    g = s (|x - c| - R),  e = (x - c)/|x - c|
                                                  dg/dx = s e        d2g/dx2 = s (I - e e^T) / |x - c|
    cylinder  g = s (|P (x - a)| - R),  P = I - t t^T,  e = P (x - a)/|P (x - a)|
                                                  dg/dx = s e        d2g/dx2 = s (P - e e^T) / |P (x - a)|

(``n`` the plane's unit normal through ``p``; ``c``, ``R`` the centre and radius;
``a``, ``t`` a point of the axis and its unit direction).  The normal of each is
``dg/dx``; a node on the centre or the axis has none and is left out of ``mask``.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..core.validate import flag, real
from .surfaces import ContactSurface

__all__ = ["RigidSurface3D", "RigidPlane3D", "RigidSphere", "RigidCylinder", "exact_gaps"]


def _vector3(v: Any, name: str, unit: bool = False) -> np.ndarray:
    a = np.asarray(v, dtype=float).ravel()
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be three finite numbers, got {v!r}")
    if unit:
        n = np.linalg.norm(a)
        if n == 0:
            raise ValueError(f"{name} must be a non-zero vector")
        a = a / n
    return a


def _frame(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors ``u, v`` with ``(u, v, t)`` right-handed and orthonormal."""
    a = np.eye(3)[int(np.argmin(np.abs(t)))]
    u = np.cross(a, t)
    u /= np.linalg.norm(u)
    return u, np.cross(t, u)


class RigidSurface3D(ContactSurface):
    """A rigid surface of a 3D model with an exact gap (:meth:`exact_gap`); its faces
    (quad4 or tri3, counter-clockwise seen from the side the slave is on) only draw
    it and serve the preflight."""

    def exact_gap(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``g (n,)``, ``dg/dx (3, n)``, ``d2g/dx2 (3, 3, n)`` of the points ``x (3, n)``
        and whether each has a gap (module docstring)."""
        raise NotImplementedError


class RigidPlane3D(RigidSurface3D):
    """The rigid plane through ``point`` with unit normal ``normal`` (pointing to the
    slave's side), drawn as one square face of side ``size`` centred on ``point``."""

    def __init__(self, point: Any, normal: Any, size: float = 1e3, name: str = "plane"):
        self.point, self.normal = _vector3(point, "point"), _vector3(normal, "normal", True)
        size = real("size", size, 0.0, low_open=True)
        u, v = _frame(self.normal)
        c = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * 0.5 * size
        X = self.point[:, None] + np.outer(u, c[:, 0]) + np.outer(v, c[:, 1])
        super().__init__(None, None, np.array([[0, 1, 2, 3]]), X=X, name=name, cell="quad4")

    def exact_gap(self, x):
        n = x.shape[1]
        g = self.normal @ (x - self.point[:, None])
        return (g, np.repeat(self.normal[:, None], n, axis=1), np.zeros((3, 3, n)),
                np.ones(n, dtype=bool))


def _round(x: np.ndarray, centre: np.ndarray, P: np.ndarray, radius: float, sign: float):
    """Gap, gradient, Hessian and ``ok`` of ``s (|P (x - c)| - R)``."""
    d = P @ (x - centre[:, None])
    r = np.sqrt(np.sum(d * d, axis=0))
    ok = r > 1e-12 * radius
    rs = np.where(ok, r, 1.0)
    e = d / rs
    H = (P[:, :, None] - e[:, None, :] * e[None, :, :]) / rs
    return sign * (r - radius), sign * e, sign * H, ok


class RigidSphere(RigidSurface3D):
    """The rigid sphere of ``center`` and ``radius``; the slave outside it (default) or
    inside (``inside=True``).  Drawn as an icosahedron refined ``refine`` times onto it."""

    def __init__(self, center: Any, radius: float, inside: bool = False, refine: int = 3,
                 name: str = "sphere"):
        self.center = _vector3(center, "center")
        self.radius = real("radius", radius, 0.0, low_open=True)
        self.inside = flag("inside", inside)
        X, tri = _icosphere(int(refine))
        super().__init__(None, None, tri[:, ::-1] if inside else tri,
                         X=self.center[:, None] + self.radius * X, name=name, cell="tri3")

    def exact_gap(self, x):
        return _round(x, self.center, np.eye(3), self.radius, -1.0 if self.inside else 1.0)


class RigidCylinder(RigidSurface3D):
    """The rigid (infinite) cylinder of axis through ``point`` along ``direction`` and
    ``radius``; the slave outside (default) or inside.  Drawn as ``n_around`` x
    ``n_along`` quad4 faces over ``length`` centred on ``point``."""

    def __init__(self, point: Any, direction: Any, radius: float, inside: bool = False,
                 length: float = 10.0, n_around: int = 64, n_along: int = 8,
                 name: str = "cylinder"):
        self.point = _vector3(point, "point")
        self.direction = _vector3(direction, "direction", True)
        self.radius = real("radius", radius, 0.0, low_open=True)
        self.inside = flag("inside", inside)
        length = real("length", length, 0.0, low_open=True)
        u, v = _frame(self.direction)
        th = np.linspace(0.0, 2 * np.pi, n_around, endpoint=False)
        s = np.linspace(-0.5 * length, 0.5 * length, n_along + 1)
        ring = np.outer(u, np.cos(th)) + np.outer(v, np.sin(th))          # (3, n_around)
        X = (self.point[:, None, None] + self.radius * ring[:, None, :]
             + self.direction[:, None, None] * s[None, :, None]).reshape(3, -1)
        i, j = np.meshgrid(np.arange(n_along), np.arange(n_around), indexing="ij")
        a = i * n_around + j
        b = i * n_around + (j + 1) % n_around
        quads = np.column_stack([a.ravel(), b.ravel(), (b + n_around).ravel(),
                                 (a + n_around).ravel()])
        super().__init__(None, None, quads[:, ::-1] if inside else quads, X=X, name=name,
                         cell="quad4")

    def exact_gap(self, x):
        P = np.eye(3) - np.outer(self.direction, self.direction)
        return _round(x, self.point, P, self.radius, -1.0 if self.inside else 1.0)


def _icosphere(refine: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit-sphere nodes (3, n) and outward counter-clockwise triangles."""
    f = (1 + 5 ** 0.5) / 2
    X = np.array([[-1, f, 0], [1, f, 0], [-1, -f, 0], [1, -f, 0], [0, -1, f], [0, 1, f],
                  [0, -1, -f], [0, 1, -f], [f, 0, -1], [f, 0, 1], [-f, 0, -1], [-f, 0, 1]], float)
    tri = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9],
                    [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2],
                    [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
                    [8, 6, 7], [9, 8, 1]])
    X = list(X / np.linalg.norm(X, axis=1)[:, None])
    for _ in range(max(refine, 0)):
        mids: dict = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in mids:
                m = X[a] + X[b]
                X.append(m / np.linalg.norm(m))
                mids[key] = len(X) - 1
            return mids[key]
        new = []
        for a, b, c in tri:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        tri = np.array(new)
    return np.array(X).T, tri


def exact_gaps(master: RigidSurface3D, xs: np.ndarray, lam: np.ndarray | None,
               tangent: bool, area: np.ndarray, n_m: int):
    """The NTS :class:`~.contact_eval.ContactEval` of the slave nodes ``xs (3, n_s)``
    against the exact surface of ``master`` (module docstring); ``n_m`` master nodes
    (their dofs, none varying, close the local dof layout)."""
    from .contact_eval import ContactEval, node_gap_eval
    n_s = xs.shape[1]
    g, dg, d2g, ok = master.exact_gap(xs)
    g = np.where(ok, g, 0.0)
    info = {"xi": np.zeros((2, n_s)), "segment": np.where(ok, 0, -1), "normal": dg}
    if not tangent:
        return ContactEval(g=g, G=None, H=None, area=area, mask=ok, info=info)
    k = np.flatnonzero(ok)
    return node_gap_eval(g, k, np.zeros((k.size, 0), dtype=np.int64), dg[:, k].T,
                         None if lam is None else d2g[:, :, k], lam, n_m, 3, area, ok, info)
