"""Scene ``tied3d``: a 3D cantilever meshed as two non-matching parts glued by a
``TiePair``, against the one-piece beam (issue 38).

The beam of ``cantilever3d`` cut across at ``X = L/2`` or along at ``Z = h/2``
(meeting the clamped face: the slave nodes there are clamped, so the tie merges them,
:class:`~skfem_mortar.contact.tie.TiePair`), tet1 or hex1 parts, standard or dual
multipliers (``multipliers``), or the one-piece beam (``parts=one``)
(:mod:`~skfem_mortar.scenes._tied3d`: the parts, the one-piece reference, the
readings).  Metrics: ``tip_deflection`` against the one-piece beam (``_exact``,
``_error``: the two meshes' discretization difference) and Timoshenko's (``_beam``),
``interface_force`` against ``P`` (across), ``force_balance`` (the two sides' tie
forces over ``P``), ``traction_error`` (the multipliers' L2 error against the
one-piece beam's interface traction), ``oscillation`` (the multipliers' largest
departure from the mean of their neighbours over the largest multiplier), and the same
two of the tie's nodal forces over the tributary areas (``force_traction_error``,
``force_oscillation``, :func:`tie_readings`).

Standard multipliers on tri3 faces read rougher than dual ones (tet1, across: their
L2 error 2.4 to 3x, their oscillation 2.5x the dual's) without locking: their
nodal forces ``D^T lam`` are as close to the reference as the dual multipliers, and
the nodal values ``lam = D^-1 f`` carry the forces' roughness amplified by the
consistent mass ``D``, whose eigenvalues over the lumped areas span ``[1/4, 1]`` on
linear triangles (a checkerboard comes out up to 4 times larger).  Both fall with
``h`` (``tests/test_tied3d.py``, ``benchmarks/series3d.py``).
"""
from __future__ import annotations

import numpy as np

from ..contact.mortar_support import tributary_weights
from ..contact.segmentation import surface_cell
from ..contact.surfaces import ContactSurface
from ..contact.tie import TiePair
from ..core.model import Model
from . import Scene, Setup
from ._tied3d import (PARAMS, build_bodies, cut_plane, cut_traction, derived, estimate_dofs,
                      one_piece, oscillation, tied_metrics, tip_deflection, traction_error)

__all__ = ["SCENE", "build"]


def _reference(params: dict, n_steps: int) -> tuple[float, tuple]:
    """The one-piece beam, solved in ``n_steps``: its tip deflection and its traction on
    the interface plane (:func:`~skfem_mortar.scenes._tied3d.cut_traction`)."""
    from ..solver.stepping import solve  # the scenes build, the solver solves

    parts = one_piece(params)
    ref = solve(Model(parts.items, geometry="3d"), n_steps=n_steps)
    return (tip_deflection(parts.bodies, ref.z),
            cut_traction(parts.bodies[0], ref.z, *cut_plane(params)))


def tie_readings(tie: TiePair, z: np.ndarray, cut: tuple, axis: int, P: float) -> dict:
    """``traction_error``, ``oscillation``, ``force_balance`` and ``n_tied`` of ``tie``
    at ``z`` against the one-piece beam's ``cut``
    (:func:`~skfem_mortar.scenes._tied3d.cut_traction`), the oscillation of the
    one-piece traction itself (``oscillation_exact``: what the elements' own stresses
    give), and the same two readings of the tie's nodal forces on the slave read as
    tractions, ``f_A / w_A`` with ``f = D^T lam`` and ``w_A = int N_A dA``
    (``force_traction_error``, ``force_oscillation``: the lumped reading the one-piece
    traction is, the same for either space; for dual multipliers ``D`` is diagonal with
    ``D_AA = w_A``, so it equals the multipliers' own)."""
    X_ref, t_ref, conn_ref, cell_ref = cut
    s = tie.slave
    cell = surface_cell(s)
    lam = tie.traction(z)
    weight = tributary_weights(s.X, s.segments, cell, 2) * tie.tied
    fs, fm = tie.forces(z)
    lumped = fs / np.where(weight > 0.0, weight, 1.0)
    return {"traction_error": traction_error(s.X, lam, weight, X_ref, t_ref, axis),
            "oscillation": oscillation(lam, s.segments, cell, tie.tied),
            "force_traction_error": traction_error(s.X, lumped, weight, X_ref, t_ref, axis),
            "force_oscillation": oscillation(lumped, s.segments, cell, tie.tied),
            "oscillation_exact": oscillation(t_ref, conn_ref, cell_ref,
                                             np.ones(t_ref.shape[1], dtype=bool)),
            "force_balance": float(np.abs(fs.sum(axis=1) + fm.sum(axis=1)).max() / P),
            "n_tied": int(tie.tied.sum())}


def build(params: dict, method: str | None = None) -> Setup:
    """The parts and the tie (or the one-piece beam); the readings of
    :func:`~skfem_mortar.scenes._tied3d.tied_metrics` and :func:`tie_readings`."""
    parts = build_bodies(params)
    tie = None
    if parts.slave is not None:
        tie = TiePair(ContactSurface.from_solid(*parts.slave, name="slave_interface"),
                      ContactSurface.from_solid(*parts.master, name="master_interface"),
                      dual=params["multipliers"] == "dual", name="tie")
    model = Model(parts.items + ([tie] if tie else []), geometry="3d")

    def metrics(result) -> dict:
        z = result.z
        w = tip_deflection(parts.bodies, z)
        if tie is None:
            return tied_metrics(params, w, w, None, parts.tip_force)
        ref, cut = _reference(params, max(1, len(result.steps)))
        out = tied_metrics(params, w, ref, tie.forces(z)[0].sum(axis=1), parts.tip_force)
        out.update(tie_readings(tie, z, cut, cut_plane(params)[0], parts.tip_force))
        return out

    return Setup(model=model, metrics=metrics,
                 outputs=[*parts.bodies, *(tie.outputs() if tie else [])])


SCENE = Scene(
    name="tied3d",
    summary="A 3D cantilever meshed as two non-matching parts glued by mortar tying "
            "(across the beam or along it, meeting the clamp), against the one-piece beam.",
    params=PARAMS,
    build=build,
    default_steps=1,
    estimate_dofs=estimate_dofs,
    sizes=("n_a", "n_b", "refine", "length"),
    derived=derived,
    one_step=lambda values, method: values["kinematics"] == "small",
    one_step_text="at small strain",
)
