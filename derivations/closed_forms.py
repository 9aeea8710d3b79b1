"""Closed forms of the layer functions W0(Y), W1(Y) for the three permittivity models.

``W0(Y) = int_0^Y w dy`` and ``W1(Y) = int_0^Y (w/y) W0 dy`` (see ``model.py``) carry all
the voltage dependence of ``I = lambda J1 + lambda^2 J2``.  ``w(y)`` is analytic on the real
axis; its nearest complex singularities (zeros of ``Qhat``) are at ``2.09 +- 7.46i``
(constant), ``-0.17 +- 6.07i`` (affine) and ``+-2 pi i`` (linear).

Three regimes, each an expansion derived here:

* Debye-Hueckel / matched region (``|Y|`` up to ~31): Taylor expansions of ``w`` computed
  by exact power-series arithmetic (30 significant digits) about centres ``k/2``, each
  used on ``|Y - k/2| <= 1/4`` (ratio <= 1/24 of the convergence radius, 10 coefficients:
  truncation <= 2e-14 relative to max(|W|, 1), measured against 45-term series).  Why so
  fine a spacing: the evaluation cost is the number of terms (a Horner step each, at both
  faces of every point), and centres 1/2 apart need 10 coefficients where centres 2 apart
  needed 19 (and 6 where 9 were needed at the ``leading`` accuracy); the tables stay a few
  kB.  The patch at 0 is the small-voltage (Debye-Hueckel) expansion.
* Depletion zone (anode, ``T = -Y > 31``, large ``A2``): ``w(-t) -> rho t / sqrt(a + b t)``
  with ``a = 1 - 3 rho``, ``b = 2 rho`` up to ``O(t e^{-t})``; integrated in closed form
  (SymPy), plus the constants ``K0 = lim (int_0^T w - Omega(T))`` and ``K1`` (mpmath).
  For the constant model this is ``-W0 = (sqrt2/3) s^{3/2} + sqrt2 s^{1/2} + K0``,
  ``s = T - 1``: the depletion zone whose width grows like ``sqrt(phi0)``.
  For the linear model ``rho = 0``: no depletion zone, ``W0 -> -zeta(2)``, ``W1 -> -zeta(3)``.
* Accumulation (cathode, ``Y > 9``, only reached by the constant model above ~80 V):
  ``w ~ y e^{-y/2}/sqrt2``: ``W0 = W0inf - sqrt2 (Y + 2) e^{-Y/2}``,
  ``W1 = W1inf - sqrt2 W0inf e^{-Y/2}`` (leading terms).

The linear model also has the exact forms ``W0 = -Li2(1 - e^Y)``, ``W1 = -Li3(1 - e^Y)``
(derived in :func:`linear_exact`), emitted as kernels and used as an independent check.
"""

from __future__ import annotations

import mpmath as mp
import sympy as sp
from mpmath.libmp import fone, mpf_div, mpf_mul, mpf_neg, mpf_sum
from sympy.codegen.cfunctions import expm1

from . import model as M
from .kernel import Kernel

#: working precision (decimal digits) of every number written into the kernels
DPS = 24
mp.mp.dps = DPS

RHO = {"constant": mp.mpf(1), "linear": mp.mpf(0), "affine": mp.mpf(5) / 1005}
NTERMS = 9
#: spacing of the patch centres (centre k * PATCH_STEP, used on |Y - centre| <= PATCH_STEP / 2)
PATCH_STEP = 0.5
K_MIN = -63  # patches from Y = -31.75 ...
K_MAX = 19  # ... to Y = 9.75


# ---- exact power-series arithmetic on mpmath numbers ----------------------------------
# s_mul and s_inv hold most of the time of the derivation (a few million products): they call
# mpmath's raw-tuple layer, the very operations ``mp.fsum(x * y ...)`` performs (each product
# rounded to the working precision, their sum rounded once) without building an ``mpf`` per
# product: the same numbers to the bit, in ~60 % of the time.
def _raw(a):
    return [mp.mpf(v)._mpf_ for v in a]


def s_mul(a, b):
    prec, rnd = mp.mp._prec_rounding
    ra, rb = _raw(a), _raw(b)
    return [mp.mp.make_mpf(mpf_sum([mpf_mul(ra[i], rb[k - i], prec, rnd) for i in range(k + 1)], prec, rnd))
            for k in range(len(ra))]


