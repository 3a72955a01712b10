"""Preflight, methods: a :class:`PreflightWarning` where a method is known not to work
for the configuration (NTS with a slave coarser than the master, NTS on non-matching
deformable meshes: off the patch test) or two bodies in contact lie beyond the
measured stiffness ratio, before the solve, naming the fix (:func:`warn_methods`)."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..core.errors import warn_at_user
from .diagnosis import nts_patch_text, stiffness_ratio_text
from .preflight_pairs import contact_pairs

__all__ = ["PreflightWarning", "warn_methods"]


class PreflightWarning(UserWarning):
    """A configuration a method is known to handle badly (the solve still runs)."""


def warn_methods(model: Any, z: np.ndarray | None = None, load_factor: float = 0.0) -> None:
    """A :class:`PreflightWarning` for every NTS pair with a known failure cause
    (:func:`skfem_mortar.contact.nts.failure_hints`: a slave coarser than the master
    where they meet, nearly coincident slave nodes) or whose deformable meshes
    do not match where they meet (:func:`.diagnosis.nts_patch_text`: off the
    patch test), and for every pair of bodies stiffer one than the other beyond
    the measured range (:func:`.diagnosis.stiffness_ratio_text`), naming the fix,
    before the solve rather than after a cascade of step cuts."""
    for pair in contact_pairs(model):
        if pair.method == "nts":
            hints = [pair.discretization.failure_hint(),  # nts.failure_hints (geometry only)
                     nts_patch_text(pair)]
            if any(hints):
                warn_at_user("; ".join(h for h in hints if h), PreflightWarning)
    if z is not None:
        for text in stiffness_ratio_text(model, z, load_factor):
            warn_at_user(text, PreflightWarning)
