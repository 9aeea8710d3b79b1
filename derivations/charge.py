"""Electrode charge, differential capacitance and the small-signal response.

Seed paper section 4: Gauss's law ``dD_z/dz = rho Z``, ``D_z = eps E_z``; blocking electrodes
carry the surface charge ``sigma = D_z(-e)`` (anode face, where ``phi0`` is applied; the
cathode carries ``-D_z(e) = -sigma`` since ``D_z(e) = D_z(-e)``).  In the paper's scaling
``D_bar = D_z/(e phi4 F C_moy)`` (``model.py``).  Results derived and checked here
(``python -m derivations.charge``):

1. The face induction terminates at first order in lambda (neutral core, K = 0):
   ``D_bar(+-1) = lambda Dhat(Yc)`` EXACTLY, ``Dhat = sqrt(2 Hhat)`` (no lambda^2 term, unlike
   the moment ``I = lambda J1 + lambda^2 J2``).  Hence
   ``sigma = S Dhat(ln B1)``, ``S = e phi4 F C_moy lambda = sqrt(phi4 C_moy eps_core R T)``
   (C/m^2): independent of the thickness (up to ``exp(-core/lambda)``).
2. ``dDhat/dY = chat(Y) sign(Y)`` with the LAYER CAPACITANCE ``chat(Y) = exprel(Y) w(Y)``
   (``w`` the layer integrand of ``model.py``; ``chat(0) = 1``; linear model ``chat = e^Y``),
   and electroneutrality ``Hhat(Yc) = Hhat(Yc - A2)`` gives
   ``dYc/dA2 = chat_a / (chat_c + chat_a)``.  So the differential capacitance per area is
   two layers in series:  ``C_d = dsigma/dphi0 = (eps_core/lambda_D) Cdhat``,
   ``Cdhat = chat_c chat_a / (chat_c + chat_a)``, ``lambda_D = lambda e``;
   ``Cdhat -> 1/2`` (Debye-Hueckel: ``C_d = eps_core/(2 lambda_D)``).
3. Linear model exactly (``model.linear_exact_solution``): ``D_bar(1) = z0 (B1 - 1) coth(1/z0)``,
   ``B1 - 1 = tanh(A2/2)``: the closed form is ``lambda tanh(A2/2)``, off by
   ``coth(1/lambda) - 1 ~ 2 exp(-2/lambda)``; ``Cdhat = sech^2(A2/2)/2``.
4. Large voltage (``e^{-A2} -> 0`` at the anode): ``Dhat^2 -> (1 - rho) + 2 rho (A2 - 1 - ln B1)``
   (the paper's table value of ``D(+-1)``): ``sigma ~ S sqrt(2 A2)`` for the constant model
   (depletion zone, ``sigma ~ phi0^{1/2}``), ``S sqrt(2 rho A2)`` for the affine one, ``S`` for the
   linear one (saturation).
5. Small signal about zero volts, constant permittivity in the core (linearised Nernst-Planck
   + Gauss, thermal scaling ``psi = F phi/(R T)``, time ``t D/e^2``, frequency ``W``): with
   ``k^2 = 1/lambda^2 + i W`` the induction is ``d = J/k^2 + A cosh(k x)`` and
   ``Zhat = psi0/J = (2/lambda^2) [1/k^2 + (1/(iW) - 1/k^2) tanh(k)/k]``;
   SI: ``Z = (e/kappa) Zhat`` with the core conductivity ``kappa = phi4 F^2 D C_moy/(R T)``.
   The moment ``int p z dz`` linearises to ``(1 + A3)/lambda^2 int d (1 - x^2)/2 dx`` (thermal
   units), also closed form (``moment_transfer``).
6. Small voltage (``small_voltage_yc``): ``Yc/A2 = 1/2 + sum c_k(rho) A2^k`` (odd k) from
   electroneutrality in truncated power series, used below ``A2 = SMALL_A2`` where ``ln B1`` of
   the closed root loses ``eps/(B1 - 1)``; its bound is twice the first omitted term.  With it
   ``sigma_hat/A2 -> 1/2`` and ``C_d -> eps_core/(2 lambda_D)`` without cancellation; the
   exact solution at any thickness (``ipmc_asym/kernels/charge_exact.py``) has
   ``D(+-1) = lambda sqrt(Dhat(Yc)^2 + kappa^2)`` (``derivations/exact.py``), hence
   ``C_d(0) = eps_core coth(1/lambda)/(2 lambda_D)``.
"""

