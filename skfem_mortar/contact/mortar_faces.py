"""What :class:`~skfem_mortar.contact.mortar_method.Mortar` needs between faces (tri3,
quad4: the contact surfaces of 3D bodies): which cells it takes, its options there,
and the integration points it hands the one kernel.

Between faces the kernel (:func:`~skfem_mortar.contact.mortar_kernel.evaluate`)
integrates over the 3D segmentation's cells
(:func:`~skfem_mortar.contact.segmentation3d.segment_faces`: auxiliary plane,
clipping, fan cells) at the points of
:class:`~skfem_mortar.contact.points3d.FacePoints`: a triangle rule of degree
``n_gauss`` on each cell (default :data:`~skfem_mortar.contact.points3d.N_GAUSS`, 5),
on the candidate pairs of the method's own search (so the reservation holds what
the kernel integrates).  The segmentation is rebuilt at every evaluation (policy
``"iteration"``); a frozen one (``"step"``) is not offered on faces.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .cells import CellType
from .discretization import OptionTable
from .points3d import N_GAUSS, FacePoints
from .segmentation3d import FACES, segment_faces

__all__ = ["FACE_OPTIONS", "takes_faces", "face_points", "N_GAUSS_FACES"]

#: the highest triangle rule degree on an integration cell (the rule of degree ``q`` has
#: ``ceil((q + 1) / 2)^2`` points: 100 at 20, far past any exact integrand here)
N_GAUSS_FACES = 20

#: the options of :class:`~.mortar_method.Mortar` between faces
FACE_OPTIONS: OptionTable = {
    "margin": (lambda v: v is None or (np.isfinite(v) and v > 0), "a finite number > 0"),
    "n_gauss": (lambda v: isinstance(v, (int, np.integer)) and 1 <= v <= N_GAUSS_FACES,
                f"an integer in [1, {N_GAUSS_FACES}] (the degree of the triangle rule on "
                f"each integration cell between faces; default {N_GAUSS})")}


def takes_faces(cells: tuple[CellType, CellType], segmenter: Any, method: str, master: Any,
                segmentation: str) -> bool:
    """Whether the cells are faces, segmented by the 3D segmentation (True) or lines (False).

    Raises
    ------
    ValueError
        Faces other than tri3/quad4 (quadratic faces), a rigid master with an exact
        gap (:class:`~skfem_mortar.contact.rigid3d.RigidSurface3D`: its faces only
        draw it) or ``segmentation="step"`` on faces; each names the alternative.
    """
    if segmenter is not segment_faces:
        return False
    for what, c in zip(("slave", "master"), cells):
        if c.name not in FACES:
            raise ValueError(f"{what} cells must be one of {list(FACES)} for {method} between "
                             f"faces, got {c.name} (quadratic faces are not offered yet: use "
                             f"tet1 or hex1 bodies)")
    if callable(getattr(master, "exact_gap", None)):
        raise ValueError(f"{method} against a rigid {type(master).__name__} (an exact "
                         f"surface) is not offered; use method='nts', or give the rigid "
                         f"master as a ContactSurface of its faces")
    if segmentation != "iteration":
        raise ValueError(f"segmentation={segmentation!r} (frozen cells) is not offered for "
                         f"{method} between faces; use segmentation='iteration'")
    return True


def face_points(cells: tuple[CellType, CellType], options: dict,
                pairs: tuple[np.ndarray, np.ndarray]) -> FacePoints:
    """The kernel's points between faces on the candidate ``pairs``, with the rule of
    ``options["n_gauss"]`` (default :data:`~skfem_mortar.contact.points3d.N_GAUSS`)."""
    return FacePoints(cells, int(options.get("n_gauss", N_GAUSS)), pairs=pairs, frozen=False)
