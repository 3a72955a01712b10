"""
Add contact to a scikit-fem model: a cable inflated into a cushion
==================================================================

The cushion is an ordinary scikit-fem mesh; skfem-mortar adds the cable, the
follower pressure, and mortar contact between the cable and the cushion's
bottom face. Run it as a script, or cell by cell in Jupyter / VS Code.
"""

# %%
import numpy as np
import skfem

from skfem_mortar import (Cable, ContactPair, Dirichlet, FollowerPressure, Model,
                          NeoHooke, Solid, solve)
from skfem_mortar.contact.surfaces import ContactSurface

# %%
# The cushion: a scikit-fem mesh with named boundaries.
mesh = (skfem.MeshTri.init_tensor(np.linspace(-1.5, 1.5, 49), np.linspace(0.65, 1.4, 13))
        .with_boundaries({"bottom": lambda x: np.isclose(x[1], 0.65),
                          "top": lambda x: np.isclose(x[1], 1.4)}))
cushion = Solid(mesh, NeoHooke(E=20.0, nu=0.3), element="tri1", name="cushion")

# %%
# The cable: pinned at (-1, 0) and (1, 0), stress-free arc of length 2.4.
cable = Cable.between((-1.0, 0.0), (1.0, 0.0), 2.4, 48, bulge="left", EA=50.0, law="svk",
                      name="cable")
pressure = FollowerPressure(cable, 20.0, side="left", name="pressure")

# %%
# Contact: the cable's upper side (slave) against the cushion's bottom (master),
# with the default method, dual mortar (``method="mortar"`` or ``"nts"`` for the others).
pair = ContactPair(ContactSurface.from_cable(cable, side="left"),
                   ContactSurface.from_solid(cushion, "bottom"), name="contact")
model = Model([cable, cushion, pressure, pair,
               Dirichlet(cable, cable.support_dofs(), name="supports"),
               Dirichlet(cushion, cushion.dofs_on("top"), name="clamp")])

# %%
# Solve in 10 load steps (block Newton over displacements and multipliers).
result = solve(model, n_steps=10)
z = result.z
contact = pair.contact_data(z)
print("Newton iterations per step:", [s.newton_iterations for s in result.steps])
print("active nodes:", int(pair.active.sum()),
      " peak pressure: %.3f" % contact["pressure"].max(),
      " contact force:", np.round(pair.total_force(z), 4))

# %%
# The contact forces on both sides balance (action and reaction).
f_cable, f_cushion = pair.forces(z)
print("action + reaction:", f_cable.sum(axis=1) + f_cushion.sum(axis=1))

# %%
# Save the result series (ParaView: open cable.pvd, cushion.pvd, contact.pvd) and a picture.
import tempfile  # noqa: E402

out = tempfile.mkdtemp(prefix="cable_cushion_")
result.save(out)
picture = result.plot(f"{out}/figure.png", title="cable against cushion")
print("written to", out)
