"""Node-to-segment contact onto curved 3-node master segments.

A 3-node master segment ``(x_1, x_2, x_3)`` = (start, end, mid) is the curve

    x(xi) = N_1 x_1 + N_2 x_2 + N_3 x_3,   xi in [-1, 1],
    N_1 = xi (xi - 1)/2,  N_2 = xi (xi + 1)/2,  N_3 = 1 - xi^2,

with tangent ``t = x'(xi)``, ``x'' = x_1 + x_2 - 2 x_3`` and the outward normal
``n = (t_y, -t_x) / |t|``.  A slave node ``x_s`` projects on it by the
closest-point condition::

    f(xi) = (x_s - x(xi)) . x'(xi) = 0,   f'(xi) = -|x'|^2 + (x_s - x(xi)) . x'',

solved by Newton on ``xi`` from the chord's projection, each step limited to
``|dxi| <= 0.5`` and ``xi`` to ``[-3, 3]`` (a node beyond an end converges onto
the curve's extension, as the linear NTS continues onto the segment's line);
the normal gap is ``g = (x_s - x(xi)) . n(xi)``, ``> 0`` open.

Exact derivatives: with ``q = [x_s, x_1, x_2, x_3]`` (8 unknowns) the gap is
``g(q) = G(xi(q), q)`` with ``dG/dxi = 0`` at the projection (``x_s - x`` is
parallel to ``n`` and ``n . x' = 0``, ``n' . n = 0``), so
``dg/dq = dG/dq`` and ``d2g/dq2 = G_qq + 2 G_qxi xi_q + G_xixi xi_q xi_q``:
the second derivatives need only the exact gradient ``xi_q`` of the projection.
Both come from forward-mode jets (:class:`~skfem_mortar.contact.jets.Jet`):
from the converged ``xi`` (a constant), two Newton steps taken in jets give
``xi`` with exact first and second derivatives (each step doubles the order
of agreement), and ``g`` composed from them is exact to second order.

The partner search, the choice among candidate segments (smallest distance to
the clipped projection, then the smaller overshoot), the hysteresis ``stick``
(a fraction of the segment, ``2 stick`` in ``xi``), the locks and the free ends
are those of :func:`skfem_mortar.contact.nts.project` (except at a free end: a
node that keeps its segment by the hysteresis keeps it up to ``stick`` beyond
the end, where the linear kernel drops it beyond ``end_tolerance``; a slave end
over the master end otherwise toggles in and out), with ``xi`` mapped from
``[-1, 1]`` to the linear kernel's ``[0, 1]`` in what it reports
(``info["xi"]``), so the NTS method's segment memory works unchanged.  A
slave surface of 3-node segments makes every node (vertices and mid nodes) a
contact point with the tributary weight ``int N_A dGamma`` (``L/6, L/6, 2L/3``
on a straight segment), the consistent weights of a uniform pressure.
"""
from __future__ import annotations

import numpy as np

from ..core.chain import curve_points, segments_at_nodes, tributary_lengths
from .scatter import Triplets
from .contact_eval import ContactEval
from .jets import Jet, at_gauss, sqrt
from .nts_projection import candidates, choose_segments

__all__ = ["evaluate", "project", "project_values", "projection_jets", "arc_length",
           "curve_values", "N_NEWTON", "XI_LIMIT", "N_ARC"]

#: Newton steps of the closest-point projection on values (quadratic convergence
#: from the chord's projection: 1e-15 in ~6 steps on a segment bent by 10 % of its length)
N_NEWTON = 30
#: the projection's ``xi`` stays in ``[-XI_LIMIT, XI_LIMIT]`` (the curve's extension
#: beyond the ends, far enough for any candidate that can win)
XI_LIMIT = 3.0
#: Gauss points of :func:`arc_length` (the slip of friction along curved segments)
N_ARC = 8


