"""Electrode charge and differential capacitance from the exact solution (fidelity ``exact``).

Derivations: ``derivations/exact.py`` (first integral, thickness constraint) and
``derivations/charge.py`` (face induction, layer capacitances, small-voltage series).  For one
point ``(lam, A2, rho)``:

* ``Yc = ln B1`` and ``Ya = Yc - A2`` without cancellation (:func:`layer_potentials`): the
  generated small-voltage series of ``Yc/A2`` below ``SMALL_A2``, the closed root above.
* The face induction is ``D(+-1) = lam sqrt(Dhat(Yc)^2 + kappa^2)`` for ANY thickness
  (first integral ``D^2/2 = H/A2 + K``, ``K = lam^2 kappa^2/2``), so
  ``sigma = S sqrt(Dc^2 + kappa^2)`` with ``kappa = e^{-ell}`` from the thickness constraint
  ``L(ell, A2) = lam int_{Ya}^{Yc} ehat dy/sqrt(s^2 + kappa^2) = 2``, solved here by the same
  Gauss-Legendre panels as the moment's ``exact`` rung (:mod:`ipmc_asym.kernels.exact`).
* ``C_d = dsigma/dphi0`` analytically: implicit differentiation of the constraint,
  ``d ell/dA2 = -L_A2/L_ell``.  ``L_ell`` is the Newton derivative of the length; ``L_A2`` only
  moves the end points, where ``s^2 = Dc^2`` (electroneutrality) and
  ``dYc/dA2 = p = chat_a/(chat_c + chat_a)``:  ``L_A2 = lam (ehat_c p + ehat_a (1 - p))/Dk``,
  ``Dk = sqrt(Dc^2 + kappa^2)``.  With ``t = kappa/Dc`` (formed in logs: ``kappa`` underflows
  in thick strips):
  ``Cdhat = [Cds + t^2 lam (ehat_c p + ehat_a (1 - p))/(sqrt(1 + t^2) L_ell)]/sqrt(1 + t^2)``,
  ``Cds = chat_c chat_a/(chat_c + chat_a)`` the neutral-core series capacitance.
* Neutral-core asymptotics (:func:`kappa_neutral_log`) for the error of the closed forms: as
  ``kappa -> 0`` each side of the constraint is ``lam (ln(2|Y|/kappa) + I(Y))``,
  ``I(Y) = int_0^|Y| (ehat/|s| - 1/u) du``, so ``ln kappa = ln 2 - 1/lam + (W_c + W_a)/2``,
  ``W = ln|Y| + I(Y)`` (linear model: exactly ``kappa = 2 (B1 - 1) e^{-1/lam}`` up to
  ``1 + O(e^{-2/lam})``, ``derivations.exact:linear_check``).  The closed forms' relative errors
  are then ``sqrt(1 + t^2) - 1 ~ t^2/2`` (``sigma``) and
  ``t^2 |ehat_c/(2 chat_c) + ehat_a/(2 chat_a) - 1/2|`` (``C_d``; ``L_ell -> 2 lam``).

Every function returns hat quantities: ``sigma = (S F/RT) g phi0`` with ``g = sigma_hat/A2`` (a
secant capacitance, so ``sigma -> C_d(0) phi0`` without forming ``A2^2``), ``C_d = (S F/RT) Cdhat``.
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.kernels import _generated as G
from ipmc_asym.kernels import _generated_charge as GC
from ipmc_asym.kernels._generated_exact import exact_outer
from ipmc_asym.kernels.closed import b1_model
from ipmc_asym.kernels.exact import (
    _S,
    _W,
    _X,
    LENGTH_TOL,
    Y_SWITCH,
    _accumulate,
    _asinh_scaled,
    _core_fill,
    _core_layout,
    _outer_count,
    _outer_fill,
)
from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.special import gauss_legendre

__all__ = ["layer_potentials", "charge_exact_point", "kappa_neutral_log", "closed_charge_errors",
           "SMALL_A2", "TINY_A2"]

#: below this A2 the generated series gives Yc/A2 (its truncation < 1e-19 relative there,
#: ``derivations.charge:small_voltage_yc``); above it ln B1 of the closed root (B1 - 1 > 0.12)
SMALL_A2 = 0.25
#: below this A2 every rung is its Debye-Hueckel limit (relative corrections O(A2) < 1e-29):
#: no A2^2 is formed (it underflows from A2 ~ 1e-154)
TINY_A2 = 1e-30
_GQ_X, _GQ_W, _ = gauss_legendre(12)
_GQ_X = np.ascontiguousarray(_GQ_X)
_GQ_W = np.ascontiguousarray(_GQ_W)


@jit
def layer_potentials(A2, rho, model_id):
    """``(Yc, Ya, series_bound)`` at ``A2 > 0``: ``Yc = ln B1``, ``Ya = Yc - A2``, both to rounding.

    ``series_bound``: the relative truncation bound of the small-voltage series (0 above ``SMALL_A2``).
    """
    if A2 <= SMALL_A2:
        r, b = GC.yc_small(A2, rho)
        return A2 * r, A2 * (r - 1.0), b
    Yc = math.log(b1_model(A2, rho, model_id))
    return Yc, Yc - A2, 0.0


@jit
def _ehat(y, rho):
    return rho + (1.0 - rho) * math.exp(y)


@jit
def _w_side(Y, rho):
    """``W(Y) = ln|Y| + int_0^|Y| (ehat/|s| - 1/u) du`` along the side of sign(Y) (12-point panels)."""
    sg = 1.0 if Y > 0.0 else -1.0
    T = abs(Y)
    if T < 1e-3:  # integrand -> sg (1/2 - 2 rho/3) at u = 0; the O(u) rest is < 1e-6 here
        return math.log(T) + sg * (0.5 - 2.0 * rho / 3.0) * T
    total = 0.0
    a = 0.0
    b = min(0.5, T)
    while True:
        hm = 0.5 * (b - a)
        xm = 0.5 * (a + b)
        s = 0.0
        for j in range(_GQ_X.shape[0]):
            u = xm + hm * _GQ_X[j]
            y = sg * u
            # ehat/|s| - 1/u = (ehat u/|s| - 1)/u with |s| = Dhat(y) = u sqrt(Qhat)
            s += _GQ_W[j] * (_ehat(y, rho) * u / G.dhat(y, rho) - 1.0) / u
        total += hm * s
        if b >= T:
            break
        a = b
        b = min(2.0 * b, T)
    return math.log(T) + total


@jit
def kappa_neutral_log(lam, Yc, Ya, rho):
    """``ln kappa`` of a thick strip (neutral core): ``ln 2 - 1/lam + (W(Yc) + W(Ya))/2``."""
    return math.log(2.0) - 1.0 / lam + 0.5 * (_w_side(Yc, rho) + _w_side(Ya, rho))


@jit
def _w_cheap_bound(Yc, Ya, rho):
    """A cheap upper bound of ``W(Yc) + W(Ya)``, only used to skip the quadrature where ``t^2 < 1e-40``.

    Growth rates: on the cathode side ``I(Y) <= |Y|`` (``ehat/|s| <= 1 + 1/u`` for the linear
    model, ``<= 1/u`` for the constant one); on the anode side ``I(Y) ~ sqrt(2|Y|)`` (the
    depletion zone, ``|s|^2 ~ 2 rho u``, ``ehat -> rho``).  The constant 1 covers the O(1) rest;
    checked against :func:`_w_side` for rho in [0, 1] and A2 in [1e-29, 3000]
    (tests/kernels/test_charge_exact.py).
    """
    return (math.log(abs(Yc)) + abs(Yc) + math.log(abs(Ya)) + math.sqrt(2.0 * abs(Ya)) + 1.0)


@jit
def closed_charge_errors(lam, Yc, Ya, rho, cc, ca):
    """Relative errors ``(sigma, C_d)`` of the neutral-core closed forms against the exact solution.

    ``cc, ca``: the layer capacitances at ``Yc``, ``Ya``.  Twice the leading neutral-core
    asymptotics of :mod:`this module <ipmc_asym.kernels.charge_exact>` (``t^2/2`` and
    ``t^2 |ehat_c/(2 chat_c) + ehat_a/(2 chat_a) - 1/2|``); exactly 0 where a cheap bound of ``t^2``
    is below 1e-40 (no quadrature: the thick strips of the paper).
    """
    Dc = G.dhat(Yc, rho)
    ln_t_cheap = math.log(2.0) - 1.0 / lam + 0.5 * _w_cheap_bound(Yc, Ya, rho) - math.log(Dc)
    if ln_t_cheap < -46.0:  # t^2 < 1e-40
        return 0.0, 0.0
    ln_t = kappa_neutral_log(lam, Yc, Ya, rho) - math.log(Dc)
    t2 = math.exp(min(2.0 * ln_t, 700.0))
    # (ehat_c p + ehat_a (1-p))/(2 Cds) = ehat_c/(2 chat_c) + ehat_a/(2 chat_a); chat_a underflows
    # only in the linear model (chat = ehat = e^y there: the ratio is 1)
    ra = _ehat(Ya, rho) / ca if ca > 0.0 else 1.0
    br = abs(0.5 * (_ehat(Yc, rho) / cc + ra) - 0.5)
    return 2.0 * (math.sqrt(1.0 + t2) - 1.0), 2.0 * t2 * br


@jit
def _length(lam, ends, rho, ell, CF, CG, CY, CH, OE, OS2, OY, OH, npo, OF, OG, acc):
    """``(L, dL/d ell)`` of the thickness constraint at ``ell`` (both sides)."""
    n = _X.shape[0]
    kappa2 = math.exp(-2.0 * ell)
    L = 0.0
    dL = 0.0
    for s in range(2):
        sgn = 1.0 if s == 0 else -1.0
        ysw = min(Y_SWITCH, ends[s])
        V1 = _asinh_scaled(ysw, ell)
        m, dm = _core_layout(ysw, V1)
        v_bottom = V1 - dm
        npc = _core_fill(ysw, sgn, V1, m, rho, _X, 1, CF, CG, CY, CH, v_bottom > 20.0)
        acc[0] = lam * v_bottom
        acc[1] = lam * math.tanh(V1)  # int sech^2 dv over the core; the rest is G - sech^2
        acc[2] = 0.0
        acc[3] = 0.0
        _accumulate(lam, CF, CG, CY, CH, npc, acc[0], _W, _S, False, acc)
        for q in range(npo[s] * n):
            f, g = exact_outer(OE[s, q], OS2[s, q], kappa2)
            OF[q] = f
            OG[q] = g
        _accumulate(lam, OF, OG, OY[s], OH[s], npo[s], acc[0], _W, _S, False, acc)
        L += acc[0]
        dL += acc[1]
    return L, dL


@jit
def charge_exact_point(lam, A2, rho, Yc, Ya):
    """``(g, Cdhat, t, niter)`` of the exact solution at ``A2 > 0`` (``Yc``, ``Ya`` from :func:`layer_potentials`).

    ``g = sigma_hat/A2``, ``Cdhat = dsigma_hat/dA2``, ``t = kappa/Dhat(Yc)``; ``niter`` the
    Newton passes, -1 if the thickness constraint was not met to ``LENGTH_TOL`` (then nothing
    may be reported).
    """
    n = _X.shape[0]
    ends = np.empty(2)
    ends[0] = Yc
    ends[1] = -Ya
    nout = max(_outer_count(Yc), _outer_count(-Ya)) * n + 1
    OE = np.empty((2, nout))
    OS2 = np.empty((2, nout))
    OY = np.empty((2, nout))
    OH = np.empty((2, nout))
    npo = np.zeros(2, dtype=np.int64)
    for s in range(2):
        npo[s] = _outer_fill(ends[s], 1.0 if s == 0 else -1.0, rho, _X, 1, OE[s], OS2[s], OY[s], OH[s])
    OF = np.empty(nout)
    OG = np.empty(nout)
    ncore = 80 * n
    CF = np.empty(ncore)
    CG = np.empty(ncore)
    CY = np.empty(ncore)
    CH = np.empty(ncore)
    acc = np.empty(4)
    # int ehat dy over [Ya, Yc] = (1 - rho) e^Yc (1 - e^{-A2}) + rho A2: L <= lam e^ell that
    lo = max(math.log(2.0 / (lam * ((1.0 - rho) * math.exp(Yc) * -math.expm1(-A2) + rho * A2))), -300.0)
    ell = 1.0 / lam - 0.5 * (math.log(2.0 * min(Yc, Y_SWITCH)) + math.log(2.0 * min(-Ya, Y_SWITCH)))
    ell = min(max(ell, lo), 1e7)
    lo_done = False
    hi = math.inf
    niter = -1
    dL = 1.0
    for it in range(100):
        L, dL = _length(lam, ends, rho, ell, CF, CG, CY, CH, OE, OS2, OY, OH, npo, OF, OG, acc)
        r = math.log(0.5 * L)
        if abs(r) <= LENGTH_TOL:
            niter = it + 1
            break
        if r < 0.0:
            lo = max(lo, ell)
            lo_done = True
        else:
            hi = min(hi, ell)
        new = ell - r * L / dL  # Newton on ln L (about linear in ell for kappa >> 1 and << 1)
        if not (lo < new < hi):
            if not lo_done:
                new = lo
            elif hi == math.inf:
                new = ell + max(1.0, 2.0 * (ell - lo))
            else:
                new = 0.5 * (lo + hi)
        if new == ell:  # stalled in round-off: accept 100x the tolerance (~1e-12 on sigma)
            if abs(r) <= 100.0 * LENGTH_TOL:
                niter = it + 1
            break
        ell = new
    Dc = G.dhat(Yc, rho)
    ln_t = -ell - math.log(Dc)
    t2 = math.exp(min(2.0 * ln_t, 700.0))
    q = math.sqrt(1.0 + t2)
    cc = GC.layer_capacitance(Yc, rho)
    ca = GC.layer_capacitance(Ya, rho)
    p = ca / (cc + ca)
    cds = cc * p
    side = lam * (_ehat(Yc, rho) * p + _ehat(Ya, rho) * (1.0 - p)) / q  # Dc * dL/dA2
    cd = (cds + t2 * side / dL) / q
    return Dc / A2 * q, cd, math.sqrt(t2), niter
