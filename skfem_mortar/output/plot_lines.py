"""Line plots (matplotlib, off-screen): the contact pressure along the interface
per method (with a friction run's tangential traction), and the Newton
convergence per load step.
"""
from __future__ import annotations

import os
import textwrap
from pathlib import Path
from typing import Sequence

import numpy as np

from .plot_common import PRESSURE_WORDS, TANGENTIAL_WORDS, _save

__all__ = ["plot_pressure", "pressure_figure", "plot_newton"]

def pressure_figure(curves: Sequence[dict],
                    title: str = "contact pressure along the interface"):
    """The figure of :func:`plot_pressure` (not saved).

    One panel per method: the pressure against position (solid lines, the left
    axis, starting at 0); where a curve has ``tangential_traction`` (a friction
    run), that panel gets a second axis on the right with the tangential
    traction, dashed, in the colour of the curve's pressure (lines with gid
    ``"tangential traction"``, the axis labelled :data:`TANGENTIAL_WORDS`).  A
    frictionless panel has no second axis.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods = list(dict.fromkeys(c["method"] for c in curves))
    fig, axes = plt.subplots(1, len(methods), figsize=(5.5 * len(methods), 4.2),
                             sharey=True, squeeze=False)
    for ax, m in zip(axes[0], methods):
        mine = [c for c in curves if c["method"] == m]
        twin = ax.twinx() if any(c.get("tangential_traction") is not None for c in mine) \
            else None
        for c in mine:
            order = np.argsort(c["x"])
            x = np.asarray(c["x"])[order]
            prof = c.get("profile")
            if prof is None:
                (ln,) = ax.plot(x, np.asarray(c["pressure"])[order], ".-", label=c["label"])
            else:
                (ln,) = ax.plot(prof["x"], prof["pressure"], "-", label=c["label"])
                ax.plot(x, np.asarray(c["pressure"])[order], ".", color=ln.get_color())
            ln.set_gid("pressure")
            if twin is not None and c.get("tangential_traction") is not None:
                (lt,) = twin.plot(x, np.asarray(c["tangential_traction"], dtype=float)[order],
                                  "--", color=ln.get_color(), lw=1.0)
                lt.set_gid("tangential traction")
        ax.set_title(m)
        ax.set_xlabel("x (current position of the slave node)")
        ax.grid(alpha=0.3)
        if twin is not None:
            twin.set_ylabel(textwrap.fill(TANGENTIAL_WORDS, 45), fontsize=9)
            twin.set_gid("tangential traction axis")
            ax.plot([], [], "--", color="grey", label="tangential traction (right axis)")
        ax.legend(fontsize=8)
    axes[0][0].set_ylim(bottom=0.0)
    axes[0][0].set_ylabel(textwrap.fill(PRESSURE_WORDS, 45), fontsize=9)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_pressure(curves: Sequence[dict], path: str | os.PathLike,
                  title: str = "contact pressure along the interface") -> Path:
    """Contact pressure against position, one panel per method; the pressure
    axis starts at 0 (:func:`pressure_figure`, written as a PNG).

    Parameters
    ----------
    curves : sequence of dict
        Each with ``method``, ``label`` (e.g. the load factor), ``x`` and
        ``pressure`` arrays (the nodes), optionally ``tangential_traction`` (an
        array at the same nodes: a friction run's, drawn dashed on a second axis)
        and ``profile``: a
        :func:`~skfem_mortar.output.contact_output.pressure_profile` dict, drawn as
        the continuous line (for 3-node segments, the quadratic profile) with the
        nodes as markers.
    """
    return _save(pressure_figure(curves, title), path)


def plot_newton(steps: Sequence[dict], path: str | os.PathLike,
                title: str = "Newton convergence per load step") -> Path:
    """Residual norm against iteration, one line per load step (log scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    cmap = plt.get_cmap("viridis")
    for k, s in enumerate(steps):
        r = np.maximum(np.asarray(s["residual_norms"], dtype=float), 1e-300)
        ax.semilogy(np.arange(len(r)), r, "o-", ms=3, color=cmap(k / max(1, len(steps) - 1)),
                    label=f"lf={s['load_factor']:.3g}" if len(steps) <= 10 else None)
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("Newton iteration")
    ax.set_ylabel("residual norm (force)")
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    if len(steps) <= 10:
        ax.legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)
