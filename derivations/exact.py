"""The exact moment integral at any thickness: first integral, thickness constraint, moment.

Fidelity ``exact`` (``ipmc_asym/kernels/exact.py``).  Nothing is neglected: the core need not
be neutral and the layers may overlap.  From ``model.py`` (seed paper section 4, ``y = ln C``):

* First integral ``D^2/2 = H(y)/A2 + K``.  With ``lambda^2 = (A0 + A1)/A2``,
  ``Hhat = H/(A0 + A1)`` and ``s(y) = y sqrt(Qhat(y))`` (``s^2 = 2 Hhat``) this is
  ``D = lambda sqrt(s^2 + kappa^2)`` where ``kappa^2 = 2 K / lambda^2`` (:func:`d_of_kappa`).
  ``D`` vanishes nowhere (``D' = C - 1`` has one minimum, at ``y = 0``, equal to
  ``lambda kappa``), so ``K >= 0`` and ``y`` is monotonic in ``z``.
* Electroneutrality ``D(1) = D(-1)`` holds for ANY ``K``: ``B1`` is the exact root of the
  quadratic of ``model.b1_quadratic_rho``, independent of the thickness.
* ``y' = A2 E = A2 D/eps`` gives ``dz = eps dy/(A2 D) = lambda ehat dy/sqrt(s^2 + kappa^2)``
  and the thickness constraint (the profile's length in ``z`` is 2) fixes ``kappa``:

      lambda int_{Ya}^{Yc} ehat(y) dy / sqrt(y^2 Qhat(y) + kappa^2) = 2.

  ``kappa`` ranges from ~1e-1286 (nominal constant model: ``ln kappa ~ -1/lambda``) to O(10)
  (1 um strips), so the root is found in ``ell = -ln kappa``.
* Core variable (:func:`core_change_of_variable`): with ``y = kappa sinh v``,
  ``ehat dy / sqrt(y^2 Qhat + kappa^2) = F dv``,
  ``F = ehat / sqrt(1 + (Qhat - 1) tanh^2 v)``: smooth and O(1) for every ``kappa``, equal to
  ``1 + O(y)`` in the core, so the part of the core where ``|y|`` underflows contributes its
  length in ``v`` exactly.  Away from the core (``|y| >= 1/2``) the integrand in ``y`` is used
  as is.
* ``d/d ell`` of the length integrand at fixed ``y`` (for Newton on ``ell``):
  ``F (1 - t2)/(1 + (Qhat - 1) t2)`` in ``v`` and ``F_y kappa^2/(y^2 Qhat + kappa^2)`` in ``y``
  (:func:`ell_derivatives`).
* Moment (:func:`moment_exact_assembly`): ``p = C/A2 - A3 phi + B2`` and ``phi = (ln B1 - y)/A2``
  so ``I = int p z dz = (1/A2) int C z dz + (A3/A2) int y z dz`` (``int z dz = 0``), with
  ``int C z dz = 2 D(1) - A1 - A0 (B1 - B1 e^{-A2})/A2`` exactly (``model.integral_Cz_identity``)
  and ``int y z dz`` split at ``z0`` (where ``y = 0``): on each side ``z = z0 +- zeta`` with
  ``zeta`` the distance from ``z0``, so
  ``int y z dz = z0 (Y1c + Y1a) + Y2c - Y2a``,  ``Y1 = int y dzeta``, ``Y2 = int y zeta dzeta``.
"""

from __future__ import annotations

import sympy as sp

from . import model as M
from .kernel import Kernel

v, t2, kappa, kappa2 = sp.symbols("v t2 kappa kappa2", positive=True)
Qs = sp.Symbol("Q", positive=True)  # Qhat(y) as a placeholder
ell = sp.Symbol("ell", real=True)
lam, A2, A3, rho, B1, y = M.lam, M.A2, M.A3, M.rho, M.B1, M.y


def ehat(yy):
    return (1 - rho) * sp.exp(yy) + rho


def qhat(yy):
    _, Q = M.w_layer()
    return Q.subs(M.y, yy)


def d_of_kappa():
    """``D^2/2 = H/A2 + K`` equals ``lambda^2 (s^2 + kappa^2)/2`` with ``kappa^2 = 2K/lambda^2``."""
    C = sp.exp(y)
    H = M.H_of_C(C)
    s2 = 2 * M.H_of_C(C).subs({M.A0: 1 - rho, M.A1: rho})  # 2 Hhat = y^2 Qhat
    sub = {M.A0: (1 - rho) * lam**2 * A2, M.A1: rho * lam**2 * A2}
    lhs = (H / A2 + M.K).subs(sub)
    rhs = lam**2 * (s2 + 2 * M.K / lam**2) / 2
    assert sp.simplify(sp.expand(lhs - rhs)) == 0
    return True


