"""The slave surface of a contact pair as an output series: pressure and gap per node."""
from __future__ import annotations

import numpy as np

__all__ = ["ContactOutput", "output_gap"]


def output_gap(data: dict) -> np.ndarray:
    """The gap column of the output files: the gap where the node faces a master
    (``has_master``), else its distance to the master surface (finite)."""
    return np.where(data["has_master"], data["gap"], data["distance"]).astype(float)


class ContactOutput:  # an Output (skfem_mortar.core.model) for the output layer
    """Adapter that lets a :class:`~skfem_mortar.contact.pair.ContactPair` be written
    like a body: a polyline of the slave surface with point data

    - ``displacement`` of the slave nodes,
    - ``pressure``: the multiplier as a traction (> 0 compression),
    - ``gap``: the normal gap as a length (> 0 open); where the node faces no
      master segment, its distance to the master surface (a length, as in
      contact.csv: never a NaN, never a 0 that reads as touching unless the
      node sits on the master's end), and
    - ``has_master``: 1 where the node faces a master segment, else 0.
    """

    def __init__(self, pair, name: str | None = None):
        self.pair = pair
        self.name = name or pair.name

    def output_mesh(self):
        s = self.pair.slave
        return s.X.T.copy(), [("line", np.asarray(s.segments))]

    def output_data(self, z: np.ndarray):
        s = self.pair.slave
        data = self.pair.contact_data(z)
        if "node" in data:  # rows along the surface: back to the surface's node order
            back = np.argsort(data["node"])
            data = {k: np.asarray(v)[back] for k, v in data.items()}
        return ({"displacement": (s.x(z) - s.X).T.copy(),
                 "pressure": np.asarray(data["pressure"], dtype=float),
                 "gap": output_gap(data),
                 "has_master": np.asarray(data["has_master"], dtype=float)}, {})
