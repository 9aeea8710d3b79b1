"""The small-voltage (Debye-Hueckel) series of the moment integral, at any thickness.

Why: every rung divides quantities of order ``A2`` by ``A2`` (``Yc = ln B1 ~ A2/2`` from a
rounded ``B1``, ``(C - 1)/A2``, ``int C z dz / A2``), so its relative rounding error grows like
``eps/A2`` and the result is meaningless once ``A2`` is below ~1e-8 (and NaN or overflowing
in the subnormal range).  Below ``DH_A2`` the kernels evaluate this series instead: no
cancellation, exact as ``A2 -> 0``, with a derived bound on what it leaves out.

Derivation (seed paper section 4, the system of ``model.py`` in ``s = z/lam``, ``u = 1/lam``):
with ``X = ln C = ln B1 - A2 phi`` and ``eps = A2 lam^2 ((1 - rho) C + rho)`` the system is
``(g X_s)_s = (C - 1)/A2``, ``g = 1 + (1 - rho)(C - 1)``, ``X(-u) = ln B1 - A2``,
``X(u) = ln B1``, ``int (C - 1) ds = 0``.  Expanding ``X = sum_k A2^k x_k`` gives at each order
``x_k'' - x_k = (source from lower orders)``, solved exactly on the basis ``s^m e^{j s}``
(undetermined coefficients, resonant terms ``j = +-1`` with one more power of ``s``) with the
two boundary conditions and neutrality fixing ``x_k`` and the ``A2^k`` term of ``ln B1``.
The moment ``I = int_{-1}^{1} p z dz = lam^2 int s (C/A2 - A3 phi) ds`` then is

    I = I0(u) + A2^2 I2(u) + A2^4 I4(u) + ...     (even in A2: M_A = A5 I is odd in phi0)
    I0 = (1 + A3) (lam coth(1/lam) - lam^2)

exact in ``lam`` (overlapping layers included).  As ``u -> oo`` (dropping ``e^{-u}``) each
``I_k`` is ``lam j1_k + lam^2 j2_k``: the series of the layer rungs' ``J1``, ``J2``
(``model.moment_assembly``), e.g. ``J1 -> 1 + A3``, ``J2 -> -(1 + A3)``.

Remainder bound: ``|I4| <= (K4A + K4B |A3|) n(u)`` with ``n(u) = lam coth(1/lam) - lam^2``
(``I0 = (1 + A3) n``); the constants are the maxima over ``u`` in [0.02, 1e4] (22 points, log-spaced) and ``rho`` in
{0, 0.2, .., 1} of the A3-free and A3 parts of ``I4/n`` (computed from the order-4 solution at 40 digits),
times ``MARGIN``.  The terms beyond decrease by ~0.1 A2^2 each (nearest singularities at
``|A2| ~ pi``: ``B1`` of the linear model has poles at ``A2 = +-i pi``), so below ``DH_A2``
twice the ``A2^4`` term bounds the whole remainder.

Evaluation without cancellation: with ``Q = e^{-2u}`` the ``I_k`` are polynomials in ``Q``
over ``u^2 (1 - Q)^j`` (no overflow at any ``u``); below ``U_SERIES`` (thin strips, where
``1 - Q`` cancels) their Taylor series in ``u`` (radius pi, terms to ``u^16``: truncation
<= (U_SERIES/pi)^18 ~ 1e-14 relative).
"""

from __future__ import annotations

import functools

import mpmath as mp
import sympy as sp
from sympy.codegen.cfunctions import expm1

from . import model as M
from .kernel import Kernel

s, u, E = sp.symbols("s u E", positive=True)
a = sp.Symbol("a")
rho, A3, A2, lam = M.rho, M.A3, M.A2, M.lam
Qs = sp.Symbol("Q", positive=True)

#: below this A2 (phi0 ~ 5e-5 V at 300 K) the rungs evaluate the series: there the bound
#: 2 (K4A + K4B |A3|) A2^4 is <= ~3e-13 relative, and the rungs' own rounding (~eps/A2)
#: is <= ~1e-13 just above it
DH_A2 = 2e-3
#: below this u = 1/lam the Taylor series in u replaces the Q = e^{-2u} form
U_SERIES = 0.5
#: powers of u kept in the small-u series (even powers up to U_ORDER - 2)
U_ORDER = 18
#: safety factor on the measured maxima of the order-4 coefficient
MARGIN = 1.25


