"""Shared set-up of the tests: Hertz's half cylinder on a rigid plane.

The scene's geometry and load (R = 8, P = 3.2032, E = 200), a cylinder body
made by the caller (its element is what the tests compare), pressed in 2 load
steps onto a ``RigidPlane`` of one long segment.
"""
import numpy as np

from skfem_mortar import ContactPair, Dirichlet, Model
from skfem_mortar.scenes.hertz import FINE_ZONE, graded_quarter_disk, hertz_exact
from skfem_mortar.solver.stepping import solve
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane
from skfem_mortar.loads.traction import Traction

R, P, E = 8.0, 3.2032, 200.0


def exact(nu):
    """Hertz's answer (rigid base) for the cylinder's Poisson ratio ``nu``."""
    return hertz_exact(R, P, E, nu, None, 0.3)


def graded_mesh(nu, refine=-2, factor=1.0):
    """The scene's graded quarter disk at element size ``factor (a/30) 2^-refine``."""
    a = exact(nu)["half_width"]
    return graded_quarter_disk(R, factor * a / 30.0 * 2.0 ** (-refine), FINE_ZONE * a)


def press(cyl, method, steps=2):
    """Load ``cyl`` (tags ``arc``, ``top``, ``axis``) onto the plane; returns
    ``(pair, result, pressures sorted from the axis outward)``."""
    pair = ContactPair(ContactSurface.from_solid(cyl, "arc"),
                       RigidPlane((0, 0), (0, 1), length=4 * R), method)
    model = Model([cyl, Traction(cyl, "top", (0.0, -P / (2 * R))),
                   Dirichlet(cyl, cyl.dofs_on("axis", "x"), 0.0), pair])
    res = solve(model, steps)
    d = pair.contact_data(res.z)
    return pair, res, d["pressure"][np.argsort(d["x"])]
