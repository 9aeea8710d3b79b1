"""Reduced system, first integral, exact electroneutrality and the layer reduction.

Seed paper section 4 (the system ``syst``), with ``y = ln C`` (zero in the neutral core):

    E = -phi',  D = eps E,  D' = C - 1,  eps = A0 C + A1,  C' = A2 C E,  p' = (C + A3) E
    phi(-1) = 1, phi(1) = 0, D(1) = D(-1)

Results derived and checked here (run ``python -m derivations.model``):

1. ``C = B1 exp(-A2 phi)``, ``p = C/A2 - A3 phi + B2`` (paper).
2. First integral ``D^2/2 = H(y)/A2 + K`` with
   ``H(y) = A0 (C-1)^2/2 + A1 (C - 1 - ln C)``  (>= 0, zero only at C = 1).
3. Electroneutrality ``D(1) = D(-1)`` <=> ``H(ln B1) = H(ln B1 - A2)`` EXACTLY (any K):
   a quadratic in ``B1`` with the ``e^{-A2}`` terms; its limits
   ``B1 -> A2/(1 - e^{-A2})`` (constant), ``2/(1 + e^{-A2})`` (linear), the affine root.
4. ``integral C z dz = 2 D(1) - A1 - A0 (B1 - B1 e^{-A2}) / A2`` EXACTLY (integration by
   parts of ``D' = C - 1`` and ``eps E = -(A0 C + A1) phi'``).
5. With the core neutral (K = 0, exponentially small error in 1/lambda), each electrode
   layer is a quadrature in y: ``dz = eps dy / sqrt(2 A2 H)``.  Writing
   ``lambda^2 = (A0 + A1)/A2``, ``rho = A1/(A0 + A1)`` and the analytic function
   ``w(y) = ehat(y) / sqrt(Qhat(y))``, ``ehat = (1-rho) e^y + rho``,
   ``Qhat = 2 Hhat / y^2 = (1-rho) exprel(y)^2 + rho e2rel(y)`` (``w(0) = 1``),
   and ``W0(Y) = int_0^Y w dy``, ``W1(Y) = int_0^Y (w/y) W0 dy``, the moment integral is
   EXACTLY two terms in lambda:

       I = lambda J1 + lambda^2 J2
       J1 = 2 Dhat(Yc)/A2 + (A3/A2) (W0(Yc) - W0(Ya))
       J2 = -rho - (1 - rho)(B1 - B1 e^{-A2})/A2 + (A3/A2) (W1(Ya) - W1(Yc))

   with ``Yc = ln B1`` (cathode), ``Ya = ln B1 - A2`` (anode), ``Dhat = |Y| sqrt(Qhat)``.
   Hence ``I ~ 1/e`` at leading order (lambda ~ 1/e), with an O(1/e^2) correction.
"""

from __future__ import annotations

import sympy as sp

# ---- symbols -------------------------------------------------------------------------
z, y, Y = sp.symbols("z y Y", real=True)
A0, A1, A2, A3 = sp.symbols("A0 A1 A2 A3", positive=True)
B1 = sp.symbols("B1", positive=True)
rho = sp.symbols("rho", nonnegative=True)
lam = sp.symbols("lam", positive=True)
K = sp.symbols("K", real=True)

# Stable primitives (implemented numerically in ipmc_asym/kernels/special.py).
exprel = sp.Function("exprel")  # (e^y - 1)/y
e2rel = sp.Function("e2rel")  # 2 (e^y - 1 - y)/y^2

EXPREL_DEF = (sp.exp(y) - 1) / y
E2REL_DEF = 2 * (sp.exp(y) - 1 - y) / y**2


def H_of_C(C):
    """First-integral potential H (times A2: D^2/2 = H/A2 + K)."""
    return A0 * (C - 1) ** 2 / 2 + A1 * (C - 1 - sp.log(C))


