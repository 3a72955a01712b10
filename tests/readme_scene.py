"""The README's model (a cable pressed by a follower pressure into a cushion),
coarse, as a user writes it: shared by the tests of shared bodies and of
Dirichlet's nodes."""
import numpy as np
import skfem

from skfem_mortar import Cable, ContactPair, Dirichlet, FollowerPressure, NeoHooke, Solid
from skfem_mortar.contact.surfaces import ContactSurface


def cushion(element="tri1", nx=13, ny=4):
    """The cushion (``nx`` x ``ny`` vertices) with boundaries bottom, top and left."""
    mesh = (skfem.MeshTri.init_tensor(np.linspace(-1.5, 1.5, nx), np.linspace(0.65, 1.4, ny))
            .with_boundaries({"bottom": lambda x: np.isclose(x[1], 0.65),
                              "top": lambda x: np.isclose(x[1], 1.4),
                              "left": lambda x: np.isclose(x[0], -1.5)}))
    return Solid(mesh, NeoHooke(E=20.0, nu=0.3), element=element, name="cushion")


def cable():
    return Cable.between((-1.0, 0.0), (1.0, 0.0), 2.4, 12, EA=50.0, law="svk", name="cable")


def items(cable, cushion, method, clamp=None):
    """The pair, the pressure and the supports, ``clamp(cushion)`` (default: its
    top dofs) holding the cushion; returns ``(items, pair)``."""
    pair = ContactPair(ContactSurface.from_cable(cable, side="left"),
                       ContactSurface.from_solid(cushion, "bottom"), method=method,
                       name="contact")
    held = (clamp or (lambda b: Dirichlet(b, b.dofs_on("top"), name="clamp")))(cushion)
    return [pair, FollowerPressure(cable, 20.0, side="left", name="pressure"),
            Dirichlet(cable, cable.support_dofs(), name="supports"), held], pair
