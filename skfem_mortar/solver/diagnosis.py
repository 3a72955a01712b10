"""The physical cause of a load step given up, where it can be known (issue 32).

:func:`failure_causes` is asked by :func:`~skfem_mortar.solver.stepping.solve`
when a step fails even at the smallest increment; its sentences join the
items' :meth:`~skfem_mortar.core.item.Item.failure_hint` in the
:class:`~skfem_mortar.core.errors.ConvergenceError`.  Each reads the last
converged state and the load the failed step aimed at, never the failed
iterate (a diverged Newton iterate has been thrown 1e10 away: its gaps and
stretches say nothing):

* a body held only by contact that the load pulls off the master
  (:func:`skfem_mortar.contact.diagnosis.pulled_off`);
* a cable the load puts in compression (:func:`compressed_cables`);
* two bodies in contact beyond the measured stiffness ratio
  (:func:`skfem_mortar.contact.diagnosis.stiffness_ratio_text`).
"""
from __future__ import annotations

import logging
from typing import Any

import numpy as np

from ..bodies.cable import Cable
from ..contact import diagnosis as contact_diagnosis

__all__ = ["failure_causes", "compressed_cables", "round_off_above_load", "COMPRESSED",
           "STATICS", "FLOOR_CHECK"]

log = logging.getLogger(__name__)

#: an axial force below ``-COMPRESSED`` times the largest one counts as compression
#: (the forces of :func:`compressed_cables` are exact to round-off where the
#: statics is determinate; 1e-6 is far above that and far below a real compression)
COMPRESSED = 1e-6
#: the cable's axial forces balance the load when the least-squares residual of
#: the statics is below this fraction of the load (else the cable is a
#: mechanism at that geometry and must deform to carry it: nothing is concluded)
STATICS = 1e-6

#: a converged step whose round-off floor (``NewtonReport.floor``) is above this
#: fraction of its force scale has its residual checked against that scale
#: (:func:`round_off_above_load`); below it the accepted residual is at most
#: ``tolerance + floor``, far below the scale, and nothing is assembled
FLOOR_CHECK = 1e-3


def round_off_above_load(model: Any, z: np.ndarray, target: float, report: Any) -> str:
    """Why a step Newton reports converged is still no equilibrium ("" if it is one).

    Newton accepts a row's residual below its round-off floor ``100 eps
    max_j |K_ij| L`` (:func:`~skfem_mortar.solver.newton.round_off_floor`).  A body
    ``1e15`` times stiffer than the other has a floor far above the load: the
    step "converges" with a residual larger than the load itself (measured:
    two blocks at a ratio of 1e15, load 0.01, residual 0.02 to 0.04 on the
    stiff block's rows; the patch scene at 1e15, support reaction 0 instead of
    q).  When the floor exceeds ``FLOOR_CHECK`` of the step's force scale ``S``,
    the residual at ``z`` is assembled and a norm above the force level
    ``max(S, |reactions|)`` is refused (the reactions: a step that adds no load,
    ``S = 0``, still carries the forces of the steps before; a hidden wrong answer
    shows as missing reactions, 0 instead of q in the patch scene)."""
    if not report.floor > FLOOR_CHECK * report.scale:
        return ""
    R, _, _ = model.assemble(z, target, tangent=False)
    held = model.prescribed(target)[0]
    level = max(report.scale, float(np.linalg.norm(R[held])))
    R[held] = 0.0                                           # reactions
    r = float(np.linalg.norm(R))
    if r <= level:
        return ""
    return (f"the step converged only to round-off: its residual {r:.3g} is larger than the "
            f"step's force level {level:.3g} (its load {report.scale:.3g}, the reactions; "
            f"round-off floor {report.floor:.3g}), so the equilibrium is not checked")


