"""The ``exact`` rung with the pressure term of the Nernst-Planck law (option ``pressure_term``).

Derivation in ``derivations/pressure.py`` (paper eqs (4)-(5), static): with
``beta = (v1 - M1 v2/M2) C_moy``, ``g0 = 1 - beta (1 + A3)``, ``b0 = beta/g0`` and
``m = e^y - 1`` (``y = ln C``), the length element is ``dz = lambda_b ehat_b dy/sqrt(S + kappa^2)``
with ``lambda_b = lambda/sqrt(g0)``, ``ehat_b = ehat/(1 - b0 m)`` and ``S`` the first-integral
potential.  That is the form of :mod:`ipmc_asym.kernels.exact`, whose panel layout, Newton on
``ell = -ln kappa`` and moment accumulation are reused here unchanged; what differs:

* the face values ``(Yc, Ya)`` solve ``V(Yc) - V(Ya) = A2`` (the voltage) and
  ``S(Yc) = S(Ya)`` (electroneutrality, any ``kappa``) by Newton from the paper's ``B1``;
* ``S`` in the core (``|y| < 1/2``) is ``y^2 Q`` with ``Q = int_0^1 2 tau q(y tau) dtau`` by
  Gauss-Legendre (``q`` entire in the disc ``|y| < 1/2`` up to the pole of ``1/(1 - b0 m)``,
  far for ``|b0| < 1``), beyond it the closed form;
* the moment is ``I = (1/A2) int P z dz`` with the closed-form pressure ``P(y)`` accumulated in
  place of ``y`` (``int z dz = 0``).

At ``beta = 0`` every piece reduces to the paper's model (``tests/kernels/test_pressure.py``
compares with :func:`ipmc_asym.kernels.exact.moment_exact`).
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.kernels._generated import b1_exact
from ipmc_asym.kernels._generated_exact import exact_outer
from ipmc_asym.kernels._generated_pressure import (
    pressure_core_q,
    pressure_ehat,
    pressure_p,
    pressure_s_far,
    pressure_s_outer,
    pressure_volt,
)
from ipmc_asym.kernels.exact import (
    LENGTH_TOL,
    Y_SWITCH,
    _accumulate,
    _asinh_scaled,
    _core_layout,
    _outer_count,
)
from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.special import gauss_legendre

__all__ = ["moment_pressure", "pressure_groups", "face_values", "pressure_of_y", "volt_of_y", "NODES"]

NODES = 10
_X, _W, _S = (np.ascontiguousarray(a) for a in gauss_legendre(NODES))
#: Gauss-Legendre nodes for ``Q = int_0^1 2 tau q(y tau) dtau`` (|y| <= 1/2: truncation < 1e-17)
_QN = 16
_QX, _QW, _ = (np.ascontiguousarray(a) for a in gauss_legendre(_QN))


@jit
def pressure_groups(beta, A3):
    """``(g0, b0)``: ``g0 = 1 - beta (1 + A3)`` (``gamma - beta C`` at ``C = 1``), ``b0 = beta/g0``."""
    g0 = 1.0 - beta * (1.0 + A3)
    return g0, beta / g0


@jit
def _l1(x):
    """``L1(x) = -ln(1 - x)/x`` (``x < 1``; 1 at 0), series below ``|x| = 0.05``."""
    if abs(x) < 0.05:
        s = 0.0
        for k in range(12, 0, -1):
            s = (s + 1.0 / k) * x if k > 1 else s + 1.0
        return s
    return -math.log1p(-x) / x


@jit
def _r3(x):
    """``R3(x) = (ln(1 - x) + x + x^2/2)/x^3`` (``x < 1``; -1/3 at 0), series below ``|x| = 1/2``."""
    if abs(x) <= 0.5:
        s = 0.0
        for k in range(60, 2, -1):
            s = s * x - 1.0 / k
        return s
    return (math.log1p(-x) + x + 0.5 * x * x) / (x * x * x)


@jit
def _q_core(y, rho, b0):
    """``Q(y) = S(y)/y^2 = int_0^1 2 tau q(y tau) dtau`` (``|y| <= 1/2``)."""
    s = 0.0
    for i in range(_QN):
        t = 0.5 * (_QX[i] + 1.0)
        s += _QW[i] * t * pressure_core_q(y * t, rho, b0)
    return s  # 2 * (1/2) * sum


@jit
def _s_of_y(y, rho, b0):
    """First-integral potential ``S(y)`` (``D^2 = lambda^2 (S + kappa^2)/g0``)."""
    if abs(y) < Y_SWITCH:
        return y * y * _q_core(y, rho, b0)
    em = math.expm1(y)
    x = b0 * em
    if abs(x) > 0.5:
        return pressure_s_far(y, em, math.log1p(-x), rho, b0, 1.0 / b0)
    return pressure_s_outer(y, em, _r3(x), 1.0 - rho, b0)


@jit
def _p_of_y(y, A3, b0, g0):
    em = math.expm1(y)
    return pressure_p(y, em, _l1(b0 * em), A3, b0, g0)


@jit
def _v_of_y(y, b0, g0):
    em = math.expm1(y)
    return pressure_volt(y, em, _l1(b0 * em), b0, g0)


@jit
def pressure_of_y(y, A3, b0, g0, out):
    """``P(y)`` at every ``y`` (array) into ``out``: ``p = P/A2 + const``, ``P(0) = 0``."""
    for i in range(y.shape[0]):
        out[i] = _p_of_y(y[i], A3, b0, g0)
    return out


@jit
def volt_of_y(y, b0, g0):
    """``V(y)``, ``V' = 1/(g0 (1 - b0 m))``: ``A2 (phi(y1) - phi(y2)) = V(y2) - V(y1)``."""
    return _v_of_y(y, b0, g0)


