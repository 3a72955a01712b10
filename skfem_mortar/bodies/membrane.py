"""Membranes of revolution: a meridian curve of 2-node elements in an
axisymmetric model (coordinates ``(r, z) = (x, y)``, the axis at ``r = 0``).

An element ``e = (i, j)`` of reference length ``L0`` has the current chord
``d = x_j - x_i`` (length ``l``, unit tangent ``t``), the meridional stretch
``l1 = l / L0`` and, at its Gauss points ``xi_q`` (two, never on the axis),
the hoop stretch ``l2 = r / R`` (``r = N_a x_a,r`` current, ``R`` reference
radius).  With a law ``W(l1, l2)`` per unit reference area and thickness
(:mod:`.membrane_laws`) the element energy over the full revolution is

    Pi_e = 2 pi H L0 sum_q w_q R_q W(l1, l2_q) ,

its residual (element forces, totals over the revolution)

    r_e = sum_q c_q (W_1 g1 + W_2 g2_q),    c_q = 2 pi H L0 w_q R_q ,
    g1 = d l1 / d x_e = [-t, t] / L0,       g2_q = d l2 / d x_e = [N_i, 0, N_j, 0] / R_q

and its tangent, exact,

    K_e = sum_q c_q (W_11 g1 g1^T + W_12 (g1 g2^T + g2 g1^T) + W_22 g2 g2^T)
          + (sum_q c_q W_1) / (L0 l) [[P, -P], [-P, P]],    P = I - t t^T .

*The pole.*  A node with ``|R| <= 1e-10`` times the membrane's size is on the
axis: it is snapped to ``R = 0`` and the membrane prescribes ``u_r = 0`` there
itself (:meth:`Membrane.prescribed`), so a node on the axis stays there by
construction.  The hoop stretch ``r / R`` is 0/0 at such a node, but it is
evaluated at the Gauss points only, where ``R > 0`` (an element with both
nodes on the axis is refused).  A node with ``R`` below ``-1e-10`` times the
size is refused, naming the membrane and the smallest ``R``.
"""
from __future__ import annotations

import numpy as np

from ..core.chain import segment_lengths
from ..core.errors import InversionError
from ..core.item import Contribution, Item
from ..core.validate import flag, real
from .cable import node_chain
from .membrane_laws import MembraneLaw, membrane_law

__all__ = ["Membrane", "AXIS_RTOL"]

#: a node with ``|R|`` at most this times the membrane's size is on the axis
AXIS_RTOL = 1e-10

_XI = 0.5 * (1.0 + np.array([-1.0, 1.0]) / np.sqrt(3.0))   # 2-point Gauss on [0, 1]
_W = np.array([0.5, 0.5])
_NQ = np.array([1.0 - _XI, _XI])                           # (2 nodes, 2 points)


