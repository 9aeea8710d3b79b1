"""The pressure term of the Nernst-Planck law (paper eq. (5)), kept: the ``pressure_term`` option.

The paper drops the term ``(C v1/RT)(1 - M1 v2/(M2 v1)) grad p`` of its Nernst-Planck law
(5) in section 4 ("hypothese que nous verifierons par la suite") and states after its table
of face values that the error is "< 2 % in the nominal case".  Here it is kept.

1. Static strip (all velocities zero): the Darcy law (4) with ``V4 = V3`` gives
   ``grad p = (C F - rho2 Z3) E`` and the Nernst-Planck law (5) with ``V1 = V2`` gives
   ``grad C = (Z1 M1 C/RT) E - (C v1/RT)(1 - M1 v2/(M2 v1)) grad p``, ``Z1 M1 = F``
   (monovalent cation).  Hence (:func:`boltzmann_relation`)

       d ln C/dz = (F E/RT) [1 - (v1 - M1 v2/M2)(C - rho2 Z3/F)]

   and, dimensionless (paper eq. (22): ``p = F phi0 C_moy pbar``),
   ``d ln C/dz = A2 E (gamma - beta C)`` with ``beta = (v1 - M1 v2/M2) C_moy`` and
   ``gamma = 1 - beta A3``.  ``beta -> 0`` is the paper's system.
2. With ``y = ln C`` (zero in the neutral core), ``g0 = gamma - beta = 1 - beta (1 + A3)``,
   ``b0 = beta/g0`` and ``m = e^y - 1``: ``gamma - beta C = g0 (1 - b0 m)``.  Closed forms
   (each checked here by differentiation):

   * voltage: ``dphi/dy = -1/(A2 g0 (1 - b0 m))`` so ``A2 (phi(y1) - phi(y2)) = V(y2) - V(y1)``,
     ``V(y) = [y + b0 m L1(b0 m)]/(g0 (1 + b0))``, ``L1(x) = -ln(1 - x)/x``.  The BCs
     ``phi(-1) = 1``, ``phi(1) = 0`` read ``V(Yc) - V(Ya) = A2``.
   * pressure: ``dp/dy = (C + A3)/(A2 g0 (1 - b0 m))`` so ``p = P(y)/A2 + const`` with
     ``P(y) = [A3 y + m L1(b0 m)/g0]/(g0 (1 + b0))`` (``= m + A3 y`` at ``beta = 0``: the
     paper's ``p = C/A2 - A3 phi``).
   * first integral: ``D D' = eps E (C - 1)`` and ``E dz = dy/(A2 g0 (1 - b0 m))`` give
     ``D^2 = (lambda^2/g0) (S(y) + kappa^2)`` with ``lambda^2 = (A0 + A1)/A2`` (the core
     Debye length of the paper's model), ``S(y) = 2 int_0^y ehat(u) m(u)/(1 - b0 m(u)) du``,
     ``ehat = 1 + (1 - rho) m``, ``S ~ y^2`` at 0.  In closed form
     ``S = S0 + 2 b0 T`` with ``S0 = (1 - rho) m^2 + 2 rho (m - y)`` (the paper's model) and
     ``T`` a polynomial in ``m`` plus ``y`` plus ``m^3 R3(b0 m)``,
     ``R3(x) = (ln(1 - x) + x + x^2/2)/x^3`` (:func:`s_closed`): no negative power of ``b0``,
     so the closed form holds as ``beta -> 0`` without cancellation; where ``|b0 m| > 1/2`` the
     partial fractions in ``m`` with ``ln(1 - b0 m)`` (:func:`s_far`) instead.
   * electroneutrality ``D(1) = D(-1)`` <=> ``S(Yc) = S(Ya)`` for any ``kappa``.
   * ``dz = eps dy/(A2 D g0 (1 - b0 m)) = lambda_b ehat_b dy/sqrt(S + kappa^2)`` with
     ``lambda_b = lambda/sqrt(g0)``, ``ehat_b = ehat/(1 - b0 m)`` (:func:`dz_dy`): the form of
     the ``exact`` rung (``derivations/exact.py``) with ``(lambda, ehat, y^2 Qhat)`` replaced by
     ``(lambda_b, ehat_b, S)``, so its thickness constraint, core variable and panels carry
     over.  In the core ``S = y^2 Q``, ``Q = int_0^1 2 tau q(y tau) dtau``,
     ``q = ehat exprel/(1 - b0 m)`` (:func:`core_q`): no cancellation at small ``y``.
   * moment: ``I = int p z dz = (1/A2) int P z dz`` (``int z dz = 0``).
3. The size of the term: the ratio of the pressure term to the migration term of (5) is
   ``beta (C + A3)`` (:func:`term_ratio`), ``beta (B1 + A3)`` at the cathode.

Run ``python -m derivations.pressure`` for the checks.
"""

