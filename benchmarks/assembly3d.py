# %%
"""Assembly of a 3D solid's residual and tangent: this package's kernel against
scikit-fem's own forms for the same law, side by side in one run.

    python benchmarks/assembly3d.py [--dofs 1e4 3e4 1e5] [--repeat 3] [--json out.json]
                                    [--elements tet1 hex1] [--laws neo-hooke linear]

For tet1 and hex1 unit cubes of about the given numbers of dofs, at a random state
of 2 % strain, for a NeoHooke and a LinearElastic law:

- ``ours``: ``Model([solid]).assemble`` as a solve calls it: :meth:`Solid.assemble`
  (element residuals and tangents, COO triplets over fixed index arrays) summed
  into the model's fixed CSR pattern (built at the first call, not timed: the
  best of ``--repeat`` >= 2 calls); ``triplets``: :meth:`Solid.assemble` alone;
- ``skfem``: the same law written as scikit-fem forms over the same basis and
  quadrature, ``LinearForm`` and ``BilinearForm.assemble`` (CSR): for NeoHooke the
  stress and tangent evaluated inside the forms with ``skfem.helpers``
  (``P = mu (F - F^-T) + lambda ln J F^-T``, ``Grad v : A : Grad du = mu Grad v :
  Grad du + (mu - lambda ln J) (F^-1 Grad du) : (F^-1 Grad v)^T + lambda (F^-T :
  Grad du)(F^-T : Grad v)``), for LinearElastic skfem's own
  ``skfem.models.elasticity.linear_elasticity`` and ``linear_stress``;

and prints per phase the best of ``--repeat`` wall times, the time per element,
the peak of numpy's allocations during the call (``tracemalloc``) per dof, and
what stays in memory between calls per dof: our kernel's cached arrays (``dN``,
``dN dx``, per component copies, the COO indices; ``kept``) beside the skfem
basis's own (its shape functions and gradients at every point, which both paths
hold: ``basis``).
The two residuals and tangents are checked equal (to 1e-12 relative) first.
"""
from __future__ import annotations

import argparse
import json
import time
import tracemalloc

import numpy as np
from skfem import BilinearForm, LinearForm, MeshHex1, MeshTet1
from skfem.helpers import ddot, det, grad, inv, mul, transpose
from skfem.models.elasticity import linear_elasticity, linear_stress

from skfem_mortar.bodies.hyperelastic import NeoHooke
from skfem_mortar.bodies.material import LinearElastic
from skfem_mortar.bodies.solid import Solid
from skfem_mortar.core.model import Model

E, NU = 1.0, 0.3


def neo_hooke_forms(mu: float, lmbda: float) -> tuple[LinearForm, BilinearForm]:
    """NeoHooke's residual and tangent as scikit-fem forms (module docstring)."""
    def F_of(w):
        G = grad(w["u"])
        return G + np.eye(3)[:, :, None, None]

    @LinearForm
    def residual(v, w):
        F = F_of(w)
        FiT = transpose(inv(F))
        return ddot(mu * (F - FiT) + lmbda * np.log(det(F)) * FiT, grad(v))

    @BilinearForm
    def tangent(du, v, w):
        F = F_of(w)
        Fi = inv(F)
        FiT = transpose(Fi)
        c = mu - lmbda * np.log(det(F))
        return (mu * ddot(grad(du), grad(v))
                + c * ddot(mul(Fi, grad(du)), transpose(mul(Fi, grad(v))))
                + lmbda * ddot(FiT, grad(du)) * ddot(FiT, grad(v)))
    return residual, tangent


def linear_forms(mu: float, lmbda: float) -> tuple[LinearForm, BilinearForm]:
    """skfem's linear elasticity: ``sigma(eps(u)) : eps(v)`` and its bilinear form."""
    stress = linear_stress(lmbda, mu)

    @LinearForm
    def residual(v, w):
        G = grad(w["u"])
        return ddot(stress(0.5 * (G + transpose(G))), grad(v))
    return residual, linear_elasticity(lmbda, mu)