def dz_dy():
    """``dz/dy = eps/(A2 D)`` in the normalised variables: ``lambda ehat / sqrt(s^2 + kappa^2)``."""
    sub = {M.A0: (1 - rho) * lam**2 * A2, M.A1: rho * lam**2 * A2}
    eps = (M.A0 * sp.exp(y) + M.A1).subs(sub)
    s2 = y**2 * Qs
    D = lam * sp.sqrt(s2 + kappa**2)
    expr = eps / (A2 * D)
    target = lam * ehat(y) / sp.sqrt(y**2 * Qs + kappa**2)
    assert sp.simplify(expr - target) == 0
    return target


def core_change_of_variable():
    """``y = kappa sinh v``: ``ehat dy/sqrt(y^2 Q + kappa^2) = F dv`` with ``F`` below.

    Returns ``F(y, t2)`` with ``Q`` kept as ``Qhat(y)`` (``t2 = tanh^2 v``).
    """
    yv = kappa * sp.sinh(v)
    lhs = sp.diff(yv, v) / sp.sqrt(yv**2 * Qs + kappa**2)
    rhs = 1 / sp.sqrt(1 + (Qs - 1) * sp.tanh(v) ** 2)
    # both positive: compare squares
    diff = sp.simplify((lhs**2 - rhs**2).rewrite(sp.exp))
    assert diff == 0, diff
    e = sp.Symbol("ehat", positive=True)
    return e / sp.sqrt(1 + (Qs - 1) * t2)


def ell_derivatives():
    """``d/d ell`` (``kappa = e^{-ell}``) of the length integrands at fixed ``y``.

    Returns ``(G_v, G_y)`` as factors multiplying ``F`` (in ``v``) and ``F_y`` (in ``y``).
    """
    Fy = ehat(y) / sp.sqrt(y**2 * Qs + sp.exp(-2 * ell))
    gy = sp.simplify(sp.diff(Fy, ell) / Fy)
    target_y = sp.exp(-2 * ell) / (y**2 * Qs + sp.exp(-2 * ell))
    assert sp.simplify(gy - target_y) == 0
    # in v the measure dv depends on kappa too; the derivative at fixed y is the y-form
    # times dy/dv: kappa^2/(y^2 Q + kappa^2) = kappa^2/(kappa^2 cosh^2 v (1 + (Q-1) t2))
    gv = target_y.subs(sp.exp(-2 * ell), kappa**2).subs(y, kappa * sp.sinh(v))
    target_v = (1 - sp.tanh(v) ** 2) / (1 + (Qs - 1) * sp.tanh(v) ** 2)
    assert sp.simplify((gv - target_v).rewrite(sp.exp)) == 0
    return (1 - t2) / (1 + (Qs - 1) * t2), kappa2 / (y**2 * Qs + kappa2)


#: terms of the Taylor series of Qhat - 1 used in the core (|y| <= 1/2): the coefficients are
#: O(1/k!) (Qhat is a combination of exprel^2 and e2rel), truncation < 1e-19 (checked below)
N_QSERIES = 20


def qm1_series():
    """``Qhat(y) - 1`` as a polynomial in ``y`` (``|y| <= 1/2``), coefficients polynomials in rho.

    No cancellation near ``y = 0`` and no transcendental call; the truncation is checked
    against the exact ``Qhat`` at ``|y| = 1/2`` for rho in {0, 1/2, 1}.
    """
    Qdef = qhat(y).subs({M.exprel(y): M.EXPREL_DEF, M.e2rel(y): M.E2REL_DEF})
    N = N_QSERIES
    ex = sum(y**k / sp.factorial(k + 1) for k in range(N + 1))  # exprel
    e2 = sum(2 * y**k / sp.factorial(k + 2) for k in range(N + 1))  # e2rel
    ex2 = sp.expand(ex * ex)
    ex2 = sum(ex2.coeff(y, k) * y**k for k in range(N + 1))
    poly = sp.expand((1 - rho) * ex2 + rho * e2 - 1)
    assert poly.subs(y, 0) == 0
    for r in (0, sp.Rational(1, 2), 1):
        for yy in (sp.Rational(1, 2), -sp.Rational(1, 2)):
            exact = (Qdef - 1).subs({rho: r, y: yy}).evalf(40)
            approx = poly.subs({rho: r, y: yy}).evalf(40)
            assert abs(exact - approx) < 1e-19, (r, yy, exact - approx)
    # each coefficient a_k + b_k rho printed as two floats; evaluated as four interleaved
    # Horner chains in y^4: one Horner chain of N steps is one dependent chain of ~3N
    # operations per core node, which set half the exact rung's cost; four chains are a
    # quarter as deep and run side by side (rounding differs by ~1e-16)
    coef = []
    for k in range(1, N + 1):
        ck = sp.expand(poly.coeff(y, k))
        a, b = ck.subs(rho, 0), ck.coeff(rho, 1)
        assert sp.expand(ck - a - b * rho) == 0
        coef.append(sp.Float(a, 30) + sp.Float(b, 30) * rho)
    return y * interleaved_horner(coef, y, 4)


