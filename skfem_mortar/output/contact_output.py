"""The slave surface of a contact pair as an output series: pressure and gap per node."""
from __future__ import annotations

import numpy as np

__all__ = ["ContactOutput", "output_gap", "pressure_profile", "STATUS_CODES"]

#: the friction statuses of ``contact_data["status"]`` as the VTU series writes
#: them (the codes of :mod:`skfem_mortar.contact.friction`, which this layer
#: does not import)
STATUS_CODES = {"open": 0, "stick": 1, "slip": 2}


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
    - ``has_master``: 1 where the node faces a master segment, else 0;
    - with friction also ``tangential_traction`` (along the node's tangent, on
      the slave), ``slip`` (within the last step, a length) and ``status``
      (0 open, 1 stick, 2 slip).
    """

    def __init__(self, pair, name: str | None = None):
        self.pair = pair
        self.name = name or pair.name

    def output_mesh(self):
        s = self.pair.slave
        # the surface's cell type names its VTK cells (its own method: this layer
        # does not import contact)
        return s.X.T.copy(), s.output_cells()

    def output_data(self, z: np.ndarray):
        s = self.pair.slave
        data = self.pair.contact_data(z)
        if "node" in data:  # rows along the surface: back to the surface's node order
            back = np.argsort(data["node"])
            data = {k: np.asarray(v)[back] for k, v in data.items()}
        point = {"displacement": (s.x(z) - s.X).T.copy(),
                 "pressure": np.asarray(data["pressure"], dtype=float),
                 "gap": output_gap(data),
                 "has_master": np.asarray(data["has_master"], dtype=float)}
        if "tangential_traction" in data:  # a pair with friction
            point.update({
                "tangential_traction": np.asarray(data["tangential_traction"], dtype=float),
                "slip": np.asarray(data["slip"], dtype=float),
                "status": np.array([STATUS_CODES[str(v)] for v in data["status"]],
                                   dtype=float)})
        return point, {}


def pressure_profile(pair, z: np.ndarray, n_per_segment: int = 8) -> dict[str, np.ndarray]:
    """The contact pressure as a continuous profile along the current slave surface.

    On each slave cell ``p(xi) = sum_A N_A(xi) p_A`` with the cell's own shape
    functions from the cell table (line2: linear; line3: quadratic, so the profile
    follows the curved trace) and the nodal pressures ``p_A`` of :meth:`ContactPair.contact_data`
    -- for standard mortar multipliers exactly the discrete traction
    ``lam_h = sum_A N_A lam_A``, for NTS and dual multipliers the interpolant of the
    nodal values.  Sampled at ``n_per_segment`` equal steps of ``xi`` per segment.

    Returns
    -------
    dict with ``s`` (arc length along the slave, chain order, from its first node),
    ``x``, ``y`` (current positions) and ``pressure``, each ``(n_seg n_per_segment + 1,)``.
    """
    n_per_segment = int(n_per_segment)
    if n_per_segment < 1:
        raise ValueError(f"n_per_segment must be an integer >= 1, got {n_per_segment}")
    s = pair.slave
    data = pair.contact_data(z)
    p = np.zeros(s.n_nodes)
    p[data["node"]] = data["pressure"]
    x = s.x(z)
    seg = np.asarray(s.segments)
    xi = np.linspace(-1.0, 1.0, n_per_segment + 1)[None, :-1]
    pts = s.interpolate(x, xi)                                      # (2, n_seg, k)
    ps = s.interpolate(p[None, :], xi)[0]                           # (n_seg, k)
    last = seg[-1, s.cell.corners[1]]
    X = np.hstack([pts.reshape(2, -1), x[:, [last]]])
    P = np.r_[ps.ravel(), p[last]]
    d = np.hypot(*np.diff(X, axis=1))
    return {"s": np.r_[0.0, np.cumsum(d)], "x": X[0], "y": X[1], "pressure": P}
