"""Small analytic items used to test the solver independently of any body."""
import numpy as np

from skfem_mortar.core.item import Contribution, Item


class Spring(Item):
    """A chain of springs between consecutive dofs, force law f(e) = k atan(e)
    (softening) or f(e) = k sinh(e) (stiffening).

    Residual of dof i: sum over springs of the spring force, minus the load
    ``load_factor * load`` on the last dof. With the stiffening law a large load
    step makes Newton overshoot by orders of magnitude, so step cutting is needed.
    """

    dof_kind = "u"

    def __init__(self, n: int, k: float = 1.0, load: float = 0.0, law: str = "atan",
                 name: str = "spring"):
        self.n_dofs = n
        self.k = k
        self.load = load
        self.law = law
        self.name = name

    def assemble(self, z, load_factor, tangent=True):
        u = z[self.dofs]
        e = np.diff(u)
        with np.errstate(over="ignore"):
            if self.law == "atan":
                f, df = self.k * np.arctan(e), self.k / (1.0 + e**2)
            else:
                f, df = self.k * np.sinh(e), self.k * np.cosh(e)
        idx = self.offset + np.column_stack([np.arange(self.n_dofs - 1),
                                             np.arange(1, self.n_dofs)])
        r = np.column_stack([-f, f])
        k = df[:, None, None] * np.array([[1.0, -1.0], [-1.0, 1.0]])
        c = Contribution.from_dofs(idx, r, k if tangent else None)
        c.r_index = np.append(c.r_index, self.offset + self.n_dofs - 1)
        c.r_value = np.append(c.r_value, -load_factor * self.load)
        return c