def s_inv(a):
    prec, rnd = mp.mp._prec_rounding
    ra = _raw(a)
    out = [mpf_div(fone, ra[0], prec, rnd)]
    for k in range(1, len(ra)):
        s = mpf_sum([mpf_mul(ra[i], out[k - i], prec, rnd) for i in range(1, k + 1)], prec, rnd)
        out.append(mpf_div(mpf_neg(s), ra[0], prec, rnd))
    return [mp.mp.make_mpf(v) for v in out]


def s_invsqrt(a):
    """(a)^{-1/2} by the recurrence for f^2 a = 1 via g = sqrt(a)."""
    n = len(a)
    g = [mp.mpf(0)] * n
    g[0] = mp.sqrt(a[0])
    for k in range(1, n):
        g[k] = (a[k] - mp.fsum(g[i] * g[k - i] for i in range(1, k))) / (2 * g[0])
    return s_inv(g)


def w_series(c, rho, n):
    """Taylor coefficients of w(c + h) in h (n terms)."""
    ec = mp.exp(c)
    ex = [ec / mp.factorial(k) for k in range(n + 2)]  # e^{c+h}
    if c == 0:
        exprel = [1 / mp.factorial(k + 1) for k in range(n)]
        e2rel = [2 / mp.factorial(k + 2) for k in range(n)]
    else:
        num1 = list(ex[:n])
        num1[0] -= 1  # e^{c+h} - 1
        inv_y = s_inv([mp.mpf(c), mp.mpf(1)] + [mp.mpf(0)] * (n - 2))
        exprel = s_mul(num1, inv_y)
        num2 = list(num1)
        num2[0] -= c
        num2[1] -= 1  # e^{c+h} - 1 - (c+h)
        e2rel = [2 * v for v in s_mul(s_mul(num2, inv_y), inv_y)]
    Q = [(1 - rho) * v for v in s_mul(exprel, exprel)]
    Q = [Q[k] + rho * e2rel[k] for k in range(n)]
    eh = [(1 - rho) * ex[k] for k in range(n)]
    eh[0] += rho
    return s_mul(eh, s_invsqrt(Q))


def sqrtq_series(rho, n):
    """Taylor coefficients of sqrt(Qhat(y)) at y = 0 (Dhat(Y) = |Y| sqrt(Qhat(Y)))."""
    exprel = [1 / mp.factorial(k + 1) for k in range(n)]
    e2rel = [2 / mp.factorial(k + 2) for k in range(n)]
    Q = [(1 - rho) * v for v in s_mul(exprel, exprel)]
    Q = [Q[k] + rho * e2rel[k] for k in range(n)]
    return s_mul(Q, s_invsqrt(Q))


#: terms of the sqrt(Qhat) series used for |Y| <= 1/2 (radius >= 6: error ~ 12^-14;
#: measured against 30 terms: <= 6e-17 relative)
N_SQRTQ = 14


#: coefficients evaluated at order 1 (``leading``): W0 to ~(1/24)^6 ~ 1e-8 (measured <= 7e-9;
#: the ``leading`` error estimate adds 1e-6 for it), W1 -- which only feeds that estimate -- to
#: ~(1/24)^4 (measured <= 3e-5), sqrt(Qhat) to <= 1e-8 (|Y| <= 1/2)
N_W0_LEADING = 6
N_W1_ESTIMATE = 4
N_SQRTQ_LEADING = 8


NCONT = 44  # terms used to continue W0, W1 from one centre to the next (ratio <= 1/3)


def _patch(c, rho, W0c, W1c, n):
    """Taylor polynomials (n+1 coefficients) in h = Y - c of W0 and W1 about c."""
    ws = w_series(c, rho, n + 2)
    W0 = [W0c] + [ws[k] / (k + 1) for k in range(n + 1)]
    if c == 0:
        W0_over_y = [ws[k] / (k + 1) for k in range(n + 1)]
        integrand = s_mul(ws[: n + 1], W0_over_y)
    else:
        inv_y = s_inv([mp.mpf(c), mp.mpf(1)] + [mp.mpf(0)] * (n - 1))
        integrand = s_mul(s_mul(ws[: n + 1], inv_y), W0[: n + 1])
    W1 = [W1c] + [integrand[k] / (k + 1) for k in range(n)]
    return W0[: n + 1], W1[: n + 1]


def _peval(coefs, h):
    return mp.fsum(cf * h**k for k, cf in enumerate(coefs))


