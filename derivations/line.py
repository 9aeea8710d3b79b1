"""Electrode surface resistance: the strip as an RC transmission line along its length.

The two plated electrodes have a sheet (surface) resistance ``R_s`` (Ohm/sq).  The voltage
across the thickness at ``x`` is ``V(x) = phi_top(x) - phi_bottom(x)``; the current ``I(x)``
that still has to cross the thickness beyond ``x`` flows out along one electrode and back
along the other, so each electrode drops ``R_s/(2l)`` per unit length in opposite senses and

    dV/dx = -r I,   r = 2 R_s/(2l)       (series resistance per length, both electrodes, Ohm/m)
    dI/dx = -y V,   y = 2l/Z_area(s)     (shunt admittance per length, S/m)

with ``Z_area`` the through-thickness impedance per unit electrode area (linearised PNP or the
reduced circuit, ``ipmc_asym.dynamics.circuit``).  Drive ``V(0) = V0`` at the clamp, open far
end ``I(L) = 0``.  Results derived and checked here (``python -m derivations.line``), with
``gamma = sqrt(r y)``, ``g = gamma L`` (``g^2 = 2 R_s L^2/Z_area``: the width cancels) and
``xi = x/L``:

1. ``V(x)/V0 = cosh(gamma (L - x))/cosh(gamma L)`` (telegrapher's equations).
2. ``Z_in = V0/I(0) = Z0 coth(gamma L)``, ``Z0 = sqrt(r/y)``; relative to the uniform strip
   ``Z_u = 1/(y L) = Z_area/(2l L)``: ``Z_in/Z_u = g coth g``.
3. The moment per unit length follows the local voltage, ``M(x) = H_M(s) V(x)``; the small-
   displacement beam (curvature ``M/(E I_p)``, clamped at 0) gives the tip deflection
   ``w = -int_0^L (L - x) M dx/(E I_p)`` and rotation ``theta = -int_0^L M dx/(E I_p)``:
   relative to the uniform strip (``-M L^2/(2 E I_p)``, ``-M L/(E I_p)``)
   ``F_w = 2 (g sinh g - cosh g + 1)/(g^2 cosh g)`` and ``F_theta = tanh(g)/g``.
4. Overflow-free forms for ``Re g >= 0`` (the principal root; ``Re y >= 0`` for a passive
   ``Z_area``), with ``q = e^{-2g}``, ``m1 = expm1(-g)``, ``m2 = expm1(-2g)``:
   ``g coth g = -g (1 + q)/m2``, ``tanh(g)/g = -m2/(g (1 + q))``,
   ``F_w = 2 (-g m2 - m1^2)/(g^2 (1 + q))``, ``V/V0 = (e^{-g xi} + e^{-g (2 - xi)})/(1 + q)``.
   No difference of large terms: ``-g m2 ~ 2 g^2`` and ``m1^2 ~ g^2`` at small ``g`` (one bit).
5. Limits: ``g -> 0`` gives 1 for every factor (the uniform strip, series ``1 + g^2/3``,
   ``1 - g^2/4``, ``1 - g^2/3``); ``Re g -> infinity`` gives ``Z_in -> Z0`` (``coth -> 1``).
"""

from __future__ import annotations

import sympy as sp

# ---- symbols -------------------------------------------------------------------------
x, L = sp.symbols("x L", positive=True)
r, yv = sp.symbols("r y", positive=True)  # checks on the positive axis; the identities are analytic in g
g = sp.symbols("g", positive=True)
xi = sp.symbols("xi", positive=True)
V0 = sp.symbols("V0", positive=True)
gamma = sp.sqrt(r * yv)

#: the closed forms in terms of g = gamma L and xi = x/L; each is derived (and asserted equal) below
Z_RATIO = g / sp.tanh(g)  # Z_in / Z_u
F_THETA = sp.tanh(g) / g  # theta / theta_u
F_W = 2 * (g * sp.sinh(g) - sp.cosh(g) + 1) / (g**2 * sp.cosh(g))  # w / w_u
PROFILE = sp.cosh(g * (1 - xi)) / sp.cosh(g)  # V(x)/V0

#: test points off the real axis (arg g = 45 degrees is the RC line's high-frequency limit)
COMPLEX_POINTS = (sp.Rational(3, 10) + sp.I / 7, sp.Rational(5, 2) + 2 * sp.I, sp.Integer(7) + 7 * sp.I,
                  sp.Rational(1, 1000) + sp.I / 1000)


def profile():
    """``V(x)/V0`` solving ``V'' = r y V``, ``V(0) = V0``, ``V'(L) = 0`` (``I = -V'/r``)."""
    V = V0 * sp.cosh(gamma * (L - x)) / sp.cosh(gamma * L)
    assert sp.simplify(sp.diff(V, x, 2) - r * yv * V) == 0
    assert sp.simplify(V.subs(x, 0) - V0) == 0
    assert sp.simplify(sp.diff(V, x).subs(x, L)) == 0
    return V / V0


def input_impedance():
    """``Z_in = V0/I(0) = Z0 coth(gamma L)`` and ``Z_in/Z_u = g coth g`` (``Z_u = 1/(y L)``)."""
    V = V0 * profile()
    I0 = -sp.diff(V, x).subs(x, 0) / r
    Zin = sp.simplify(V0 / I0)
    Z0 = sp.sqrt(r / yv)
    assert sp.simplify(Zin - Z0 / sp.tanh(gamma * L)) == 0
    ratio = sp.simplify(Zin * yv * L)
    assert sp.simplify(ratio.subs(r, g**2 / (yv * L**2)) - Z_RATIO) == 0
    return Zin, Z_RATIO


