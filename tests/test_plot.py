"""Pictures are drawn off-screen and show something."""
import numpy as np
import pytest

from skfem_mortar.output.plot import figure, plot_newton, plot_pressure
from skfem_mortar.app.runner import run_scene


def _png_pixels(path):
    import matplotlib.image as mpimg

    return mpimg.imread(str(path))


def test_figure_of_a_deformed_block(tmp_path):
    summary, result, setup = run_scene("block", {"refine": 2}, steps=2, return_result=True)
    path = figure(setup, result, tmp_path / "figure.png", title="block")
    img = _png_pixels(path)
    assert img.shape[0] > 100 and img.shape[1] > 200
    # both halves hold drawn pixels (not a blank white canvas)
    half = img.shape[1] // 2
    for part in (img[:, :half, :3], img[:, half:, :3]):
        assert (part.min(axis=2) < 0.8).mean() > 0.02


def test_line_plots(tmp_path):
    x = np.linspace(-1, 1, 11)
    curves = [{"method": m, "label": f"lf={lf}", "x": x, "pressure": lf * (1 - x**2)}
              for m in ("nts", "mortar") for lf in (0.5, 1.0)]
    assert plot_pressure(curves, tmp_path / "pressure.png").stat().st_size > 1000
    steps = [{"load_factor": 1.0, "residual_norms": [1.0, 1e-3, 1e-9, 0.0]}]
    assert plot_newton(steps, tmp_path / "newton.png").stat().st_size > 1000
