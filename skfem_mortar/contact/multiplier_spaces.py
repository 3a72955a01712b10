"""Multiplier spaces: what a contact multiplier is, as objects in a registry.

A :class:`~skfem_mortar.contact.pair.ContactPair` reads its multipliers
through the space of its method and never asks which space it is.  A space
answers:

* ``kind``: ``"force"`` (a nodal force, NTS) or ``"traction"`` (the
  coefficient of a traction field, mortar);
* :meth:`MultiplierSpace.pressure` / :meth:`~MultiplierSpace.multipliers`: the
  pressure of a multiplier and back (``p = lam / a_A`` for nodal forces,
  ``p = lam`` for tractions; ``a_A`` the tributary length);
* :meth:`~MultiplierSpace.gap_length` and :meth:`~MultiplierSpace.slip_length`:
  the method's gap and slip as lengths (mortar's weighted ones over ``a_A``);
* :meth:`~MultiplierSpace.row_scale`, :meth:`~MultiplierSpace.complementarity`,
  :meth:`~MultiplierSpace.p_ref`: the multiplier rows' scale ``s``, the
  complementarity parameter ``c`` from the bodies' stiffness ``k`` and the
  tangential rows' first pressure guess (force rows: ``s = 1``, ``c = k``,
  ``p_ref = c h``; traction rows: ``s = h``, ``c = k / h^2``,
  ``p_ref = c h^2``; ``h`` the mean tributary length);
* :meth:`~MultiplierSpace.bound_weight` and ``bound_moves``: the nodal weight
  ``w`` of a bound given per unit area (Tresca: ``Xi = bound * w``) and whether
  ``w`` moves with the slave (then the pair chains ``dXi/dw dw/dx``);
* :meth:`~MultiplierSpace.evaluate` and :meth:`~MultiplierSpace.slip`: the
  method's gaps and slips in this space's multipliers (the built-ins take them
  as the method computes them);
* ``mask_tolerance``: per dimension of the slave cells, the support ratio
  ``r_A = s_A / w_A`` (the node's mortar support over its tributary weight) at or
  below which a mortar kernel masks a slave node (:func:`mask_tolerance`; the
  masked band below).

The masked band
---------------
A kept slave node whose faces are covered by the master over a small part only
(support ratio ``r``) has a multiplier that extrapolates the traction of the
covered part to the node: its gap row is nearly a multiple of its neighbours'
rows, and the round-off of the weighted gaps (at most ``eps s_A |x|`` a row,
measured) reaches its multiplier amplified.  On the partly projected 3D patch
(``tests/test_partly_projected3d.py``; the displacements and the forces stay
exact) the pressure error at such a node is about ``3e-13 / r^2`` with standard
multipliers (3.0e-9 at ``r = 1.0e-2``, 2.7e-8 at 2.6e-3, 1.3e-5 at 1.0e-4) and
about ``3e-14 / r^1.5`` with dual ones (2.3e-10 at 2.6e-3, 1.8e-9 at 9.3e-4,
3.2e-8 at 1.0e-4), where the patch test allows 1e-8.  Reading the pressure as
the node's force over its support, ``(D^T lam)_A / s_A``, gains a factor 20 to
800 with standard multipliers (5.5e-8 at ``r = 1e-4``) and nothing with dual
ones (``D`` is diagonal): it does not close the band.  So the band is masked
on faces: ``mask_tolerance`` is 1e-2 for :class:`StandardSpace` and 1e-3 for
:class:`DualSpace` there (the errors at the edge of the band, 3e-9 and 2e-9, are 3
and 5 times below 1e-8).  A masked node's function goes to its kept neighbours (its
multiplier is zero and the covered part keeps its traction), so masking costs no
accuracy of the forces.

The price is a jump: when a node's mask switches (a sliding master uncovers it),
its neighbours' weighted gaps jump by its former ``g_A``, about ``r w_A`` times the
gap there, so the jump grows with the tolerance.  On lines both spaces keep
:data:`MASK_TOL` = 1e-6: the 2D sliding path stays continuous to 1e-7 of the gap
slopes (``tests/test_mortar.py``, sliding path continuity, fails with the faces'
tolerances), and the
2D readings are far milder (the 2D offset patch, one pair, line2: at most 2.3e-8
at ``r = 9e-6``, 2e-10 at ``r = 1e-4``, 1.5e-9 and 1.3e-8 at ``r = 1e-6``, against
1.3e-5 on quad4 faces at ``r = 1e-4``).  Any other space has :data:`MASK_TOL` in
every dimension unless it sets its own (a number for every dimension, or a dict
``{dim: tolerance}``).

The built-in spaces are :class:`NodalSpace` (``"nodal"``, NTS),
:class:`StandardSpace` (``"standard"``, mortar with ``Phi_A = N_A``) and
:class:`DualSpace` (``"dual"``, biorthogonal ``Phi_A = sum_B A_AB N_B`` with
``A_e = D_e M_e^-1``).  A method names its space with the attribute
``multiplier_space``; a method without it gets ``"nodal"`` for
``multiplier_kind = "force"`` and ``"standard"`` (``"dual"`` where the method's
``dual`` is set) for ``"traction"`` (:func:`space_for`).  A new space is a
subclass and one :func:`register_space` call.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .jets import inv

from ..core.validate import flag

__all__ = ["MultiplierSpace", "NodalSpace", "StandardSpace", "DualSpace", "register_space",
           "unregister_space", "registered_spaces", "space_for", "make_space",
           "mask_tolerance", "MASK_TOL"]

MASK_TOL = 1e-6
"""The support ratio at or below which a slave node is masked in a space that does
not set its own ``mask_tolerance`` (module doc, "The masked band")."""


def _mean_area(area: np.ndarray) -> float | None:
    """The mean of the positive tributary lengths (None if there are none)."""
    return float(np.mean(area[area > 0])) if np.any(area > 0) else None


def _safe(area: np.ndarray) -> np.ndarray:
    """Tributary lengths with 1 where a node has none (no division by zero)."""
    return np.where(area > 0, area, 1.0)


class MultiplierSpace:
    """What a contact multiplier is (module doc); the base is the nodal-force space.

    Attributes
    ----------
    name : str
        The registered name.
    kind : {"force", "traction"}
        A nodal force or the coefficient of a traction field.
    bound_moves : bool
        Whether :meth:`bound_weight` depends on the current positions.
    mask_tolerance : float or dict
        A mortar kernel masks a slave node whose support ``s_A`` is at most
        ``mask_tolerance`` times its tributary weight ``w_A`` (module doc, "The
        masked band"); a dict gives it per dimension of the slave cells
        (``{1: lines, 2: faces}``, :data:`MASK_TOL` where missing);
        :data:`MASK_TOL` unless a space sets its own.
    """

    name = "nodal"
    kind = "force"
    bound_moves = True
    mask_tolerance = MASK_TOL
    #: whether ``D`` is diagonal in this space (biorthogonal multipliers)
    diagonal = False

    def kernel_options(self) -> dict:
        """The keywords that tell a mortar kernel this space's basis (none for nodal forces)."""
        return {}

    def evaluate(self, method: Any, xs: np.ndarray, xm: np.ndarray, lam: np.ndarray | None,
                 tangent: bool) -> Any:
        """The method's :class:`~skfem_mortar.contact.contact_eval.ContactEval`
        (``g``, ``G = dg/dx``, ``H = sum_A lam_A d2 g_A/dx2``) in this space."""
        return method.evaluate(xs, xm, lam, tangent)

    def slip(self, method: Any, xs: np.ndarray, xm: np.ndarray, history: dict,
             lam_t: np.ndarray | None, tangent: bool, ev: Any) -> Any:
        """The method's :class:`~skfem_mortar.contact.slip.SlipEval` in this space."""
        return method.slip(xs, xm, history, lam_t, tangent, ev)

    def pressure(self, lam: np.ndarray, area: np.ndarray) -> np.ndarray:
        """The traction of multipliers ``lam``: ``lam / a_A``."""
        return lam / _safe(area)

    def multipliers(self, p: Any, area: np.ndarray) -> np.ndarray:
        """The multipliers of a traction ``p`` (the inverse of :meth:`pressure`): ``p a_A``."""
        return p * area

    def gap_length(self, g: np.ndarray, area: np.ndarray) -> np.ndarray:
        """The method's gap as a length: the nodal gap itself."""
        return g

    def slip_length(self, u: np.ndarray, area: np.ndarray) -> np.ndarray:
        """The method's slip as a length: the nodal slip itself."""
        return u

    def row_scale(self, area: np.ndarray) -> float:
        """The multiplier rows' scale ``s`` (rows of nodal forces are forces: 1)."""
        return 1.0

    def complementarity(self, k: float, area: np.ndarray) -> float:
        """``c`` from the bodies' stiffness ``k`` (force / length): ``k``."""
        return k

    def p_ref(self, c: float, area: np.ndarray) -> float:
        """The tangential rows' first pressure guess: ``c h`` (the force a gap of
        one tributary length ``h`` would give)."""
        h = _mean_area(area)
        return float(c * (1.0 if h is None else h) ** 1)

    def bound_weight(self, area: np.ndarray) -> np.ndarray | float:
        """The nodal weight of a bound per unit area: the current tributary length."""
        return area


class NodalSpace(MultiplierSpace):
    """Nodal forces (NTS): one multiplier per slave node, a force."""


class StandardSpace(MultiplierSpace):
    """Tractions in the standard mortar basis ``Phi_A = N_A`` (mortar): ``p = lam``,
    the weighted gap ``g_A = sum_e int Phi_A g`` is a gap times a length, the
    rows are scaled by ``h`` and ``c`` by ``1 / h^2``, a bound per unit area is
    the nodal bound (weight 1)."""

    name = "standard"
    kind = "traction"
    bound_moves = False
    #: the masked band of standard multipliers (module doc): on faces the error is
    #: ``3e-13 / r^2``; lines keep 1e-6 (the sliding path's continuity)
    mask_tolerance = {1: MASK_TOL, 2: 1e-2}

    def kernel_options(self) -> dict:
        """``Phi_A = N_A``: the kernels' ``space`` is this one (standard shape functions)."""
        return {"space": self}

    def pressure(self, lam: np.ndarray, area: np.ndarray) -> np.ndarray:
        return lam.copy()

    def multipliers(self, p: Any, area: np.ndarray) -> Any:
        return p

    def gap_length(self, g: np.ndarray, area: np.ndarray) -> np.ndarray:
        return g / _safe(area)

    def slip_length(self, u: np.ndarray, area: np.ndarray) -> np.ndarray:
        return u / _safe(area)

    def row_scale(self, area: np.ndarray) -> float:
        """Traction rows times a length are forces: ``s = h``."""
        h = _mean_area(area)
        return 1.0 if h is None else h

    def complementarity(self, k: float, area: np.ndarray) -> float:
        h = _mean_area(area)
        h = 1.0 if h is None else h
        return k / (h * h)

    def p_ref(self, c: float, area: np.ndarray) -> float:
        h = _mean_area(area)
        return float(c * (1.0 if h is None else h) ** 2)

    def bound_weight(self, area: np.ndarray) -> np.ndarray | float:
        return 1.0


class DualSpace(StandardSpace):
    """Tractions in the biorthogonal basis ``Phi_A = sum_B A_AB N_B`` (mortar-dual).

    On each slave cell ``e``, ``A_e = D_e M_e^-1`` with ``D_e = diag(int N_A)``
    and ``M_e = int N_A N_B`` (:meth:`coefficients`), so that
    ``int Phi_A N_B = delta_AB int N_A`` and ``D`` is diagonal.  At a boundary
    or crosspoint node (no multiplier) its basis function is merged into the
    neighbour's (the kernel's ``multiplier_support``).  Quadratic cells in 3D
    need a basis transformation of the displacement basis first (Popp et al.
    2012); :meth:`transformation` is its place (identity for every cell type
    now).
    """

    name = "dual"
    diagonal = True
    #: the masked band of dual multipliers (module doc): on faces the error is
    #: ``3e-14 / r^1.5``; lines keep 1e-6 (the sliding path's continuity)
    mask_tolerance = {1: MASK_TOL, 2: 1e-3}

    def kernel_options(self) -> dict:
        """The biorthogonal basis: the kernels' ``space`` is this one (it has
        :meth:`coefficients`)."""
        return {"space": self}

    @staticmethod
    def coefficients(D_e: np.ndarray, M_e: np.ndarray) -> np.ndarray:
        """``A_e = D_e M_e^-1`` of every cell (``D_e``, ``M_e`` of shape
        ``(n_cells, k, k)``), by a solve of ``M_e^T A_e^T = D_e^T``."""
        return np.linalg.solve(np.swapaxes(M_e, 1, 2), np.swapaxes(D_e, 1, 2)).swapaxes(1, 2)

    @staticmethod
    def cell_coefficients(D: list, M: dict) -> dict:
        """``A_e = D_e M_e^-1`` entry by entry, for the kernels' jets: ``D`` the ``k``
        diagonal entries of ``D_e``, ``M`` the upper triangle ``M[(a, b)]``, ``a <= b``,
        of the symmetric ``M_e`` (each an array or a jet of shape (n,)), inverted by
        cofactors (``k`` = 2 or 3: line cells, tri3) or Gauss-Jordan elimination
        (``k >= 4``: quad4), so the derivatives of ``A_e`` follow.  Returns ``{(a, b): A_ab}``; the same as :meth:`coefficients` on arrays."""
        k = len(D)
        Mi = _sym_inverse(M, k)
        return {(a, b): D[a] * Mi[min(a, b), max(a, b)] for a in range(k) for b in range(k)}

    @staticmethod
    def transformation(n_nodes: int) -> np.ndarray:
        """The displacement basis transformation of a cell of ``n_nodes`` nodes
        before ``A_e`` is built: the identity (3D quadratic cells will need another)."""
        return np.eye(n_nodes)


def _sym_inverse(M: dict, k: int) -> dict:
    """Inverse of the symmetric ``k x k`` matrix ``M[(a, b)]`` (a <= b), arrays or jets:
    by cofactors for ``k`` = 2, 3 (the line cells), by Gauss-Jordan elimination without
    pivoting for ``k >= 4`` (quad4: ``M_e`` is symmetric positive definite, so every
    pivot is positive); ValueError naming ``k`` below 2."""
    if k == 2:
        a, b, d = M[0, 0], M[0, 1], M[1, 1]
        r = inv(a * d - b * b)
        return {(0, 0): d * r, (0, 1): -(b * r), (1, 1): a * r}
    if k < 2:
        raise ValueError(f"k must be 2 or more (nodes of a cell), got {k}")
    if k > 3:
        return _gauss_jordan(M, k)
    a, b, c, d, e, f = M[0, 0], M[0, 1], M[0, 2], M[1, 1], M[1, 2], M[2, 2]
    C = {(0, 0): d * f - e * e, (0, 1): c * e - b * f, (0, 2): b * e - c * d,
         (1, 1): a * f - c * c, (1, 2): b * c - a * e, (2, 2): a * d - b * b}
    det = a * C[0, 0] + b * C[0, 1] + c * C[0, 2]
    r = inv(det)
    return {key: v * r for key, v in C.items()}


def _gauss_jordan(M: dict, k: int) -> dict:
    """``M^-1`` of a symmetric positive definite ``M[(a, b)]`` (a <= b) by Gauss-Jordan
    elimination on ``[M | I]`` (entries arrays or jets), its upper triangle."""
    A = [[M[min(i, j), max(i, j)] for j in range(k)] for i in range(k)]
    E = [[1.0 if i == j else 0.0 for j in range(k)] for i in range(k)]
    for c in range(k):
        p = inv(A[c][c])
        A[c] = [x * p for x in A[c]]
        E[c] = [x * p for x in E[c]]
        for r in range(k):
            if r != c:
                f = A[r][c]
                A[r] = [x - f * y for x, y in zip(A[r], A[c])]
                E[r] = [x - f * y for x, y in zip(E[r], E[c])]
    return {(a, b): E[a][b] for a in range(k) for b in range(a, k)}


_REGISTRY: dict[str, MultiplierSpace] = {}


def register_space(space: MultiplierSpace) -> None:
    """Make ``space`` (an instance) known by its ``name`` (ValueError if the name
    is taken, not a non-empty string, its ``kind`` not force or traction, or its
    ``mask_tolerance`` not in ``[0, 1)``)."""
    name = getattr(space, "name", None)
    if not isinstance(space, MultiplierSpace) or not isinstance(name, str) or not name:
        raise ValueError(f"space must be a MultiplierSpace with a non-empty name, got {space!r}")
    if name in _REGISTRY:
        raise ValueError(f"multiplier space {name!r} is registered already")
    if space.kind not in ("force", "traction"):
        raise ValueError(f"multiplier space {name!r}: kind must be 'force' or 'traction', "
                         f"got {space.kind!r}")
    for dim in (1, 2):                         # numbers in [0, 1) (ValueError)
        mask_tolerance(space, dim)
    _REGISTRY[name] = space


def unregister_space(name: str) -> None:
    """Forget a registered space (KeyError if it is not registered)."""
    del _REGISTRY[name]


def registered_spaces() -> tuple[str, ...]:
    return tuple(_REGISTRY)


def make_space(name: str) -> MultiplierSpace:
    """The registered space ``name`` (ValueError naming the registered ones)."""
    if name not in _REGISTRY:
        raise ValueError(f"multiplier_space must be one of {', '.join(_REGISTRY)}, got {name!r}")
    return _REGISTRY[name]


def mask_tolerance(space: "MultiplierSpace | str | None", dim: int) -> float:
    """The support ratio at or below which a mortar kernel masks a slave node of cells
    of dimension ``dim`` (1 lines, 2 faces) in ``space`` (a registered name, a space,
    or None: :data:`MASK_TOL`): its ``mask_tolerance``, a number or ``{dim: number}``
    (module doc, "The masked band").

    Raises
    ------
    ValueError
        For a name that is not registered, or a tolerance that is not a number in
        ``[0, 1)``, naming the space.
    """
    if space is None:
        return MASK_TOL
    sp = make_space(space) if isinstance(space, str) else space
    tol = getattr(sp, "mask_tolerance", MASK_TOL)
    if isinstance(tol, dict):
        tol = tol.get(int(dim), MASK_TOL)
    if (isinstance(tol, bool) or not isinstance(tol, (int, float))
            or not 0.0 <= tol < 1.0):
        raise ValueError(f"mask_tolerance of the multiplier space {getattr(sp, 'name', sp)!r} "
                         f"must be a number in [0, 1) (or a dict of them by dimension), "
                         f"got {tol!r}")
    return float(tol)


def traction_space(**flags: Any) -> MultiplierSpace:
    """The traction space named by a constructor's flags (``TiePair(..., dual=True)``):
    ``"dual"`` for ``dual=True``, ``"standard"`` for ``dual=False`` or none.

    Raises
    ------
    ValueError
        For a keyword other than ``dual``, or ``dual`` not a bool.
    """
    unknown = sorted(set(flags) - {"dual"})
    if unknown:
        raise ValueError(f"unexpected keyword(s) {', '.join(unknown)}: the multiplier basis "
                         f"is chosen by dual=True or False")
    return make_space("dual" if flag("dual", flags.get("dual", False)) else "standard")


def space_for(method: Any) -> MultiplierSpace:
    """The space of a contact discretization: its ``multiplier_space`` if it names
    one, else from its ``multiplier_kind`` (module doc)."""
    name = getattr(method, "multiplier_space", None)
    if name is None:
        name = "nodal" if method.multiplier_kind == "force" else (
            "dual" if getattr(method, "dual", False) else "standard")
    return make_space(name)


for _space in (NodalSpace(), StandardSpace(), DualSpace()):
    register_space(_space)