def march(rho, kmin, kmax, step=2):
    """Patches about c = step * k for k in [kmin, kmax] (kmin <= 0 <= kmax).

    W0 and W1 at each centre are obtained by analytic continuation from the previous centre
    (``NCONT``-term Taylor series evaluated at h = +-step, well inside the convergence radius),
    starting from W0(0) = W1(0) = 0: no quadrature involved.
    """
    out = {}
    for direction, klim in ((-1, kmin), (1, kmax)):
        W0c = W1c = mp.mpf(0)
        k = 0
        while True:
            c = mp.mpf(step * k)
            a, b = _patch(c, rho, W0c, W1c, NCONT)
            out[k] = (a, b)
            if k == klim:
                break
            h = mp.mpf(step * direction)
            W0c, W1c = _peval(a, h), _peval(b, h)
            k += direction
    return out


# ---- asymptotics (SymPy) ---------------------------------------------------------------
t, T = sp.symbols("t T", positive=True)


def depletion_forms(rho_val):
    """Omega(T) = int w_inf, and the W1 integrand's primitive, for w_inf = rho t/sqrt(a + b t)."""
    r = sp.nsimplify(str(rho_val)) if rho_val not in (0, 1) else sp.Integer(int(rho_val))
    if r == 0:
        return sp.Integer(0), sp.Integer(0), sp.Integer(0)
    a, b = 1 - 3 * r, 2 * r
    t1 = sp.Max(0, -a / b)  # where a + b t = 0 (constant model: t = 1)
    u, U = sp.symbols("u U", positive=True)  # u = t - t1 >= 0
    winf = r * (u + t1) / sp.sqrt(a + b * t1 + b * u)
    # risch=False: the same antiderivatives (hence the same generated code) in a third of the time
    Om_U = sp.simplify(sp.integrate(winf, (u, 0, U), risch=False))
    K0 = sp.Symbol("K0")
    P1_U = sp.simplify(sp.integrate(sp.expand(r / sp.sqrt(a + b * t1 + b * u) * (Om_U.subs(U, u) + K0)), (u, 0, U),
                                    risch=False))
    Om = Om_U.subs(U, T - t1)
    P1 = P1_U.subs(U, T - t1)
    return Om, P1, t1


def depletion_constants(rho_val, Om, P1, t1):
    """K0, K1 with -W0(-T) = Omega(T) + K0, -W1(-T) = P1(T) + K1 up to O(T e^{-T}).

    W0(-60), W1(-60) come from the analytic continuation of the patches (``march``).
    """
    rho = mp.mpf(rho_val)
    kfar = -30  # centre 2 kfar = -60 (steps of 2)
    pts = march(rho, kfar, 0, step=2)
    Tb = mp.mpf(60)
    W0T = -pts[kfar][0][0]
    W1T = -pts[kfar][1][0]
    Omf = sp.lambdify(T, Om, "mpmath")
    K0 = W0T - (Omf(Tb) if Om != 0 else 0)
    P1f = sp.lambdify((T, sp.Symbol("K0")), P1, "mpmath")
    K1 = W1T - (P1f(Tb, K0) if P1 != 0 else 0)
    return K0, K1


def accumulation_constants(rho_val):
    """W0(inf), W1(inf) for the constant model (continued to Y = 80; tail ~ e^{-40})."""
    pts = march(mp.mpf(rho_val), 0, 40)
    return pts[40][0][0], pts[40][1][0]


def linear_exact():
    """Linear model (rho = 0): w = y e^y/(e^y - 1), W0 = -Li2(1 - e^Y), W1 = -Li3(1 - e^Y)."""
    y = M.y
    w, _ = M.w_layer()
    w0 = sp.simplify(w.subs(M.rho, 0).subs({M.exprel(y): M.EXPREL_DEF, M.e2rel(y): M.E2REL_DEF}))
    W0 = -sp.polylog(2, 1 - sp.exp(y))
    W1 = -sp.polylog(3, 1 - sp.exp(y))
    # W0' = w and W1' = (w/y) W0, checked at sample points (polylog derivatives do not
    # simplify symbolically through log(exp(y)))
    r0 = sp.diff(W0, y) - y * sp.exp(y) / (sp.exp(y) - 1)
    r1 = sp.diff(W1, y) - (sp.exp(y) / (sp.exp(y) - 1)) * W0
    r2 = w0 - y * sp.exp(y) / (sp.exp(y) - 1)
    for yv in (sp.Rational(-7, 2), sp.Rational(-1, 3), sp.Rational(1, 5), sp.Rational(5, 2)):
        for r in (r0, r1, r2):
            assert abs(complex(r.subs(y, yv).evalf(30))) < 1e-25, (r, yv)
    return W0, W1


