"""What the contact layer can tell about a model that will not solve, or did not.

Read by the preflight (:mod:`.preflight_methods`, warnings before the solve) and by
:func:`skfem_mortar.solver.stepping.solve` when it gives a step up (the
physical cause added to the :class:`~skfem_mortar.core.errors.ConvergenceError`):

* :func:`stiffness_ratio_text`: two bodies in contact whose stiffness ratio lies
  beyond what the package has measured (:data:`MEASURED_RATIO`).
* :func:`nts_patch_text`: NTS on a deformable pair whose meshes do not match
  where they meet: NTS is off the contact patch test there
  (:data:`NTS_PATCH_ERRORS`).
* :func:`pulled_off`: a body held only by contact while the load pulls it away
  from the master: frictionless contact only pushes, so the contact opens
  entirely and nothing holds the body.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..core.chain import polyline
from . import nts
from .nts_faces import face_sizes, project_faces
from .search import nearest_vertex
from .surface_kinds import CURVE, FACE, entry
from .preflight_pairs import contact_pairs
from .preflight_rigid import _columns, _describe, _times_modes, _touching_rows, free_combinations

__all__ = ["MEASURED_RATIO", "NTS_PATCH_ERRORS", "stiffness_ratio_text", "nts_patch_text",
           "pulled_off"]

#: the largest stiffness ratio between two bodies in contact that the package has
#: measured (docs/robustness.md: the patch test at E_top / E_bottom in 1e-3 .. 1e6
#: to round-off, Hertz on an elastic base at E_base / E in 1e-3 .. 1e6 within 5 %)
MEASURED_RATIO = 1e6

#: the pressure errors of NTS measured on non-matching patch tests
#: (``skfem-mortar run patch --method nts``, largest nodal deviation from q):
#: 0.062 at the defaults (5 on 4, quad1), 0.082 (10 on 7), 0.14 (7 on 10),
#: 0.135 (quad2 5 on 4), 0.38 (quad2 7 on 10); the issue's quadratic and mixed
#: patch tests 11 to 47 %; mortar and mortar-dual pass all of them to round-off
NTS_PATCH_ERRORS = "6 % to 47 %"

#: a master node coincides with a slave node when they lie within this fraction of
#: the median slave segment length (mesh generators place shared nodes to round-off)
MATCH = 1e-6


# --------------------------------------------------------------------------- stiffness
def _stiffness(body: Any, z: np.ndarray, load_factor: float,
               young: bool = True) -> tuple[str, float]:
    """``("E", Young's modulus)`` for a solid with an isotropic material (when
    ``young``), else ``("k", mean absolute tangent diagonal)`` of the body at ``z``."""
    E = getattr(getattr(body, "material", None), "E", None) if young else None
    if E is not None and np.isfinite(E) and E > 0:
        return "E", float(E)
    c = body.assemble(z, load_factor, tangent=True)
    on = c.k_rows == c.k_cols
    d = np.abs(np.bincount(c.k_rows[on] - body.offset, weights=c.k_vals[on],
                           minlength=body.n_dofs))
    return "k", float(d.mean()) if d.size else 0.0


def stiffness_ratio_text(model: Any, z: np.ndarray, load_factor: float) -> list[str]:
    """One sentence per contact pair between two bodies whose stiffness ratio
    exceeds :data:`MEASURED_RATIO`: Young's moduli when both are solids with one,
    else the mean tangent diagonals (both force per length)."""
    out = []
    for pair in contact_pairs(model):
        a, b = pair.slave.body, pair.master.body
        if a is None or b is None or a is b:
            continue
        (ka, sa), (kb, sb) = _stiffness(a, z, load_factor), _stiffness(b, z, load_factor)
        if ka != kb:
            (ka, sa), (kb, sb) = (_stiffness(a, z, load_factor, young=False),
                                  _stiffness(b, z, load_factor, young=False))
        lo, hi = sorted([(sa, a), (sb, b)], key=lambda t: t[0])
        if lo[0] <= 0.0 or hi[0] <= MEASURED_RATIO * (1.0 + 1e-9) * lo[0]:
            continue
        what = ("Young's moduli" if ka == "E" else "mean tangent diagonals")
        out.append(
            f"contact {pair.name!r}: body {hi[1].name!r} is {hi[0] / lo[0]:.3g} times stiffer "
            f"than body {lo[1].name!r} ({what} {hi[0]:.3g} and {lo[0]:.3g}), beyond the "
            f"stiffness ratios the package has measured (up to {MEASURED_RATIO:g}); the stiff "
            f"body's forces carry a round-off of about 1e-16 times its stiffness, which can "
            f"exceed the load, and then equilibrium cannot be checked: make the stiff body "
            f"at most {MEASURED_RATIO:g} times stiffer (it is rigid for the soft one already), or "
            f"replace it by a rigid surface (RigidPlane, RigidCircle) or Dirichlet data")
    return out


# --------------------------------------------------------------------------- NTS patch test
#: the NTS patch errors measured in 3D (the warning's text; tests/test_nts3d.py)
NTS_PATCH_ERRORS_3D = "19 % to 52 %"


def _matching(pair: Any) -> bool:
    """Whether every master node where the surfaces meet coincides with a slave
    node (reference configuration): matching meshes, or a slave that refines
    the master, on which NTS passes the patch test (measured: 6 on 6, 10 on 5,
    12 on 4, 20 on 2, quadratic 10 on 5 to round-off).

    Each master node is projected on the slave chain (:func:`.nts.project`, linear
    cost); where they meet: a projection within one median slave segment length
    ``h``; coincident: its distance and its distance from the nearer end of the
    slave segment both within ``MATCH h``."""
    xs, xm = np.asarray(pair.slave.X, float), np.asarray(pair.master.X, float)
    pm = xm[:, np.unique(pair.master.segments)]
    return entry(_MATCHING, pair.slave.cell, "the NTS patch check")(pair, xs, pm)


def _matching_faces(pair: Any, xs: np.ndarray, pm: np.ndarray) -> bool:
    """:func:`_matching` on faces: coincident with a slave node."""
    h = float(np.median(face_sizes(xs, pair.slave.segments)))
    pr = project_faces(pm, xs, pair.slave.segments, pair.slave.cell, h)
    meet = pr["mask"] & (np.abs(pr["g"]) <= h)
    d, _ = nearest_vertex(xs, pm)
    return bool(np.all((d <= MATCH * h) | ~meet))


def _matching_curves(pair: Any, xs: np.ndarray, pm: np.ndarray) -> bool:
    """:func:`_matching` on curves: coincident with a slave node, off the segment ends."""
    seg_s = polyline(pair.slave.segments, pair.slave.cell)
    h = float(np.median(np.hypot(*(xs[:, seg_s[:, 1]] - xs[:, seg_s[:, 0]]))))
    pr = nts.project(pm, xs, seg_s)
    meet = pr["mask"] & (np.abs(pr["g"]) <= h)
    off_end = np.minimum(np.abs(pr["xi"]), np.abs(1.0 - pr["xi"])) * pr["l"]
    return bool(np.all((np.abs(pr["g"]) <= MATCH * h) & (off_end <= MATCH * h) | ~meet))


#: the coincidence check of each surface kind (:mod:`.surface_kinds`)
_MATCHING = {CURVE: _matching_curves, FACE: _matching_faces}


def nts_patch_text(pair: Any) -> str:
    """For an NTS pair between two deformable bodies whose meshes do not match
    where they meet: how far off the contact patch test NTS is and the fix
    ("" otherwise)."""
    if pair.method != "nts" or pair.master.body is None or _matching(pair):
        return ""
    return (f"{pair.name}: NTS on meshes that do not match where they meet (master nodes "
            f"between slave nodes) fails the contact patch test: a uniform pressure comes "
            f"out {NTS_PATCH_ERRORS} off at the nodes in the measured plane cases (6 % on the "
            f"patch scene's 5 on 4 defaults, 14 % on 7 on 10, 38 % on quadratic 7 on 10) and "
            f"{NTS_PATCH_ERRORS_3D} off on stacked 3D blocks of 4 and 6 cells a side (tet1 "
            f"and hex1 in all four pairings, either side the slave); the contact force is right; "
            f"method=\"mortar-dual\" (the default) passes it to round-off: "
            f"ContactPair(slave, master, method=\"mortar-dual\")")


# --------------------------------------------------------------------------- held only by contact
def pulled_off(model: Any, z: np.ndarray, load_factor: float, fixed: np.ndarray) -> list[str]:
    """The bodies that only contact holds and that the load at ``load_factor``
    pulls away from it, one sentence each group ([] if none).

    With ``N`` the combinations of rigid modes that nothing but contact holds
    (:func:`~.preflight_rigid.free_combinations` with ``contact=False``), ``f`` the
    external load and ``C`` the unit normal rows of every slave node facing a
    master (positive: the gap opens; a frictionless contact force is ``C^T lam``,
    ``lam >= 0``), the load is balanced along ``N`` only if
    ``N^T M^T (f + C^T lam) = 0`` has a solution ``lam >= 0`` (non-negative
    least squares).  A residual above ``1e-6`` of ``|N^T M^T f|`` means no
    compressive contact force can balance it: the contact opens entirely.
    Pairs with friction, whose tangential force is bounded otherwise, are left
    out (no sentence for a body they touch).
    """
    bodies, N, _ = free_combinations(model, z, load_factor, fixed, contact=False)
    if N.size == 0 or N.shape[1] == 0:
        return []
    f = -model.load_residual(z, load_factor)
    Mf = _times_modes(sp.csr_matrix(f[None, :]), bodies)[0]        # (n_modes,) M^T f
    b = N.T @ Mf
    if not np.linalg.norm(b) > 1e-12 * max(np.linalg.norm(f), np.finfo(float).tiny):
        return []
    pairs = contact_pairs(model)
    if any(getattr(p, "multipliers_per_node", 1) > 1 for p in pairs):  # tangential rows
        return []
    rows = [_touching_rows(p, z, load_factor, int(model.n), facing=True).rows for p in pairs]
    A = (N.T @ _times_modes(sp.vstack(rows), bodies).T) if rows else np.zeros((N.shape[1], 0))
    from scipy.optimize import nnls  # 0.3 s to import: only when a step is given up
    r = A @ nnls(A, -b)[0] + b if A.shape[1] else b        # the load contact cannot balance
    if np.linalg.norm(r) <= 1e-6 * np.linalg.norm(b):
        return []
    return [_pulled_text(bodies, N, N @ r, Mf, pairs)]


def _pulled_text(bodies: list, N: np.ndarray, u: np.ndarray, Mf: np.ndarray,
                 pairs: list) -> str:
    """The sentence of :func:`pulled_off`: the bodies the unbalanced load ``u``
    (on the modes) moves, their free modes, the pairs that touch them and the
    load's resultant on them."""
    names, parts = [], []
    for bd, col in zip(bodies, _columns(bodies)):
        if np.linalg.norm(u[col]) <= 1e-6 * np.linalg.norm(u):
            continue
        names.append(bd.item.name)
        on = [p.name for p in pairs if bd.item in (p.slave.body, p.master.body)]
        held = f"contact {', '.join(map(repr, on))}" if on else "no contact"
        n_t = np.shape(bd.item.X)[0] if bd.n_modes > 1 else 1   # its translations
        force = ", ".join(f"{v:.3g}" for v in Mf[col][:n_t])
        parts.append(f"body {bd.item.name!r}: its {_describe(bd, N[col])} held "
                     f"by {held} alone, and the load on it (resultant ({force}) at this load "
                     f"factor) pulls it away from the master")
    return ("; ".join(parts) + ": no compressive contact force can balance that load, so the "
            "contact opens entirely and nothing holds the "
            + ("body" if len(names) == 1 else "bodies")
            + " (frictionless contact only pushes); support it (Dirichlet data, or a spring "
              "to ground), or reverse the load so that it presses the body onto the master")