def _curve(P: tuple, xi):
    """``x(xi)``, ``x'(xi)`` and ``x''`` of 3-node segments with nodes ``P = (x1, x2, x3)``
    (each a pair of arrays or jets), at ``xi`` (array or jet)."""
    (x1, y1), (x2, y2), (x3, y3) = P
    N1, N2, N3 = 0.5 * xi * (xi - 1.0), 0.5 * xi * (xi + 1.0), 1.0 - xi * xi
    d1, d2, d3 = xi - 0.5, xi + 0.5, -2.0 * xi
    x = (x1 * N1 + x2 * N2 + x3 * N3, y1 * N1 + y2 * N2 + y3 * N3)
    t = (x1 * d1 + x2 * d2 + x3 * d3, y1 * d1 + y2 * d2 + y3 * d3)
    tt = (x1 + x2 - x3 * 2.0, y1 + y2 - y3 * 2.0)
    return x, t, tt


curve_values = _curve


def _newton_step(xs: tuple, P: tuple, xi):
    """``xi - f / f'`` of the closest-point condition (arrays or jets)."""
    x, t, tt = _curve(P, xi)
    rx, ry = xs[0] - x[0], xs[1] - x[1]
    f = rx * t[0] + ry * t[1]
    df = rx * tt[0] + ry * tt[1] - (t[0] * t[0] + t[1] * t[1])
    return xi - f / df, f, df


def project_values(xs: np.ndarray, P: tuple) -> tuple[np.ndarray, bool]:
    """Closest-point ``xi`` (n,) of the points ``xs (2, n)`` on the curves ``P``,
    by safeguarded Newton from the chord's projection; and whether it converged."""
    (x1, y1), (x2, y2), _ = P
    tx, ty = x2 - x1, y2 - y1
    xi = 2.0 * ((xs[0] - x1) * tx + (xs[1] - y1) * ty) / np.maximum(tx * tx + ty * ty, 1e-300) - 1.0
    xi = np.clip(xi, -XI_LIMIT, XI_LIMIT)
    done = False
    for _ in range(N_NEWTON):
        new, f, df = _newton_step((xs[0], xs[1]), P, xi)
        # f' > 0 is a distance maximum (the node far inside the curve's bend): step
        # against f instead, towards the minimum along the curve
        step = np.where(df < 0, new - xi, -np.sign(f) * 0.5)
        step = np.clip(step, -0.5, 0.5)
        xi_new = np.clip(xi + step, -XI_LIMIT, XI_LIMIT)
        change = np.abs(xi_new - xi)
        xi = xi_new
        if np.all(change <= 1e-14 * (1.0 + np.abs(xi))):
            done = True
            break
    return xi, done