def interleaved_horner(coef, x, ways):
    """``sum_k coef[k] x^k`` as ``sum_r x^r H_r(x^ways)`` (``r < ways``), each ``H_r`` by Horner:
    ``ways`` independent chains of ``len(coef)/ways`` steps (powers of ``x`` up to ``ways``)."""
    z = x**ways
    total = sp.Integer(0)
    for r in range(ways):
        h = sp.Integer(0)
        for c in reversed(coef[r::ways]):
            h = c + z * h if h != 0 else c
        total += x**r * h
    return total


def integrands():
    """``(F, G)`` in the core variable and ``(F_y, G_y)`` in ``y``, with ``Qhat`` substituted.

    In the core (``|y| <= 1/2``) ``Qhat - 1`` comes from :func:`qm1_series` and
    ``ehat = rho + (1 - rho) exp(y)`` (one transcendental call per node).
    """

    Fv = core_change_of_variable()
    gv, gy = ell_derivatives()
    Q = qhat(y)
    e = ehat(y)
    # exp, not expm1: in the core ehat = rho + (1 - rho) e^y >= e^{-1/2}, so exp's rounding
    # (~1e-16 absolute) stays ~2e-16 relative, and glibc's expm1 costs several exp calls (the
    # yardstick's profile: 48 % of its time in expm1 against 9 % in exp, as many calls)
    e_core = rho + (1 - rho) * sp.exp(y)
    assert sp.simplify(e_core - e) == 0
    Qc = 1 + qm1_series()
    F = Fv.subs({sp.Symbol("ehat", positive=True): e_core, Qs: Qc})
    G = (Fv * gv).subs({sp.Symbol("ehat", positive=True): e_core, Qs: Qc})
    Fy = e / sp.sqrt(y**2 * Q + kappa2)
    Gy = Fy * gy.subs(Qs, Q)
    return F, G, Fy, Gy


def outer_split():
    """``F_y, G_y`` from ``(ehat, s2 = y^2 Qhat)`` and ``kappa^2``: the y-nodes do not move with
    ``kappa``, so ``ehat`` and ``s2`` are computed once per point and only this part per Newton step."""

    e, s2 = sp.symbols("ehat s2", positive=True)
    _, _, Fy, Gy = integrands()
    Q = qhat(y)
    Fs = e / sp.sqrt(s2 + kappa2)
    Gs = Fs * kappa2 / (s2 + kappa2)
    back = {e: ehat(y), s2: y**2 * Q}
    assert sp.simplify(Fs.subs(back) - Fy) == 0 and sp.simplify(Gs.subs(back) - Gy) == 0
    # s2 = 2 Hhat(C) = (1-rho)(C-1)^2 + 2 rho (C - 1 - y) with C - 1 = e^y - 1 from the one exp
    # call (for |y| >= 1/2, |e^y - 1| >= 0.39 e^y: exp's rounding stays <= 2.6 ulp relative, and
    # C - 1 - y has no harmful cancellation); computed once per point, not per Newton step
    em = sp.Symbol("em")
    s2_c = (1 - rho) * em**2 + 2 * rho * (em - y)
    e_c = ehat(y)  # rho + (1-rho) e^y: no cancellation (e^y ~ 1e-300 at the linear model's anode)
    check = sp.simplify((s2_c.subs(em, sp.exp(y) - 1) - (y**2 * Q).subs(
        {M.exprel(y): M.EXPREL_DEF, M.e2rel(y): M.E2REL_DEF})))
    assert check == 0, check
    return (e, s2), (e_c, s2_c.subs(em, sp.exp(y) - 1)), (Fs, Gs)


