"""Follower pressure on cables and on the boundary of solids.

A pressure ``p`` acting normal to the *deformed* curve, per unit current
length, on a facet (segment) parametrized by ``xi in [0, 1]`` with shape
functions ``N_a`` and current node positions ``x_a``:

    f_a = s p lf  int_0^1 N_a(xi) Q x_{,xi} dxi  =  s p lf  sum_b G_ab Q x_b ,
    G_ab = int_0^1 N_a N_b' dxi ,      Q = [[0, -1], [1, 0]]  (turn by +90 deg)

because ``Q x_{,xi} dxi`` is the current normal times the current length
element.  ``s = +1`` pushes to the *left* of the facet direction, ``-1`` to
its right, ``lf`` is the load factor.  For 2-node facets ``G`` gives the
consistent nodal load ``p l / 2`` along the facet normal at each end node.
The load is linear in ``x``, so its (non-symmetric) load stiffness is the
constant matrix

    K_ab = d(-f_a)/dx_b = -s p lf G_ab Q

(the residual is ``R = f_int - f_ext``; loads enter with a minus sign).
Linear (2-node) and quadratic (3-node: ends, then midside) facets are supported.

*Axisymmetric models* (``(r, z) = (x, y)``, forces are totals over the full
revolution): the load acts on the current surface of revolution, area element
``2 pi r |x_{,xi}| dxi``, so

    f_a = 2 pi s p lf  int_0^1 N_a r Q x_{,xi} dxi ,   r = N_c x_{c,r} ,

quadratic in ``x``; its load stiffness (exact, not symmetric)

    K_{a i, b j} = -2 pi s p lf int_0^1 N_a (N_b delta_{j r} (Q x_{,xi})_i
                                             + r N_b' Q_ij) dxi ,

by 3-point Gauss (exact for the quintic integrands of 3-node facets).
"""
from __future__ import annotations

import numpy as np

from ..bodies.cable import side_sign
from ..core.item import Contribution, Item
from ..core.validate import flag, real

__all__ = ["FollowerPressure", "facet_load_matrix", "facet_chain", "facet_shapes", "revolved_load"]

_Q = np.array([[0.0, -1.0], [1.0, 0.0]])


def facet_load_matrix(n_loc: int) -> np.ndarray:
    """``G_ab = int_0^1 N_a(xi) N_b'(xi) dxi`` for 2-node or 3-node facets.

    Node order: the two ends, then (3-node) the midside node.  Integrated by
    3-point Gauss, exact for these cubic integrands.
    """
    N, dN, w = facet_shapes(n_loc)
    return np.einsum("aq,bq,q->ab", N, dN, w)


