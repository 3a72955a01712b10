"""Forward-mode jets: a value with its exact gradient and Hessian.

A :class:`Jet` carries ``v`` (values stacked over segments and Gauss points),
``g`` (gradients with respect to the local coordinates of a mortar segment) and
``h`` (Hessians). Arithmetic on jets applies the chain rule exactly, so every
quantity composed from them (normals, projections, the mortar integrand) comes
with exact first and second derivatives. Used by :mod:`mortar_segmentation` and
:mod:`mortar`.
"""
from __future__ import annotations

import numpy as np

__all__ = ["Jet", "cross", "normalize", "value", "at_gauss", "constant_like", "inv", "sqrt", "where"]


def _outer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, None] * b[None, :]


def _zero(h: np.ndarray) -> bool:
    """A gradient or Hessian known to vanish: the broadcast zero views made by
    ``Jet.variable``/``constant`` (stride 0 over the variables; with one variable that
    stride says nothing, so the values are looked at)."""
    return h.strides[0] == 0 and (h.shape[0] > 1 or not np.any(h))


def _full(a: tuple, b: tuple) -> tuple:
    """``np.broadcast_shapes(a, b)``, without its cost where the shapes are equal
    (the common case: a fixed cost of every jet operation on small blocks)."""
    return a if a == b else np.broadcast_shapes(a, b)


_ZEROS: dict[tuple, np.ndarray] = {}


def _zeros(shape: tuple) -> np.ndarray:
    """A read-only broadcast view of zeros of ``shape`` (stride 0: :func:`_zero`),
    made once per shape."""
    z = _ZEROS.get(shape)
    if z is None:
        if len(_ZEROS) > 256:  # bounded: shapes follow the block sizes of a run
            _ZEROS.clear()
        z = _ZEROS[shape] = np.broadcast_to(np.zeros(()), shape)
    return z


_UNITS: dict[tuple, np.ndarray] = {}


def _unit(i: int, shape: tuple) -> np.ndarray:
    """The gradient ``e_i`` of an independent variable, a read-only broadcast view of
    ``shape`` ``(nv,) + S``, made once per ``(i, shape)`` (a call makes dozens of
    variables of a few shapes)."""
    key = (i, shape)
    e = _UNITS.get(key)
    if e is None:
        if len(_UNITS) > 1024:  # bounded: shapes follow the block sizes of a run
            _UNITS.clear()
        u = np.zeros((shape[0],) + (1,) * (len(shape) - 1))
        u[i] = 1.0
        e = _UNITS[key] = np.broadcast_to(u, shape)
    return e


def _sum(a: np.ndarray, axis: int) -> np.ndarray:
    """``a.sum(axis)`` to the bit: fewer than 8 terms numpy adds one by one in order
    (8 and more pairwise, left to it), and so does this, whole slices at a time (a
    Hessian's sum over 2 Gauss points: 4.7 times faster, numpy's inner loop over the
    short axis being the slow part)."""
    n = a.shape[axis]
    if not 1 < n < 8:
        return a.sum(axis)
    part = [slice(None)] * a.ndim

    def at(i: int) -> np.ndarray:
        part[axis] = i
        return a[tuple(part)]
    out = at(0) + at(1)
    for i in range(2, n):
        out += at(i)
    return out