def moment_factors():
    """``F_theta = (1/L) int V/V0 dx`` and ``F_w = (2/L^2) int (L - x) V/V0 dx`` in terms of ``g``."""
    P = profile().subs(r, g**2 / (yv * L**2))
    P = sp.simplify(P)
    Fth = sp.simplify(sp.integrate(P, (x, 0, L)) / L)
    Fw = sp.simplify(2 * sp.integrate((L - x) * P, (x, 0, L)) / L**2)
    assert sp.simplify((Fth - F_THETA).rewrite(sp.exp)) == 0
    assert sp.simplify((Fw - F_W).rewrite(sp.exp)) == 0
    # the profile in g and xi is the derived V/V0 at gamma = g/L, x = xi L
    Pg = profile().subs(r, g**2 / (yv * L**2)).subs(x, xi * L)
    assert sp.simplify((Pg - PROFILE).rewrite(sp.exp)) == 0
    return F_THETA, F_W


def stable_forms():
    """The overflow-free forms of item 4, as functions of ``g`` (and ``xi`` for the profile)."""
    q = sp.exp(-2 * g)
    m1 = sp.exp(-g) - 1  # expm1(-g)
    m2 = sp.exp(-2 * g) - 1  # expm1(-2 g)
    return {
        "impedance": -g * (1 + q) / m2,
        "rotation": -m2 / (g * (1 + q)),
        "deflection": 2 * (-g * m2 - m1**2) / (g**2 * (1 + q)),
        "profile": (sp.exp(-g * xi) + sp.exp(-g * (2 - xi))) / (1 + q),
    }


def closed_forms():
    """The closed forms of items 1-3 as functions of ``g`` (and ``xi``); :func:`check_all` derives them."""
    return {"impedance": Z_RATIO, "rotation": F_THETA, "deflection": F_W, "profile": PROFILE}


def check_stable_forms():
    """The stable forms equal the closed forms (symbolically, and at complex ``g`` to 30 digits)."""
    cf, sf = closed_forms(), stable_forms()
    for k in cf:
        assert sp.simplify((cf[k] - sf[k]).rewrite(sp.exp)) == 0, k
        for gv in COMPLEX_POINTS:
            d = (cf[k] - sf[k]).subs({g: gv, xi: sp.Rational(3, 7)})
            assert abs(complex(sp.N(d, 30))) < 1e-25, (k, gv)
    return True


def small_g_series(order: int = 6):
    """Series in ``g`` of each factor (the uniform strip at ``g = 0``)."""
    cf = closed_forms()
    return {k: sp.series(cf[k], g, 0, order).removeO() for k in ("impedance", "rotation", "deflection")}


def large_g_limit():
    """``Z_in/Z0 = coth(g) -> 1`` as ``Re g -> infinity``."""
    return sp.limit(sp.cosh(g) / sp.sinh(g), g, sp.oo)


def ladder_profile_check():
    """The segment count enters only at second order: a uniform N-segment ladder (series ``r h``,
    shunt ``y h`` at interior nodes and ``y h/2`` at the two ends) has the exact solution
    ``V_j/V0 = cosh(mu (N - j))/cosh(mu N)`` with ``2 (cosh mu - 1) = g^2/N^2``, i.e.
    ``mu N = 2 N asinh(g/(2N)) = g (1 - g^2/(24 N^2) + ...)``: even powers of ``1/N`` (Richardson
    between N and 2N removes the ``1/N^2`` term)."""
    N, j, mu = sp.symbols("N j mu", positive=True)
    Vj = sp.cosh(mu * (N - j))
    # interior node: (V_{j-1} - 2 V_j + V_{j+1}) = (g/N)^2 V_j with 2 (cosh mu - 1) = (g/N)^2
    lhs = Vj.subs(j, j - 1) - 2 * Vj + Vj.subs(j, j + 1)
    assert sp.simplify((lhs - 2 * (sp.cosh(mu) - 1) * Vj).rewrite(sp.exp)) == 0
    # far end (half shunt): V_{N-1} - V_N = (g/N)^2/2 V_N
    assert sp.simplify((Vj.subs(j, N - 1) - Vj.subs(j, N)) - (sp.cosh(mu) - 1) * Vj.subs(j, N)) == 0
    muN = sp.series(2 * N * sp.asinh(g / (2 * N)), N, sp.oo, 5).removeO()
    return sp.simplify(muN)


def check_all():
    """Every derivation step and identity of this module (raises on a failure)."""
    input_impedance()
    moment_factors()
    check_stable_forms()
    series = small_g_series()
    assert series["impedance"] == 1 + g**2 / 3 - g**4 / 45
    assert large_g_limit() == 1
    ladder_profile_check()
    return True


def main():
    print("V(x)/V0 =", profile())
    Zin, zr = input_impedance()
    print("Z_in =", Zin, "; Z_in/Z_u =", zr)
    th, w = moment_factors()
    print("F_theta =", th, "; F_w =", w)
    check_stable_forms()
    print("stable forms: equal to the closed forms")
    for k, s in small_g_series().items():
        print(f"{k}: {s}")
    print("coth(g) as Re g -> oo:", large_g_limit())
    print("ladder mu N =", ladder_profile_check())


if __name__ == "__main__":
    main()