# ---- functions of s: {(m, j): c} = sum c s^m e^{j s} -----------------------------------
def _add(*fs):
    out = {}
    for f in fs:
        for key, c in f.items():
            out[key] = out.get(key, 0) + c
    return {k: v for k, v in out.items() if v != 0}


def _scale(f, c):
    return {k: v * c for k, v in f.items()}


def _mul(f, g):
    out = {}
    for (m1, k1), c1 in f.items():
        for (m2, k2), c2 in g.items():
            key = (m1 + m2, k1 + k2)
            out[key] = out.get(key, 0) + c1 * c2
    return out


def _diff(f):
    out = {}
    for (m, k), c in f.items():
        if m:
            out[(m - 1, k)] = out.get((m - 1, k), 0) + m * c
        if k:
            out[(m, k)] = out.get((m, k), 0) + k * c
    return out


def _at(f, sign):
    """Value at ``s = sign u`` with ``e^u = E``."""
    return sum(c * (sign * u) ** m * E ** (sign * k) for (m, k), c in f.items())


@functools.lru_cache(maxsize=None)
def _int_mono(m, k):
    F = sp.integrate(s**m * sp.exp(k * s), s)
    return sp.expand(F.subs(s, u) - F.subs(s, -u)).subs(sp.exp(u), E).subs(sp.exp(-u), 1 / E)


def _integ(f):
    """``int_{-u}^{u} f ds``."""
    return sum(c * _int_mono(m, k) for (m, k), c in f.items())


@functools.lru_cache(maxsize=None)
def _part_mono(m, k):
    """A particular solution of ``x'' - x = s^m e^{k s}``."""
    deg = m + (1 if k * k == 1 else 0)  # resonance: one more power of s
    cs = sp.symbols(f"p0:{deg + 1}")
    P = sum(cs[i] * s**i for i in range(deg + 1))
    r = sp.expand(sp.diff(P, s, 2) + 2 * k * sp.diff(P, s) + (k * k - 1) * P - s**m)
    sol = sp.solve(sp.Poly(r, s).all_coeffs(), cs, dict=True)[0]
    P = sp.Poly(P.subs(sol).subs({c: 0 for c in cs}), s)
    return {(i, k): P.coeff_monomial(s**i) for i in range(deg + 1) if P.coeff_monomial(s**i) != 0}


def _particular(src):
    out = {}
    for (m, k), c in src.items():
        for key, v in _part_mono(m, k).items():
            out[key] = out.get(key, 0) + v * c
    return out


_ONE = {(0, 0): sp.Integer(1)}
_SINH = {(0, 1): sp.Rational(1, 2), (0, -1): -sp.Rational(1, 2)}
_COSH = {(0, 1): sp.Rational(1, 2), (0, -1): sp.Rational(1, 2)}


def _evalpoly(expr, env):
    """A polynomial in the symbols of ``env`` (coefficients in rho) as a function of s."""
    out = {}
    for term in sp.Add.make_args(sp.expand(expr)):
        f, c = _ONE, sp.Integer(1)
        for fac in sp.Mul.make_args(term):
            base, ex = fac.as_base_exp()
            if base in env:
                for _ in range(int(ex)):
                    f = _mul(f, env[base])
            else:
                c *= fac
        out = _add(out, _scale(f, c))
    return out


def _det3(m):
    """The determinant of a 3x3 matrix by cofactors, unexpanded: SymPy's ``det`` expands every
    product of the order-3 entries (~40 s); the remainder bound only evaluates it numerically."""
    return (m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1])
            - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
            + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]))


