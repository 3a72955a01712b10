"""
Hertz line contact
==================

A cylinder of radius 8 pressed by a line load onto a rigid plane; compare the
computed peak pressure and contact half-width with Hertz' formulas (reference
problem 6, ``docs/reference_problems.rst``).
"""

# %%
from skfem_mortar import run_scene

hertz = {m: run_scene("hertz", {"base": "rigid"}, method=m) for m in ("nts", "mortar-dual")}
for m, s in hertz.items():
    met = s["metrics"]
    print(f"{m:12s} peak {met['peak_pressure']:.4f} (exact {met['peak_pressure_exact']:.4f},"
          f" error {met['peak_pressure_error']:.1%}), half-width error {met['half_width_error']:.1%}")