def check_first_integral():
    """d/dz (D^2/2) = D D' must equal dH/dz / A2 along solutions."""
    C = sp.Function("C")(z)
    eps = A0 * C + A1
    E = sp.diff(C, z) / (A2 * C)  # from C' = A2 C E
    D = eps * E
    lhs = D * (C - 1)  # D D'
    rhs = sp.diff(H_of_C(C), z) / A2
    assert sp.simplify(lhs - rhs) == 0
    # and the paper's form: D^2/2 = (A0 C^2/2 + (A1 - A0) C)/A2 + A1 phi + const
    phi = sp.symbols("phi")
    Cphi = B1 * sp.exp(-A2 * phi)
    paper = (A0 / 2 * Cphi**2 + (A1 - A0) * Cphi) / A2 + A1 * phi
    ours = H_of_C(Cphi) / A2
    diff = sp.simplify(sp.expand(sp.expand_log(ours - paper, force=True)))
    assert sp.diff(diff, phi) == 0, diff  # differ by a constant only
    return True


def electroneutrality_equation():
    """H(ln B1) - H(ln B1 - A2) = 0 as a polynomial in B1 (exact, with e^{-A2})."""
    eq = sp.expand(sp.expand_log(H_of_C(B1) - H_of_C(B1 * sp.exp(-A2)), force=True))
    return sp.collect(eq, B1)


def b1_quadratic_rho():
    """Coefficients (a, b, c) of a B1^2 + b B1 + c = 0 after dividing by (A0 + A1).

    With q = 1 - e^{-A2}:  a = (1-rho) q (2-q)/2, b = (2 rho - 1) q, c = -rho A2.
    """
    q = sp.symbols("q", positive=True)
    eq = electroneutrality_equation()
    eq = eq.xreplace({sp.exp(-2 * A2): (1 - q) ** 2, sp.exp(-A2): 1 - q})
    eq = sp.expand(eq.subs({A0: (1 - rho), A1: rho}))
    poly = sp.Poly(eq, B1)
    a, b, c = [sp.factor(cf) for cf in poly.all_coeffs()]
    assert sp.simplify(a - (1 - rho) * q * (2 - q) / 2) == 0
    assert sp.simplify(b - (2 * rho - 1) * q) == 0
    assert sp.simplify(c + rho * A2) == 0
    return q, a, b, c


def b1_limits():
    """Exact B1 in the three models and the paper's large-A2 forms."""
    eq = electroneutrality_equation()
    const = sp.solve(eq.subs(A0, 0), B1)
    lin = [s for s in sp.solve(eq.subs(A1, 0), B1) if s != 0]
    assert len(const) == 1 and sp.simplify(const[0] - A2 / (1 - sp.exp(-A2))) == 0
    assert len(lin) == 1 and sp.simplify(lin[0] - 2 / (1 + sp.exp(-A2))) == 0
    # affine, e^{-A2} -> 0: the paper's B1 = (A0-A1)/A0 (1 + sqrt(1 + 2 A2 A0 A1/(A0-A1)^2))
    eq_inf = eq.xreplace({sp.exp(-A2): 0, sp.exp(-2 * A2): 0})
    roots = sp.solve(eq_inf, B1)
    paper = (A0 - A1) / A0 * (1 + sp.sqrt(1 + 2 * A2 * A0 * A1 / (A0 - A1) ** 2))
    num = {A0: sp.Rational(88, 100000), A1: sp.Rational(44, 10000000), A2: sp.Rational(387, 10)}
    vals = [complex(r.subs(num).evalf()) for r in roots]
    assert any(abs(v - complex(paper.subs(num).evalf())) < 1e-12 for v in vals)
    return {"constant": const[0], "linear": lin[0], "affine_large_A2": paper}