@jit
def face_values(A2, rho, b0, g0):
    """``(Yc, Ya, ok)``: ``ln C`` at the cathode and the anode with the pressure term.

    Newton on ``V(Yc) - V(Ya) = A2``, ``S(Yc) = S(Ya)`` from the paper's exact ``B1``
    (``Ya = Yc - A2``), with step halving that keeps ``1 - b0 m > 0`` at both faces.
    """
    Yc = math.log(b1_exact(A2, rho))
    Ya = Yc - A2
    if b0 > 0.0 and 1.0 - b0 * math.expm1(Yc) < 0.5:
        # beta > 0: C saturates below 1 + 1/b0; start inside, where 1 - b0 m = 1/2
        Yc = math.log1p(0.5 / b0)
    for it in range(400):
        mc = math.expm1(Yc)
        ma = math.expm1(Ya)
        f1 = _v_of_y(Yc, b0, g0) - _v_of_y(Ya, b0, g0) - A2
        f2 = _s_of_y(Yc, rho, b0) - _s_of_y(Ya, rho, b0)
        dc = 1.0 - b0 * mc
        da = 1.0 - b0 * ma
        j11 = 1.0 / (g0 * dc)
        j12 = -1.0 / (g0 * da)
        j21 = 2.0 * (1.0 + (1.0 - rho) * mc) * mc / dc
        j22 = -2.0 * (1.0 + (1.0 - rho) * ma) * ma / da
        det = j11 * j22 - j12 * j21
        if det == 0.0 or not math.isfinite(det):
            break
        sc = (f1 * j22 - f2 * j12) / det
        sa = (j11 * f2 - j21 * f1) / det
        # steps of at most 2 in ln C: S grows only like y/|b0| where b0 m << -1, and a full
        # Newton step from the paper's B1 can overshoot by orders of magnitude there
        t = min(1.0, 2.0 / max(abs(sc), abs(sa)))
        for _ in range(60):
            if 1.0 - b0 * math.expm1(Yc - t * sc) > 0.0 and 1.0 - b0 * math.expm1(Ya - t * sa) > 0.0:
                break
            t *= 0.5
        Yc -= t * sc
        Ya -= t * sa
        if abs(sc) <= 1e-15 * (1.0 + abs(Yc)) and abs(sa) <= 1e-15 * (1.0 + abs(Ya)):
            break
    # accepted where both equations hold to rounding (relative 1e-12)
    r1 = abs(_v_of_y(Yc, b0, g0) - _v_of_y(Ya, b0, g0) - A2) / A2
    sc_ = _s_of_y(Yc, rho, b0)
    r2 = abs(sc_ - _s_of_y(Ya, rho, b0)) / sc_ if sc_ > 0.0 else math.inf
    return Yc, Ya, r1 <= 1e-12 and r2 <= 1e-12