def timed(fun, repeat: int) -> tuple[float, float, object]:
    """Best wall time of ``repeat`` calls, peak traced allocation (bytes), last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fun()
        best = min(best, time.perf_counter() - t)
    tracemalloc.start()
    fun()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return best, peak, out


def case(element: str, law: str, dofs: float, repeat: int) -> dict:
    n = max(2, int(round((dofs / 3.0) ** (1.0 / 3.0))))
    grid = (np.linspace(0.0, 1.0, n),) * 3
    mesh = MeshTet1.init_tensor(*grid) if element == "tet1" else MeshHex1.init_tensor(*grid)
    material = NeoHooke(E=E, nu=NU) if law == "neo-hooke" else LinearElastic(E=E, nu=NU)
    solid = Solid(mesh, material, element)
    model = Model([solid])
    N = solid.n_dofs
    z = solid.interpolate(lambda X: 0.02 * np.sin(3.0 * X[[1, 2, 0]]))
    forms = neo_hooke_forms if law == "neo-hooke" else linear_forms
    res_form, tan_form = forms(material.mu, material.lmbda)

    def ours():
        return model.assemble(z, 1.0)[:2]

    def ours_triplets():
        return solid.assemble(z, 1.0)

    def skfem():
        w = solid.basis.interpolate(z)
        return res_form.assemble(solid.basis, u=w), tan_form.assemble(solid.basis, u=w)

    t_ours, m_ours, (r1, K1) = timed(ours, max(repeat, 2))
    t_trip, m_trip, _ = timed(ours_triplets, repeat)
    t_sk, m_sk, (r2, K2) = timed(skfem, repeat)
    scale = abs(K2).max()
    assert abs(K1 - K2).max() < 1e-12 * scale, "the two tangents differ"
    assert np.abs(r1 - r2).max() < 1e-12 * np.abs(r2).max() * 10 + 1e-300
    n_el = mesh.nelements
    kept = sum(a.nbytes for a in (solid._dN, solid._dNdx, *[x for pair in solid._by_component
                                                           for x in pair], *solid._kidx[1:]))
    basis = sum(np.asarray(f).nbytes for phi in solid.basis.basis for f in
                (phi[0].value, phi[0].grad))
    return {"kept_bytes_per_dof": kept / N, "basis_bytes_per_dof": basis / N,"element": element, "law": law, "dofs": N, "elements": n_el,
            "quadrature_points": int(solid._dx.shape[1]),
            "ours_s": t_ours, "ours_triplets_s": t_trip, "skfem_s": t_sk,
            "ours_us_per_element": 1e6 * t_ours / n_el,
            "skfem_us_per_element": 1e6 * t_sk / n_el,
            "ours_bytes_per_dof": m_ours / N, "ours_triplets_bytes_per_dof": m_trip / N,
            "skfem_bytes_per_dof": m_sk / N, "speedup": t_sk / t_ours}


def main(argv: list[str] | None = None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dofs", type=float, nargs="+", default=[1e4, 3e4, 1e5])
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--json")
    p.add_argument("--elements", nargs="+", default=["tet1", "hex1"], choices=["tet1", "hex1"])
    p.add_argument("--laws", nargs="+", default=["neo-hooke", "linear"],
                   choices=["neo-hooke", "linear"])
    a = p.parse_args(argv)
    rows = []
    print(f"{'element':8s}{'law':11s}{'dofs':>8s}{'n_el':>8s}{'ours s':>9s}{'trip s':>9s}"
          f"{'skfem s':>9s}{'us/el':>8s}{'sk us/el':>9s}{'B/dof':>8s}{'sk B/dof':>9s}{'x':>6s}"
          f"{'kept B/dof':>11s}{'basis B/dof':>12s}")
    for element in a.elements:
        for law in a.laws:
            for dofs in a.dofs:
                r = case(element, law, dofs, a.repeat)
                rows.append(r)
                print(f"{element:8s}{law:11s}{r['dofs']:8d}{r['elements']:8d}"
                      f"{r['ours_s']:9.3f}{r['ours_triplets_s']:9.3f}{r['skfem_s']:9.3f}"
                      f"{r['ours_us_per_element']:8.2f}{r['skfem_us_per_element']:9.2f}"
                      f"{r['ours_bytes_per_dof']:8.0f}{r['skfem_bytes_per_dof']:9.0f}"
                      f"{r['speedup']:6.1f}{r['kept_bytes_per_dof']:11.0f}"
                      f"{r['basis_bytes_per_dof']:12.0f}", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    return rows


if __name__ == "__main__":
    main()