# ---- kernels -------------------------------------------------------------------------
def model_tables(name):
    """Rows of the patch tables (``NTERMS + 1`` coefficients each) about ``PATCH_STEP * k``."""
    rho = RHO[name]
    pts = march(rho, K_MIN, K_MAX, step=PATCH_STEP)
    W0rows = [pts[k][0][: NTERMS + 1] for k in range(K_MIN, K_MAX + 1)]
    W1rows = [pts[k][1][: NTERMS + 1] for k in range(K_MIN, K_MAX + 1)]
    return W0rows, W1rows


def kernels():
    """Kernels and module constants for the closed forms (the patch tables: :func:`tables`).

    The numbers are computed at ``DPS`` digits whatever the global mpmath precision
    (tests and other modules set their own): the generated file must not depend on import
    order.
    """
    with mp.workdps(DPS):
        return _kernels()


def tables():
    """The patch tables of the three models and their layout, at ``DPS`` digits as :func:`kernels`.

    Apart from the kernels: a third of the derivation's time, which only the generated module
    needs, not a comparison of the kernels with their expressions.
    """
    with mp.workdps(DPS):
        return _tables()


def _tables():
    out = {name: model_tables(name) for name in ("constant", "linear", "affine")}
    out["_kmin"], out["_kmax"], out["_step"] = K_MIN, K_MAX, PATCH_STEP
    out["_sqrtq"] = {name: sqrtq_series(RHO[name], N_SQRTQ) for name in RHO}
    # unrolled Horner evaluators (name, (coefficients of W0, of W1) or coefficients of sqrt(Qhat))
    out["_horner"] = {"patch_full": (NTERMS + 1, NTERMS + 1), "patch_leading": (N_W0_LEADING, N_W1_ESTIMATE),
                      "sqrtq_full": N_SQRTQ, "sqrtq_leading": N_SQRTQ_LEADING}
    return out


def _kernels():

    ks, consts = [], {}
    Y = M.Y
    # linear exact (polylogs) -- independent check of the patches
    W0l, W1l = linear_exact()
    li2, li3 = sp.Function("li2"), sp.Function("li3")
    arg = -expm1(Y)
    ks.append(Kernel("w0_linear_exact", (Y,), (-li2(arg),), "W0 = -Li2(1 - e^Y), linear model (exact).",
                     "derivations.closed_forms:linear_exact"))
    ks.append(Kernel("w1_linear_exact", (Y,), (-li3(arg),), "W1 = -Li3(1 - e^Y), linear model (exact).",
                     "derivations.closed_forms:linear_exact"))
    for name in ("constant", "linear", "affine"):
        Om, P1, t1 = depletion_forms(RHO[name])
        K0, K1 = depletion_constants(RHO[name], Om, P1, t1)
        consts[f"K0_{name.upper()}"] = K0
        consts[f"K1_{name.upper()}"] = K1
        K0s = sp.Symbol(f"K0_{name.upper()}")
        K1s = sp.Symbol(f"K1_{name.upper()}")
        Om_T = Om.subs(T, -Y)
        P1_T = P1.subs(sp.Symbol("K0"), K0s).subs(T, -Y)
        ks.append(Kernel(
            f"depletion_{name}", (Y,), (-(Om_T + K0s), -(P1_T + K1s)),
            f"(W0, W1) for Y << 0 (depletion zone, {name} model); error O(|Y| e^Y).",
            "derivations.closed_forms:depletion_forms"))
        if name == "constant":  # the only model whose cathode reaches the accumulation regime
            W0inf, W1inf = accumulation_constants(RHO[name])
            consts["W0INF_CONSTANT"] = W0inf
            consts["W1INF_CONSTANT"] = W1inf
    accY = sp.Symbol("Y")
    W0i, W1i = sp.Symbol("W0INF_CONSTANT"), sp.Symbol("W1INF_CONSTANT")
    ks.append(Kernel(
        "accumulation_constant", (accY,),
        (W0i - sp.sqrt(2) * (accY + 2) * sp.exp(-accY / 2), W1i - sp.sqrt(2) * W0i * sp.exp(-accY / 2)),
        "(W0, W1) for Y >> 1 (cathode accumulation, constant model), leading terms.",
        "derivations.closed_forms:accumulation"))
    return ks, consts