from __future__ import annotations

import sympy as sp
from sympy.codegen.cfunctions import expm1

from . import model as M
from .kernel import Kernel

y, rho, A3 = M.y, M.rho, M.A3
beta, b0, g0 = sp.symbols("beta b0 g0", real=True)
m, em, l1, r3, u, x, tau, omr = sp.symbols("m em l1 r3 u x tau omr", real=True)


def boltzmann_relation():
    """Paper eqs (4)-(5), static: ``d ln C/dz`` with the pressure term; returns the bracket."""
    F, R, T, C, E, v1, v2, M1, M2, rho2, Z3 = sp.symbols("F R T C E v1 v2 M1 M2 rho2 Z3", real=True)
    dC, dp = sp.symbols("dC dp", real=True)
    # Darcy (4) with V4 - V3 = 0: grad p - (C F - rho2 Z3) E = 0
    dp_sol = sp.solve(sp.Eq(dp - (C * F - rho2 * Z3) * E, 0), dp)[0]
    # Nernst-Planck (5) with V1 - V2 = 0, Z1 M1 = F: the bracket vanishes
    Z1M1 = F
    nernst = dC - Z1M1 * C / (R * T) * E + C * v1 / (R * T) * (1 - M1 * v2 / (M2 * v1)) * dp
    dC_sol = sp.solve(sp.Eq(nernst.subs(dp, dp_sol), 0), dC)[0]
    issue_form = F * E / (R * T) * (1 - (v1 - M1 * v2 / M2) * (C - rho2 * Z3 / F))
    assert sp.simplify(dC_sol / C - issue_form) == 0
    # dimensionless: C = C_moy Cb, rho2 Z3 = -A3 C_moy F, beta = (v1 - M1 v2/M2) C_moy
    Cm, Cb, bet, a3 = sp.symbols("C_moy Cb beta A3", positive=True)
    br = (1 - (v1 - M1 * v2 / M2) * (C - rho2 * Z3 / F)).subs(
        {C: Cm * Cb, Z3: -a3 * Cm * F / rho2}).subs(v1, bet / Cm + M1 * v2 / M2)
    gamma = 1 - bet * a3
    assert sp.simplify(br - (gamma - bet * Cb)) == 0
    return gamma - bet * Cb


def _em(yy):
    return sp.exp(yy) - 1


def L1_def(xx):
    return -sp.log(1 - xx) / xx


def R3_def(xx):
    return (sp.log(1 - xx) + xx + xx**2 / 2) / xx**3


def groups_check():
    """``gamma - beta C = g0 (1 - b0 m)``, ``gamma = g0 (1 + b0)``."""
    gamma = 1 - beta * A3
    G0 = 1 - beta * (1 + A3)
    C = sp.exp(y)
    assert sp.simplify((gamma - beta * C) - G0 * (1 - (beta / G0) * _em(y))) == 0
    assert sp.simplify(gamma - G0 * (1 + beta / G0)) == 0
    return True


def volt_closed():
    """``V(y)`` with ``V' = 1/(g0 (1 - b0 m))``; in terms of ``(y, em, l1)``."""
    V = (y + b0 * _em(y) * L1_def(b0 * _em(y))) / (g0 * (1 + b0))
    assert sp.simplify(sp.diff(V, y) - 1 / (g0 * (1 - b0 * _em(y)))) == 0
    return (y + b0 * em * l1) / (g0 * (1 + b0))


