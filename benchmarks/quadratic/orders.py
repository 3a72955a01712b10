"""Hertz convergence of linear and quadratic bodies: errors, orders, cost.

    python benchmarks/quadratic/orders.py [--method mortar-dual] [--refine -2 -1 0 1]
                                          [--elements tri1 tri2 quad1 quad2] [--load 0.2]

Runs the ``hertz`` scene with small-strain kinematics on the rigid base for each
element and mesh level and prints one markdown table: dofs, multipliers, Newton
iterations, wall time (build and solve; mortar in one load step, NTS in four),
the peak-pressure error (the scene's metric) and the L2 error of the pressure
profile interpolated from the nodal pressures with the segments' shape functions
(:func:`profile_l2_error`), both against linear Hertz theory,
and the orders between consecutive levels, measured against the element size
``h`` (``log(e1/e0) / log(h1/h0)``) and against the dofs
(``-2 log(e1/e0) / log(n1/n0)``, the order in an equivalent ``h`` of a 2D
mesh).  Then the equal-cost comparison: each quadratic row next to the linear
row of the same shape with the closest dofs.  The default load gives
``a / R = 0.012``: the deviation of the contact on the current configuration
from linear theory is O(a / R) and is the floor the errors reach.
"""
from __future__ import annotations

import argparse
import math
import time
import warnings

import numpy as np

from skfem_mortar.app.runner import build_scene
from skfem_mortar.scenes.hertz import hertz_exact
from skfem_mortar.solver.stepping import solve

#: Gauss points per slave segment for the L2 error of the pressure profile
N_GAUSS = 8


def profile_l2_error(pair, z: np.ndarray, a: float, p0: float) -> float:
    """Relative L2 error over the slave surface of the pressure profile interpolated
    from the nodal pressures with the segments' own shape functions (2-node: linear,
    3-node: quadratic), against ``p0 sqrt(1 - x^2 / a^2)`` (0 beyond ``a``), in the
    current ``x``; Gauss rule of :data:`N_GAUSS` points per segment."""
    d = pair.contact_data(z)
    n = pair.slave.n_nodes
    p, x = np.zeros(n), np.zeros(n)
    p[d["node"]], x[d["node"]] = d["pressure"], d["x"]
    seg = pair.slave.segments
    eta, w = np.polynomial.legendre.leggauss(N_GAUSS)
    if seg.shape[1] == 3:
        N = np.stack([eta * (eta - 1) / 2, eta * (eta + 1) / 2, 1 - eta ** 2])
        dN = np.stack([eta - 0.5, eta + 0.5, -2 * eta])
    else:
        N = np.stack([(1 - eta) / 2, (1 + eta) / 2])
        dN = np.stack([-0.5 + 0 * eta, 0.5 + 0 * eta])
    xg = x[seg] @ N                                     # (n_seg, n_gauss)
    jac = np.abs(x[seg] @ dN)
    ph = p[seg] @ N
    pe = p0 * np.sqrt(np.clip(1 - (xg / a) ** 2, 0.0, None))
    return float(np.sqrt(np.sum((ph - pe) ** 2 * jac * w) / np.sum(pe ** 2 * jac * w)))


def run(element: str, refine: int, method: str, load: float) -> dict:
    params = {"element": element, "refine": refine, "kinematics": "small", "load": load}
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        setup, values, _ = build_scene("hertz", params, method)
        res = solve(setup.model, 1 if method != "nts" else 4)
    elapsed = time.perf_counter() - t0
    m = setup.metrics(res)
    ex = hertz_exact(values["radius"], values["load"], values["E"], values["nu"], None, 0.3)
    pair = setup.model.item("contact")
    return {"element": element, "refine": refine, "h": m["element_size"],
            "dofs": int(setup.model.n_u), "multipliers": int(pair.n_dofs),
            "iterations": sum(st.newton_iterations for st in res.steps),
            "time": elapsed, "peak": m["peak_pressure_error"],
            "l2": profile_l2_error(pair, res.z, ex["half_width"], ex["peak_pressure"])}


def fitted_order(rows: list[dict], key: str, against: str) -> float:
    """Least-squares slope of ``log e`` against ``log h`` (or ``-log(dofs) / 2``) over all rows."""
    e = np.log([r[key] for r in rows])
    t = np.log([r["h"] for r in rows]) if against == "h" else -0.5 * np.log([r["dofs"] for r in rows])
    return float(np.polyfit(t, e, 1)[0])


def orders(rows: list[dict], key: str) -> list[tuple[float, float]]:
    """(order in h, order in dofs) of ``key`` between consecutive rows (nan for the first)."""
    out = [(math.nan, math.nan)]
    for r0, r1 in zip(rows, rows[1:]):
        e = math.log(r1[key] / r0[key])
        out.append((e / math.log(r1["h"] / r0["h"]), -2.0 * e / math.log(r1["dofs"] / r0["dofs"])))
    return out


def table(by_element: dict[str, list[dict]]) -> str:
    lines = ["| element | refine | h | dofs | mult. | its | time s | peak err | order h/dofs "
             "| L2 err | order h/dofs |", "|" + "---|" * 11]
    for el, rows in by_element.items():
        op, ol = orders(rows, "peak"), orders(rows, "l2")
        for r, (p_h, p_n), (l_h, l_n) in zip(rows, op, ol):
            lines.append(f"| {el} | {r['refine']} | {r['h']:.4g} | {r['dofs']} | {r['multipliers']} "
                         f"| {r['iterations']} | {r['time']:.2f} | {r['peak']:.3e} | {p_h:.2f} / {p_n:.2f} "
                         f"| {r['l2']:.3e} | {l_h:.2f} / {l_n:.2f} |")
    lines += ["", "| element | fitted order of peak err in h / dofs | of L2 err in h / dofs |",
              "|---|---|---|"]
    for el, rows in by_element.items():
        if len(rows) > 1:
            lines.append(f"| {el} | {fitted_order(rows, 'peak', 'h'):.2f} / "
                         f"{fitted_order(rows, 'peak', 'dofs'):.2f} | {fitted_order(rows, 'l2', 'h'):.2f}"
                         f" / {fitted_order(rows, 'l2', 'dofs'):.2f} |")
    return "\n".join(lines)


def equal_cost(by_element: dict[str, list[dict]]) -> str:
    lines = ["| quadratic | dofs | peak err | L2 err | linear | dofs | peak err | L2 err |",
             "|" + "---|" * 8]
    for el, rows in by_element.items():
        lin = by_element.get(el[:-1] + "1")
        if not el.endswith("2") or not lin:
            continue
        for r in rows:
            q = min(lin, key=lambda x: abs(math.log(x["dofs"] / r["dofs"])))
            lines.append(f"| {el} r{r['refine']} | {r['dofs']} | {r['peak']:.3e} | {r['l2']:.3e} "
                         f"| {q['element']} r{q['refine']} | {q['dofs']} | {q['peak']:.3e} "
                         f"| {q['l2']:.3e} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--method", default="mortar-dual")
    ap.add_argument("--refine", type=int, nargs="+", default=[-2, -1, 0, 1])
    ap.add_argument("--elements", nargs="+", default=["tri1", "tri2", "quad1", "quad2"])
    ap.add_argument("--load", type=float, default=0.2)
    a = ap.parse_args(argv)
    by_element = {el: [run(el, r, a.method, a.load) for r in a.refine] for el in a.elements}
    print(f"hertz, rigid base, small strain, {a.method}, load {a.load}\n")
    print(table(by_element))
    print()
    print(equal_cost(by_element))


if __name__ == "__main__":
    main()