@functools.lru_cache(maxsize=None)
@functools.lru_cache(maxsize=None)
def solutions(n: int = 3):
    """``(xs, env, rhs)``: the orders ``x_1 .. x_n`` of ``X = ln C = sum_k A2^k x_k`` (``env`` maps
    each ``x_k`` and its derivative ``dx_k`` to a function of s, ``{(m, j): c}``) and ``(C - 1)/A2``
    as a series in ``a = A2``.

    Orders up to 2 are simplified (they become kernels); higher orders are left as they come
    (only evaluated numerically, for the remainder bound).
    """
    xs = sp.symbols(f"x1:{n + 1}")
    dxs = sp.symbols(f"dx1:{n + 1}")
    X = sum(a ** (k + 1) * xs[k] for k in range(n))
    dX = sum(a ** (k + 1) * dxs[k] for k in range(n))
    C1 = sp.expand(sp.series(sp.exp(X) - 1, a, 0, n + 1).removeO())  # C - 1
    flux = sp.expand(sp.series((1 + (1 - rho) * C1) * dX / a, a, 0, n).removeO())  # g X_s / A2
    rhs = sp.expand(sp.series(C1 / a, a, 0, n).removeO())  # (C - 1)/A2
    env = {}
    Aa, Bb, bk = sp.symbols("Aa Bb bk")
    for order in range(n):
        fk = _evalpoly(flux.coeff(a, order) - dxs[order], env)
        rk = _evalpoly(rhs.coeff(a, order) - xs[order], env)
        part = _particular(_add(rk, _scale(_diff(fk), -1)))
        xg = _add(part, _scale(_SINH, Aa), _scale(_COSH, Bb))
        eqs = [_at(xg, 1) - bk, _at(xg, -1) - (bk - 1 if order == 0 else bk), _integ(_add(xg, rk))]
        if order <= 2:
            sol = sp.solve(eqs, [Aa, Bb, bk], dict=True)[0]
            xk = {k: sp.factor(sp.together(v.subs(sol))) for k, v in xg.items()}
            xk = {k: v for k, v in xk.items() if v != 0}
        else:  # Cramer's rule, unsimplified (evaluated numerically only)
            Mx, rv = sp.linear_eq_to_matrix(eqs, [Aa, Bb, bk])
            det = _det3(Mx)
            coef = []
            for i in (0, 1):  # Aa, Bb (bk, the A2^k term of ln B1, does not enter x_k)
                Mi = Mx.copy()
                Mi[:, i] = rv
                coef.append(_det3(Mi) / det)
            # x_k built from its parts rather than by substituting into xg: ``subs`` walks the
            # unexpanded determinants once per term
            xk = _add(part, _scale(_SINH, coef[0]), _scale(_COSH, coef[1]))
        env[xs[order]] = xk
        env[dxs[order]] = _diff(xk)
    return xs, env, rhs


def perturbation(n: int = 3) -> dict:
    """``{k: I_k(u, E, rho, A3)}`` for even ``k < n`` (``E = e^u``), from ``x_1 .. x_n``
    (:func:`solutions`); orders up to 2 simplified."""
    xs, env, rhs = solutions(n)
    # p z: C/A2 - A3 phi with phi = (ln B1 - X)/A2; constants drop (int s ds = 0)
    Ia = sp.expand(rhs + A3 * sum(a**k * xs[k] for k in range(n)))
    out = {}
    for order in range(0, n, 2):
        val = _integ(_mul(_evalpoly(Ia.coeff(a, order), env), {(1, 0): sp.Integer(1)})) / u**2
        out[order] = sp.factor(sp.together(val)) if order <= 2 else val
    return out


def profile_leading():
    """The Debye-Hueckel profiles: order 0, in the overflow-free form that is evaluated.

    ``X = A2 x_1 + O(A2^2)`` with ``x_1 = sinh(s)/(2 sinh u)`` (checked here), so ``C - 1 = A2 S``
    with ``S = x_1``; ``phi = (ln B1 - X)/A2 = 1/2 - S`` (``ln B1 = A2 x_1(u) + ..., x_1(u) = 1/2``);
    the field ``E = -dphi/dz_bar = u dS/ds``.  ``S`` is odd and ``E`` even in ``s``: at ``a = |s|``,
    ``k = u``,

        |S| = e^{a - k} (1 - e^{-2a}) / (2 (1 - e^{-2k})),   E = k e^{a - k} (1 + e^{-2a}) / (2 (1 - e^{-2k}))

    (checked against ``x_1``): every exponential is at most 1 (no overflow at thick strips) and each
    ``1 - e^{-x}`` is ``-expm1(-x)`` (no cancellation at thin ones).

    Returns
    -------
    list of (name, args, expression, doc)
        ``dh_profile_s(a, k)`` = ``|S|`` and ``dh_profile_e(a, k)`` = ``E``.
    """
    xs, env, _ = solutions()
    x1 = sum(c * s**m * sp.exp(j * s) for (m, j), c in env[xs[0]].items()).subs(E, sp.exp(u))
    assert sp.simplify((x1 - sp.sinh(s) / (2 * sp.sinh(u))).rewrite(sp.exp)) == 0, x1
    assert sp.simplify(x1.subs(s, u)) == sp.Rational(1, 2)
    ka, kk = sp.symbols("a k", positive=True)
    S_abs = sp.exp(ka - kk) * (-expm1(-2 * ka)) / (2 * (-expm1(-2 * kk)))
    E_abs = kk * sp.exp(ka - kk) * (1 + sp.exp(-2 * ka)) / (2 * (-expm1(-2 * kk)))
    at = {ka: s, kk: u}  # s > 0: a = s
    assert sp.simplify((S_abs.subs(at).rewrite(sp.exp) - x1).rewrite(sp.exp)) == 0
    assert sp.simplify((E_abs.subs(at).rewrite(sp.exp) - u * sp.diff(x1, s)).rewrite(sp.exp)) == 0
    return [
        ("dh_profile_s", (ka, kk), S_abs,
         "|S| at a = |z_bar|/lam, k = 1/lam: C - 1 = A2 S, phi = 1/2 - S (S odd in z_bar), leading order in A2."),
        ("dh_profile_e", (ka, kk), E_abs,
         "E = -dphi/dz_bar at a = |z_bar|/lam, k = 1/lam (even in z_bar), leading order in A2."),
    ]