def pressure_closed():
    """``P(y)`` with ``P' = (C + A3)/(g0 (1 - b0 m))``, ``P(0) = 0``; in terms of ``(y, em, l1)``."""
    P = (A3 * y + _em(y) * L1_def(b0 * _em(y)) / g0) / (g0 * (1 + b0))
    # the coupling constants: g0 (1 + b0) = gamma = 1 - beta A3 and A3 + 1/g0 ... from beta
    target = (sp.exp(y) + A3) / (g0 * (1 - b0 * _em(y)))
    # P' = target only where g0 = 1 - beta (1 + A3), b0 = beta/g0: eliminate A3
    dP = sp.diff(P, y).subs(A3, (1 - g0) / beta - 1).subs(beta, b0 * g0)
    t2 = target.subs(A3, (1 - g0) / beta - 1).subs(beta, b0 * g0)
    assert sp.simplify(dP - t2) == 0
    assert sp.limit(P.subs(y, x), x, 0) == 0
    # beta -> 0 (b0 = 0, g0 = 1): P = m + A3 y, the paper's C/A2 - A3 phi up to a constant
    assert sp.simplify(sp.limit(P.subs(g0, 1), b0, 0) - (_em(y) + A3 * y)) == 0
    return (A3 * y + em * l1 / g0) / (g0 * (1 + b0))


def s_closed():
    """``S(y) = 2 int_0^y ehat m/(1 - b0 m) du`` in closed form, regular at ``b0 = 0``.

    Returns the expression in ``(y, em, r3)`` (``em = e^y - 1``, ``r3 = R3(b0 em)``).
    """
    # T(m) = int_0^m (1 + (1-rho) w) w^2 / ((1 + w)(1 - b0 w)) dw   (du = dw/(1 + w))
    w = sp.Symbol("w", real=True)
    integrand = (1 + (1 - rho) * w) * w**2 / ((1 + w) * (1 - b0 * w))
    c1 = sp.simplify((integrand * (1 + w)).subs(w, -1))
    c2 = sp.simplify(sp.cancel(integrand * (1 - b0 * w)).subs(w, 1 / b0))
    poly = sp.cancel(integrand - c1 / (1 + w) - c2 / (1 - b0 * w))
    assert sp.Poly(sp.numer(poly), w).degree() - sp.Poly(sp.denom(poly), w).degree() <= 1
    assert not sp.denom(poly).has(w), poly
    # log(1 + m) = y and log(1 - b0 m) = -b0 m - (b0 m)^2/2 + (b0 m)^3 R3(b0 m)
    log1 = -b0 * m - (b0 * m) ** 2 / 2 + (b0 * m) ** 3 * r3
    T = sp.integrate(poly, (w, 0, m)) + c1 * y - c2 / b0 * log1
    # check against the exact antiderivative
    Tex = sp.integrate(poly, (w, 0, m)) + c1 * sp.log(1 + m) - c2 / b0 * sp.log(1 - b0 * m)
    assert sp.simplify(sp.diff(Tex, m) - integrand.subs(w, m)) == 0
    Ts = sp.simplify(sp.expand(T))
    S0 = (1 - rho) * m**2 + 2 * rho * (m - y)
    S = sp.expand(S0 + 2 * b0 * Ts)
    # regular at b0 = 0: no negative power of b0 left
    num, den = sp.fraction(sp.together(S))
    assert sp.simplify(den.subs(b0, 0)) != 0, den
    # check: dS/dy = 2 ehat m/(1 - b0 m) with m = e^y - 1, r3 = R3(b0 m)
    Sy = S.subs(r3, R3_def(b0 * m)).subs(m, _em(y))
    dS = sp.diff(Sy, y) - 2 * (1 + (1 - rho) * _em(y)) * _em(y) / (1 - b0 * _em(y))
    for vals in ({rho: 0, b0: sp.Rational(-3, 100)}, {rho: 1, b0: sp.Rational(1, 50)},
                 {rho: sp.Rational(1, 201), b0: sp.Rational(-1, 7)}):
        for yy in (sp.Rational(-7, 2), sp.Rational(3, 4), sp.Rational(5, 2)):
            assert abs(sp.N(dS.subs(vals).subs(y, yy), 30)) < 1e-25, (vals, yy)
    # S(0) = 0 (m = 0)
    assert sp.simplify(S.subs({m: 0, y: 0})) == 0
    # beta -> 0: the paper's first integral 2 Hhat
    assert sp.simplify(S.subs(b0, 0) - S0) == 0
    # each coefficient factored: (rho - 1 - b0) multiplies the em^3 R3 term as one factor, so
    # that for rho = 1 (constant model) the two b0 em^3 terms are not formed and subtracted
    # and in terms of omr = 1 - rho (an argument): b0 + 1 - rho is then b0 + omr, exact for the
    # constant model (omr = 0) instead of (b0 + 1) - 1
    poly = sp.Poly(sp.expand(S.subs(rho, 1 - omr)), m, r3, y)
    Sf = sum(sp.factor(c) * m**i * r3**j * y**k for (i, j, k), c in poly.terms())
    assert sp.simplify(Sf.subs(omr, 1 - rho) - S) == 0
    return Sf.subs(m, em)