class FollowerPressure(Item):
    """Pressure normal to the deformed cable or solid boundary, ramped with the load factor.

    Parameters
    ----------
    body : Cable, Membrane or Solid
        A cable or membrane (the chain of its elements is loaded), or a body with an skfem
        ``mesh`` and vector ``basis`` (then ``facets`` selects the boundary).
    pressure : float
        Final pressure ``p`` (force per current length per unit reference
        thickness: a model's thickness multiplies the force, an out-of-plane
        stretch does not change the loaded area; in an axisymmetric model:
        force per current area of the surface of revolution), finite.  The
        applied value is ``load_factor * p`` (or ``p`` when ``ramp`` is False).
    side : {"left", "right"} for a cable; {"inward", "outward"} for a solid
        Where the load pushes: left or right of the chain direction of the
        cable (a counter-clockwise ring has its outside on the right); into
        the solid (an ordinary pressure, default) or out of it (suction).
    facets : str or int array, solid only
        A boundary name of ``body.mesh.boundaries`` or facet indices.
    ramp : bool
        Scale the pressure with the load factor.
    load_stiffness : bool
        Include the load stiffness in the tangent (True).  False exists only
        to show, in a test, that Newton then loses its quadratic convergence.
    name : str
    """

    dof_kind = None
    phase = "loads"
    geometries = ("plane", "axisymmetric")   # 3D: its own item
    #: the load follows the surface: its tangent is not symmetric
    symmetric = False

    def __init__(self, body: Item, pressure: float, *, side: str | None = None,
                 facets: str | np.ndarray | None = None, ramp: bool = True,
                 load_stiffness: bool = True,
                 name: str | None = None):
        self.body = body
        self.pressure = real("pressure", pressure)
        self.ramp = flag("ramp", ramp)
        self.load_stiffness = flag("load_stiffness", load_stiffness)
        self.name = name or f"pressure_{getattr(body, 'name', 'body')}"
        if is_chain(body):
            self.sign = side_sign("left" if side is None else side)
        elif not (side is None or (isinstance(side, str) and side in ("inward", "outward"))):
            raise ValueError(f"side must be 'inward' or 'outward' for a solid, got {side!r}")
        else:
            self.sign = -1 if side == "outward" else 1
        self._dofs, self._X = facet_chain(body, facets)
        self._G = facet_load_matrix(self._dofs.shape[1])
        self._B = np.kron(self._G, _Q)       # (2 n_loc, 2 n_loc): f_e = s p B x_e
        self._flat = self._dofs.reshape(len(self._dofs), -1)

    def current_pressure(self, load_factor: float) -> float:
        """The applied pressure ``lf p`` (or ``p`` when not ramped)."""
        return self.pressure * (load_factor if self.ramp else 1.0)

    def assemble(self, z: np.ndarray, load_factor: float,
                 tangent: bool = True) -> Contribution:
        """Residual ``-f_a`` and load stiffness ``-s p lf G_ab Q`` (module docstring)."""
        c = self.sign * self.current_pressure(load_factor)
        dofs = self.body.offset + self._flat
        x = self._X.reshape(len(dofs), -1) + np.asarray(z)[dofs]   # (n_f, 2 n_loc)
        if self.geometry == "axisymmetric":
            f, k = revolved_load(x.reshape(len(dofs), -1, 2), c,
                                 tangent and self.load_stiffness)
            return Contribution.from_dofs(dofs, -f, None if k is None else -k)
        r = -c * (x @ self._B.T)
        if not (tangent and self.load_stiffness):
            return Contribution.from_dofs(dofs, r)
        k = np.broadcast_to(-c * self._B, (len(dofs),) + self._B.shape)
        return Contribution.from_dofs(dofs, r, k)

    def resultant(self, z: np.ndarray, load_factor: float = 1.0) -> np.ndarray:
        """Total applied force (2,) = sum of the nodal loads ``f_a``, over the
        model's thickness ``H`` (:attr:`~skfem_mortar.core.item.Item.thickness`);
        in an axisymmetric model ``(0, F_z)``, the axial force over the revolution."""
        c = self.thickness * self.sign * self.current_pressure(load_factor)
        dofs = self.body.offset + self._flat
        x = self._X.reshape(len(dofs), -1) + np.asarray(z)[dofs]
        if self.geometry == "axisymmetric":    # a total over the revolution (r: zero)
            f = revolved_load(x.reshape(len(dofs), -1, 2), c, False)[0]
            return np.array([0.0, f.reshape(len(dofs), -1, 2)[..., 1].sum()])
        f = c * (x @ self._B.T)
        return f.reshape(len(dofs), -1, 2).sum(axis=(0, 1))


