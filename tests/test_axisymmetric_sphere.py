"""Scene ``thick_sphere`` against Lame (every element at small strain): the L2
displacement error's observed order over three meshes, and the locking of plain linear
triangles at nu = 0.4999 that MINI and the one-point (mean dilatation) quads do not
show."""
import numpy as np
import pytest

from skfem_mortar.scenes import get_scene
from skfem_mortar.solver.stepping import solve

SCENE = get_scene("thick_sphere")


def errors(element: str, nu: float, meshes: tuple[int, ...]) -> np.ndarray:
    out = []
    for n in meshes:
        setup = SCENE.build(SCENE.resolve({"element": element, "nu": nu, "n": n}), None)
        result = solve(setup.model, n_steps=1)
        assert result.converged
        # every element at small strain (MINI and the one-point quads too): Lame's theory
        assert setup.model.items[0].kinematics == "small"
        out.append(setup.metrics(result)["l2_error"])
    return np.array(out)


def orders(err: np.ndarray) -> np.ndarray:
    return np.log2(err[:-1] / err[1:])          # the meshes halve h


# (element, nu, meshes, expected order); linear triangles are pre-asymptotic on n = 2
# (order 1.44 there), so they and the nearly incompressible bodies run on 4, 8, 16
CONVERGING = [("tri1", 0.3, (4, 8, 16), 2), ("quad1", 0.3, (2, 4, 8), 2),
              ("tri2", 0.3, (2, 4, 8), 3), ("quad2", 0.3, (2, 4, 8), 3),
              ("mini", 0.4999, (4, 8, 16), 2), ("sri", 0.4999, (4, 8, 16), 2)]


@pytest.mark.parametrize("element,nu,meshes,order", CONVERGING)
def test_error_falls_at_the_element_order(element, nu, meshes, order):
    err = errors(element, nu, meshes)
    # measured orders 1.78..3.03 (scene docstring); 0.25 below the nominal order
    # admits the pre-asymptotic first halving, and a wrong hoop or weight (error
    # stalling at O(1) or falling at order <= 1) fails
    assert np.all(orders(err) >= order - 0.25), (err, orders(err))
    assert err[-1] < 0.02


def test_plain_linear_triangles_lock():
    """At nu = 0.4999 plain tri1 stays far off on the meshes where MINI and the
    one-point quads converge (their errors 1.8e-2 and 4e-3 at n = 8)."""
    err = errors("tri1", 0.4999, (4, 8, 16))
    assert err.min() > 0.10, err                 # measured 0.87, 0.68, 0.47


def test_reference_volume_and_mid_nodes_on_the_arcs():
    """The quadratic mesh's mid nodes lie on the arcs (the scene's geometry), and the
    2 pi R weight integrates the wall's volume 4/3 pi (b^3 - a^3) / 2 (a hemisphere
    of the wall) to the rule's order."""
    from skfem_mortar.scenes.thick_sphere import sphere_mesh

    a, b = 1.0, 2.0
    mesh = sphere_mesh(a, b, 3, "quad2")
    rho = np.hypot(*mesh.doflocs)
    facet_mid = mesh.doflocs[:, mesh.nvertices:mesh.nvertices + mesh.nfacets]
    on_inner = np.isclose(np.hypot(*facet_mid[:, mesh.boundaries["inner"]]), a, rtol=1e-14)
    assert on_inner.all() and rho.min() == pytest.approx(a, rel=1e-14)
    setup = SCENE.build(SCENE.resolve({"element": "quad2", "n": 3}), None)
    V = setup.model.items[0]._dx.sum()
    # isoparametric quadratic arcs: measured 1.5e-5 at n = 3 (straight chords: 1.7e-2)
    assert V == pytest.approx(2.0 / 3.0 * np.pi * (b ** 3 - a ** 3), rel=1e-4)
