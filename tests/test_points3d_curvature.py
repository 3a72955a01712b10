"""The back-projection's second derivatives by the implicit function theorem
(contact/points3d.py, ``_curvature``): one Newton step in jet arithmetic plus the
curvature term gives the Hessians of a second full jet step.

A further full jet step (``JET_STEPS = 3``) changes the gradients and the Hessians
(symmetrized: :meth:`~skfem_mortar.contact.jets.Jet.hessian`; the stored ``h`` is
unsymmetrized and the two ways place their outer products differently) by round-off
only, 1e-13 against entries of order 1 to 4 (measured 2e-15); without the curvature
term (``JET_STEPS = 1``) the Hessians are off by order 1 (measured 0.8 to 4), so the
comparison can fail.
"""
import numpy as np
import pytest

from skfem_mortar.contact import points3d
from skfem_mortar.contact.points3d import integration_points
from skfem_mortar.contact.segmentation3d import segment_faces
from test_points3d import _pair
from test_segmentation3d import PAIRINGS


@pytest.mark.parametrize("case", ["warped", "sliding", "vertex on edge"])
@pytest.mark.parametrize("cells", PAIRINGS)
def test_one_step_and_the_curvature_are_a_second_step(monkeypatch, cells, case):
    rng = np.random.default_rng(5)
    xs, Ss, xm, Sm = _pair(case, *cells, rng)
    seg = segment_faces(xs, Ss, xm, Sm, cells, pairs=([0], [0]))
    out = {}
    for steps in (1, 2, 3):
        monkeypatch.setattr(points3d, "JET_STEPS", steps)
        ip = integration_points(xs, Ss, xm, Sm, cells, seg, pad=False)
        out[steps] = [*ip.xi_s, *ip.xi_m, ip.w]
    for a, b in zip(out[2], out[3]):
        assert np.abs(a.v - b.v).max() < 1e-13
        assert np.abs(a.g - b.g).max() < 1e-13
        assert np.abs(a.hessian() - b.hessian()).max() < 1e-13
    assert max(np.abs(a.hessian() - b.hessian()).max()
               for a, b in zip(out[1][:4], out[2][:4])) > 1e-2