def integral_Cz_identity():
    """int_{-1}^{1} C z dz = 2 D(1) - A1 - A0 (B1 - B1 e^{-A2})/A2 (exact).

    int (C-1) z = int D' z = [D z] - int D = D(1) + D(-1) - int eps E dz and
    int eps E dz = -int (A0 C + A1) phi' dz = A1 + A0 (C(1) - C(-1))/A2  (C dphi = -dC/A2).
    Checked here on an arbitrary smooth test profile satisfying the same relations.
    """
    # symbolic check of the last step with phi as the variable of integration
    phi = sp.symbols("phi")
    Cphi = B1 * sp.exp(-A2 * phi)
    int_epsE = sp.integrate(A0 * Cphi + A1, (phi, 0, 1))  # phi runs 0 (z=1) .. 1 (z=-1)
    assert sp.simplify(int_epsE - (A1 + A0 * (B1 - B1 * sp.exp(-A2)) / A2)) == 0
    return 2 * sp.Symbol("D1") - A1 - A0 * (B1 - B1 * sp.exp(-A2)) / A2


def w_layer():
    """The layer integrand w(y) = ehat/sqrt(Qhat) and its stable form; checks Qhat."""
    C = sp.exp(y)
    Hhat = H_of_C(C).subs({A0: 1 - rho, A1: rho})
    Qhat = 2 * Hhat / y**2
    Q_stable = (1 - rho) * exprel(y) ** 2 + rho * e2rel(y)
    back = Q_stable.subs({exprel(y): EXPREL_DEF, e2rel(y): E2REL_DEF})
    assert sp.simplify(sp.expand(back - sp.expand_log(Qhat, force=True))) == 0
    ehat = (1 - rho) * sp.exp(y) + rho
    w = ehat / sp.sqrt(Q_stable)
    # w(0) = 1 : the core Debye scaling
    assert sp.limit((ehat / sp.sqrt(Qhat)).subs(rho, sp.Rational(1, 3)), y, 0) == 1
    return w, Q_stable


def dhat_stable():
    """Dhat(Y) = sqrt(2 Hhat(Y)) = |Y| sqrt(Qhat(Y)) (D(1) = lambda Dhat(Yc))."""
    _, Q = w_layer()
    return sp.Abs(Y) * sp.sqrt(Q.subs(y, Y))


def moment_assembly():
    """I = lam J1 + lam^2 J2 from the layer functions (see module docstring)."""
    W0c, W0a, W1c, W1a, Dc, cminus = sp.symbols("W0c W0a W1c W1a Dhat_c c_minus")
    J1 = 2 * Dc / A2 + A3 / A2 * (W0c - W0a)
    J2 = -rho - (1 - rho) * (B1 - cminus) / A2 + A3 / A2 * (W1a - W1c)
    return (W0c, W0a, W1c, W1a, Dc, cminus), J1, J2


def table_of_values():
    """The paper's table of boundary/centre values, recomputed from the first integral."""
    C_m, C_c, C_p = B1 * sp.exp(-A2), sp.Integer(1), B1
    D2 = lambda C: 2 * H_of_C(C) / A2  # noqa: E731  (K = 0: neutral core)
    Dm = sp.sqrt(D2(C_m))
    paper_D = sp.sqrt((A0 + 2 * A1 * (A2 - 1 - sp.log(B1))) / A2)
    # the paper's D(+-1) holds for the paper's approximations: e^{-A2} -> 0 and
    # A0 (B1-2) B1 = 2 A1 (A2 - B1) (its own B1 equation); check at the linear/const limits
    lin = sp.simplify((Dm**2 - paper_D**2).subs(A1, 0).subs(B1, 2).subs(sp.exp(-A2), 0))
    # the paper's D(+-1) is exactly our anode value with C(-1) -> 0 outside the logarithm
    # (ln C(-1) = ln B1 - A2 kept): H(C(-1)) -> A0/2 + A1 (A2 - ln B1 - 1)
    cm_ = sp.Symbol("c_m", positive=True)
    Hm = A0 * (cm_ - 1) ** 2 / 2 + A1 * (cm_ - 1 - (sp.log(B1) - A2))
    assert sp.simplify(2 * Hm.subs(cm_, 0) / A2 - paper_D**2) == 0
    # and the paper's E(-1) = D/A1, E(1) = D/(A0 B1 + A1) are D/eps at the faces
    assert sp.simplify((A0 * C_p + A1) - (A0 * B1 + A1)) == 0
    rows = {
        "C": (C_m, C_c, C_p),
        "phi": (1, sp.log(B1) / A2, 0),
        "eps": (A0 * C_m + A1, A0 + A1, A0 * B1 + A1),
        "rhoZ": (C_m - 1, 0, B1 - 1),
        "p (B2=0)": (C_m / A2 - A3, 1 / A2 - A3 * sp.log(B1) / A2, B1 / A2),
        "D": (Dm, 0, sp.sqrt(D2(C_p))),
        "E": (Dm / (A0 * C_m + A1), 0, sp.sqrt(D2(C_p)) / (A0 * B1 + A1)),
    }
    return rows, {"paper_D_linear_limit_residual": lin}


