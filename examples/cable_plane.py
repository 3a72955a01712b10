"""
A cable pressed against a rigid plane
=====================================

A pinned cable inflated by a follower pressure meets the rigid plane y = d.
Frictionless contact keeps the tension constant, the cable lies flat on the
plane over ``|x| < c``, and the contact force is 2 c p. We build the model from
its parts and compare NTS and mortar with the analytic answer (reference
problem 4, ``docs/reference_problems.rst``): n = 200 cable elements, or 50
when ``SKFEM_MORTAR_QUICK=1`` (the documentation's gallery).
"""

# %%
import os

import numpy as np

from skfem_mortar import Cable, ContactPair, Dirichlet, FollowerPressure, Model, solve
from skfem_mortar.scenes.cable_flat import flat_exact
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane

a, L0, EA, p, d = 1.0, 2.0, 100.0, 20.0, 0.5
n = 50 if os.environ.get("SKFEM_MORTAR_QUICK") == "1" else 200
exact = flat_exact(a, L0, EA, p, d, "linear")
print("exact: contact force %.6f, tension %.6f" % (exact["contact_force"], exact["tension"]))


# %%
def cable_on_plane(method: str, n: int = 200):
    """Cable of n elements against the plane y = d, solved in 8 load steps."""
    cable = Cable.between((-a, 0.0), (a, 0.0), L0, n, bulge="left", EA=EA, law="linear",
                          name="cable", tension_floor=0.1 * p * a)
    plane = RigidPlane((0.0, d), (0.0, -1.0), length=100.0, name="plane")
    pair = ContactPair(ContactSurface.from_cable(cable, side="left"), plane, method,
                       name="contact")
    model = Model([cable, pair, FollowerPressure(cable, p, side="left", name="pressure"),
                   Dirichlet(cable, cable.support_dofs(), name="supports")])
    result = solve(model, n_steps=8)
    force = np.linalg.norm(pair.total_force(result.z))
    tension = cable.tension(result.z).mean()
    return force, tension


results = {m: cable_on_plane(m, n) for m in ("nts", "mortar", "mortar-dual")}
for m, (force, tension) in results.items():
    print(f"{m:12s} contact force {force:.6f} (error {abs(force / exact['contact_force'] - 1):.1e})"
          f"  tension {tension:.6f} (error {abs(tension / exact['tension'] - 1):.1e})")
