"""Friction laws and the nonlinear complementarity function of stick and slip, node by node.

Signs (those of :class:`~skfem_mortar.contact.pair.ContactPair`)
----------------------------------------------------------------
The pair adds ``-G^T lam`` to the body rows, so the contact force on the slave
is ``+G^T lam``.  The normal multiplier ``lam_n >= 0`` is the pressure (a
nodal force for NTS, a traction for mortar), the gap ``g_n > 0`` is open
(NTS: the nodal gap; mortar: the weighted gap), and the normal row is

    C_n = lam_n - max(0, lam_n - c_n g_n)

(active where ``lam_n - c_n g_n >= 0``).  The slip ``u_t`` of
:mod:`skfem_mortar.contact.slip` is the motion of the slave relative to the
master within the load step along the tangent ``tau`` of the slave node
(NTS: the current master segment's direction ``e``; mortar: the rotated
nodal normal ``tau_A = (n_y, -n_x)``, the same direction for facing surfaces)
and its derivative with respect to the slave node is about ``+tau`` (times
``D_AA`` for mortar).  With the same rows ``-G_t^T lam_t`` in the body, the
tangential multiplier ``lam_t`` is then the tangential traction (force) on
the slave along ``tau``, and friction opposes the slip: ``lam_t u_t <= 0``.

The complementarity function
----------------------------
Hueber, Stadler, Wohlmuth (2008) and Gitterle, Popp, Gee, Wall (2010) write,
with their multiplier ``z_t = -lam_t`` (minus the slave traction),
``C_t = max(Xi, |z_t + c_t u_t|) z_t - Xi (z_t + c_t u_t)``.  In the pair's
sign (``lam_t = -z_t``, the function times -1, which changes none of its
zeros)::

    s   = lam_t - c_t u_t                                (augmented tangential multiplier)
    C_t = max(Xi, |s|) lam_t - Xi s,
    Xi  = mu (lam_n - c_n g_n)         Coulomb  (the brief's ``mu (lam_n + c_n g_n)``
                                                 with ``g > 0`` open)
    Xi  = bound * w                    Tresca   (``w`` the nodal weight on the current
                                                 surface, see :class:`Tresca`)

on the nodes whose normal row is active; elsewhere (open) ``C_t = lam_t``.
Per node, with the status chosen as

* **open**: normal inactive, or ``Xi <= 0``:  ``C_t = lam_t`` (``lam_t = 0``);
* **stick**: ``|s| < Xi``:  ``C_t = Xi c_t u_t`` (zero iff ``u_t = 0``);
* **slip**: ``|s| >= Xi > 0``:  ``C_t = |s| lam_t - Xi s`` (zero iff
  ``lam_t = Xi sign(s)``, i.e. ``|lam_t| = Xi`` and ``lam_t = -Xi sign(u_t)``
  where ``u_t != 0``),

the derivatives (exact on each branch) are::

    stick:  dC/dlam_t = 0,                         dC/du_t = c_t Xi,
            dC/dXi    = c_t u_t
    slip:   dC/dlam_t = |s| - Xi + sign(s) lam_t,  dC/du_t = c_t (Xi - sign(s) lam_t),
            dC/dXi    = -s
    open:   dC/dlam_t = 1,  all others 0

and ``dXi/dlam_n = mu``, ``dXi/dg_n = -mu c_n`` (Coulomb), 0 (Tresca), so
``dC/dlam_n = dC/dXi dXi/dlam_n`` and ``dC/dg_n = dC/dXi dXi/dg_n``.  NTS's
Tresca bound ``bound * a_A(x)`` moves with the slave: the pair adds
``dC/dXi * bound * da_A/dx`` (:attr:`FrictionRows.d_bound`,
:mod:`~skfem_mortar.contact.tributary`).

Kinks, without regularization: ``|s|`` is never differentiated at ``s = 0``,
because a slip node has ``|s| >= Xi > 0`` and ``s = 0`` lies inside the stick
branch; at the tie ``|s| = Xi`` the slip branch's derivative is taken (both
branches have the same value there, ``C_t = Xi (lam_t - s)``); at ``Xi = 0``
(normal active on its boundary ``lam_n = c_n g_n``) the node is open, the
same choice the normal row makes at ``lam_n - c_n g_n = 0`` the other way
round.  ``C_t`` is piecewise smooth (piecewise polynomial in ``lam``, ``u_t``,
``g_n``) and every one-sided choice above is an element of its B-subdifferential
(the derivative of an active smooth piece), so ``C_t`` is semismooth and the
semi-smooth Newton method with these derivatives converges locally
superlinearly, quadratically once the statuses settle (Qi and Sun 1993;
Hintermueller, Ito, Kunisch 2003 for ``max``; Hueber, Stadler, Wohlmuth 2008).

The projected slip derivatives
------------------------------
Away from a solution a slip node can carry ``|lam_t| > Xi``; then the exact
``dC/du_t = c_t (Xi - sign(s) lam_t)`` has the wrong sign, and the Newton step
drives the slip against the friction it should oppose (seen at contact edges,
where ``Xi`` is small: the statuses cycle between stick and slip, the cycling
guard freezes them, Newton then meets the slip branch's spurious root
``s = 0`` and the KKT check cuts the step).  :func:`complementarity`
therefore uses, by default, ``lam_t`` projected onto ``|lam_t| <= Xi`` in the
slip branch's ``dC/dlam_t`` and ``dC/du_t``::

    l   = lam_t min(1, Xi / |lam_t|),
    dC/dlam_t = |s| - Xi + sign(s) l,   dC/du_t = c_t (Xi - sign(s) l)  (>= 0),

which is the exact derivative wherever ``|lam_t| <= Xi``, in particular at
every solution (a sliding node has ``lam_t = Xi sign(s)``), so the local
quadratic rate is that of the exact Newton method; only iterates with
``|lam_t| > Xi`` see a different (inexact) step.  ``jacobian="exact"``
gives the exact derivatives (the finite-difference tests use it).  Measured
(``docs/friction.md``): ironing at ``mu = 0.3`` takes 40 steps with every
method (54 and 73 with the exact derivatives, mortar and dual), seed at
``mu = 0.3`` 10 to 16 (18 to 49).

Second-order terms
------------------
``C_t`` rows need only first derivatives: their Jacobian is
``dC/dlam_n``, ``dC/dlam_t`` (diagonal) and ``dC/du_t G_t + dC/dg_n G_n``
(``G_t = du_t/dx`` from :mod:`~skfem_mortar.contact.slip`, ``G_n = dg_n/dx``).
The body rows ``-G_n^T lam_n - G_t^T lam_t`` need
``H_n = sum lam_n d2 g_n/dx2`` and ``H_t = sum lam_t d2 u_t/dx2`` (``K_uu -= H_n + H_t``);
there are no second derivatives of the friction law itself.

Units: ``C_t`` is a multiplier squared (``Xi c_t u_t``); the pair scales the
rows by a fixed pressure of the step (see ``docs/friction.md``).
"""
from __future__ import annotations