from __future__ import annotations

import functools

import sympy as sp
from sympy import QQ
from sympy.codegen.cfunctions import expm1
from sympy.polys.rings import ring

from . import model as M
from .kernel import Kernel
from .kernels_spec import MODEL_RHO

# ---- symbols -------------------------------------------------------------------------
Y, y, A2, rho, lam = M.Y, M.y, M.A2, M.rho, M.lam
B1 = M.B1
W = sp.symbols("W", positive=True)  # dimensionless angular frequency  omega e^2 / D
x = sp.symbols("x", real=True)
Jc = sp.symbols("J")  # total current (complex amplitude)


def face_induction():
    """D(1)^2 = 2 H(Yc)/A2 (K = 0) equals lambda^2 * 2 Hhat(Yc): D(1) = lambda Dhat exactly."""
    C = sp.exp(Y)
    H = M.H_of_C(C)
    Hhat = H.subs({M.A0: 1 - rho, M.A1: rho})
    lam2 = (M.A0 + M.A1) / A2
    lhs = 2 * H / A2
    rhs = lam2 * 2 * Hhat
    # with A0 = (A0 + A1)(1 - rho), A1 = (A0 + A1) rho
    s = sp.symbols("s", positive=True)
    check = sp.simplify((lhs - rhs).subs({M.A0: s * (1 - rho), M.A1: s * rho}).subs(
        {rho: sp.Rational(1, 3)}))
    assert check == 0
    return sp.sqrt(2 * Hhat)


def sigma_scale_check():
    """e phi4 F C_moy lambda = sqrt(phi4 C_moy eps_core R T) with lambda^2 = eps_core R T/(e^2 phi4 F^2 C_moy)."""
    e, phi4, F, Cm, eps, R, T = sp.symbols("e phi4 F C_moy eps R T", positive=True)
    lamv = sp.sqrt(eps * R * T / (e**2 * phi4 * F**2 * Cm))
    assert sp.simplify(e * phi4 * F * Cm * lamv - sp.sqrt(phi4 * Cm * eps * R * T)) == 0
    # C_d scale: S F/(R T) = eps/lambda_D
    lD = lamv * e
    assert sp.simplify(sp.sqrt(phi4 * Cm * eps * R * T) * F / (R * T) - eps / lD) == 0
    return True


def layer_capacitance():
    """chat(y) = exprel(y) w(y) and the check dDhat/dY = sign(Y) chat(Y) (Y != 0)."""
    w, Q = M.w_layer()
    chat = M.exprel(y) * w
    # check against the derivative of Dhat = sqrt(2 Hhat), with the primitives expanded
    Hhat = M.H_of_C(sp.exp(y)).subs({M.A0: 1 - rho, M.A1: rho})
    dD = sp.diff(sp.sqrt(2 * Hhat), y)
    chat_f = chat.subs({M.exprel(y): M.EXPREL_DEF, M.e2rel(y): M.E2REL_DEF})
    for yv in (sp.Rational(-7, 2), sp.Rational(-1, 5), sp.Rational(3, 10), sp.Rational(5, 2)):
        for rv in (0, sp.Rational(1, 3), 1):
            sgn = 1 if yv > 0 else -1
            r = (dD - sgn * chat_f).subs({y: yv, rho: rv})
            assert abs(complex(sp.N(r, 30))) < 1e-25, (yv, rv)
    # linear model: chat = e^y
    lin = chat_f.subs(rho, 0)
    for yv in (sp.Rational(-9, 2), sp.Rational(-1, 7), sp.Rational(2, 3), sp.Rational(7, 2)):
        assert abs(complex(sp.N((lin - sp.exp(y)).subs(y, yv), 30))) < 1e-25
    assert sp.limit(chat_f.subs(rho, sp.Rational(1, 3)), y, 0) == 1
    return chat


