"""
The paper's scene with the scene API
====================================

``run_scene`` builds the scene ``seed`` (cable inflated into a cushion), solves it
and returns the summary that ``skfem-mortar run seed --json`` prints.
"""

# %%
from skfem_mortar import run_scene

summaries = {m: run_scene("seed", {"n_cable": 24, "refine_cushion": 1}, method=m)
             for m in ("nts", "mortar", "mortar-dual")}
for m, s in summaries.items():
    met = s["metrics"]
    print(f"{m:12s} {s['wall_time_s']:.2f} s  iterations {[x['newton_iterations'] for x in s['steps']]}"
          f"  contact force {met['contact_force']:.4f}  length {met['contact_length']:.3f}"
          f"  equilibrium errors {met['cable_equilibrium_error']:.1e}, "
          f"{met['cushion_equilibrium_error']:.1e}")