from dataclasses import dataclass, fields
import numpy as np

from ..core.validate import real

__all__ = ["Coulomb", "Tresca", "FrictionLaw", "FrictionRows", "OPEN", "STICK", "SLIP",
           "STATUS_NAMES", "NO_FRICTION", "FRICTIONLESS", "as_law", "JACOBIANS", "complementarity"]

#: node status codes of :func:`complementarity`
OPEN, STICK, SLIP = 0, 1, 2
STATUS_NAMES = ("open", "stick", "slip")


def _finite(name: str, value: float, low: float, strict: bool) -> float:
    """``value`` as a float, ValueError naming ``name`` unless a finite real number
    above ``low`` (a string such as ``"0.3"`` is refused, not converted)."""
    return real(name, value, low, low_open=strict)


def _start(value: float) -> float:
    """``start`` as a float, ValueError naming it unless a finite real number in ``[0, 1)``
    (the load factor after which friction acts)."""
    return real("start", value, 0.0, 1.0, high_open=True)


class FrictionLaw:
    """A friction law a :class:`~skfem_mortar.contact.pair.ContactPair` plugs in.

    A law is what the pair asks about friction, node by node, and nothing of the
    pair's rows: the slip bound ``Xi`` and its derivatives (:meth:`slip_bound`),
    ``dXi/dw`` of a bound proportional to the nodal weight ``w``
    (:meth:`weight_derivative`, which the pair chains with ``dw/dx`` where the
    multiplier space's weight moves with the slave), when it acts (:meth:`acts`,
    :meth:`at`) and how a failure names it (:meth:`describe`).  A new law
    subclasses this class (a frozen dataclass whose first field is its
    parameter) and needs no change elsewhere.

    Attributes
    ----------
    start : float
        The load factor after which friction acts (0: every step).
    tangential_multipliers : int
        Tangential multipliers per slave node and tangent direction (``d - 1``
        directions in ``d`` dimensions: 1 in 2D); 0 for :data:`FRICTIONLESS`,
        which has no tangential rows.
    """

    start: float = 0.0
    tangential_multipliers: int = 1

    def acts(self, load_factor: float) -> bool:
        """Whether friction acts in the load step ending at ``load_factor``:
        ``start == 0`` (every step) or ``load_factor > start``."""
        return self.start == 0.0 or load_factor > self.start

    def at(self, load_factor: float) -> "FrictionLaw":
        """The law of the load step ending at ``load_factor``: this one where it
        :meth:`acts`, else :data:`NO_FRICTION` (every node open)."""
        return self if self.acts(load_factor) else NO_FRICTION

    def slip_bound(self, lam_n: np.ndarray, g_n: np.ndarray, c_n: float,
                   weight: np.ndarray | float = 1.0
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(Xi, dXi/dlam_n, dXi/dg_n)`` per node (``weight``: the multiplier
        space's nodal weight of a bound given per unit area)."""
        raise NotImplementedError

    def weight_derivative(self) -> float:
        """``dXi/dw`` where ``Xi`` is proportional to the nodal weight ``w`` (0: it is not)."""
        return 0.0

    def describe(self) -> str:
        """The bound in words, for a failure hint (e.g. ``mu = 0.3 times the normal force``)."""
        return repr(self)

    def __repr__(self) -> str:
        name = fields(self)[0].name   # the law's own parameter: mu or bound
        more = f", start={self.start!r}" if self.start else ""
        return f"{type(self).__name__}({name}={getattr(self, name)!r}{more})"


class _Frictionless(FrictionLaw):
    """No friction: no tangential multipliers, no tangential rows (the pair of
    ``friction=None``)."""

    tangential_multipliers = 0

    def slip_bound(self, lam_n, g_n, c_n, weight=1.0):
        z = np.zeros(np.shape(lam_n))
        return z, z.copy(), z.copy()

    def __repr__(self) -> str:
        return "FRICTIONLESS"


#: the law of a pair without friction (``friction=None``): no tangential rows
FRICTIONLESS = _Frictionless()


def as_law(friction: "FrictionLaw | None") -> FrictionLaw:
    """The law of a pair's ``friction`` argument: :data:`FRICTIONLESS` for None, a
    :class:`FrictionLaw` as it is (ValueError naming ``friction`` otherwise)."""
    if friction is None:
        return FRICTIONLESS
    if not isinstance(friction, FrictionLaw):
        raise ValueError(f"friction must be None, Coulomb(mu) or Tresca(bound), got "
                         f"{friction!r}")
    return friction


@dataclass(frozen=True, repr=False)
class Coulomb(FrictionLaw):
    """Coulomb friction: ``|lam_t| <= mu lam_n``.

    Parameters
    ----------
    mu : float
        Friction coefficient, finite and ``>= 0`` (``mu = 0``: every active node
        is open tangentially, ``lam_t = 0``).
    start : float, optional
        The load factor after which friction acts, in ``[0, 1)`` (default 0:
        in every step).  A load step whose target load factor ``t`` has
        ``t <= start`` is frictionless (``lam_t = 0`` on every node); the slip
        of the first step with ``t > start`` is measured from the state that
        ended the last frictionless one.  For a normal loading that theory
        calls shear-free (elastically similar bodies) followed by a tangential
        one: frictional pressing in finite load steps locks in the slip a
        node makes within the step in which it touches down, as stick
        traction (:meth:`acts`; docs/friction.md).
    """

    mu: float
    start: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "mu", _finite("mu", self.mu, 0.0, strict=False))
        object.__setattr__(self, "start", _start(self.start))

    def slip_bound(self, lam_n: np.ndarray, g_n: np.ndarray, c_n: float,
                   weight: np.ndarray | float = 1.0
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The slip bound ``Xi = mu (lam_n - c_n g_n)`` and ``dXi/dlam_n = mu``,
        ``dXi/dg_n = -mu c_n`` (``weight`` unused: ``mu lam_n`` has the multiplier's units)."""
        lam_n, g_n = np.asarray(lam_n, float), np.asarray(g_n, float)
        xi = self.mu * (lam_n - c_n * g_n)
        return xi, np.full(xi.shape, self.mu), np.full(xi.shape, -self.mu * c_n)

    def describe(self) -> str:
        return f"mu = {self.mu:g} times the normal force"


@dataclass(frozen=True, repr=False)
class Tresca(FrictionLaw):
    """Tresca friction: ``|t_t| <= bound``, a fixed bound on the tangential traction.

    Parameters
    ----------
    bound : float
        The bound, a traction: force per unit *current* area (per unit current
        length and unit thickness in plane problems), finite and ``> 0``.
    start : float, optional
        The load factor after which friction acts, in ``[0, 1)`` (default 0);
        as :class:`Coulomb`'s.

    Notes
    -----
    One meaning for every method: ``bound`` bounds the Cauchy tangential
    traction, the force per unit area of the deformed contact surface.  That
    is the physical one (a shear strength of the interface acts on the area
    that touches now, whatever the body's reference shape), and it is what the
    mortar weak form integrates: its tractions act on the current slave
    surface, so a sliding contact carries ``bound`` times the current contact
    length.  The nodal bound is ``bound * weight``, in the units of the
    tangential multiplier: mortar multipliers are tractions, ``weight = 1``
    (the ``D_AA``-weighted condition ``|sum_B D_AB lam_t,B| <= D_AA bound`` for
    dual multipliers, ``D`` diagonal, and its nodal form for standard ones);
    NTS multipliers are nodal forces, ``weight`` the tributary length
    ``a_A(x)`` on the current positions (its derivative enters the rows'
    Jacobian, :mod:`skfem_mortar.contact.tributary`), 2- and 3-node segments
    alike.  ``contact_data``'s ``tangential_traction`` is per current length
    too, so a sliding node reads ``bound`` with every method.
    """

    bound: float
    start: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "bound", _finite("bound", self.bound, 0.0, strict=True))
        object.__setattr__(self, "start", _start(self.start))

    def slip_bound(self, lam_n: np.ndarray, g_n: np.ndarray, c_n: float,
                   weight: np.ndarray | float = 1.0
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The slip bound ``Xi = bound * weight`` and its derivatives (zero)."""
        shape = np.broadcast_shapes(np.shape(lam_n), np.shape(weight))
        xi = np.broadcast_to(self.bound * np.asarray(weight, float), shape).copy()
        return xi, np.zeros(shape), np.zeros(shape)

    def weight_derivative(self) -> float:
        """``dXi/dw = bound``."""
        return self.bound

    def describe(self) -> str:
        return f"the Tresca bound {self.bound:g} times the contact length"


#: the law of a frictional pair's steps before its ``start`` (every node open)
NO_FRICTION = Coulomb(0.0)


@dataclass
class FrictionRows:
    """The tangential complementarity rows of the slave nodes and their derivatives.

    Attributes
    ----------
    C : ndarray (n,)
        ``C_t`` per node (see the module doc).
    status : int ndarray (n,)
        :data:`OPEN`, :data:`STICK` or :data:`SLIP`.
    d_lam_n, d_lam_t, d_g, d_u : ndarray (n,)
        ``dC_t/dlam_n``, ``dC_t/dlam_t``, ``dC_t/dg_n``, ``dC_t/du_t`` (the branch
        of ``status``; the rows' Jacobian is diagonal in these).
    d_bound : ndarray (n,)
        ``dC_t/dXi``: with a bound that depends on the positions (NTS's Tresca
        bound ``bound * a_A(x)``), the rows' Jacobian adds ``d_bound dXi/dx``.
    bound : ndarray (n,)
        The slip bound ``Xi`` (0 on open nodes).
    s : ndarray (n,)
        The augmented tangential multiplier ``lam_t - c_t u_t``.
    """

    C: np.ndarray
    status: np.ndarray
    d_lam_n: np.ndarray
    d_lam_t: np.ndarray
    d_g: np.ndarray
    d_u: np.ndarray
    bound: np.ndarray
    s: np.ndarray
    d_bound: np.ndarray

    def where(self, code: int) -> np.ndarray:
        """The nodes of one status (bool per node)."""
        return self.status == code


#: the slip branch's derivatives (:func:`complementarity`): ``"projected"`` (the
#: default) or ``"exact"``
JACOBIANS = ("projected", "exact")


def complementarity(law: FrictionLaw, lam_n: np.ndarray, lam_t: np.ndarray, g_n: np.ndarray,
                    u_t: np.ndarray, c_n: float, c_t: float, active: np.ndarray | None = None,
                    weight: np.ndarray | float = 1.0,
                    status: np.ndarray | None = None,
                    jacobian: str = "projected") -> FrictionRows:
    """``C_t = max(Xi, |s|) lam_t - Xi s``, ``s = lam_t - c_t u_t``, per slave node, with its
    status and exact derivatives (module doc).

    Parameters
    ----------
    law : FrictionLaw
    lam_n, lam_t : ndarray (n,)
        Normal and tangential multipliers (the pair's signs, module doc).
    g_n : ndarray (n,)
        Gaps (``> 0`` open; mortar: weighted).
    u_t : ndarray (n,)
        Slips within the step (:mod:`~skfem_mortar.contact.slip`).
    c_n, c_t : float
        Complementarity parameters (finite, ``> 0``): ``c_n`` the pair's normal one,
        ``c_t`` the tangential one (the pair takes ``c_t = c_n``: the slip has the
        units of the gap, so the same stiffness makes the row unit-free).
    active : bool ndarray (n,), optional
        The normal active set (the pair's, after its guards); default
        ``lam_n - c_n g_n >= 0``.  Inactive nodes are open.
    weight : float or ndarray (n,)
        The nodal weight of a :class:`Tresca` bound (NTS: the current tributary
        length, mortar: 1); unused by :class:`Coulomb`.
    status : int ndarray (n,), optional
        Impose these branches (:data:`STICK`, :data:`SLIP`) instead of choosing
        them from ``|s|`` and ``Xi`` (the contact pair's first iteration of a
        step and its cycling guard, :class:`~skfem_mortar.contact.active_set.StatusSet`);
        a node whose normal row is inactive or whose ``Xi <= 0`` is open whatever
        ``status`` says.  Default: the plain choice of the module doc.
    jacobian : {"projected", "exact"}
        The slip branch's ``dC/dlam_t`` and ``dC/du_t``: ``"exact"`` the
        derivatives of the module doc; ``"projected"`` (default) the same with
        ``lam_t`` replaced by its projection onto the disk ``|lam_t| <= Xi``,
        ``lam_t min(1, Xi / |lam_t|)`` (module doc, "The projected slip
        derivatives").  Both agree wherever ``|lam_t| <= Xi``, so at every
        solution.

    Returns
    -------
    FrictionRows
    """
    if not isinstance(law, FrictionLaw):
        raise ValueError(f"law must be a Coulomb or Tresca friction law (or another "
                         f"FrictionLaw), got {law!r}")
    if jacobian not in JACOBIANS:
        raise ValueError(f"jacobian must be one of {', '.join(map(repr, JACOBIANS))}, got "
                         f"{jacobian!r}")
    c_n = _finite("c_n", c_n, 0.0, strict=True)
    c_t = _finite("c_t", c_t, 0.0, strict=True)
    lam_n = np.asarray(lam_n, float)
    n = lam_n.shape
    arrays = {"lam_t": lam_t, "g_n": g_n, "u_t": u_t}
    for name, a in arrays.items():
        if np.shape(a) != n:
            raise ValueError(f"{name} must have the shape of lam_n {n}, got {np.shape(a)}")
    lam_t, g_n, u_t = (np.asarray(a, float) for a in arrays.values())
    if active is None:
        active = lam_n - c_n * g_n >= 0
    active = np.asarray(active, dtype=bool)
    if active.shape != n:
        raise ValueError(f"active must have the shape of lam_n {n}, got {active.shape}")
    xi, dxi_dl, dxi_dg = law.slip_bound(lam_n, g_n, c_n, weight)
    s = lam_t - c_t * u_t
    a = np.abs(s)
    if status is None:
        chosen = np.where(a < xi, STICK, SLIP)
    else:
        chosen = np.asarray(status)
        if chosen.shape != n or not np.all(np.isin(chosen, (OPEN, STICK, SLIP))):
            raise ValueError(f"status must hold OPEN, STICK or SLIP codes in the shape of "
                             f"lam_n {n}")
    st = np.where(~active | (xi <= 0) | (chosen == OPEN), OPEN, chosen)
    stick, slip, opened = st == STICK, st == SLIP, st == OPEN
    sg = np.sign(s)
    C = np.where(opened, lam_t, np.where(stick, xi * c_t * u_t, a * lam_t - xi * s))
    lt = lam_t if jacobian == "exact" else _projected(lam_t, xi)
    d_lt = np.where(opened, 1.0, np.where(stick, 0.0, a - xi + sg * lt))
    d_u = np.where(stick, c_t * xi, np.where(slip, c_t * (xi - sg * lt), 0.0))
    d_xi = np.where(stick, c_t * u_t, np.where(slip, -s, 0.0))
    return FrictionRows(C=C, status=st.astype(np.int8), d_lam_n=d_xi * dxi_dl,
                        d_lam_t=d_lt, d_g=d_xi * dxi_dg, d_u=d_u,
                        bound=np.where(opened, 0.0, xi), s=s, d_bound=d_xi)


def _projected(lam_t: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """``lam_t`` projected onto the disk ``|lam_t| <= Xi`` (``Xi > 0``; where
    ``Xi <= 0``, 0): ``lam_t min(1, Xi / |lam_t|)``."""
    bound = np.maximum(xi, 0.0)
    return np.clip(lam_t, -bound, bound)