def series_capacitance():
    """dYc/dA2 = chat_a/(chat_c + chat_a) from Hhat(Yc) = Hhat(Yc - A2); Cdhat = chat_c chat_a/(chat_c + chat_a)."""
    cc, ca = sp.symbols("chat_c chat_a", positive=True)
    # implicit differentiation with dHhat/dY = Dhat chat sign(Y) and Dhat(Yc) = Dhat(Ya):
    # Dhat chat_c dYc = -Dhat chat_a (dYc - dA2)
    dYc = sp.symbols("dYc")
    sol = sp.solve(sp.Eq(cc * dYc, -ca * (dYc - 1)), dYc)[0]
    assert sp.simplify(sol - ca / (cc + ca)) == 0
    return (cc, ca), cc * sol


def linear_exact():
    """Linear model: exact D(1) and C_d from model.linear_exact_solution; closed-form ratio."""
    Cz, b1, _ = M.linear_exact_solution()
    z0 = [s for s in Cz.free_symbols if s.name == "z0"][0]
    D = z0**2 * sp.diff(Cz, M.z)  # D = z0^2 C' in the linear model
    D1 = sp.simplify(D.subs(M.z, 1).subs(B1, b1))
    tanh_form = z0 * sp.tanh(A2 / 2) / sp.tanh(1 / z0)
    assert sp.simplify((D1 - tanh_form).rewrite(sp.exp)) == 0
    cd = sp.simplify(sp.diff(sp.tanh(A2 / 2), A2))
    assert sp.simplify(cd - sp.sech(A2 / 2) ** 2 / 2) == 0
    return D1.subs(z0, lam), tanh_form.subs(z0, lam)


def large_voltage():
    """Dhat^2 at the anode with C(-1) = B1 e^{-A2} -> 0 (ln C(-1) = ln B1 - A2 kept)."""
    Bs = sp.symbols("B1", positive=True)
    ca = sp.symbols("c_a", positive=True)
    Hhat_a = (1 - rho) * (ca - 1) ** 2 / 2 + rho * (ca - 1 - (sp.log(Bs) - A2))
    d2 = sp.expand(2 * Hhat_a.subs(ca, 0))
    # the paper's table value D(+-1)^2 (model.table_of_values) divided by lambda^2
    paper = (M.A0 + 2 * M.A1 * (A2 - 1 - sp.log(Bs))) / A2
    s = sp.symbols("s", positive=True)
    assert sp.simplify(paper.subs({M.A0: s * (1 - rho), M.A1: s * rho}) / (s / A2) - d2) == 0
    # B1 in the same limit: constant A2, linear 2, affine the paper's root
    b_inf = {
        "constant": A2,
        "linear": sp.Integer(2),
        "affine": (1 - 2 * rho) / (1 - rho) * (1 + sp.sqrt(1 + 2 * A2 * rho * (1 - rho) / (1 - 2 * rho) ** 2)),
    }
    return d2, Bs, b_inf


def large_voltage_sigma(model: str):
    """(Dhat_inf(A2), dDhat_inf/dA2) for one model (rho fixed), SymPy expressions in A2."""

    d2, Bs, b_inf = large_voltage()
    r = MODEL_RHO[model]
    expr = sp.sqrt(d2.subs(rho, r).subs(Bs, b_inf[model].subs(rho, r)))
    return expr, sp.diff(expr, A2)


def debye_hueckel_series(model: str, order: int = 5):
    """Series of Dhat(ln B1(A2)) in A2 about 0 (B1 from the exact electroneutrality)."""

    r = MODEL_RHO[model]
    q, a, b, c = M.b1_quadratic_rho()
    a, b, c = (sp.simplify(v.subs(rho, r)) for v in (a, b, c))
    if a == 0:
        root = -c / b
    elif c == 0:
        root = -b / a
    else:
        root = (-b + sp.sqrt(b**2 - 4 * a * c)) / (2 * a)
    root = root.subs(q, 1 - sp.exp(-A2))
    Hhat = M.H_of_C(sp.exp(Y)).subs({M.A0: 1 - r, M.A1: r})
    # Dhat = sqrt(2 Hhat(Y)) = Y sqrt(2 Hhat/Y^2) for Y > 0 (cathode, Yc > 0 for A2 > 0)
    Yc = sp.log(root)
    g = sp.series(2 * Hhat / Y**2, Y, 0, order + 1).removeO()
    Ys = sp.series(Yc, A2, 0, order + 1).removeO()
    dh = sp.series(Ys * sp.sqrt(g.subs(Y, Ys)), A2, 0, order + 1).removeO()
    return sp.expand(dh)