def project(xs: np.ndarray, xm: np.ndarray, seg_m: np.ndarray, margin: float | None = None,
            end_tolerance: float = 1e-8, prefer: np.ndarray | None = None,
            stick: float = 0.05, lock: np.ndarray | None = None) -> dict:
    """Closest-point projection of every slave node on a chain of 3-node master segments.

    Same parameters and result keys as :func:`skfem_mortar.contact.nts.project`
    (``xi`` reported in ``[0, 1]`` along the segment, ``(1 + xi) / 2`` of the
    curve's parameter; ``n``, ``e`` the normal and unit tangent at the
    projection; ``l`` the segment's chord length), plus ``xi_curve`` (the
    parameter in ``[-1, 1]``).
    """
    if not (np.isfinite(stick) and stick >= 0):
        raise ValueError(f"stick must be a finite number >= 0, got {stick}")
    if not (np.isfinite(end_tolerance) and end_tolerance >= 0):
        raise ValueError(f"end_tolerance must be a finite number >= 0, got {end_tolerance}")
    n_s, n_m, n_seg = xs.shape[1], xm.shape[1], len(seg_m)
    chord = np.hypot(*(xm[:, seg_m[:, 1]] - xm[:, seg_m[:, 0]]))
    if margin is None:
        margin = float(np.median(chord)) if chord.size else 0.0
    seg_of_end, seg_of_start = segments_at_nodes(seg_m, n_m)
    key = candidates(xs, xm, seg_m, margin)
    i_n, i_e = key // n_seg, key % n_seg
    P = tuple((xm[0, seg_m[i_e, a]], xm[1, seg_m[i_e, a]]) for a in range(3))
    xq = xs[:, i_n]
    xi_c, _ = project_values(xq, P)
    u = 0.5 * (1.0 + xi_c)                       # along the segment, [0, 1] inside
    (cx, cy), _, _ = _curve(P, np.clip(xi_c, -1.0, 1.0))
    dist = np.hypot(xq[0] - cx, xq[1] - cy)
    best = choose_segments(i_n, i_e, u, dist, n_s, prefer, stick, lock)
    k, e = i_n[best], i_e[best]
    segment = np.full(n_s, -1, dtype=np.int64)
    segment[k] = e
    xi_all = np.zeros(n_s)
    xi_all[k] = xi_c[best]
    mask = segment >= 0
    is_first = seg_of_end[seg_m[:, 0]] < 0
    is_last = seg_of_start[seg_m[:, 1]] < 0
    es = np.where(mask, segment, 0)
    u_all = 0.5 * (1.0 + xi_all)
    # a node that kept its segment (the hysteresis ``prefer``) stays on it within
    # ``stick`` beyond a free end too: sliding off by round-off-sized amounts (a
    # slave end over the master end) would toggle it on and off every iteration
    kept = np.zeros(n_s, dtype=bool)
    if prefer is not None:
        kept = mask & (segment == prefer)
    tol = np.where(kept, max(stick, end_tolerance), end_tolerance)
    off = (is_first[es] & (u_all < -tol)) | (is_last[es] & (u_all > 1 + tol))
    mask &= ~off
    Pk = tuple((xm[0, seg_m[es, a]], xm[1, seg_m[es, a]]) for a in range(3))
    x, t, _ = _curve(Pk, xi_all)
    lt = np.hypot(t[0], t[1])
    e_vec = np.vstack(t) / np.where(lt > 0, lt, 1.0)
    n = np.vstack([e_vec[1], -e_vec[0]])
    g = np.where(mask, np.sum((xs - np.vstack(x)) * n, axis=0), 0.0)
    return {"segment": np.where(mask, segment, -1), "xi": u_all, "xi_curve": xi_all,
            "mask": mask, "n": n, "e": e_vec, "l": chord[es], "g": g}


def projection_jets(xs: np.ndarray, P: tuple, xi: np.ndarray, second: bool
                    ) -> tuple[tuple, tuple, Jet]:
    """The slave points, the segment nodes and the closest-point parameter as jets of
    the 8 local coordinates ``[x_s, x_1, x_2, x_3]`` (x, y each): ``xi`` (the
    converged value) refined by two Newton steps in jets, exact to second order
    (module doc).  Returns ``(js, JP, xi)``."""
    nv = 8
    var = [Jet.variable(v, i, nv, second) for i, v in enumerate(
        [xs[0], xs[1], P[0][0], P[0][1], P[1][0], P[1][1], P[2][0], P[2][1]])]
    js = (var[0], var[1])
    JP = ((var[2], var[3]), (var[4], var[5]), (var[6], var[7]))
    z = Jet.constant(xi, nv, second)
    for _ in range(2):
        z, _, _ = _newton_step(js, JP, z)
    return js, JP, z


def arc_length(P: tuple, a, b, n_gauss: int = N_ARC):
    """The arc length ``int_a^b |x'(xi)| dxi`` along 3-node segments (signed: negative
    for ``b < a``), by an ``n_gauss``-point Gauss rule on ``[a, b]``.

    ``P = (x_1, x_2, x_3)`` the nodes (pairs of arrays or jets, shape (n,)),
    ``a``, ``b`` the curve parameters (arrays or jets, (n,)); the result is a
    jet when any input is one, with the exact derivatives of the rule.  ``|x'|``
    is the square root of a quadratic in ``xi``: constant on a straight segment
    with a centred mid node (the rule is exact there, ``(b - a) L / 2``), and
    smooth otherwise (8 points: 2e-14 relative against adaptive quadrature on a
    segment whose mid node sits 10 % of the chord off it; the rule defines the
    slip, its derivatives are those of the rule, so this is accuracy, not
    consistency).
    """
    eta, w = np.polynomial.legendre.leggauss(n_gauss)
    PE = tuple((at_gauss(p[0]), at_gauss(p[1])) for p in P)
    xi = at_gauss(a) * ((1.0 - eta) * 0.5) + at_gauss(b) * ((1.0 + eta) * 0.5)
    _, t, _ = _curve(PE, xi)
    speed = sqrt(t[0] * t[0] + t[1] * t[1]) * w
    return speed.sum(1) * ((b - a) * 0.5)