def s_far():
    """``S(y)`` for ``|b0 m| > 1/2``: ``2 [-(1 - rho) m/b0 - rho y/(1 + b0) - (b0 + 1 - rho) ln(1 - b0 m)/(b0^2 (1 + b0))]``.

    ``S = 2 int_0^m (1 + (1 - rho) w) w/((1 + w)(1 - b0 w)) dw``: a constant and two poles.  No
    cancellation where ``|b0 m|`` is large (``S ~ m/|b0|`` there, while the ``R3`` form of
    :func:`s_closed` subtracts terms ``~ m^2``).  In terms of ``(y, em, lg)``,
    ``lg = ln(1 - b0 em)``, ``ib0 = 1/b0``.
    """
    lg = sp.Symbol("lg", real=True)
    ib0 = sp.Symbol("ib0", real=True)  # 1/b0 as an argument: the printer writes no negative power
    S = 2 * (-(1 - rho) * m * ib0 - rho * y / (1 + b0) - (b0 + 1 - rho) * ib0**2 / (1 + b0) * lg)
    Sy = S.subs(lg, sp.log(1 - b0 * m)).subs(ib0, 1 / b0).subs(m, _em(y))
    dS = sp.diff(Sy, y) - 2 * (1 + (1 - rho) * _em(y)) * _em(y) / (1 - b0 * _em(y))
    assert sp.simplify(dS) == 0
    assert sp.simplify(Sy.subs(y, 0)) == 0
    return S.subs(m, em), lg, ib0


def core_q():
    """``q(x) = ehat exprel/(1 - b0 m)``: ``S(y) = y^2 int_0^1 2 tau q(y tau) dtau`` (``Q(0) = 1``)."""
    q = (1 + (1 - rho) * _em(x)) * M.exprel(x) / (1 - b0 * _em(x))
    # S'(y) = 2 ehat(y) m(y)/(1 - b0 m(y)) = 2 y q(y); and d/dy [y^2 int_0^1 2 tau q(y tau)] = 2 y q(y)
    qd = q.subs(M.exprel(x), (sp.exp(x) - 1) / x)
    yy = sp.Symbol("yy", positive=True)
    lhs = sp.diff(yy**2 * sp.Integral(2 * tau * qd.subs(x, yy * tau), (tau, 0, 1)), yy)
    # y^2 int 2 tau q(y tau) dtau = int_0^y 2 s q(s) ds: its derivative is 2 y q(y)
    sub = sp.Integral(2 * x * qd, (x, 0, yy))
    assert sp.simplify(sp.diff(sub, yy) - 2 * yy * qd.subs(x, yy)) == 0
    del lhs
    assert sp.limit(qd.subs({rho: sp.Rational(1, 3), b0: sp.Rational(1, 5)}), x, 0) == 1
    return (1 + (1 - rho) * expm1(x)) * M.exprel(x) / (1 - b0 * expm1(x))