@jit
def _core_fill(ysw, sgn, V1, m, rho, b0, A3, g0, X, split, F, G, Pn, H, asym):
    """:func:`ipmc_asym.kernels.exact._core_fill` with ``(ehat_b, Q)`` and ``P(y)`` at the nodes."""
    n = X.shape[0]
    em2V1 = math.expm1(-2.0 * V1)
    p = 0
    for j in range(m, 0, -1):
        d_lo = 0.0 if j == 1 else (1.0 if j == 2 else 2.0 ** (j - 2))
        d_hi = min(1.0 if j == 1 else 2.0 ** (j - 1), V1)
        hs = (d_hi - d_lo) / split
        for k in range(split):
            top = d_hi - k * hs
            h = 0.5 * hs
            H[p] = h
            for i in range(n):
                dd = top - h * (X[i] + 1.0)
                sech2 = 0.0
                if asym:
                    y = sgn * ysw * math.exp(-dd)
                    t2 = 1.0
                else:
                    vv = V1 - dd
                    e2v = math.exp(-2.0 * vv)
                    em = -math.expm1(-2.0 * vv)
                    y = sgn * ysw * math.exp(-dd) * (em / -em2V1)
                    th = em / (1.0 + e2v)
                    t2 = th * th
                    sech2 = 4.0 * e2v / ((1.0 + e2v) * (1.0 + e2v))
                e = pressure_ehat(y, rho, b0)
                t1 = 1.0 + (_q_core(y, rho, b0) - 1.0) * t2
                f = e / math.sqrt(t1)
                F[p * n + i] = f
                G[p * n + i] = f * (1.0 - t2) / t1 - sech2
                Pn[p * n + i] = _p_of_y(y, A3, b0, g0)
            p += 1
    return p


@jit
def _outer_fill(Yend, sgn, rho, b0, A3, g0, X, split, E, S2, Pn, H):
    """``(ehat_b, S, P)`` at the y-nodes (1/2, 1, 2, 4, ... Yend); returns the count of panels."""
    n = X.shape[0]
    p = 0
    a = Y_SWITCH
    while a < Yend:
        b = min(2.0 * a, Yend)
        hs = (b - a) / split
        for k in range(split):
            lo = a + k * hs
            h = 0.5 * hs
            H[p] = h
            for i in range(n):
                y = sgn * (lo + h * (X[i] + 1.0))
                E[p * n + i] = pressure_ehat(y, rho, b0)
                S2[p * n + i] = _s_of_y(y, rho, b0)
                Pn[p * n + i] = _p_of_y(y, A3, b0, g0)
            p += 1
        a = b
    return p