def facet_shapes(n_loc: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """3-point Gauss on ``[0, 1]``: shape functions ``N`` (n_loc, 3), their
    derivatives ``dN`` (n_loc, 3) and the weights (3,) of a 2- or 3-node facet."""
    xi, w = np.polynomial.legendre.leggauss(3)
    xi, w = 0.5 * (xi + 1.0), 0.5 * w
    if n_loc == 2:
        return np.array([1.0 - xi, xi]), np.array([-np.ones(3), np.ones(3)]), w
    if n_loc == 3:
        return (np.array([(1 - xi) * (1 - 2 * xi), xi * (2 * xi - 1), 4 * xi * (1 - xi)]),
                np.array([4 * xi - 3, 4 * xi - 1, 4 - 8 * xi]), w)
    raise ValueError(f"facets must have 2 or 3 nodes, got {n_loc}")


def revolved_load(x: np.ndarray, c: float, tangent: bool
                  ) -> tuple[np.ndarray, np.ndarray | None]:
    """The axisymmetric facet loads ``f`` (n_f, 2 n_loc) of the signed pressure
    ``c = s p lf`` on facets of current nodes ``x`` (n_f, n_loc, 2), and with
    ``tangent`` their derivative ``df/dx`` (n_f, 2 n_loc, 2 n_loc) (module docstring)."""
    n_f, n_loc, _ = x.shape
    N, dN, w = facet_shapes(n_loc)
    r = np.einsum("fa,aq->fq", x[..., 0], N)                 # (n_f, n_q)
    g = np.einsum("fai,aq->fqi", x, dN)                      # x_{,xi}
    Qg = g @ _Q.T                                            # (n_f, n_q, 2)
    f = 2 * np.pi * c * np.einsum("q,aq,fq,fqi->fai", w, N, r, Qg).reshape(n_f, -1)
    if not tangent:
        return f, None
    k = np.zeros((n_f, n_loc, 2, n_loc, 2))
    k[..., 0] = 2 * np.pi * c * np.einsum("abq,fqi->faib", w * N[:, None] * N[None], Qg)
    M = 2 * np.pi * c * np.einsum("abq,fq->fab", w * N[:, None] * dN[None], r)
    k += M[:, :, None, :, None] * _Q[None, None, :, None, :]
    return f, k.reshape(n_f, 2 * n_loc, 2 * n_loc)


def is_chain(body: Item) -> bool:
    """Whether ``body`` is a chain of 2-node elements (a cable, a membrane)."""
    return hasattr(body, "elements") and hasattr(body, "closed")


def facet_chain(body: Item, facets: str | np.ndarray | None
                ) -> tuple[np.ndarray, np.ndarray]:
    """The loaded facets of ``body``: local dofs (n_f, n_loc, 2) and reference
    coordinates (n_f, n_loc, 2).  A cable or membrane: its elements in chain
    order (``facets`` must be None); a solid: the boundary facets ``facets``
    (a name or indices), each oriented with the body on its left."""
    if is_chain(body):
        if facets is not None:
            raise ValueError("facets is only for solids; a cable is loaded along its chain")
        el = body.elements
        return (np.stack([body.node_dofs[:, el[:, 0]].T, body.node_dofs[:, el[:, 1]].T], axis=1),
                np.stack([body.X[:, el[:, 0]].T, body.X[:, el[:, 1]].T], axis=1))
    if hasattr(body, "basis") and hasattr(body, "mesh"):
        if body.mesh.p.shape[0] == 3:
            raise ValueError("body is a 3D solid: a pressure on its faces is "
                             "FollowerPressure3D(body, pressure, facets) "
                             "(skfem_mortar.loads.pressure3d)")
        return _solid_facet_chain(body, facets)
    raise ValueError("body must be a Cable, a Membrane or a body with an skfem mesh and basis")


def _solid_facet_chain(body, facets):
    """Local dofs (n_f, n_loc, 2) and reference coordinates of boundary facets,
    each oriented so that the body lies on its left (outward normal on the right).
    """
    from ..bodies.checks import check_boundary_facets   # here: a cable's load needs no skfem
    from ..bodies.solid import boundary_facets

    mesh, basis = body.mesh, body.basis
    if facets is None:
        raise ValueError("facets (a boundary name or facet indices) is required for a solid")
    facets_in = facets
    facets = boundary_facets(mesh, facets,
                             "facets must be one of the mesh boundaries {known}, got {tag!r}",
                             name="facets")
    check_boundary_facets(mesh, facets, facets_in, "facets")
    v = mesh.facets[:, facets].T.copy()                      # (n_f, 2) vertices
    nd = basis.nodal_dofs
    cols = [nd[:, v[:, 0]].T, nd[:, v[:, 1]].T]
    if basis.facet_dofs.shape[1] > 0:
        fd = basis.facet_dofs
        if fd.shape[0] != 2:
            raise ValueError("only linear or quadratic facets are supported")
        cols.append(fd[:, facets].T)
    dofs = np.stack(cols, axis=1)                            # (n_f, n_loc, 2)
    X = basis.doflocs[:, dofs[:, :, 0]].transpose(1, 2, 0)   # (n_f, n_loc, 2)
    # orientation: the element's centroid must be on the left of (v0 -> v1) (own test,
    # as in ContactSurface.from_solid: skfem's facets carry no vertex order along a chain)
    t = mesh.f2t[0, facets]
    centroid = mesh.p[:, mesh.t[:, t]].mean(axis=1).T        # (n_f, 2)
    d = X[:, 1] - X[:, 0]
    left = np.column_stack([-d[:, 1], d[:, 0]])
    flip = np.einsum("fi,fi->f", left, centroid - 0.5 * (X[:, 0] + X[:, 1])) < 0
    dofs[flip, 0], dofs[flip, 1] = dofs[flip, 1].copy(), dofs[flip, 0].copy()
    X[flip, 0], X[flip, 1] = X[flip, 1].copy(), X[flip, 0].copy()
    return dofs, X
