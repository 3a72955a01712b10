"""Partly projected faces in a solved body (issue 38, "Tests that must exist").

Scene ``patch3d``'s blocks (:func:`~skfem_mortar.scenes._patch3d.build_bodies`: 12 lower
cells a side, the footprint ``[1/4, 3/4]^2`` under 4 upper cells) with the lower block's
covered top split in two master surfaces at its grid line ``x = c = 1/3``, one contact pair
each on the one slave surface (the upper block's bottom).  The upper block's first free
x-line is moved to ``c + d``, so the row of slave faces ``[1/4, c + d]`` is covered by the
right master over the relative width ``eps = d / (c + d - 1/4)`` and by the left one over
``1 - eps``: every face of that row is partly projected onto each master (quad4 faces of
hex1, tri3 faces of tet1).

Why the patch answer is exact: the two masters tile the footprint, so the slave's whole
bottom is in contact, the uncovered lower top carries the same pressure, and the uniform
uniaxial state of ``patch3d`` (:func:`~skfem_mortar.scenes._patch3d.exact_patch3d`) is
affine.  In each pair the multiplier functions of the kept nodes sum to one over the
covered part (the mask merges a masked node's function into its kept neighbours), so the
constant pressure ``p`` is in each pair's multiplier space; the exact displacement closes
every weighted gap; the pair of them solves the discrete equations.

The masked band: in each pair the nodes whose support ``s_A`` is at most
``mask_tolerance w_A`` (``w_A`` the tributary weight; the space's tolerance,
:func:`~skfem_mortar.contact.multiplier_spaces.mask_tolerance`: on faces 1e-2
standard, 1e-3 dual) carry no multiplier.  A kept node of small support ratio ``r = s_A / w_A`` is
exact only up to the conditioning of its row: its weighted gap is nearly a combination
of its neighbours' rows, and the round-off of the weighted gaps reaches its multiplier
amplified.  Measured on this model (quad4, the far node of the straddling row in the
right pair; one Newton step from the exact state, which reads within a factor 2.5 of
the converged error) with every node kept down to ``r = 1e-6`` (the tolerance before):

=======  =================  ====================  ================
width    ``s_A / w_A``      standard ``p`` error  dual ``p`` error
=======  =================  ====================  ================
1e-1     1.0e-2             3.0e-9                3.9e-11
5e-2     2.6e-3             2.7e-8                2.3e-10
3e-2     9.3e-4             4.1e-7                1.8e-9
1e-2     1.0e-4             1.3e-5                3.2e-8
3e-3     9.3e-6             3.8e-3                2.9e-7
=======  =================  ====================  ================

(``s_A / w_A`` is the width squared on these quad4 faces, about a tenth of it on the
tri3 ones, whose errors are smaller): about ``3e-13 / r^2`` (standard) and
``3e-14 / r^1.5`` (dual), so the tolerances keep every node whose pressure reads
within 1e-8 and mask the others.  The cases take widths on both sides of the
tolerance, among them widths the old tolerance kept with errors of 1.2e-5 (standard
at 1e-2) and 1.9e-7 (dual at 3e-3), now masked and exact.  The displacements and the
contact forces are exact for every eps.
"""
import numpy as np
import pytest

from skfem_mortar import ContactPair, ContactSurface, Model, solve
from skfem_mortar.contact.mortar_support import tributary_weights
from skfem_mortar.contact.multiplier_spaces import mask_tolerance
from skfem_mortar.scenes import _patch3d, patch3d
from skfem_mortar.solver.newton import NewtonOptions

#: the patch test's round-off on the pressure at kept nodes (the issue's bound)
PATCH = 1e-8
#: displacements: round-off of Newton to rtol 1e-13 on 4e3 dofs (measured <= 2e-12)
EXACT_U = 1e-10
#: the multiplier space of each method (the mask tolerance is the space's)
SPACE = {"mortar": "standard", "mortar-dual": "dual"}
#: the lower block's grid line where the master is split, and the footprint's edges
C, LO, HI = 1.0 / 3.0, 0.25, 0.75


def _build(element, method, eps, kinematics):
    params = {p.name: p.default for p in patch3d.SCENE.params}
    params.update(element=element, kinematics=kinematics, n_lower=12, margin=3, n_upper=4)
    d = eps * (C - LO) / (1.0 - eps)          # d / (c + d - 1/4) = eps
    parts = _patch3d.build_bodies(params, upper_lines=[LO, C + d, 0.5, 0.625, HI])
    lower = parts.lower
    covered = lower.mesh.boundaries["covered"]
    x = lower.mesh.p[0, lower.mesh.facets[:, covered]].mean(axis=0)
    slave = ContactSurface.from_solid(*parts.slave, name="slave_face")
    pairs = [ContactPair(slave, ContactSurface.from_solid(lower, covered[side], name=name),
                         method, name=name)
             for name, side in (("left", x < C), ("right", x > C))]
    return Model(parts.items + pairs, geometry="3d"), pairs, parts, params


CASES = [("hex1", "mortar", 2e-1, "small"), ("hex1", "mortar", 1e-2, "finite"),
         ("hex1", "mortar-dual", 3e-3, "small"), ("hex1", "mortar-dual", 1e-4, "finite"),
         ("tet1/hex1", "mortar", 1e-7, "finite"), ("tet1/hex1", "mortar-dual", 1e-5, "small")]


@pytest.mark.parametrize("element,method,eps,kinematics", CASES)
def test_partly_projected_faces_in_a_solved_patch(element, method, eps, kinematics):
    model, pairs, parts, params = _build(element, method, eps, kinematics)
    z = solve(model, n_steps=1, newton=NewtonOptions(rtol=1e-13)).z
    assert np.all(np.isfinite(z))
    exact = _patch3d.exact_patch3d(params)
    assert _patch3d.displacement_error(parts, exact, z) < EXACT_U
    p0 = exact["pressure"]
    s = pairs[0].slave
    w = tributary_weights(s.X, s.segments, s.cell, 9)
    force = 0.0
    for pair in pairs:
        p, g, ev = pair.pressure_and_gap(z)
        kept = ev.mask
        # outside the band: every kept node's support ratio is above the space's tolerance
        tol = mask_tolerance(SPACE[method], 2)        # faces
        assert kept.any() and np.all(ev.area[kept] > tol * w[kept])
        assert np.abs(p[kept] - p0).max() < PATCH * p0, (pair.name, p[kept] - p0)
        assert np.abs(g[kept]).max() < 1e-12        # closed (a length; h = 0.125)
        force += pair.forces(z)[0].sum(axis=1)[2]
        for lift in (1e-4, -1e-4):                  # the upper block moved by +-lift
            zl = z.copy()
            zl[parts.upper.offset + parts.upper.node_dofs[2]] += lift
            gl = pair.pressure_and_gap(zl)[1][kept]
            assert np.all(np.isfinite(gl)) and np.all(np.sign(gl) == np.sign(lift))
    assert abs(abs(force) - exact["contact_force"]) < PATCH * exact["contact_force"]