@jit
def moment_pressure_nodes(lam, A2, A3, rho, beta, X, Wt, S, split):
    """:func:`moment_pressure` with given Gauss-Legendre nodes and panels split ``split`` times."""
    n = X.shape[0]
    g0, b0 = pressure_groups(beta, A3)
    nan = math.nan
    if not g0 > 0.0 or not abs(b0) < 1.0:
        return nan, nan, nan, nan, -1, nan
    Yc, Ya, fok = face_values(A2, rho, b0, g0)
    if not fok:
        return nan, nan, nan, nan, -1, nan
    lam_b = lam / math.sqrt(g0)
    B1 = math.exp(Yc)
    ends = (Yc, -Ya)
    sgns = (1.0, -1.0)
    nout = max(_outer_count(Yc), _outer_count(-Ya)) * split * n + 1
    OE = np.empty((2, nout))
    OS2 = np.empty((2, nout))
    OP = np.empty((2, nout))
    OH = np.empty((2, nout))
    npo = np.zeros(2, dtype=np.int64)
    for s in range(2):
        npo[s] = _outer_fill(ends[s], sgns[s], rho, b0, A3, g0, X, split, OE[s], OS2[s], OP[s], OH[s])
    OF = np.empty(nout)
    OG = np.empty(nout)
    ncore = 80 * split * n
    CF = np.empty((2, ncore))
    CG = np.empty((2, ncore))
    CP = np.empty((2, ncore))
    CH = np.empty((2, ncore))
    npc = np.zeros(2, dtype=np.int64)
    frozen = np.zeros(2, dtype=np.bool_)
    acc = np.empty(4)
    res = np.empty((2, 5))
    ell = 1.0 / lam_b - 0.5 * (math.log(2.0 * min(Yc, Y_SWITCH)) + math.log(2.0 * min(-Ya, Y_SWITCH)))
    # sqrt(S + kappa^2) >= kappa and ehat_b is monotone in y: L <= lam_b e^ell max(ehat_b) (Yc - Ya)
    emax = max(pressure_ehat(Yc, rho, b0), pressure_ehat(Ya, rho, b0))
    lo = max(math.log(2.0 / (lam_b * emax * (Yc - Ya))), -300.0)
    lo_done = False
    ell = min(max(ell, lo), 1e7)
    hi = math.inf
    niter = -1
    moments = False
    stalled = False
    r_prev = math.inf
    for it in range(100):
        kappa2 = math.exp(-2.0 * ell)
        for s in range(2):
            ysw = min(Y_SWITCH, ends[s])
            V1 = _asinh_scaled(ysw, ell)
            m, dm = _core_layout(ysw, V1)
            v_bottom = V1 - dm
            asym = v_bottom > 20.0
            if not (asym and frozen[s]):
                npc[s] = _core_fill(ysw, sgns[s], V1, m, rho, b0, A3, g0, X, split, CF[s], CG[s], CP[s], CH[s], asym)
                frozen[s] = asym
            acc[0] = lam_b * v_bottom
            acc[1] = lam_b * math.tanh(V1)
            acc[2] = 0.0
            acc[3] = 0.0
            _accumulate(lam_b, CF[s], CG[s], CP[s], CH[s], npc[s], acc[0], Wt, S, moments, acc)
            zeta1 = acc[0]
            for q in range(npo[s] * n):
                f, g = exact_outer(OE[s, q], OS2[s, q], kappa2)
                OF[q] = f
                OG[q] = g
            first = min(split, npo[s]) if ends[s] > 1.0 else npo[s]
            _accumulate(lam_b, OF, OG, OP[s], OH[s], first, acc[0], Wt, S, moments, acc)
            zeta1 = acc[0]
            _accumulate(lam_b, OF[first * n:], OG[first * n:], OP[s, first * n:], OH[s, first:],
                        npo[s] - first, acc[0], Wt, S, moments, acc)
            for k in range(4):
                res[s, k] = acc[k]
            res[s, 4] = zeta1
        L = res[0, 0] + res[1, 0]
        r = math.log(0.5 * L)
        if moments and (abs(r) <= LENGTH_TOL or (stalled and abs(r) <= 100.0 * LENGTH_TOL)):
            niter = it + 1
            break
        if r < 0.0:
            lo = max(lo, ell)
            lo_done = True
        else:
            hi = min(hi, ell)
        linear = frozen[0] and frozen[1]
        new = ell - ((L - 2.0) if linear else r * L) / (res[0, 1] + res[1, 1])
        if not (lo < new < hi):
            if not lo_done:
                new = lo
            elif hi == math.inf:
                new = ell + max(1.0, 2.0 * (ell - lo))
            else:
                new = 0.5 * (lo + hi)
        moments = abs(r) < 1e-7 or linear or abs(r) >= r_prev
        r_prev = abs(r)
        if new == ell:
            moments = True
            stalled = True
        ell = new
    Lc = res[0, 0]
    La = res[1, 0]
    z0 = 0.5 * (La - Lc)
    kappa2 = math.exp(-2.0 * ell)
    # I = (1/A2) int P z dz, z = z0 + zeta on the cathode side, z0 - zeta on the anode side
    I = (z0 * (res[0, 2] + res[1, 2]) + res[0, 3] - res[1, 3]) / A2
    D1 = lam_b * math.sqrt(_s_of_y(Yc, rho, b0) + kappa2)
    return I, B1, ell, res[0, 4] + res[1, 4], niter, D1


@jit
def moment_pressure(lam, A2, A3, rho, beta):
    """Exact moment integral ``I`` (for ``|phi0|``) with the pressure term, any thickness.

    Parameters
    ----------
    lam : float  core Debye length / e of the paper's model, ``sqrt((A0 + A1)/A2)``
    A2, A3 : float  dimensionless groups (``A2 > 0``)
    rho : float  ``A1/(A0 + A1)`` in [0, 1]
    beta : float  ``(v1 - M1 v2/M2) C_moy`` (0: the paper's model)

    Returns
    -------
    I, B1, ell, core, niter, D1
        As :func:`ipmc_asym.kernels.exact.moment_exact`, plus the face induction
        ``D1 = D(1)/(e phi4 F C_moy)``; ``niter = -1`` (and NaN) where the face values or the
        thickness constraint were not met (then nothing may be reported).
    """
    return moment_pressure_nodes(lam, A2, A3, rho, beta, _X, _W, _S, 1)