def check_leading():
    """``I0 = (1 + A3)(lam coth(1/lam) - lam^2)``, the linear (Debye-Hueckel) solution."""
    I0 = perturbation()[0]
    target = (1 + A3) * (sp.coth(u) / u - 1 / u**2)
    assert sp.simplify((I0.subs(E, sp.exp(u)) - target).rewrite(sp.exp)) == 0
    return True


def q_form(expr):
    """``expr(u, E)`` with ``E = Q^{-1/2}`` as (numerator polynomial in Q, denominator)."""
    num, den = sp.fraction(sp.together(expr))
    deg = max(sp.degree(num, E), sp.degree(den, E))
    num = sp.expand(num * E**-deg).subs(E, Qs ** sp.Rational(-1, 2))
    den = sp.expand(den * E**-deg).subs(E, Qs ** sp.Rational(-1, 2))
    return sp.collect(sp.expand(num), Qs), sp.factor(den)


def layer_limit(expr):
    """``(j1, j2)`` with ``expr -> lam j1 + lam^2 j2`` as ``u -> oo`` (``Q = e^{-2u} -> 0``)."""
    num, den = q_form(expr)
    lim = sp.expand(sp.cancel(num.subs(Qs, 0) / den.subs(Qs, 0)).subs(u, 1 / lam))
    j1, j2 = lim.coeff(lam, 1), lim.coeff(lam, 2)
    assert sp.simplify(lim - j1 * lam - j2 * lam**2) == 0, lim
    return sp.factor(j1), sp.factor(j2)


@functools.lru_cache(maxsize=None)
def small_u(order: int):
    """Taylor polynomial in ``u`` (to ``u^(U_ORDER - 2)``) of ``I_order``."""
    num, den = q_form(perturbation()[order])
    m = 6  # den = 432 u^2 (1 - Q)^4 ~ 6912 u^6 (I0: u^2 (1 - Q) ~ 2 u^3)
    n = U_ORDER + m + 2
    q_ser = sum((-2 * u) ** k / sp.factorial(k) for k in range(n))  # Q = e^{-2u}

    def trunc(ex):
        # ex(Q = q_ser) by Horner's rule in Q on polynomials cut at u^n after every product: the
        # same coefficients as expanding the substitution, without the terms of degree >= n in u
        # that the full expansion builds and drops (25x faster at order 2)
        gens = (u,) + tuple(sorted(ex.free_symbols - {u, Qs}, key=str))
        q = sp.Poly(q_ser, *gens)

        def cut(p):
            if p.degree(u) < n:
                return p
            return sp.Poly.from_dict({m: c for m, c in p.as_dict().items() if m[0] < n}, *gens, domain=p.domain)

        r = sp.Poly(0, *gens)
        for c in sp.Poly(ex, Qs).all_coeffs():  # highest power of Q first
            r = cut(r * q + sp.Poly(c, *gens))
        p = sp.Poly(r.as_expr(), u)
        return [p.coeff_monomial(u**k) for k in range(n)]

    a, b = trunc(num), trunc(den)
    lo = next(k for k, c in enumerate(b) if c != 0)
    assert lo <= m and all(c == 0 for c in a[:lo]), "I_k is not finite as u -> 0"
    a, b = a[lo:], b[lo:]
    inv = [1 / b[0]]  # power series of 1/(den/u^lo), exact rationals
    for k in range(1, U_ORDER):
        inv.append(-sum(b[i] * inv[k - i] for i in range(1, k + 1)) / b[0])
    coef = [sp.factor(sp.expand(sum(a[i] * inv[k - i] for i in range(k + 1)))) for k in range(U_ORDER)]
    return sum(c * u**k for k, c in enumerate(coef))


