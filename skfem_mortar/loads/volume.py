"""Volume control: an item that prescribes the volume a surface encloses, with
the pressure as one extra unknown of the same Newton system.

With the enclosed volume ``V(x)`` of the current surface and the target
``V*(lf)``, the item adds the pressure ``p`` (its one unknown, ``dof_kind ==
"lam"``) and the term ``-p (V(x) - V*(lf))`` to the total potential, so

    R_u += -p dV/dx ,       R_p = -(V(x) - V*(lf)) ,
    K_uu += -p d2V/dx2 ,    K_up = K_pu^T = -dV/dx ,   K_pp = 0 :

a symmetric (indefinite) block; at equilibrium ``p`` is the pressure that
holds the volume ``V*``, pushing outward when positive.

The volume is a pluggable function of the surface's facets
(:class:`VolumeFunction`).  :class:`MeridianVolume`, of an axisymmetric model,
is the volume of revolution ``V = pi oint r^2 dz`` over the closed meridian:
the loaded facets, closed by the axis (``r = 0``) and by stated fixed walls;
a wall ``z = const`` (a plane of symmetry) and the axis add nothing, and a
fixed wall of another shape adds a constant, ``walls`` (its own
``pi int r^2 dz``, given by the caller).  Per facet, by 3-point Gauss (exact
for 2- and 3-node facets)::

    V_f = pi sum_q w_q r_q^2 z'_q ,    dV/dr_a = 2 pi sum_q w_q r_q N_a z'_q ,
    dV/dz_a = pi sum_q w_q r_q^2 N_a' ,
    d2V/dr_a dr_b = 2 pi sum_q w_q N_a N_b z'_q ,  d2V/dr_a dz_b = 2 pi sum_q w_q r_q N_a N_b' .

Without walls the facets' orientation is taken so that the reference volume
is positive (counter-clockwise in the ``(r, z)`` plane); with walls the
facets must come counter-clockwise with them (a negative reference volume is
refused).  A 3D volume function (a closed triangulated surface) plugs in the
same way later.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from ..core.item import Contribution, Item
from ..core.validate import real
from .pressure import facet_chain, facet_shapes

__all__ = ["VolumeFunction", "MeridianVolume", "VolumeControl"]


class VolumeFunction:
    """The volume enclosed by facets: :meth:`evaluate` of the current nodes."""

    def evaluate(self, x: np.ndarray, hessian: bool = True
                 ) -> tuple[float, np.ndarray, np.ndarray | None]:
        """``V``, ``dV/dx`` (n_f, n_loc dim) and (``hessian``) ``d2V/dx2``
        (n_f, n_loc dim, n_loc dim) of facets with current nodes ``x`` (n_f, n_loc, dim)."""
        raise NotImplementedError


class MeridianVolume(VolumeFunction):
    """``V = pi oint r^2 dz + walls`` over a closed meridian (module docstring)."""

    def __init__(self, walls: float = 0.0):
        self.walls = real("walls", walls)

    def evaluate(self, x, hessian=True):
        n_f, n_loc, _ = x.shape
        N, dN, w = facet_shapes(n_loc)
        r = np.einsum("fa,aq->fq", x[..., 0], N)
        zp = np.einsum("fa,aq->fq", x[..., 1], dN)
        V = np.pi * float(np.einsum("q,fq,fq->", w, r * r, zp)) + self.walls
        g = np.empty((n_f, n_loc, 2))
        g[..., 0] = 2 * np.pi * np.einsum("q,fq,aq,fq->fa", w, r, N, zp)
        g[..., 1] = np.pi * np.einsum("q,fq,aq->fa", w, r * r, dN)
        if not hessian:
            return V, g.reshape(n_f, -1), None
        h = np.zeros((n_f, n_loc, 2, n_loc, 2))
        h[:, :, 0, :, 0] = 2 * np.pi * np.einsum("q,aq,bq,fq->fab", w, N, N, zp)
        rz = 2 * np.pi * np.einsum("q,fq,aq,bq->fab", w, r, N, dN)
        h[:, :, 0, :, 1] = rz
        h[:, :, 1, :, 0] = rz.transpose(0, 2, 1)
        return V, g.reshape(n_f, -1), h.reshape(n_f, 2 * n_loc, 2 * n_loc)


class VolumeControl(Item):
    """Prescribe the volume enclosed by a body's surface; the pressure is its unknown.

    Parameters
    ----------
    body : Membrane, Cable or Solid
        The body whose surface encloses the volume: the whole chain of a
        membrane, or the boundary ``facets`` of a solid.
    volume : float or callable
        The final volume ``V*`` (> 0): the target is ``V0 + lf (V* - V0)``
        with ``V0`` the reference volume; or a function ``V*(lf)``.
    facets : str or int array, solid only
        A boundary name or facet indices.
    function : VolumeFunction, optional
        The volume of the facets; default :class:`MeridianVolume` (an
        axisymmetric model).
    name : str

    Attributes
    ----------
    reference_volume : float
        ``V0``, the volume of the reference facets (the discrete one).
    """

    dof_kind = "lam"
    n_dofs = 1
    phase = "loads"
    geometries = ("axisymmetric",)   # a 3D volume function later
    symmetric = True

    def __init__(self, body: Item, volume: float | Callable[[float], float], *,
                 facets: str | np.ndarray | None = None,
                 function: VolumeFunction | None = None, name: str | None = None):
        self.body = body
        self.name = name or f"volume_{getattr(body, 'name', 'body')}"
        self.function = MeridianVolume() if function is None else function
        dofs, X = facet_chain(body, facets)
        V0 = self.function.evaluate(X, hessian=False)[0]
        if not abs(V0) > 0:
            raise ValueError(f"{self.name}: the reference surface encloses no volume")
        walls = getattr(self.function, "walls", 0.0)
        if V0 < 0 and walls:
            raise ValueError(f"{self.name}: the facets and the walls enclose a negative "
                             f"volume {V0:.6g}: give the walls' pi oint r^2 dz in the facets' "
                             f"sense, counter-clockwise in the (r, z) plane")
        if V0 < 0:   # clockwise: turn every facet around (swap its ends, keep a midside node)
            turn = [1, 0] + list(range(2, dofs.shape[1]))
            dofs, X = dofs[:, turn].copy(), X[:, turn].copy()
            V0 = self.function.evaluate(X, hessian=False)[0]
        self.reference_volume = float(V0)
        self._flat, self._X = dofs.reshape(len(dofs), -1), X
        self.volume = volume if callable(volume) else real("volume", volume, 0.0, low_open=True)

    def target(self, load_factor: float) -> float:
        """``V*(lf)``: the prescribed volume at ``load_factor``."""
        if callable(self.volume):
            return float(self.volume(load_factor))
        return self.reference_volume + load_factor * (self.volume - self.reference_volume)

    def enclosed(self, z: np.ndarray) -> float:
        """The current enclosed volume ``V(x)``."""
        x = self._X + np.asarray(z)[self.body.offset + self._flat].reshape(self._X.shape)
        return self.function.evaluate(x, hessian=False)[0]

    def pressure(self, z: np.ndarray) -> float:
        """The pressure unknown ``p``."""
        return float(np.asarray(z)[self.offset])

    def assemble(self, z: np.ndarray, load_factor: float,
                 tangent: bool = True) -> Contribution:
        """``R_u = -p dV/dx``, ``R_p = -(V - V*)`` and the symmetric tangent (module docstring)."""
        dofs = self.body.offset + self._flat
        x = self._X + np.asarray(z)[dofs].reshape(self._X.shape)
        V, g, h = self.function.evaluate(x, hessian=tangent)
        p = self.pressure(z)
        out = Contribution.from_dofs(dofs, -p * g, None if h is None else -p * h)
        row = np.array([self.offset], dtype=np.int64)
        out.r_index = np.concatenate([out.r_index, row])
        out.r_value = np.concatenate([out.r_value, [-(V - self.target(load_factor))]])
        if tangent:
            flat = dofs.ravel()
            lam = np.full(flat.size, self.offset, dtype=np.int64)
            out.k_rows = np.concatenate([out.k_rows, flat, lam])
            out.k_cols = np.concatenate([out.k_cols, lam, flat])
            out.k_vals = np.concatenate([out.k_vals, -g.ravel(), -g.ravel()])
        return out

    def __repr__(self) -> str:
        """One line: name, body, reference volume."""
        return (f"VolumeControl({self.name!r} on {getattr(self.body, 'name', '')!r}, "
                f"V0 = {self.reference_volume:.6g})")

