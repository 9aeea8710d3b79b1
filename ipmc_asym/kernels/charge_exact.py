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
from ipmc_asym.kernels.closed import b1_model
from ipmc_asym.kernels.exact import _S, _W, _X, _solve
from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.quadrature import doubling_panels
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


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _w_integrand(u, sg, rho, wt):
    """``wt (ehat/|s| - 1/u) = wt (ehat u/|s| - 1)/u`` at ``y = sg u``, ``|s| = Dhat(y) = u sqrt(Qhat)``."""
    y = sg * u
    return wt * (_ehat(y, rho) * u / G.dhat(y, rho) - 1.0) / u


_w_panels = doubling_panels(_w_integrand)


@jit
def _w_side(Y, rho):
    """``W(Y) = ln|Y| + int_0^|Y| (ehat/|s| - 1/u) du`` along the side of sign(Y) (12-point panels)."""
    sg = 1.0 if Y > 0.0 else -1.0
    T = abs(Y)
    if T < 1e-3:  # integrand -> sg (1/2 - 2 rho/3) at u = 0; the O(u) rest is < 1e-6 here
        return math.log(T) + sg * (0.5 - 2.0 * rho / 3.0) * T
    return math.log(T) + _w_panels(T, sg, rho, _GQ_X, _GQ_W)


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
def charge_exact_point(lam, A2, rho, Yc, Ya):
    """``(g, Cdhat, t, niter)`` of the exact solution at ``A2 > 0`` (``Yc``, ``Ya`` from :func:`layer_potentials`).

    ``g = sigma_hat/A2``, ``Cdhat = dsigma_hat/dA2``, ``t = kappa/Dhat(Yc)``; ``niter`` the
    Newton passes, -1 if the thickness constraint was not met to ``LENGTH_TOL`` (then nothing
    may be reported).
    """
    # int ehat dy over [Ya, Yc] = (1 - rho) e^Yc (1 - e^{-A2}) + rho A2: L <= lam e^ell that
    lo = max(math.log(2.0 / (lam * ((1.0 - rho) * math.exp(Yc) * -math.expm1(-A2) + rho * A2))), -300.0)
    # the moment rung's driver, for the length alone (Newton on ln L: about linear in ell for
    # kappa >> 1 and << 1); stalled in round-off, 100x the tolerance is accepted (~1e-12 on sigma)
    ell, niter, res = _solve(lam, Yc, Ya, lo, rho, _X, _W, _S, 1, False)
    dL = res[0, 1] + res[1, 1]
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
