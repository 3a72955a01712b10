"""Shared by the pictures: the fields and the contact pressure in words, the
numbers on colour keys (:func:`tick_labels`, :func:`colour_ticks`, a field's
value), and the PNG written atomically (:class:`Picture`, the path a notebook
shows inline).

All heavy imports happen inside the functions, so importing this module is cheap.
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

__all__ = ["relative_spread", "colour_ticks", "tick_labels", "CONSTANT_SPREAD", "FIELD_WORDS",
           "PRESSURE_WORDS", "TANGENTIAL_WORDS", "Picture"]

#: a field with relative spread ``(max - min) / max|f|`` below this is drawn in
#: one colour with its value (a frictionless cable's tension, a patch test's
#: pressure): stretching round-off or a 0.01 % variation over a colour map
#: would suggest a variation that is not there
CONSTANT_SPREAD = 1e-3
#: the fields in words, with their unit convention
FIELD_WORDS = {
    "von_mises": "von Mises stress (force/length\u00b2)",
    "tension": "cable tension (force)",
}
PRESSURE_WORDS = ("contact pressure (traction, force/length\u00b2 per unit thickness, "
                  "> 0 compression)")
TANGENTIAL_WORDS = ("tangential traction, dashed (on the slave along its tangent, "
                    "force/length\u00b2 per unit thickness)")


class Picture(type(Path())):  # the concrete Path class: Path itself takes no subclass before 3.12
    """The path of a PNG written here; a notebook shows the picture inline."""

    def _repr_png_(self) -> bytes | None:
        """The PNG's bytes (None, i.e. the text repr, for a path that is none)."""
        return self.read_bytes() if self.suffix.lower() == ".png" and self.is_file() else None


def relative_spread(values: np.ndarray) -> float:
    """``(max f - min f) / max |f|`` over the finite values (0 for none or all zero)."""
    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    if v.size == 0:
        return 0.0
    scale = float(np.abs(v).max())
    return 0.0 if scale == 0.0 else float((v.max() - v.min()) / scale)


def tick_labels(ticks: Sequence[float]) -> list[str]:
    """Labels of ``ticks`` with the fewest digits at which each reads its tick
    (to ``1e-6`` of the smallest tick spacing) and so no two read the same.

    Fixed-point for ``1e-3 <= max|t| < 1e5``, scientific otherwise; the same
    number of decimals on every label; a tick within ``1e-9`` of the span from 0
    reads ``0``.
    """
    t = np.asarray(ticks, dtype=float).ravel()
    if t.size == 0:
        return []
    span = float(t.max() - t.min())
    t = np.where(np.abs(t) <= 1e-9 * span, 0.0, t) + 0.0  # no "-0.00"
    top = float(np.abs(t).max())
    sci = top != 0.0 and not 1e-3 <= top < 1e5
    step = float(np.diff(np.sort(t)).min()) if t.size > 1 else top
    for d in range(0, 17):
        labels = [f"{v:.{d}e}" if sci else f"{v:.{d}f}" for v in t]
        read = np.array([float(x) for x in labels])
        if len(set(labels)) == len(labels) and np.all(np.abs(read - t) <= 1e-6 * step):
            return labels
    return labels


def colour_ticks(lo: float, hi: float, n: int = 5) -> tuple[np.ndarray, list[str]]:
    """At most ``n`` round ticks in ``[lo, hi]`` and their distinct labels.

    Raises
    ------
    ValueError
        Unless ``lo < hi`` are finite and ``n >= 2``.
    """
    from matplotlib.ticker import MaxNLocator

    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise ValueError(f"lo, hi must be finite with lo < hi, got {lo!r}, {hi!r}")
    if n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    t = MaxNLocator(nbins=n - 1, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    slack = 1e-9 * (hi - lo)
    t = t[(t >= lo - slack) & (t <= hi + slack)]
    if t.size < 2:
        t = np.array([lo, hi])
    return t, tick_labels(t)


def _flat(values) -> np.ndarray:
    """One array of the values of a key (a list of per-block arrays or one array)."""
    if isinstance(values, list):
        return np.concatenate([np.ravel(v) for v in values]) if values else np.zeros(0)
    return np.ravel(values)


def _titled(name: str, words: str) -> str:
    """``name: words``, or ``words`` alone where they already say the name."""
    return words if not name or name.lower() in words.lower() else f"{name}: {words}"


def _value(v: float) -> str:
    """A field's value in 4 significant digits (what a spread below 1e-3 can
    tell), fixed-point for ``1e-3 <= |v| < 1e5``."""
    if v != 0.0 and 1e-3 <= abs(v) < 1e5:
        return np.format_float_positional(v, precision=4, unique=False, fractional=False,
                                          trim="k").rstrip(".")  # "16.10": its 4 digits
    return f"{v:.4g}"


def _save(fig, path) -> Path:
    from .io import atomic_path

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return Picture(path)