class Membrane(Item):
    """A membrane of revolution (the axisymmetric form of a cable).

    Parameters
    ----------
    X : array (2, n_nodes)
        Reference node coordinates ``(R, Z)``, stress free; ``R >= 0``.
    elements : int array (n_el, 2), optional
        Node pairs along the meridian; default ``(k, k+1)`` (and ``(n-1, 0)``
        when ``closed``).
    H : float
        Reference thickness, > 0.
    law : {"neo-hooke", "svk"} or MembraneLaw
        The law (:mod:`~skfem_mortar.bodies.membrane_laws`); ``mu`` for
        neo-Hooke, ``E`` and ``nu`` for svk.
    closed : bool
        A closed meridian (a torus) for the default ``elements``.
    name : str

    Raises
    ------
    ValueError
        Naming the parameter: ``X`` not (2, n >= 2) finite numbers, a node left
        of the axis (naming the membrane and the smallest ``R``), an element of
        zero length or with both nodes on the axis, bad elements, a bad law or
        modulus.
    """

    dof_kind = "u"
    geometries = ("axisymmetric",)
    loaded = False
    phase = "bulk"

    def __init__(self, X: np.ndarray, elements: np.ndarray | None = None, *, H: float = 1.0,
                 law: str | MembraneLaw = "neo-hooke", mu: float | None = None,
                 E: float | None = None, nu: float | None = None, closed: bool = False,
                 name: str = "membrane"):
        self.closed = flag("closed", closed)
        X, elements = node_chain(X, elements, self.closed)
        X = X.copy()
        n = X.shape[1]
        self.name = name
        self.pole = _snap_axis(X, name)
        if np.any(self.pole[elements].all(axis=1)):
            raise ValueError(f"membrane {name!r}: an element lies on the axis (both nodes at R = 0)")
        self.X, self.elements = X, elements
        self.H = real("H", H, 0.0, low_open=True)
        self.law = membrane_law(law, mu, E, nu)
        self.rest_length = segment_lengths(X, elements)
        if np.any(self.rest_length <= 1e-12 * self.rest_length.max()):
            raise ValueError(f"X: element {int(np.argmin(self.rest_length))} of {name} has "
                             f"zero length")
        self._dX = X[:, elements[:, 1]] - X[:, elements[:, 0]]
        self._Rq = X[0, elements] @ _NQ                    # (n_el, 2) Gauss-point radii
        self.n_nodes, self.n_dofs = n, 2 * n
        self.node_dofs = np.arange(2 * n, dtype=np.int64).reshape(n, 2).T.copy()

    # -- kinematics (as a cable's) -------------------------------------------
    def u(self, z: np.ndarray) -> np.ndarray:
        """Nodal displacements (2, n_nodes)."""
        return np.asarray(z)[self.offset + self.node_dofs]

    def x(self, z: np.ndarray) -> np.ndarray:
        """Current node coordinates (2, n_nodes)."""
        return self.X + self.u(z)

    def element_dofs(self) -> np.ndarray:
        """Local dofs (n_el, 4) ordered ``[r_i, z_i, r_j, z_j]``."""
        i, j = self.elements[:, 0], self.elements[:, 1]
        nd = self.node_dofs
        return np.column_stack([nd[0, i], nd[1, i], nd[0, j], nd[1, j]])

    def prescribed(self, load_factor: float) -> tuple[np.ndarray, np.ndarray] | None:
        """``u_r = 0`` at the nodes on the axis (the module docstring's pole)."""
        dofs = self.offset + self.node_dofs[0, self.pole]
        return (dofs, np.zeros(dofs.size)) if dofs.size else None

    def _stretches(self, z: np.ndarray):
        u = self.u(z)
        i, j = self.elements[:, 0], self.elements[:, 1]
        d = self._dX + (u[:, j] - u[:, i])
        length = np.hypot(d[0], d[1])
        if not np.all(np.isfinite(length)) or np.any(length <= 1e-14 * self.rest_length):
            raise InversionError(f"{self.name}: an element collapsed or is not finite")
        r = (self.X[0] + u[0])[self.elements] @ _NQ       # (n_el, 2)
        return d, length, length / self.rest_length, r / self._Rq

    def stretches(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Meridional ``l1`` (n_el,) and hoop ``l2`` (n_el,) stretch, the latter
        at the element's mid-point (the mean of its Gauss points' ``r`` over ``R``)."""
        _, _, l1, _ = self._stretches(z)
        mid = (self.x(z)[0][self.elements]).mean(axis=1) / self.X[0][self.elements].mean(axis=1)
        return l1, mid

    def tensions(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Meridional ``T1 = H W_1 / l2`` and hoop ``T2 = H W_2 / l1`` per unit
        current length (n_el,), at the element's mid-point."""
        l1, l2 = self.stretches(z)
        _, W1, W2, *_ = self.law.derivatives(l1, l2)
        return self.H * W1 / l2, self.H * W2 / l1

    def current_thickness(self, z: np.ndarray) -> np.ndarray:
        """``h = H l3(l1, l2)`` (n_el,), at the element's mid-point."""
        return self.H * self.law.thickness_stretch(*self.stretches(z))

    def energy(self, z: np.ndarray) -> float:
        """``sum_e Pi_e``: the strain energy over the full revolution."""
        _, _, l1, l2 = self._stretches(z)
        W = self.law.energy(l1[:, None], l2)
        return float(np.sum(2 * np.pi * self.H * self.rest_length[:, None] * _W * self._Rq * W))

    # -- assembly ------------------------------------------------------------
    def assemble(self, z: np.ndarray, load_factor: float,
                 tangent: bool = True) -> Contribution:
        """Element forces and exact tangent (module docstring)."""
        d, length, l1, l2 = self._stretches(z)
        _, W1, W2, W11, W12, W22 = self.law.derivatives(l1[:, None], l2)
        c = 2 * np.pi * self.H * self.rest_length[:, None] * _W * self._Rq   # (n_el, 2)
        t = (d / length).T                                               # (n_el, 2)
        g1 = np.hstack([-t, t]) / self.rest_length[:, None]              # (n_el, 4)
        NR = _NQ.T[None] / self._Rq[..., None]          # g2_q's entries at r_i, r_j (n_el, 2, 2)
        r = (c * W1).sum(axis=1)[:, None] * g1
        r[:, ::2] += np.einsum("eq,eqa->ea", c * W2, NR)
        dofs = self.offset + self.element_dofs()
        if not np.all(np.isfinite(r)):
            raise InversionError(f"{self.name}: non-finite membrane forces")
        if not tangent:
            return Contribution.from_dofs(dofs, r)
        k = (c * W11).sum(axis=1)[:, None, None] * np.einsum("ea,eb->eab", g1, g1)
        h = np.zeros_like(g1)
        h[:, ::2] = np.einsum("eq,eqa->ea", c * W12, NR)                 # sum_q c W_12 g2_q
        k += np.einsum("ea,eb->eab", g1, h) + np.einsum("ea,eb->eab", h, g1)
        k[:, ::2, ::2] += np.einsum("eq,eqa,eqb->eab", c * W22, NR, NR)
        P = np.eye(2) - np.einsum("ei,ej->eij", t, t)
        geo = ((c * W1).sum(axis=1) / (self.rest_length * length))[:, None, None] * P
        k[:, :2, :2] += geo
        k[:, 2:, 2:] += geo
        k[:, :2, 2:] -= geo
        k[:, 2:, :2] -= geo
        return Contribution.from_dofs(dofs, r, k)

    # -- output --------------------------------------------------------------
    def output_mesh(self):
        """Points (n, 2) ``(R, Z)`` of the reference meridian and its cells ("line")."""
        return self.X.T.copy(), [("line", self.elements.copy())]

    def output_data(self, z: np.ndarray):
        """Point data ``displacement``; cell data both stretches, both tensions
        and the current thickness."""
        l1, l2 = self.stretches(z)
        T1, T2 = self.tensions(z)
        return ({"displacement": self.u(z).T.copy()},
                {"stretch_meridional": [l1], "stretch_hoop": [l2],
                 "tension_meridional": [T1], "tension_hoop": [T2],
                 "thickness": [self.current_thickness(z)]})

    def __repr__(self) -> str:
        """One line: name, law, sizes."""
        return (f"Membrane({self.name!r}, law {self.law.name}, H {self.H:g}: {self.n_nodes} "
                f"nodes, {len(self.elements)} elements, {int(self.pole.sum())} on the axis)")


def _snap_axis(X: np.ndarray, name: str) -> np.ndarray:
    """Snap the nodes with ``|R| <= AXIS_RTOL`` times the size to ``R = 0`` (in
    place); their mask.  ValueError naming the membrane and the smallest ``R``
    for a node left of the axis."""
    size = float(np.max(np.ptp(X, axis=1)))
    tol = AXIS_RTOL * max(size, float(np.max(np.abs(X))))
    if X[0].min() < -tol:
        raise ValueError(f"membrane {name!r}: a node lies left of the axis (R < 0), the smallest R "
                         f"is {X[0].min():.6g}; an axisymmetric body needs R >= 0")
    pole = np.abs(X[0]) <= tol
    X[0, pole] = 0.0
    return pole
