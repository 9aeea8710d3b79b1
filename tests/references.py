"""Independent reference solutions shared by the tests (written here, not taken from the package).

* linear model: exact solution ``C = 1 + (B1 - 1) sinh(z/z0)/sinh(1/z0)`` (paper eqs (29)-(30));
* constant / affine: first integral + layer quadratures (core neutral, exponentially small
  error), with scipy.integrate.quad at tight tolerances;
* :func:`jitted_reach`: what a compiled function names, read from its code (the tests that a
  rung's driver compiles no other rung's kernels).
"""

from __future__ import annotations

import math
import types
from pathlib import Path

from scipy.integrate import quad

#: the repository (tests/ is one level below it)
REPO = Path(__file__).resolve().parents[1]

QKW = dict(epsabs=1e-15, epsrel=1e-13, limit=400)


def I_linear_exact(g):
    """Exact ``I`` of the linear model (A1 = 0): the ODE is linear, C'' = (C - 1)/z0^2."""
    A0, A2, A3 = g.A0, g.A2, g.A3
    z0 = math.sqrt(A0 / A2)
    t = math.tanh(0.5 * A2)  # B1 - 1 with B1 = 2/(1 + e^{-A2})
    cw = 2.0 * math.exp(-A2) / (1.0 + math.exp(-A2))  # C(-1) = B1 e^{-A2}, no cancellation
    den = -math.expm1(-2.0 / z0)

    def ratio(x):  # sinh(x/z0)/sinh(1/z0) for 0 <= x <= 1, no overflow
        return math.exp(-(1.0 - x) / z0) * (-math.expm1(-2.0 * x / z0)) / den

    def one_minus_ratio(x):  # 1 - ratio(1 - d), d = 1 - x, cancellation-free
        d = 1.0 - x
        return (-math.expm1(-d / z0) + math.exp(-(2.0 - d) / z0) - math.exp(-2.0 / z0)) / den

    # int (C - 1) z dz = 2 (B1 - 1)(z0 coth(1/z0) - z0^2)
    coth = (1.0 + math.exp(-2.0 / z0)) / den
    part1 = 2.0 * t * (z0 * coth - z0 * z0)

    # int z ln C dz: cathode half z = x, anode half z = -(1 - d) with C = cw + t (1 - ratio)
    def f_cat(x):
        return x * math.log1p(t * ratio(x))

    def f_an(d):
        x = 1.0 - d
        return -x * math.log(cw + t * one_minus_ratio(x))

    brk = [z0 * k for k in (0.01, 0.1, 0.5, 1, 2, 5, 10, 20, 40)]
    brk = [b for b in brk if b < 1.0]
    Jc = sum(quad(f_cat, 1 - b2, 1 - b1, **QKW)[0]
             for b1, b2 in zip([0.0] + brk, brk + [1.0]))
    # anode: d from 0; the log has its knee at d ~ cw z0 / t (~1e-19): split there too
    dk = cw * z0 / t
    abrk = [dk * 10.0 ** k for k in range(-2, 40) if dk * 10.0 ** k < 0.01 * z0] + brk
    Ja = sum(quad(f_an, b1, b2, **QKW)[0] for b1, b2 in zip([0.0] + abrk, abrk + [1.0]))
    return part1 / A2 + A3 / A2 * (Jc + Ja)


def _em1my(y):
    """``e^y - 1 - y`` without cancellation."""
    if abs(y) < 1e-3:
        return y * y * (0.5 + y * (1 / 6 + y * (1 / 24 + y * (1 / 120 + y / 720))))
    return math.expm1(y) - y


