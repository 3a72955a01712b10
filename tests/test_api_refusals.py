"""The Python API refuses misuse when the object is built, with a ValueError
naming the parameter and its allowed range (issue: clear refusals): never a
silent wrong answer (a boolean mask read as dofs 0 and 1, a load counted twice,
a Dirichlet on a body outside the model prescribing another body's dofs)."""
import numpy as np
import pytest
import skfem

from skfem_mortar import (ContactPair, Dirichlet, Model, NeoHooke, NewtonOptions, Solid,
                          Traction, solve)
from skfem_mortar.contact.surfaces import ContactSurface, RigidCircle, RigidPlane

NAN, INF = float("nan"), float("inf")


def block(name="block", y0=0.0):
    m = skfem.MeshTri.init_tensor(np.linspace(0, 1, 4), np.linspace(y0, y0 + 0.5, 3))
    m = m.with_boundaries({"bottom": lambda x: np.isclose(x[1], y0),
                           "top": lambda x: np.isclose(x[1], y0 + 0.5)})
    return Solid(m, NeoHooke(E=1.0, nu=0.3), name=name)


def test_a_boolean_mask_is_read_as_a_mask():
    """scikit-fem users pass masks: a mask of the body's length selects its True
    dofs (before: the mask's 0/1 values were read as dofs 0 and 1)."""
    b = block()
    mask = np.zeros(b.n_dofs, dtype=bool)
    mask[b.dofs_on("bottom")] = True
    d = Dirichlet(b, mask)
    np.testing.assert_array_equal(d.local_dofs, np.sort(b.dofs_on("bottom")))
    with pytest.raises(ValueError, match=r"boolean mask must have shape \(%d,\)" % b.n_dofs):
        Dirichlet(b, mask[:5])


@pytest.mark.parametrize("dofs, value, match", [
    (np.array([0.5, 1.0]), 0.0, "must be integers"),
    (np.array([0, 10**6]), 0.0, r"must lie in \[0, \d+\)"),
    (np.array([-1]), 0.0, r"must lie in \[0, \d+\)"),
    (np.array([3, 3]), np.array([0.1, 0.2]), "dof 3 is listed twice with different values"),
    (np.array([3, 4]), np.array([0.1, NAN]), "value must be finite"),
    (np.array([3, 4]), np.array([0.1, 0.2, 0.3]), "one value per dof"),
])
def test_dirichlet_refuses_bad_dofs_and_values(dofs, value, match):
    with pytest.raises(ValueError, match=match):
        Dirichlet(block(), dofs, value)


def test_a_repeated_dof_with_one_value_is_fine():
    d = Dirichlet(block(), np.array([3, 3, 4]), np.array([0.1, 0.1, 0.2]))
    np.testing.assert_array_equal(d.prescribed(1.0)[1], [0.1, 0.2])


def test_items_on_bodies_outside_the_model_are_refused():
    """A Dirichlet, a load and a contact pair on a body not in the Model: each is
    refused when the Model is built (before: another body's dofs were prescribed)."""
    a, b = block("a"), block("b", y0=0.5)
    for item in (Dirichlet(b, b.dofs_on("bottom")), Traction(b, "top", (0.0, -1.0)),
                 ContactPair(ContactSurface.from_solid(b, "bottom"),
                             ContactSurface.from_solid(a, "top"))):
        with pytest.raises(ValueError, match=r"acts on body 'b', which is not in the model"):
            Model([a, item])


def test_the_same_item_twice_is_refused():
    b = block()
    load = Traction(b, "top", (0.0, -1.0))
    with pytest.raises(ValueError, match="same item .* list each item once"):
        Model([b, load, load])
    with pytest.raises(ValueError, match="not a model item"):
        Model([b, "load"])


@pytest.mark.parametrize("kw, match", [
    (dict(method="nts", margn=0.1), r"unknown option 'margn' for method 'nts': ContactPair "
                      r"takes method, .* and method 'nts' the options .*did you mean 'margin'\?"),
    (dict(method="mortar", frcition=None), r"unknown option 'frcition' .*ContactPair takes "
                                          r".*did you mean 'friction'\?"),
    (dict(methd="nts"), r"unknown option 'methd' .*did you mean 'method'\?"),
    (dict(c="10"), r"c must be a finite real number > 0, got '10' \(str\)"),
    (dict(touch_tolerance="0.1"), r"touch_tolerance must be a finite real number >= 0, got '0.1'"),
    (dict(method="mortar", n_gauss=0), r"n_gauss must be an integer in \[1, 10\]"),
    (dict(method="mortar", n_gauss=2.5), r"n_gauss must be an integer in \[1, 10\]"),
    (dict(margin=NAN), "margin must be a finite number > 0"),
    (dict(method="nts", stick=0.9), r"stick must be a number in \[0, 0.5\]"),
    (dict(c=NAN), "c must be a finite real number > 0"),
    (dict(touch_tolerance=-1.0), "touch_tolerance must be a finite real number >= 0"),
    (dict(accelerate="yes"), "accelerate must be True or False"),
    (dict(method="mortar-duall"), "method must be one of nts, mortar, mortar-dual"),
    (dict(segmentation="always"), "segmentation must be 'iteration' or 'step'"),
])
def test_contact_pair_options_are_checked_when_built(kw, match):
    a, b = block("a"), block("b", y0=0.5)
    with pytest.raises(ValueError, match=match):
        ContactPair(ContactSurface.from_solid(b, "bottom"), ContactSurface.from_solid(a, "top"),
                    **kw)