def linear_exact_solution():
    """Linear model (A1 = 0): an exact solution, and what happens at the anode.

    ``D = eps E = A0 C (C'/(A2 C)) = z0^2 C'`` with ``z0^2 = A0/A2``, so ``D' = C - 1`` is the
    LINEAR equation ``z0^2 C'' = C - 1``; with ``C(1) = B1``, ``C(-1) = B1 e^{-A2}`` and
    ``int (C - 1) = 0``:  ``C = 1 + (B1 - 1) sinh(z/z0)/sinh(1/z0)``, ``B1 = 2/(1 + e^{-A2})``
    exactly (the paper's formula, for any thickness).
    """
    z0 = sp.symbols("z0", positive=True)
    Cz = 1 + (B1 - 1) * sp.sinh(z / z0) / sp.sinh(1 / z0)
    assert sp.simplify(z0**2 * sp.diff(Cz, z, 2) - (Cz - 1)) == 0
    assert sp.simplify(sp.integrate(Cz - 1, (z, -1, 1))) == 0
    b1 = 2 / (1 + sp.exp(-A2))
    left = sp.simplify(Cz.subs(z, -1).subs(B1, b1) - b1 * sp.exp(-A2))
    assert left == 0
    statement = (
        "linear model at the anode: eps = A0 C -> A0 B1 e^{-A2} ~ 1e-16 A0, while D stays "
        "finite (D(-1) = z0 (1 - C(-1))): E = D/eps ~ e^{A2} at the face and ln C ~ ln(s + C(-1)) "
        "with s the distance in units of z0, so phi = (ln B1 - ln C)/A2 falls from 1 to ~0 "
        "logarithmically in s, from s ~ e^{-A2} (~1e-17, i.e. ~1e-19 e) to s ~ 1 (half the drop "
        "within s ~ e^{-A2/2}). The layer integrals stay finite: in y = ln C the "
        "integrand w = y e^y/(e^y - 1) is smooth and W0(-inf) = -zeta(2), W1(-inf) = -zeta(3); "
        "the kernels integrate in y, never in z."
    )
    return Cz, b1, statement


def main():
    print("first integral: D^2/2 = H(C)/A2 + K,  H =", H_of_C(sp.Symbol("C")))
    print("  check dD^2/2 = dH/A2 along solutions:", check_first_integral())
    print("exact electroneutrality H(B1) = H(B1 e^-A2):")
    print("  ", electroneutrality_equation(), "= 0")
    q, a, b, c = b1_quadratic_rho()
    print(f"  divided by A0+A1 (rho = A1/(A0+A1), q = 1 - e^-A2): a={a}, b={b}, c={c}")
    for k, v in b1_limits().items():
        print(f"  B1[{k}] = {v}")
    print("integral C z dz =", integral_Cz_identity())
    w, Q = w_layer()
    print("layer integrand w(y) =", w, " (w(0) = 1)")
    rows, chk = table_of_values()
    print("table (anode, centre, cathode), neutral core:")
    for k, v in rows.items():
        print(f"  {k:9s}", v)
    print("  paper's D(+-1) vs ours, linear limit residual:", chk["paper_D_linear_limit_residual"])
    Cz, b1, statement = linear_exact_solution()
    print("linear model exact solution: C =", Cz, " with B1 =", b1)
    print("  " + statement)


if __name__ == "__main__":
    main()
