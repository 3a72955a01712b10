"""A dead traction in an axisymmetric model acts on the surface of revolution
(``dA = 2 pi R dS``): a cylinder pulled along its axis stretches uniformly to
round-off, with the support's reaction the traction times the end's area.
(Contact in axisymmetric models and its refusals: tests/test_axi_contact_*.py.)"""
import numpy as np
import pytest
import skfem

from skfem_mortar import Dirichlet, LinearElastic, Model, Solid, Traction, solve


@pytest.mark.parametrize("element", ["tri1", "quad2"])
def test_axial_pull_of_a_cylinder_is_uniform(element):
    cls = skfem.MeshTri if element.startswith("tri") else skfem.MeshQuad
    mesh = cls.init_tensor(np.linspace(0.0, 1.0, 5), np.linspace(0.0, 2.0, 9)).with_defaults()
    body = Solid(mesh, LinearElastic(E=1.0, nu=0.3), element=element, name="cyl")
    bottom = body.dofs_on("bottom", "y")
    pull = Traction(body, "top", [0.0, 1e-3], name="pull")
    model = Model([body, Dirichlet(body, bottom, name="bottom"), pull], geometry="axisymmetric")
    result = solve(model)
    u = body.u(result.z)[body.node_dofs]
    # the exact field u_r = -nu eps r, u_z = eps z (eps = t / E) is in every element's
    # space: round-off of a 100-dof solve, 1e-12 of the displacement scale 2e-3
    exact = np.stack([-0.3e-3 * body.X[0], 1e-3 * body.X[1]])
    assert np.abs(u - exact).max() <= 1e-12 * 2e-3
    R = model.assemble(result.z, 1.0, tangent=False)[0]
    assert body.reaction(R, bottom) == pytest.approx(-1e-3 * np.pi, rel=1e-12)
    assert pull.force.sum() == pytest.approx(1e-3 * np.pi, rel=1e-12)   # over 2 pi R dR
