"""Slave nodes exactly above master nodes: the degenerate mortar segmentation.

A master node that projects onto a slave end node (within ``XI_TOL``) used to
leave a sliver ``[-1, p]`` of the slave element uncovered (its segment dropped
as too short) while the neighbouring segment started at the moving projection
``p``: the weighted gap's gradient ``G`` then carried the end point's
derivative without the sliver's cancelling one, a jump of ``G`` at the tie only
(the ``mindlin`` scene with mirrored meshes stagnated in Newton).
"""
import numpy as np
import pytest

from skfem_mortar.contact.mortar_kernel import evaluate
from skfem_mortar.contact.mortar_slip_cells import tangential_evaluate

from test_mortar import chain


def _tie_pair(eps: float = 0.0):
    """A curved slave over a V-shaped master (its corner at x = 0, 0.01 below the
    slave), every master node at a slave node's x; the slave's middle node moved by
    ``eps`` along x."""
    x = np.linspace(-0.4, 0.4, 9)
    xs = np.vstack([x[::-1], 0.5 * x[::-1] ** 2])      # right to left: outward normal down
    xs[0, 4] += eps
    xm = np.vstack([x, -0.01 - 0.05 * np.abs(x)])
    return xs, chain(9), xm, chain(9)


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("eps", [1e-9, -1e-9, 1e-13, -1e-13])
def test_gap_gradient_is_continuous_at_the_tie(dual, eps):
    # Off the tie by eps <= 1e-9, G differs from G at the tie by 1.6e-5 (standard)
    # and 3.4e-5 (dual) relative to |G|, the same for every eps down to 1e-11: the
    # error of the 2-point Gauss rule, which differs between the split segments
    # [-1, p], [p, .] and the whole one (with n_gauss = 3 the difference is
    # 4e-9).  Within XI_TOL (eps = 1e-13) it is round-off, 4e-13.  The bug made G
    # jump by 0.12 (standard) and 0.09 (dual) within XI_TOL: 1e-3 separates the
    # two by a factor 30 either way.
    r0 = evaluate(*_tie_pair(0.0), space=("dual" if dual else "standard"))
    r1 = evaluate(*_tie_pair(eps), space=("dual" if dual else "standard"))
    G0, G1 = r0.G.toarray(), r1.G.toarray()
    assert np.abs(G0 - G1).max() <= 1e-3 * np.abs(G0).max()
    # the weighted gaps themselves were always continuous (round-off of eps)
    np.testing.assert_allclose(r0.g, r1.g, atol=1e-8 * np.abs(r0.g).max())


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("eps", [1e-9, -1e-9, 1e-13, -1e-13])
def test_tangential_gradient_is_continuous_at_the_tie(dual, eps):
    # the tangential offsets r_A (friction) on the same segments: G_t moves off the
    # tie by the Gauss rule's error, 2.5e-5 (standard) and 1.7e-4 (dual) relative,
    # by round-off (1e-12) within XI_TOL; the bug's jump there was 0.038 (dual;
    # standard multipliers hid it below the Gauss error here).  1e-3 separates them.
    G0 = tangential_evaluate(*_tie_pair(0.0), space=("dual" if dual else "standard")).G.toarray()
    G1 = tangential_evaluate(*_tie_pair(eps), space=("dual" if dual else "standard")).G.toarray()
    assert np.abs(G0 - G1).max() <= 1e-3 * np.abs(G0).max()


@pytest.mark.parametrize("dual", [False, True])
def test_gap_gradient_at_the_tie_against_differences(dual):
    # one-sided differences with h = 1e-7 (each stays on one side of the tie, where
    # g is smooth): truncation h |g''| ~ 1e-6 relative plus the 3e-5 offset of G at
    # the tie (the Gauss rule's, see above); 1e-3 is far below the bug's 0.1 error in G.
    xs, ss, xm, sm = _tie_pair()
    r = evaluate(xs, ss, xm, sm, space=("dual" if dual else "standard"))
    G = r.G.toarray()
    h = 1e-7
    for sign in (1.0, -1.0):
        for k in (0, 1):             # x and y of the middle slave node (dof 2*4 + k)
            xp = xs.copy()
            xp[k, 4] += sign * h
            fd = (evaluate(xp, ss, xm, sm, space=("dual" if dual else "standard")).g - r.g) / (sign * h)
            assert np.abs(fd - G[:, 8 + k]).max() <= 1e-3 * np.abs(G).max()


@pytest.mark.parametrize("mu", [0.0, 0.3])
@pytest.mark.parametrize("method", ["nts", "mortar", "mortar-dual"])
def test_mirrored_cylinder_on_block_converges(monkeypatch, method, mu):
    # the mindlin scene without its offset: mirrored meshes, the cylinder's axis
    # node on the block's (to the mirror's round-off, 5e-16), every contact node's
    # x shared within the fine zone.  Standard mortar stagnated (the residual
    # cycling at 3.6e-4 in step 7 after cuts); now every step converges.
    import skfem_mortar.scenes.mindlin as mindlin
    from skfem_mortar.scenes import get_scene
    from skfem_mortar.solver.stepping import solve
    monkeypatch.setattr(mindlin, "OFFSET", 0.0)
    scene = get_scene("mindlin")
    values = {p.name: p.default for p in scene.params}
    # mu = 0 (frictionless) bypasses the scene's range; friction from the start, so
    # that the pressing steps, where the contact grows node on node, have it too
    values.update(mu=mu, n_a=4, n_steps=8, pressing="frictional")
    setup = scene.build(values, method)
    res = solve(setup.model, 8, **setup.solve_options)
    if method != "nts":
        # no step cut (NTS with friction cuts one step at n_a = 4 with or without
        # the offset, measured: the coarse arc, not the coincident nodes)
        assert len(res.steps) == 8
    pair = setup.model.item("contact")
    fs, fm = pair.forces(res.z)
    total = np.abs(fs).sum()
    assert total > 0.0
    # slave and master forces are the two halves of G^T lam: they cancel to round-off
    np.testing.assert_allclose(fs.sum(axis=1) + fm.sum(axis=1), 0.0, atol=1e-12 * total)