def failure_causes(model: Any, z: np.ndarray, load_factor: float, target: float) -> list[str]:
    """The causes that the last converged state ``z`` (at ``load_factor``) and the
    load at ``target`` show, as sentences ([] if none); a cause that cannot
    be computed (an item this module does not know) is skipped, never raised."""
    fixed, _ = model.prescribed(target)
    checks = (lambda: contact_diagnosis.pulled_off(model, z, target, fixed),
              lambda: compressed_cables(model, z, load_factor, target),
              lambda: contact_diagnosis.stiffness_ratio_text(model, z, load_factor))
    out: list[str] = []
    for check in checks:
        try:
            out += check()
        except Exception as exc:  # a diagnosis must never hide the ConvergenceError
            log.debug("failure diagnosis skipped: %r", exc)
    return out


def _statics(cable: Cable, z: np.ndarray, free: np.ndarray) -> np.ndarray:
    """The equilibrium matrix ``A`` (cable free dofs x elements) at ``z``: an axial
    force ``N_e`` (tension positive) gives the internal forces ``-N_e t_e`` at
    its first node and ``+N_e t_e`` at its second (``t_e`` its unit direction)."""
    x = cable.x(z)
    el = np.asarray(cable.elements)
    d = x[:, el[:, 1]] - x[:, el[:, 0]]
    t = d / np.hypot(*d)
    nd = np.asarray(cable.node_dofs)
    A = np.zeros((cable.n_dofs, len(el)))
    e = np.arange(len(el))
    for c in (0, 1):
        np.add.at(A, (nd[c, el[:, 0]] - cable.offset, e), -t[c])
        np.add.at(A, (nd[c, el[:, 1]] - cable.offset, e), t[c])
    return A[free]


def compressed_cables(model: Any, z: np.ndarray, load_factor: float,
                      target: float) -> list[str]:
    """One sentence per cable that the load at ``target`` puts in compression.

    The axial forces ``N`` that balance, at the geometry of ``z``, everything
    the rest of the model puts on the cable's free dofs (loads at ``target``,
    contact and tie forces, springs: the model's residual less the cable's
    own) solve ``A N = f`` (:func:`_statics`) by least squares; where the
    residual is below ``STATICS`` of ``|f|`` (the cable carries the load as it
    stands) the elements with ``N < -COMPRESSED max|N|`` are in compression.
    Elements already shorter than their rest length at ``z`` count too.
    """
    cables = [it for it in model.items if isinstance(it, Cable)]
    if not cables:
        return []
    fixed, _ = model.prescribed(target)
    R, _, _ = model.assemble(z, target, tangent=False)
    out = []
    for cable in cables:
        H = model.thickness if cable.per_thickness else 1.0
        own = cable.assemble(z, target, tangent=False)
        R_c = np.bincount(own.r_index, weights=H * own.r_value, minlength=model.n)
        dofs = np.arange(cable.offset, cable.offset + cable.n_dofs)
        free = ~np.isin(dofs, fixed)
        f = (R_c - R)[dofs[free]]                           # the internal forces needed
        short = int(np.sum(cable.stretch(z) < 1.0 - 1e-12))
        n_comp, rng = 0, ""
        if np.linalg.norm(f) > 0:
            A = _statics(cable, z, free)
            N, *_ = np.linalg.lstsq(A, f, rcond=None)
            if np.linalg.norm(A @ N - f) <= STATICS * np.linalg.norm(f):
                comp = N < -COMPRESSED * np.abs(N).max()
                n_comp = int(comp.sum())
                if n_comp:
                    Nc = N[comp] / H
                    rng = f"axial forces {Nc.min():.3g} to {Nc.max():.3g}"
        if n_comp or short:
            out.append(_compressed_text(cable, n_comp, rng, short))
    return out


def _compressed_text(cable: Cable, n_comp: int, rng: str, short: int) -> str:
    n = len(cable.elements)
    what = []
    if n_comp:
        what.append(f"the load puts {n_comp} of its {n} elements in compression (the {rng} "
                    f"balance it at the last converged state)")
    if short:
        what.append(f"{short} of its {n} elements are shorter than their rest length at the "
                    f"last converged state")
    slack = ", or goes slack with tension_only" if getattr(cable, "tension_only", False) else ""
    return (f"cable {cable.name!r}: {' and '.join(what)}; a cable carries no compression "
            f"(it buckles{slack}): tension it (pull its ends apart, or give it rest lengths "
            f"below the node distances) or load it from the other side (an internal "
            f"pressure on a ring)")
