"""The ``exact`` rung with the pressure term of the Nernst-Planck law (option ``pressure_term``).

Derivation in ``derivations/pressure.py`` (paper eqs (4)-(5), static): with
``beta = (v1 - M1 v2/M2) C_moy``, ``g0 = 1 - beta (1 + A3)``, ``b0 = beta/g0`` and
``m = e^y - 1`` (``y = ln C``), the length element is ``dz = lambda_b ehat_b dy/sqrt(S + kappa^2)``
with ``lambda_b = lambda/sqrt(g0)``, ``ehat_b = ehat/(1 - b0 m)`` and ``S`` the first-integral
potential.  That is the form of :mod:`ipmc_asym.kernels.exact`, whose driver (panel layout, Newton
on ``ell = -ln kappa``, moment accumulation: ``make_exact_driver``) is compiled here for this
integrand; what differs:

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
from ipmc_asym.kernels._generated_pressure import (
    pressure_core_q,
    pressure_ehat,
    pressure_p,
    pressure_s_far,
    pressure_s_outer,
    pressure_volt,
)
from ipmc_asym.kernels.exact import Y_SWITCH, make_exact_driver
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


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _core_point(y, t2, par):
    """``(F, dF/dell, P)`` at a core node: ``(ehat_b, Q)`` in place of the paper's ``(ehat, Qhat)``."""
    rho, b0, A3, g0 = par
    e = pressure_ehat(y, rho, b0)
    t1 = 1.0 + (_q_core(y, rho, b0) - 1.0) * t2
    f = e / math.sqrt(t1)
    return f, f * (1.0 - t2) / t1, _p_of_y(y, A3, b0, g0)


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _outer_point(y, par):
    """``(ehat_b, S, P)`` at an outer node."""
    rho, b0, A3, g0 = par
    return pressure_ehat(y, rho, b0), _s_of_y(y, rho, b0), _p_of_y(y, A3, b0, g0)


#: the exact rung's driver with the pressure term: moment weight ``P(y)``, ``par = (rho, b0, A3, g0)``
_core_fill, _outer_fill, _solve, _frozen_cores = make_exact_driver(_core_point, _outer_point)


@jit
def moment_pressure_nodes(lam, A2, A3, rho, beta, X, Wt, S, split):
    """:func:`moment_pressure` with given Gauss-Legendre nodes and panels split ``split`` times."""
    g0, b0 = pressure_groups(beta, A3)
    nan = math.nan
    if not g0 > 0.0 or not abs(b0) < 1.0:
        return nan, nan, nan, nan, -1, nan
    Yc, Ya, fok = face_values(A2, rho, b0, g0)
    if not fok:
        return nan, nan, nan, nan, -1, nan
    lam_b = lam / math.sqrt(g0)
    B1 = math.exp(Yc)
    # sqrt(S + kappa^2) >= kappa and ehat_b is monotone in y: L <= lam_b e^ell max(ehat_b) (Yc - Ya)
    emax = max(pressure_ehat(Yc, rho, b0), pressure_ehat(Ya, rho, b0))
    lo = max(math.log(2.0 / (lam_b * emax * (Yc - Ya))), -300.0)
    ell, niter, res = _solve(lam_b, Yc, Ya, lo, (rho, b0, A3, g0), X, Wt, S, split, True)
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