def b1_series(order: int = 4):
    """``B1 = C(+e)/C_moy`` as a series in A2 (exact electroneutrality, ``model.b1_quadratic_rho``)."""
    q, aa, bb, cc = M.b1_quadratic_rho()
    cs = sp.symbols(f"beta1:{order + 1}")
    B = 1 + sum(cs[k] * A2 ** (k + 1) for k in range(order))
    eq = (aa * B**2 + bb * B + cc).subs(q, 1 - sp.exp(-A2))
    ser = sp.expand(sp.series(eq, A2, 0, order + 2).removeO())
    sol = {}
    for k in range(order):
        ck = sp.expand(ser.coeff(A2, k + 2).subs(sol))
        sol[cs[k]] = sp.factor(sp.solve(ck, cs[k])[0])
    return sp.expand(B.subs(sol))


@functools.lru_cache(maxsize=None)
def order_four():
    """``I4(u, E, rho, A3)``, unsimplified: ``perturbation(5)[4]`` (~5 s of SymPy)."""
    return perturbation(5)[4]


@functools.lru_cache(maxsize=None)
def remainder_constants():
    """``(K4A, K4B)``: ``|I4| <= (K4A + K4B |A3|) n(u)`` over u in [0.02, 1e4], rho in [0, 1]."""
    # common subexpressions evaluated once: the unexpanded Cramer quotients of the order-3 and
    # order-4 solutions share most of their terms
    f = sp.lambdify((u, E, rho, A3), order_four(), "mpmath", cse=True)
    worst_a = worst_b = mp.mpf(0)
    with mp.workdps(60):
        for ui in mp.linspace(mp.log(mp.mpf("0.02")), mp.log(mp.mpf(10000)), 22):
            uu = mp.exp(ui)
            n = mp.coth(uu) / uu - 1 / uu**2
            for ri in range(6):
                r = mp.mpf(ri) / 5
                p0 = f(uu, mp.exp(uu), r, 0)  # I4 is linear in A3: p0 + A3 (p1 - p0)
                worst_a = max(worst_a, abs(p0) / n)
                worst_b = max(worst_b, abs(f(uu, mp.exp(uu), r, 1) - p0) / n)
    return float(MARGIN * worst_a), float(MARGIN * worst_b)


def kernels():
    """Kernels of ``_generated_dh.py`` and its constants."""
    pert = perturbation()
    ks = []
    parts = {}
    for k in (0, 2):
        num, den = q_form(pert[k])
        parts[k] = sp.Piecewise((small_u(k), u < U_SERIES), (num / den, True))
    Qv = sp.exp(-2 * u)
    ks.append(Kernel(
        "dh_moment", (u, A2, A3, rho),
        ((parts[0] + A2**2 * parts[2]).subs(Qs, Qv),),
        "Debye-Hueckel series I0(u) + A2^2 I2(u) of the moment integral, u = 1/lam (any u > 0).",
        "derivations.debye_hueckel:perturbation"))
    j = [layer_limit(pert[k]) for k in (0, 2)]
    ks.append(Kernel(
        "dh_layer_j", (A2, A3, rho),
        (j[0][0] + A2**2 * j[1][0], j[0][1] + A2**2 * j[1][1]),
        "(J1, J2) of the layer rungs to O(A2^2) (the u -> oo limit of dh_moment).",
        "derivations.debye_hueckel:layer_limit"))
    ks.append(Kernel(
        "dh_b1", (A2, rho), (b1_series(4),),
        "B1 = C(+e)/C_moy to O(A2^4) (exact electroneutrality), for A2 < DH_A2.",
        "derivations.debye_hueckel:b1_series"))
    ks.append(Kernel(
        "dh_norm", (u,), (parts[0].subs(A3, 0).subs(Qs, Qv),),
        "n(u) = lam coth(1/lam) - lam^2 = I0/(1 + A3): the scale of the remainder bound.",
        "derivations.debye_hueckel:check_leading"))
    k4a, k4b = remainder_constants()
    consts = {"DH_A2": DH_A2, "DH_K4A": k4a, "DH_K4B": k4b}
    return ks, consts


def main():
    print("I0 = (1 + A3)(lam coth(1/lam) - lam^2):", check_leading())
    pert = perturbation()
    for k in (0, 2):
        print(f"layer limit of I{k}: (j1, j2) =", layer_limit(pert[k]))
    print("B1 =", b1_series(3))
    print("K4A, K4B =", remainder_constants())


if __name__ == "__main__":
    main()