def moment_exact_assembly():
    """``I`` from ``D(1)``, ``B1`` and the four side integrals (see module docstring)."""
    dc = sp.Symbol("Dhat_c", nonnegative=True)
    cm, z0, Y1c, Y1a, Y2c, Y2a = sp.symbols("c_minus z0 Y1c Y1a Y2c Y2a", real=True)
    A0 = (1 - rho) * lam**2 * A2
    A1 = rho * lam**2 * A2
    D1 = lam * sp.sqrt(dc**2 + kappa2)
    int_Cz = 2 * D1 - A1 - A0 * (B1 - cm) / A2
    int_yz = z0 * (Y1c + Y1a) + Y2c - Y2a
    I = int_Cz / A2 + A3 / A2 * int_yz
    # kappa -> 0 and Y1 = lambda W0, Y2 -> the neutral-core layer sums: the O(lambda) term is J1
    W0c, W0a = sp.symbols("W0c W0a")
    lead = (2 * D1 / A2 + A3 / A2 * (Y1c - Y1a)).subs({kappa2: 0, Y1c: lam * W0c, Y1a: lam * W0a})
    (W0c_, W0a_, W1c_, W1a_, Dc_, cm_), J1, J2 = M.moment_assembly()
    J1s = J1.subs({W0c_: W0c, W0a_: W0a, Dc_: dc})
    assert sp.simplify(lead - lam * J1s) == 0
    # and the W-free part of the O(lambda^2) term is that of J2
    rest = sp.expand(int_Cz / A2 - 2 * D1 / A2)
    assert sp.simplify(rest - lam**2 * J2.subs({W1a_: 0, W1c_: 0, cm_: cm})) == 0
    return (dc, cm, z0, Y1c, Y1a, Y2c, Y2a), I


def linear_check():
    """Linear model (rho = 0): ``s = e^y - 1`` and the exact solution of ``model.py``.

    ``C = 1 + (B1 - 1) sinh(z/z0)/sinh(1/z0)`` has ``D = z0^2 C'`` so at y = 0 (``C = 1``)
    ``D = lambda kappa`` gives ``kappa = (B1 - 1)/sinh(1/lambda)`` (``z0 = lambda`` when rho = 0).
    """
    zz = sp.Symbol("z", real=True)
    z0 = lam
    Cz = 1 + (B1 - 1) * sp.sinh(zz / z0) / sp.sinh(1 / z0)
    D = z0**2 * sp.diff(Cz, zz)
    zc = sp.asinh(0 * zz)  # C = 1 at z = 0
    kap = sp.simplify(D.subs(zz, zc) / lam)
    assert sp.simplify(kap - (B1 - 1) / sp.sinh(1 / lam)) == 0
    return kap


def main():
    print("D(1) = lambda sqrt(s^2 + kappa^2), kappa^2 = 2K/lambda^2:", d_of_kappa())
    print("dz/dy =", dz_dy())
    print("core variable y = kappa sinh v: F =", core_change_of_variable())
    print("d/d ell factors:", ell_derivatives())
    print("I =", moment_exact_assembly()[1])
    print("linear model: kappa =", linear_check())


if __name__ == "__main__":
    main()


def kernels():
    """The kernels of ``ipmc_asym/kernels/_generated_exact.py``."""

    F, G, Fy, Gy = integrands()
    src = "derivations.exact:integrands"
    ks = [
        Kernel("exact_core", (y, t2, rho), (F, G),
               "(F, dF/d ell) in the core variable y = kappa sinh v, t2 = tanh(v)^2; dz = lambda F dv.",
               src),
    ]
    (e, s2), parts, (Fs, Gs) = outer_split()
    ks.append(Kernel("exact_outer_parts", (y, rho), parts,
                     "(ehat, s2 = y^2 Qhat) at a y-node (|y| >= 1/2): independent of kappa.",
                     "derivations.exact:outer_split"))
    ks.append(Kernel("exact_outer", (e, s2, kappa2), (Fs, Gs),
                     "(F_y, dF_y/d ell) in y from (ehat, s2), kappa2 = kappa^2; dz = lambda F_y dy.",
                     "derivations.exact:outer_split"))
    args, I = moment_exact_assembly()
    dc, cm, z0, Y1c, Y1a, Y2c, Y2a = args
    ks.append(Kernel("assemble_exact", (lam, A2, A3, rho, B1, cm, dc, kappa2, z0, Y1c, Y1a, Y2c, Y2a), (I,),
                     "I = int p z dz (for |phi0|) from D(1), B1 and the side integrals Y1, Y2.",
                     "derivations.exact:moment_exact_assembly"))
    return ks
