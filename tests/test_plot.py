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


def _tangential_lines(fig):
    return [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == "tangential traction"]


@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_pressure_plot_gains_the_tangential_traction_with_friction(mu):
    """The demo's pressure curves of a seed run: with friction each curve has its
    tangential traction, drawn dashed on a second, labelled axis; frictionless
    there is neither (the plot as before)."""
    import matplotlib.pyplot as plt

    from skfem_mortar.app.demo import pressure_curves
    from skfem_mortar.output.plot import TANGENTIAL_WORDS, pressure_figure

    _, result, setup = run_scene("seed", {"n_cable": 24, "refine_cushion": 1, "mu": mu},
                                 method="mortar", return_result=True)
    curves = pressure_curves("mortar", result, setup)
    assert curves
    fig = pressure_figure(curves)
    lines = _tangential_lines(fig)
    pressure = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == "pressure"]
    assert len(pressure) == len(curves)
    labels = [ax.get_ylabel().replace("\n", " ") for ax in fig.axes]
    if mu == 0.0:
        assert not lines and len(fig.axes) == 1
        assert all("tangential_traction" not in c for c in curves)
    else:
        assert len(lines) == len(curves) and len(fig.axes) == 2
        assert TANGENTIAL_WORDS in labels
        for ln, c in zip(lines, curves):  # the curve's values, in the order of x
            order = np.argsort(c["x"])
            assert np.array_equal(ln.get_ydata(), np.asarray(c["tangential_traction"])[order])
            assert ln.get_linestyle() == "--"
        # friction acts: the last curve's tangential traction is not zero
        assert np.abs(lines[-1].get_ydata()).max() > 1e-3 * np.max(curves[-1]["pressure"])
    plt.close(fig)
