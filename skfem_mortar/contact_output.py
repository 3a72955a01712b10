"""The slave surface of a contact pair as an output series: pressure and gap per node."""
from __future__ import annotations

import numpy as np

__all__ = ["ContactOutput"]


class ContactOutput:
    """Adapter that lets a :class:`~skfem_mortar.contact.ContactPair` be written
    like a body: a polyline of the slave surface with point data

    - ``displacement`` of the slave nodes,
    - ``pressure``: the multiplier as a traction (> 0 compression),
    - ``gap``: the normal gap as a length (> 0 open), 0 where the node faces no
      master segment, and
    - ``has_master``: 1 where the node faces a master segment, else 0 (so the
      files never carry a NaN for an undefined gap).
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
        gap = np.asarray(data["gap"], dtype=float)
        has = np.isfinite(gap)
        return ({"displacement": (s.x(z) - s.X).T.copy(),
                 "pressure": np.asarray(data["pressure"], dtype=float),
                 "gap": np.where(has, gap, 0.0), "has_master": has.astype(float)}, {})