#: small-voltage series of Yc/A2: powers A2^1 .. A2^(SMALL_ORDER - 1) (odd; the even ones vanish)
SMALL_ORDER = 16
#: the series replaces ln B1 for A2 below this (there its first omitted term is < 1e-19 relative)
SMALL_A2 = 0.25


def small_voltage_yc(order: int = SMALL_ORDER):
    """``Yc/A2`` as a series in ``A2`` (coefficients polynomials in rho) and its first omitted term.

    Electroneutrality ``Hhat(Yc) = Hhat(Yc - A2)`` (seed paper section 4, ``D(1) = D(-1)``) with
    ``Yc = A2/2 + d``: ``A2 d = -(h3(A2/2 + d) - h3(-A2/2 + d))``, ``h3 = Hhat - y^2/2 = O(y^3)``,
    solved by fixed-point iteration in truncated power series over ``QQ[rho]`` (each pass fixes
    two more orders; ``d`` is even in ``A2``).  No cancellation: ``ln B1`` from the closed root
    loses ``eps/(B1 - 1)`` relative, the series none, and ``Yc/A2 -> 1/2`` (Debye-Hueckel:
    ``sigma -> C_d(0) phi0``).  Checks: the linear model ``Yc = A2/2 - ln cosh(A2/2)``, the
    constant model ``Yc = ln(A2/(1 - e^{-A2}))``, and the exact root at ``A2 = SMALL_A2`` (30
    digits) for several rho, where the first omitted term bounds the truncation.

    Returns ``(coeffs, tail)``: ``coeffs[j]`` the coefficient of ``A2^(2j+1)`` in ``Yc/A2 - 1/2``
    (``j = 0 .. order/2 - 1``), ``tail`` that of ``A2^(order+1)``; SymPy polynomials in ``rho``.
    """
    R, a, r = ring("a,r", QQ)
    top = order + 2  # d carries a^2 .. a^(order+2): the last one is the omitted term
    cut = top + 2

    def trunc(p, n):
        return R({m: c for m, c in p.items() if m[0] <= n})

    def h3(yv):
        em, yk = R(0), R(1)
        for k in range(1, cut + 1):
            yk = trunc(yk * yv, cut)
            em += yk * QQ(1, int(sp.factorial(k)))
        return trunc((1 - r) * trunc(em * em, cut) * QQ(1, 2) + r * (em - yv) - trunc(yv * yv, cut) * QQ(1, 2), cut)

    d = R(0)
    for _ in range(top // 2 + 1):
        num = h3(a * QQ(1, 2) + d) - h3(-a * QQ(1, 2) + d)
        d = trunc(-R({(m[0] - 1, m[1]): c for m, c in num.items()}), top)
    a_s = sp.Symbol("a")
    dd = sp.expand(d.as_expr().subs(sp.Symbol("r"), rho).subs(a_s, A2))
    coeffs = [sp.expand(dd.coeff(A2, k)) for k in range(2, top + 1)]
    assert all(c == 0 for c in coeffs[1::2]), "d must be even in A2"
    even = coeffs[0::2]  # coefficients of A2^2, A2^4, ..., A2^top in d
    # the two closed-form models
    lin = sp.series(-sp.log(sp.cosh(A2 / 2)), A2, 0, top + 1).removeO()
    con = sp.series(sp.log((A2 / 2) / sp.sinh(A2 / 2)), A2, 0, top + 1).removeO()
    poly = sum(c * A2 ** (2 * j + 2) for j, c in enumerate(even))
    assert sp.expand(poly.subs(rho, 0) - lin) == 0
    assert sp.expand(poly.subs(rho, 1) - con) == 0
    # the exact root at the switch: truncation below the first omitted term (times 2)
    q, qa, qb, qc = M.b1_quadratic_rho()
    for rv in (0, sp.Rational(1, 201), sp.Rational(1, 3), sp.Rational(1, 2), sp.Rational(9, 10), 1):
        av = sp.Rational(SMALL_A2)
        sub = {rho: rv, q: 1 - sp.exp(-av), A2: av}
        ca, cb, cc = (sp.N(v.subs(sub), 60) for v in (qa, qb, qc))
        root = (-cb + sp.sqrt(cb**2 - 4 * ca * cc)) / (2 * ca) if ca != 0 else -cc / cb
        ex = sp.log(root) / av
        ser = sp.Rational(1, 2) + sum(c.subs(rho, rv) * av ** (2 * j + 1) for j, c in enumerate(even[:-1]))
        omitted = abs(sp.N(even[-1].subs(rho, rv) * av ** (top - 1), 40))
        err = abs(sp.N(ex - ser, 40))
        assert err <= 2 * omitted + sp.Float(1e-35), (rv, err, omitted)
        assert err / sp.N(ex) < 1e-18, (rv, err)
    return even[:-1], even[-1]


def small_voltage_kernel():
    """``(Yc/A2, relative truncation bound)`` for ``0 <= A2 <= SMALL_A2`` (Horner, float coefficients)."""

    coeffs, tail = small_voltage_yc()

    def horner_rho(c):
        out = sp.Integer(0)
        for k in range(sp.degree(c, rho) if c.has(rho) else 0, -1, -1):
            out = out * rho + sp.Float(c.coeff(rho, k), 30)
        return out

    a2sq = A2 * A2
    ser = sp.Integer(0)
    for c in reversed(coeffs):
        ser = ser * a2sq + horner_rho(c)
    ratio = sp.Rational(1, 2) + A2 * ser
    # relative bound: twice the first omitted term (the later ones fall by (A2/pi)^2 < 1e-2
    # each; checked against the exact root at SMALL_A2), over Yc/A2 >= 0.48 there
    bound = 2 * abs(horner_rho(tail)) * A2 ** (SMALL_ORDER + 1) / sp.Float(0.48, 30)
    return ratio, bound


@functools.lru_cache(maxsize=None)
def small_signal():
    """Linearised PNP about zero volts: (Zhat(W), moment transfer Mhat(W)) per unit psi0.

    d'' = k^2 d - J, d(+-1) = J/(iW) (blocking: N = J - iW d = 0 at the faces), d even.
    Zhat = psi0/J with psi0 = int d dx / lambda^2.  The moment integral per unit psi0 in
    thermal units: ``m = (1 + A3)/lambda^2 int d (1 - x^2)/2 dx / psi0``.

    The integrals skip the Risch algorithm (``risch=False``): it rewrites ``cosh`` in ``exp``,
    and integrating and simplifying that form takes ~4 times longer than the ``sinh``/``cosh``
    antiderivatives the other methods give.  Cached: the kernels and
    ``derivations/sensing_dynamic.py`` both start from it.
    """
    k = sp.symbols("k")
    A = (Jc / (sp.I * W) - Jc / k**2) / sp.cosh(k)
    d = Jc / k**2 + A * sp.cosh(k * x)
    # checks: the ODE and the boundary values
    assert sp.simplify(sp.diff(d, x, 2) - (k**2 * d - Jc)) == 0
    assert sp.simplify(d.subs(x, 1) - Jc / (sp.I * W)) == 0
    psi0 = sp.simplify(sp.integrate(d, (x, -1, 1), conds="none", risch=False) / lam**2)
    Zhat = sp.simplify(psi0 / Jc)
    ref = (2 / lam**2) * (1 / k**2 + (1 / (sp.I * W) - 1 / k**2) * sp.tanh(k) / k)
    for kv, lv, wv in ((sp.Rational(3, 2) + sp.I / 3, sp.Rational(1, 5), sp.Rational(7, 3)),
                       (sp.Integer(4) + 2 * sp.I, sp.Rational(1, 9), sp.Rational(1, 2))):
        r = (Zhat - ref).subs({k: kv, lam: lv, W: wv})
        assert abs(complex(sp.N(r, 30))) < 1e-20
    mom = sp.simplify(sp.integrate(d * (1 - x**2) / 2, (x, -1, 1), conds="none", risch=False) / lam**2 / psi0)
    # the same in tanh form (no e^{2k} overflow for k ~ 1/lambda ~ 1e3): a = A cosh(k)/J
    a = 1 / (sp.I * W) - 1 / k**2
    mom_stable = ((sp.Rational(2, 3) / k**2 + 2 * a * (1 / k**2 - sp.tanh(k) / k**3))
                  / (2 / k**2 + 2 * a * sp.tanh(k) / k))
    for kv, wv in ((sp.Rational(3, 2) + sp.I / 3, sp.Rational(7, 3)), (sp.Integer(4) + 2 * sp.I, sp.Rational(1, 2))):
        r = (mom - mom_stable).subs({k: kv, W: wv, lam: sp.Rational(1, 5)})
        assert abs(complex(sp.N(r, 30))) < 1e-20
    return k, ref, mom_stable


def small_signal_kernels():
    """(name, args, expression, doc) of the small-signal closed forms (complex, NumPy)."""
    k, Z, mom = small_signal()
    kk = sp.sqrt(1 / lam**2 + sp.I * W)
    return [
        ("impedance_hat", (W, lam), Z.subs(k, kk),
         "Zhat(W) = psi0/J of the linearised PNP about 0 V (constant core permittivity); Z = (e/kappa) Zhat."),
        ("moment_transfer_hat", (W, lam), mom.subs(k, kk),
         "int d (1 - x^2)/2 dx / (lambda^2 psi0): the moment integral per unit psi0 is (1 + A3) times this."),
    ]


def linear_static_state():
    """The linear model's static state at any thickness, in the distance ``xi = z + 1`` from the anode
    face, in a form accurate where the anode is depleted (the bias reference linearises about it).

    ``model.linear_exact_solution`` gives ``C = 1 + (B1 - 1) sinh(z/lambda)/sinh(1/lambda)`` with
    ``B1 = 2/(1 + e^{-A2})``; at the anode ``C(-1) = u_f = 2 e^{-A2}/(1 + e^{-A2})`` (~2e-17 at 1 V),
    which ``1 + (B1 - 1)(...)`` cannot hold (it cancels to rounding).  Written from ``u_f`` with
    ``expm1``:  ``u = u_f + (1 - u_f)(1 - e^{-xi/lambda})(1 + e^{(xi - 2)/lambda})/(1 - e^{-2/lambda})``
    keeps relative accuracy at the face, and the induction is ``D = lambda^2 u'`` (the zero flux with
    ``eps_hat = u``).  Checked here against the exact solution, the ODE ``lambda^2 u'' = u - 1``, the
    face values and ``int (u - 1) = 0``.  Returns ``(xi, uf, u, D, uf_of_A2)``.
    """
    xi, uf = sp.symbols("xi uf", real=True)
    den = -expm1(-2 / lam)  # 1 - e^{-2/lambda}
    near = -expm1(-xi / lam)  # 1 - e^{-xi/lambda}
    far = sp.exp((xi - 2) / lam)  # the cathode layer
    # e^{(xi - 2)/lambda} - e^{-2/lambda} = far * near: no cancellation where xi is below the spacing of
    # the doubles at 2 (the anode's sublayer, ~u_f lambda: 3e-17 at 1 V), where (xi - 2) rounds to -2
    u = uf + (1 - uf) * near * (1 + far) / den
    D = lam * (1 - uf) * (sp.exp(-xi / lam) + far) / den
    uf_of_A2 = 2 * sp.exp(-A2) / (1 + sp.exp(-A2))  # C(-1) = B1 e^{-A2}, no overflow for A2 >= 0
    plain = {expm1: lambda a: sp.exp(a) - 1}
    u_e, D_e = u.replace(expm1, plain[expm1]), D.replace(expm1, plain[expm1])
    Cz, b1, _ = M.linear_exact_solution()
    exact = Cz.subs(M.z, xi - 1).subs(sp.Symbol("z0", positive=True), lam).subs(B1, b1)
    assert sp.simplify((u_e.subs(uf, uf_of_A2) - exact).rewrite(sp.exp)) == 0
    assert sp.simplify(lam**2 * sp.diff(u_e, xi, 2) - (u_e - 1)) == 0
    assert sp.simplify(D_e - lam**2 * sp.diff(u_e, xi)) == 0
    assert sp.simplify(u_e.subs(xi, 0) - uf) == 0 and sp.simplify(u_e.subs(xi, 2) - (2 - uf)) == 0
    assert sp.simplify(sp.integrate(u_e - 1, (xi, 0, 2))) == 0
    assert sp.simplify(uf_of_A2 - b1 * sp.exp(-A2)) == 0
    return xi, uf, u, D, uf_of_A2


def linear_static_kernels():
    """(name, args, expression, doc) of :func:`linear_static_state` (NumPy, vectorised)."""
    xi, uf, u, D, uf_of_A2 = linear_static_state()
    return [
        ("linear_static_concentration", (xi, lam, uf), u,
         "C/C_moy of the linear model's static state at the distance xi = z + 1 from the anode face (C(0) = uf)."),
        ("linear_static_induction", (xi, lam, uf), D,
         "D_bar = lambda^2 dC/dxi of the linear model's static state (the zero flux with eps_hat = C/C_moy)."),
        ("linear_anode_concentration", (A2,), uf_of_A2,
         "``uf = C(-1)/C_moy = 2 e^{-A2}/(1 + e^{-A2})`` of the linear model at ``A2 = F |phi0|/(R T) >= 0``."),
    ]


def kernels():
    """Charge kernels: layer capacitance (generic and per model) and the series capacitance."""

    chat = layer_capacitance()
    ks = [Kernel("layer_capacitance", (y, rho), (chat,),
                 "Layer capacitance chat(y) = exprel(y) w(y) = |dDhat/dY| (chat(0) = 1).",
                 "derivations.charge:layer_capacitance")]
    for name, r in MODEL_RHO.items():
        c = chat.subs(rho, r)
        if r == 0:
            c = sp.exp(y)  # exprel(y) w(y) = e^y exactly (checked in layer_capacitance)
        ks.append(Kernel(f"layer_capacitance_{name}", (y,), (c,),
                         f"Layer capacitance chat(y), {name} model (rho = {r}).",
                         "derivations.charge:layer_capacitance"))
    (cc, ca), cd = series_capacitance()
    ks.append(Kernel("series_capacitance", (cc, ca), (cd,),
                     "Cdhat = dDhat(ln B1)/dA2 = chat_c chat_a/(chat_c + chat_a) (layers in series).",
                     "derivations.charge:series_capacitance"))
    ratio, bound = small_voltage_kernel()
    ks.append(Kernel("yc_small", (A2, rho), (ratio, bound),
                     f"(Yc/A2, relative truncation bound) for 0 <= A2 <= {SMALL_A2}: Yc = ln B1 without cancellation.",
                     "derivations.charge:small_voltage_yc"))
    return ks


def main():
    print("face induction: D(+-1) = lambda * Dhat(Yc), Dhat =", face_induction())
    print("sigma scale  e phi4 F C_moy lambda = sqrt(phi4 C_moy eps_core R T):", sigma_scale_check())
    print("layer capacitance chat(y) =", layer_capacitance())
    print("series: Cdhat =", series_capacitance()[1])
    print("linear exact D(1) =", linear_exact()[0])
    d2, _, _ = large_voltage()
    print("large voltage Dhat^2 ->", d2)
    for m in ("constant", "linear", "affine"):
        print(f"  {m}: Dhat_inf =", large_voltage_sigma(m)[0])
    print("Debye-Hueckel series (constant):", debye_hueckel_series("constant", 5))
    k, Z, mom = small_signal()
    print("small signal Zhat =", Z, " k^2 = 1/lam^2 + i W")
    print("  low frequency: Zhat * iW ->", sp.limit((Z * sp.I * W).subs(k, sp.sqrt(1 / lam**2 + sp.I * W)), W, 0))
    print("moment per psi0 =", mom)


if __name__ == "__main__":
    main()