def _acc(h: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``h + t``, in place when the shapes allow."""
    if h.shape == _full(h.shape, t.shape):
        h += t
        return h
    return h + t


def _widened(a: np.ndarray, m: int, lead: int) -> np.ndarray:
    """A gradient (``lead`` 1) or Hessian (2) with its variable axes zero-padded to ``m``."""
    if a.shape[0] == m:
        return a
    shape = (m,) * lead + a.shape[lead:]
    if _zero(a):
        return _zeros(shape)
    out = np.zeros(shape)
    out[(slice(0, a.shape[0]),) * lead] = a
    return out


def _match(a: "Jet", b: "Jet") -> tuple:
    """``a``, ``b`` of one number of variables (the larger: :meth:`Jet.widen`)."""
    m = max(a.g.shape[0], b.g.shape[0])
    return a.widen(m), b.widen(m)


def _times_variable(f: "Jet", x: "Jet", left: bool = False) -> "Jet":
    """``f x`` for the independent variable ``x`` (gradient ``e_j``, Hessian 0) and a jet
    ``f`` that is not one: ``g = f' x + f e_j``, ``h = f'' x + 2 f' e_j^T`` (stored
    unsymmetrized: in column ``j``, or row ``j`` when ``x`` is the ``left`` operand,
    where the general product puts it, so that the result is the general product's to
    the bit), without the outer product's ``nv^2`` pass.  ``f`` keeps its number of
    variables when ``j`` is among them (else it takes ``x``'s)."""
    full = _full(f.v.shape, x.v.shape)
    if f.v.shape != full:
        f = f._fill(full)
    j = x.var
    if j >= f.g.shape[0]:
        f = f.widen(x.g.shape[0])
    xv = x.v
    g = f.g * xv
    v = xv * f.v if left else f.v * xv
    g[j] += f.v
    h = None
    if f.h is not None:
        if _zero(f.h):
            h = np.zeros(f.g.shape[:1] + f.g.shape)
        else:
            h = f.h * xv
        if left:
            h[j] += 2.0 * f.g
        else:
            h[:, j] += 2.0 * f.g
    return Jet(v, g, h)


class Jet:
    """A value with its gradient and Hessian w.r.t. ``nv`` local variables.

    ``v`` has a shape ``S`` (e.g. ``(n_seg,)`` or ``(n_seg, n_gauss)``), ``g``
    the shape ``(nv,) + S`` and ``h`` the shape ``(nv, nv) + S`` (variables
    first, so that numpy's inner loops run over the long value axes); ``h`` is
    None when only first derivatives are tracked.  To save the transposed
    additions ``h`` is stored unsymmetrized: the Hessian is ``(h + h^T) / 2``
    (products add ``2 g_a g_b^T`` instead of ``g_a g_b^T + g_b g_a^T``; every
    rule is linear in ``h`` so this is exact), see :meth:`hessian`.
    Arithmetic with plain floats or arrays of shape ``S`` treats those as
    constants.
    """

    __slots__ = ("v", "g", "h", "var")
    __array_ufunc__ = None  # make numpy arrays defer to Jet's reflected operators

    def __init__(self, v: np.ndarray, g: np.ndarray, h: np.ndarray | None,
                 var: int | None = None):
        self.v, self.g, self.h, self.var = v, g, h, var

    # -- construction
    @staticmethod
    def variable(v: np.ndarray, i: int, nv: int, second: bool) -> "Jet":
        """The independent variable number ``i`` (gradient e_i, Hessian 0), as broadcast views."""
        v = np.asarray(v, dtype=float)
        h = _zeros((nv, nv) + v.shape) if second else None
        return Jet(v, _unit(i, (nv,) + v.shape), h, i)

    @staticmethod
    def constant(v: np.ndarray, nv: int, second: bool) -> "Jet":
        """A constant (zero gradient and Hessian), as broadcast views."""
        v = np.asarray(v, dtype=float)
        g = _zeros((nv,) + v.shape)
        h = _zeros((nv, nv) + v.shape) if second else None
        return Jet(v, g, h)

    # -- arithmetic
    def __add__(self, o):
        if isinstance(o, Jet):
            if self.g.shape[0] != o.g.shape[0]:
                self, o = _match(self, o)
            h = None
            if self.h is not None:   # (in-place updates only ever touch fresh arrays)
                full = _full(self.h.shape, o.h.shape)
                if _zero(o.h) and self.h.shape == full:
                    h = self.h
                elif _zero(self.h) and o.h.shape == full:
                    h = o.h
                else:
                    h = self.h + o.h
            return Jet(self.v + o.v, self.g + o.g, h)
        return Jet(self.v + o, self.g, self.h)

    __radd__ = __add__

    def __neg__(self):
        return Jet(-self.v, -self.g, None if self.h is None else -self.h)

    def __sub__(self, o):
        if isinstance(o, Jet):
            if self.g.shape[0] != o.g.shape[0]:
                self, o = _match(self, o)
            h = None
            if self.h is not None:
                full = _full(self.h.shape, o.h.shape)
                if _zero(o.h) and self.h.shape == full:
                    h = self.h
                else:
                    h = self.h - o.h
            return Jet(self.v - o.v, self.g - o.g, h)
        return Jet(self.v - o, self.g, self.h)

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        if isinstance(o, Jet):
            if self.is_constant():            # a constant: a scaled copy, no outer product
                return o * self.v
            if o.is_constant():
                return self * o.v
            if (o.var is None) != (self.var is None):   # one independent variable
                return _times_variable(self, o) if o.var is not None else _times_variable(o, self, True)
            if self.g.shape[0] != o.g.shape[0]:
                self, o = _match(self, o)
            if self.v.shape != o.v.shape:       # materialize the broadcast operand once
                full = _full(self.v.shape, o.v.shape)
                self, o = self._fill(full), o._fill(full)
            g = self.g * o.v + o.g * self.v
            h = None
            if self.h is not None:
                # stored unsymmetrized: sym(h) is the Hessian (see the class doc)
                h = _outer(self.g, o.g * 2.0)
                if not _zero(self.h):
                    h = _acc(h, self.h * o.v)
                if not _zero(o.h):
                    h = _acc(h, o.h * self.v)
            return Jet(self.v * o.v, g, h)
        o = np.asarray(o, dtype=float)
        h = None
        if self.h is not None:
            if _zero(self.h):
                h = _zeros(_full(self.h.shape, o.shape))
            else:
                h = self.h * o
        return Jet(self.v * o, self.g * o, h)

    __rmul__ = __mul__

    def _chain(self, f0, f1, f2) -> "Jet":
        """``f(self)`` given ``f, f', f''`` evaluated at ``self.v``."""
        h = None
        if self.h is not None:
            h = _outer(self.g, self.g * f2)
            if not _zero(self.h):
                h = _acc(h, self.h * f1)
        return Jet(f0, self.g * f1, h)

    def inv(self) -> "Jet":
        """``1 / self``."""
        r = 1.0 / self.v
        return self._chain(r, -r * r, 2.0 * r * r * r)

    def __truediv__(self, o):
        if isinstance(o, Jet):
            return self * o.inv()
        return self * (1.0 / np.asarray(o, dtype=float))

    def __rtruediv__(self, o):
        return self.inv() * o

    def sqrt(self) -> "Jet":
        """``sqrt(self)``."""
        s = np.sqrt(self.v)
        return self._chain(s, 0.5 / s, -0.25 / (s * self.v))

    def first(self) -> "Jet":
        """The same jet without its Hessian (first derivatives only)."""
        return Jet(self.v, self.g, None, self.var)

    def widen(self, nv: int) -> "Jet":
        """The same jet in ``nv >=`` its number of variables: the added ones (last)
        with zero derivatives (a jet may hold fewer variables than the others it meets:
        the trailing ones it does not depend on; arithmetic pads it to the larger)."""
        if self.g.shape[0] == nv:
            return self
        return Jet(self.v, _widened(self.g, nv, 1),
                   None if self.h is None else _widened(self.h, nv, 2), self.var)

    def hessian(self) -> np.ndarray:
        """The symmetric Hessian ``(h + h^T) / 2``, shape ``(nv, nv) + S``."""
        return 0.5 * (self.h + np.swapaxes(self.h, 0, 1))

    # -- shape helpers
    def expand(self) -> "Jet":
        """Insert a Gauss-point axis after the segment axis: ``(n,) -> (n, 1)``."""
        return Jet(self.v[:, None], self.g[..., None],
                   None if self.h is None else self.h[..., None], self.var)

    def is_constant(self) -> bool:
        """Whether the jet is known constant (zero gradient and Hessian views)."""
        return _zero(self.g) and (self.h is None or _zero(self.h))

    def _fill(self, shape: tuple) -> "Jet":
        """The jet broadcast to values ``shape``, materialized (contiguous; products then
        run numpy's inner loops over whole arrays, not over a broadcast length-1 axis:
        2 to 4 times faster); a zero gradient or Hessian stays a zero view."""
        if self.v.shape == shape:
            return self

        def fill(a, lead):
            s = a.shape[:lead] + shape
            return _zeros(s) if _zero(a) else np.ascontiguousarray(np.broadcast_to(a, s))
        return Jet(np.ascontiguousarray(np.broadcast_to(self.v, shape)), fill(self.g, 1),
                   None if self.h is None else fill(self.h, 2), self.var)

    def spread(self, shape: tuple) -> "Jet":
        """The jet of values ``(n,)`` repeated over a point axis, values ``shape``
        ``(n, q)``, materialized (:meth:`_fill`)."""
        return self.expand()._fill(shape)

    def sum(self, axis: int = 1) -> "Jet":
        """Sum over a value axis (e.g. the Gauss points)."""
        return Jet(self.v.sum(axis), _sum(self.g, axis + 1),
                   None if self.h is None else _sum(self.h, axis + 2))

    def take(self, idx) -> "Jet":
        """Entries ``idx`` of the leading value axis."""
        return Jet(self.v[idx], self.g[:, idx], None if self.h is None else self.h[:, :, idx],
                   self.var)

    @staticmethod
    def where(cond: np.ndarray, a: "Jet", b: "Jet") -> "Jet":
        """Elementwise ``cond ? a : b`` (both jets of the same variables)."""
        c = np.asarray(cond)
        if a.g.shape[0] != b.g.shape[0]:
            a, b = _match(a, b)
        v = np.where(c, a.v, b.v)
        g = np.where(c, a.g, b.g)
        h = None
        if a.h is not None:
            h = (_zeros(a.h.shape[:2] + v.shape) if _zero(a.h) and _zero(b.h)
                 else np.where(c, a.h, b.h))
        return Jet(v, g, h)


def value(x):
    """The value of a jet, or ``x`` itself."""
    return x.v if isinstance(x, Jet) else x


_val = value


def cross(ax, ay, bx, by):
    """2D cross product ``a x b = a_x b_y - a_y b_x`` (jets or arrays)."""
    return ax * by - ay * bx


def normalize(x, y):
    """``(x, y) / |(x, y)|`` for jets."""
    r = (x * x + y * y).sqrt().inv()
    return x * r, y * r


# -- helpers that take jets or plain arrays alike (the kernel's steps run on both)
def at_gauss(c):
    """A per-segment quantity ``(n,)`` with a Gauss-point axis: ``(n, 1)``."""
    return c.expand() if isinstance(c, Jet) else np.asarray(c)[:, None]


def constant_like(v, like):
    """``v`` as a constant of the same kind as ``like`` (a jet of its variables, or an array)."""
    if isinstance(like, Jet):
        return Jet.constant(v, like.g.shape[0], like.h is not None)
    return np.asarray(v, dtype=float)


def where(cond, a, b):
    """Elementwise ``cond ? a : b`` for jets or arrays."""
    return Jet.where(cond, a, b) if isinstance(a, Jet) else np.where(cond, a, b)


def inv(x):
    """``1 / x`` for a jet or an array."""
    return x.inv() if isinstance(x, Jet) else 1.0 / x


def sqrt(x):
    """``sqrt(x)`` for a jet or an array."""
    return x.sqrt() if isinstance(x, Jet) else np.sqrt(x)