def test_bodies_given_as_surfaces_are_refused_naming_the_role():
    """A newcomer's ``ContactPair(upper, lower)`` with the bodies themselves (before:
    TypeError "'slice' object is not callable")."""
    a, b = block("a"), block("b", y0=0.5)
    with pytest.raises(ValueError, match=r"^slave must be a contact surface "
                                         r"\(ContactSurface.from_solid\(body, .*got Solid 'b'"):
        ContactPair(b, ContactSurface.from_solid(a, "top"))
    with pytest.raises(ValueError, match=r"^master must be a contact surface .*got Solid 'a'"):
        ContactPair(ContactSurface.from_solid(b, "bottom"), a)


@pytest.mark.parametrize("make, match", [
    (lambda: RigidPlane((NAN, 0.0), (0.0, 1.0)), "point must be finite"),
    (lambda: RigidPlane((0.0, 0.0), (0.0, INF)), "normal must be finite"),
    (lambda: RigidPlane((0.0, 0.0), (0.0, 0.0)), "normal must be a finite non-zero vector"),
    (lambda: RigidPlane((0.0, 0.0), (0.0, 1.0), length=INF), "length must be a finite real"),
    (lambda: RigidCircle((0.0, NAN), 1.0), "center must be finite"),
    (lambda: RigidCircle((0.0, 0.0), NAN), "radius must be a finite real number > 0"),
    (lambda: ContactSurface(None, None, [[0, 1]], X=np.array([[0.0, NAN], [0.0, 0.0]])),
     "must be finite"),
])
def test_rigid_surfaces_refuse_non_finite_data(make, match):
    with pytest.raises(ValueError, match=match):
        make()


@pytest.mark.parametrize("kw, match", [
    (dict(rtol=NAN), r"rtol must be a finite real number in \(0, 1\)"),
    (dict(atol=INF), "atol must be a finite real number >= 0"),
    (dict(max_iter=0), "max_iter must be an integer >= 1"),
    (dict(divergence=NAN), "divergence must be a finite real number > 1"),
    (dict(max_backtracks=-1), "max_backtracks must be an integer >= 0"),
])
def test_newton_options_are_checked(kw, match):
    with pytest.raises(ValueError, match=match):
        NewtonOptions(**kw)


@pytest.mark.parametrize("kw, match", [
    (dict(growth=0.0), r"growth must be a number in \[1, 1000\]"),
    (dict(growth=NAN), r"growth must be a number in \[1, 1000\]"),
    (dict(increment=NAN), r"increment must lie in \(0, 1\]"),
    (dict(increment=-0.1), r"increment must lie in \(0, 1\]"),
    (dict(min_step=NAN), r"min_step must lie in \(0, 1\]"),
    (dict(start=NAN), r"start must lie in \[0, 1\)"),
    (dict(n_steps=10**9), r"n_steps must be an integer in \[1, 1000000\]"),
    (dict(n_steps=True), r"n_steps must be an integer"),
    (dict(easy_steps=0), "easy_steps must be an integer >= 1"),
])
def test_solve_refuses_stepping_arguments_that_hang_or_run_backwards(kw, match):
    """Refused before anything is assembled (before: growth 0 or a negative
    increment hung or ran the load backwards)."""
    b = block()
    model = Model([b, Dirichlet(b, b.dofs_on("bottom"))])
    kw = {"n_steps": 2, **kw}
    n = kw.pop("n_steps")
    with pytest.raises(ValueError, match=match):
        solve(model, n, **kw)


def test_a_tiny_load_converges():
    """Two blocks pressed by a traction of 1e-8 (E = 1): the residual tolerance
    scales with the load increment and is floored only by each row's round-off
    (100 eps k L, about 1e-14 here), so the step converges and the contact force
    balances the load to 1e-6 of it (the solver meets 1e-10 of the increment)."""
    a, b = block("a"), block("b", y0=0.5)
    pair = ContactPair(ContactSurface.from_solid(b, "bottom"), ContactSurface.from_solid(a, "top"),
                       method="mortar")
    left = b.dofs_at_nodes(np.flatnonzero(np.isclose(b.X[0], 0.0)), component=0)
    model = Model([a, b, pair, Traction(b, "top", (0.0, -1e-8)),
                   Dirichlet(a, a.dofs_on("bottom")), Dirichlet(b, left, name="side")])
    r = solve(model, 1)
    fs, _ = pair.forces(r.z)
    assert abs(fs.sum(axis=1)[1] - 1e-8) <= 1e-6 * 1e-8  # the block below pushes up