def _gap_jets(xs: np.ndarray, P: tuple, xi: np.ndarray, second: bool) -> Jet:
    """``g = (x_s - x(xi)) . n(xi)`` in jets of the 8 local coordinates
    ``[x_s, x_1, x_2, x_3]`` (x, y each), ``xi`` refined by two Newton steps in jets."""
    js, JP, z = projection_jets(xs, P, xi, second)
    x, t, _ = _curve(JP, z)
    rx, ry = js[0] - x[0], js[1] - x[1]
    # n = (t_y, -t_x) / |t|
    return (rx * t[1] - ry * t[0]) / (t[0] * t[0] + t[1] * t[1]).sqrt()


def evaluate(xs: np.ndarray, seg_s: np.ndarray, xm: np.ndarray, seg_m: np.ndarray,
             lam: np.ndarray | None = None, tangent: bool = True,
             margin: float | None = None, end_tolerance: float = 1e-8,
             prefer: np.ndarray | None = None, stick: float = 0.05,
             lock: np.ndarray | None = None) -> ContactEval:
    """NTS gaps of the slave nodes on curved 3-node master segments, ``G = dg/dx``
    and ``H = sum_k lam_k d^2 g_k/dx^2`` (exact, module doc).

    Same parameters and result as :func:`skfem_mortar.contact.nts.evaluate`;
    ``seg_s`` may have 2 or 3 columns (it sets the tributary weights ``area``),
    ``seg_m`` has 3.
    """
    n_s, n_m = xs.shape[1], xm.shape[1]
    if lam is not None:
        lam = np.asarray(lam, dtype=float).ravel()
        if lam.shape != (n_s,):
            raise ValueError(f"lam must have shape ({n_s},), got {lam.shape}")
    pr = project(xs, xm, seg_m, margin, end_tolerance, prefer, stick, lock)
    mask = pr["mask"]
    area = tributary_lengths(xs, seg_s)
    info = {"xi": pr["xi"], "segment": pr["segment"], "normal": pr["n"]}
    if not tangent:
        return ContactEval(g=pr["g"], G=None, H=None, area=area, mask=mask, info=info)
    ndof = 2 * n_s + 2 * n_m
    k = np.flatnonzero(mask)
    es = pr["segment"][k]
    second = lam is not None
    P = tuple((xm[0, seg_m[es, a]], xm[1, seg_m[es, a]]) for a in range(3))
    gj = _gap_jets(xs[:, k], P, pr["xi_curve"][k], second)
    g = pr["g"].copy()
    g[k] = gj.v
    m = seg_m[es]
    dofs = np.column_stack([2 * k, 2 * k + 1] + [2 * n_s + 2 * m[:, a] + c
                                                 for a in range(3) for c in (0, 1)])  # (n, 8)
    Gt = Triplets()
    Gt.rows(k, dofs, gj.g.T)
    G = Gt.csr((n_s, ndof))
    H = None
    if second:
        Ht = Triplets()
        Ht.block(dofs, gj.hessian() * lam[k])
        H = Ht.csr((ndof, ndof))
    return ContactEval(g=g, G=G, H=H, area=area, mask=mask, info=info)


def curve_of(xm: np.ndarray, seg_m: np.ndarray, n_per_segment: int = 8) -> np.ndarray:
    """Points ``(2, n_seg * n_per_segment + 1)`` along a chain of 3-node segments (for
    pictures and distances), in chain order."""
    xi = np.linspace(-1.0, 1.0, n_per_segment + 1)[:-1]
    pts = curve_points(xm, seg_m, xi).reshape(2, -1)
    return np.hstack([pts, xm[:, seg_m[-1, 1:2]]])