def I_layer_quadrature(g):
    """``I`` from the first integral, exact electroneutrality and per-layer quadratures."""
    A0, A1, A2, A3 = g.A0, g.A1, g.A2, g.A3
    em = -math.expm1(-A2)
    a = 0.5 * A0 * (-math.expm1(-2 * A2))
    bq = (A1 - A0) * em
    c = -A1 * A2
    B1 = (-bq + math.sqrt(bq * bq - 4 * a * c)) / (2 * a) if a > 0 else -c / bq
    yc, ya = math.log(B1), math.log(B1) - A2

    def H(y):
        cm1 = math.expm1(y)
        return 0.5 * A0 * cm1 * cm1 + A1 * _em1my(y)

    def w(y):  # |dz/dy| in a layer
        return (A0 * math.exp(y) + A1) / math.sqrt(2 * A2 * H(y))

    def yw(y):
        return y * w(y) if y != 0.0 else math.copysign(math.sqrt((A0 + A1) / A2), 1.0)

    D1 = math.sqrt(2 * H(yc) / A2)
    int_rho_z = 2 * D1 - A1 - A0 * B1 * em / A2

    # cathode, z = 1 - u: int y z dz = M0 - M1;  M1 = int_0^yc w(y') m(y') dy',
    # m(y') = int_0^y' y w dy  (u(y) = int_y^yc w)
    M0 = quad(yw, 0.0, yc, **QKW)[0]
    M1 = quad(lambda yp: w(yp) * quad(yw, 0.0, yp, **QKW)[0], 0.0, yc, **QKW)[0]
    # anode, z = -1 + v: int y z dz = -M0a + M1a;  M1a = int_ya^0 w(y') int_y'^0 y w dy dy'
    M0a = quad(yw, ya, 0.0, **QKW)[0]
    pts = [p for p in (-30.0, -10.0, -3.0, -1.0) if p > ya]
    M1a = quad(lambda yp: w(yp) * quad(yw, yp, 0.0, **QKW)[0], ya, 0.0, points=pts, **QKW)[0]
    Jy = M0 - M1 - M0a + M1a
    return int_rho_z / A2 + A3 / A2 * Jy, B1


def partial_electrode_statics(L, EI, x1, x2):
    """Small-displacement statics per unit active moment on ``[x1, x2]`` (closed form, by hand).

    ``EI w'' = m - M_a`` with ``m = A + B x`` (no load).  Free tip (``m = 0``): ``theta = -(x2 - x1)/EI``,
    ``w = -int_{x1}^{x2} (L - x) dx/EI``.  Pinned tip (``m(L) = 0``, ``w(L) = 0``):
    ``F = -m' = 3 int_{x1}^{x2} (L - x) dx/L^3``.  Clamped tip (``w(L) = w'(L) = 0``):
    ``A L + B L^2/2 = x2 - x1``, ``A L^2/2 + B L^3/6 = int_{x1}^{x2} (L - x) dx``; reaction moments
    ``m(0), m(L)``, forces ``m'(0)``, ``-m'(L)``, and ``w(L/2) = [A h^2/2 + B h^3/6 - int_{[x1, x2] and [0, h]}
    (h - x) dx]/EI`` with ``h = L/2``.
    """
    lever = ((L - x1) ** 2 - (L - x2) ** 2) / 2.0  # int_{x1}^{x2} (L - x) dx
    A = (6.0 * lever - 2.0 * (x2 - x1) * L) / L**2
    B = (6.0 * (x2 - x1) * L - 12.0 * lever) / L**3
    h = L / 2.0
    c, d = min(x1, h), min(x2, h)
    w_mid = (A * h * h / 2.0 + B * h**3 / 6.0 - ((h - c) ** 2 - (h - d) ** 2) / 2.0) / EI
    return {"w": -lever / EI, "theta": -(x2 - x1) / EI, "F": 3.0 * lever / L**3,
            "M_root": A, "M_tip": A + B * L, "F_root": B, "F_tip": -B, "w_mid": w_mid}


def _is_jitted(obj):
    import numba

    return isinstance(obj, numba.core.dispatcher.Dispatcher)


def jitted_reach(f):
    """The jitted functions a jitted ``f`` names, transitively (what Numba compiles with it: a name in
    a branch not taken is compiled all the same)."""
    seen, todo = set(), [f]
    while todo:
        g = todo.pop()
        if g in seen:
            continue
        seen.add(g)
        code, glb = g.py_func.__code__, g.py_func.__globals__
        names = set(code.co_names)
        for c in code.co_consts:  # nested code (comprehensions)
            if hasattr(c, "co_names"):
                names |= set(c.co_names)
        for n in names:
            v = glb.get(n)
            if _is_jitted(v):
                todo.append(v)
            elif isinstance(v, types.ModuleType) and v.__name__.startswith("ipmc_asym."):
                # a module's kernel called as module.name: co_names holds the attribute name too
                todo.extend(getattr(v, a) for a in names if _is_jitted(getattr(v, a, None)))
    return seen