def dz_dy():
    """``dz/dy = eps/(A2 D g0 (1 - b0 m))`` equals ``lambda_b ehat_b/sqrt(S + kappa^2)``."""
    lam, A2, kap = M.lam, M.A2, sp.Symbol("kappa", positive=True)
    Sx = sp.Symbol("S", positive=True)
    G0 = sp.Symbol("g0", positive=True)
    A0 = (1 - rho) * lam**2 * A2
    A1 = rho * lam**2 * A2
    eps = A0 * sp.exp(y) + A1
    D = lam / sp.sqrt(G0) * sp.sqrt(Sx + kap**2)
    lhs = eps / (A2 * D * G0 * (1 - b0 * _em(y)))
    ehat_b = (1 + (1 - rho) * _em(y)) / (1 - b0 * _em(y))
    rhs = lam / sp.sqrt(G0) * ehat_b / sp.sqrt(Sx + kap**2)
    assert sp.simplify(lhs - rhs) == 0
    # and the first integral: D dD/dy = eps (C - 1) dz/dy ... i.e. d(D^2/2)/dy = lam^2 S'/(2 g0)
    # equals eps (C - 1) E dz/dy with E dz/dy = 1/(A2 g0 (1 - b0 m))
    Sp = 2 * (1 + (1 - rho) * _em(y)) * _em(y) / (1 - b0 * _em(y))
    assert sp.simplify(lam**2 / G0 * Sp / 2 - eps * _em(y) / (A2 * G0 * (1 - b0 * _em(y)))) == 0
    return rhs


def term_ratio():
    """Pressure term / migration term of (5): ``(v1 - M1 v2/M2) grad p/(F E) = beta (C + A3)``."""
    gamma_minus = 1 - boltzmann_relation()  # beta (C + A3)
    Cb, bet, a3 = sp.symbols("Cb beta A3", positive=True)
    assert sp.simplify(gamma_minus - bet * (Cb + a3)) == 0
    return gamma_minus


def kernels():
    """The kernels of ``ipmc_asym/kernels/_generated_pressure.py``."""
    src = "derivations.pressure"
    ks = []
    ehat_b = (1 + (1 - rho) * expm1(y)) / (1 - b0 * expm1(y))
    ks.append(Kernel("pressure_ehat", (y, rho, b0), (ehat_b,),
                     "ehat_b = (1 + (1 - rho) m)/(1 - b0 m), m = e^y - 1; dz = lambda_b ehat_b dy/sqrt(S + kappa^2).",
                     f"{src}:dz_dy"))
    ks.append(Kernel("pressure_core_q", (x, rho, b0), (core_q(),),
                     "q(x) = ehat exprel/(1 - b0 m): S(y) = y^2 int_0^1 2 tau q(y tau) dtau in the core.",
                     f"{src}:core_q"))
    ks.append(Kernel("pressure_s_outer", (y, em, r3, omr, b0), (s_closed(),),
                     "S(y) closed form (|y| >= 1/2, |b0 em| <= 1/2), em = e^y - 1, r3 = R3(b0 em), omr = 1 - rho.",
                     f"{src}:s_closed"))
    Sf, lg, ib0 = s_far()
    ks.append(Kernel("pressure_s_far", (y, em, lg, rho, b0, ib0), (Sf,),
                     "S(y) closed form where |b0 em| > 1/2, lg = ln(1 - b0 em), ib0 = 1/b0.",
                     f"{src}:s_far"))
    ks.append(Kernel("pressure_volt", (y, em, l1, b0, g0), (volt_closed(),),
                     "V(y), V' = 1/(g0 (1 - b0 m)); the BCs read V(Yc) - V(Ya) = A2. l1 = L1(b0 em).",
                     f"{src}:volt_closed"))
    ks.append(Kernel("pressure_p", (y, em, l1, A3, b0, g0), (pressure_closed(),),
                     "P(y) = A2 (p(y) - p(0)), P' = (C + A3)/(g0 (1 - b0 m)). l1 = L1(b0 em).",
                     f"{src}:pressure_closed"))
    return ks


def main():
    print("Boltzmann relation with the pressure term: dln C/dz = A2 E *", boltzmann_relation())
    print("groups:", groups_check())
    print("V(y) =", volt_closed())
    print("P(y) =", pressure_closed())
    print("S(y) =", s_closed())
    print("S(y), |b0 m| > 1/2 =", s_far()[0])
    print("q(x) =", core_q())
    print("dz/dy =", dz_dy())
    print("term ratio =", term_ratio())


if __name__ == "__main__":
    main()
