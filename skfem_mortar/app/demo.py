"""``skfem-mortar demo``: the paper's scene end to end, with its pictures.

Runs ``seed`` with the chosen method (writing the result series, summary.json,
contact.csv), runs it once more with the other family (NTS against mortar) for
the pressure comparison, and draws ``figure.png`` (initial and deformed model),
``pressure.png`` (contact pressure along the interface at several load steps,
side by side; with friction, ``params={"mu": ...}``, the tangential traction
too, dashed on a second axis) and ``newton.png`` (residual against iteration per step).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .runner import run_scene

__all__ = ["run_demo", "pressure_curves"]

#: the pictures the demo adds to the run's files
PICTURES = ("figure.png", "newton.png", "pressure.png")


def pressure_curves(method: str, result, setup, n_curves: int = 4) -> list[dict]:
    """Contact pressure along the interface at up to ``n_curves`` load steps with
    contact, and with friction the tangential traction (``tangential_traction``)."""
    with_contact = [k for k, s in enumerate(result.steps, start=1) if s.n_active > 0]
    if not with_contact:
        return []
    pick = np.unique(np.linspace(0, len(with_contact) - 1, n_curves).round().astype(int))
    curves = []
    for i in pick:
        k = with_contact[i]
        data = setup.contact(result.states[k])
        curve = {"method": method, "label": f"lf={result.load_factors[k]:.2f}",
                 "x": data["x"], "pressure": data["pressure"]}
        if "tangential_traction" in data:  # a friction run (seed with mu > 0)
            curve["tangential_traction"] = data["tangential_traction"]
        curves.append(curve)
    return curves


def run_demo(out: str | Path = "skfem-mortar-demo", method: str = "mortar-dual",
             progress: bool = True, params: dict | None = None,
             replace: bool = False) -> dict:
    """Run the demo and write everything into ``out``; return the summary.

    ``out`` holds one run, as for :func:`~skfem_mortar.app.runner.run_scene`: it is
    locked for the whole demo, and an earlier run's files there are refused
    unless ``replace`` (then they are removed first). The pictures are listed in
    the run's manifest before they are drawn.
    """
    from ..output.outdir import add_to_manifest, output_lock
    from ..output.plot import figure, plot_newton, plot_pressure

    with output_lock(out, "demo") as out:
        summary, result, setup = run_scene("seed", params, method=method, out=out,
                                           progress=progress, replace=replace,
                                           return_result=True)
        add_to_manifest(out, PICTURES)
        figure(setup, result, out / "figure.png",
               title=f"inflated cable against a soft cushion ({method})")
        plot_newton(summary["steps"], out / "newton.png",
                    title=f"seed ({method}): Newton convergence per load step")
        other = "nts" if method != "nts" else "mortar-dual"
        _, result2, setup2 = run_scene("seed", params, method=other, progress=False,
                                       return_result=True)
        curves = pressure_curves(method, result, setup) + pressure_curves(other, result2, setup2)
        if method == "nts":  # keep NTS on the left, mortar on the right
            curves = curves[::-1]
        plot_pressure(sorted(curves, key=lambda c: c["method"] != "nts"), out / "pressure.png")
    return summary
