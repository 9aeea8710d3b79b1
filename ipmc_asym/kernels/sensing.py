"""Compiled point kernels of the static sensing response (derivation: ``derivations/sensing.py``).

Hats: ``sigma = S sigma_hat`` (``S = sqrt(phi4 C_moy eps_core R T)``, the charge scale of the
actuation's electrode charge), ``V_oc = (R T/F) v_hat``; ``b = (1 - 2 nu) kappa e/phi4_0``,
``lam = lambda_D/e``.  Rungs (``order``):

* 1, the closed form: linear in ``b``, exact in ``lam`` (the Debye-Hueckel solution,
  generated ``sense_linear``).  Error bound: twice the cubic term of the neutral-core balance,
  ``2 |c3| b^2 (1 + lam)`` (generated ``sense_cubic``), the factor ``1 + lam`` for the finite-lam
  part of the cubic term that the lam -> 0 coefficient does not hold.
* 3, the exact layer balance: Donnan core ``Y+ - Y- = Delta = -2 artanh b`` and neutrality
  ``S+ q(Y+; rho+) + S- q(Y-; rho-) = 0`` solved by safeguarded Newton with the actuation's
  layer charge ``q = sign(Y) Dhat(Y)`` and capacitance ``dq/dY = chat`` (generated in
  ``_generated`` and ``_generated_charge``), every order in ``b``; the finite-thickness factor
  ``coth(1/lam) - lam`` of the linear solution multiplies it.  Error bound: the cross term of
  finite ``lam`` and nonlinearity, ``CROSS lam`` times the balance's own departure from
  linearity (``|sigma_nc/(-b) - 1|``; for ``V_oc`` that of the Donnan law), plus rounding.
  ``CROSS`` is measured, not derived: against the BVP the coefficient is at most 3.7 (linear,
  affine) and 2.1 (constant) on 2e = 20 um - 2 mm x face strains 1e-3 - 3e-2 (docs/sensing.md;
  the grid of tests/integral/test_sensing.py); 8 keeps a factor 2 over that.
"""

from __future__ import annotations

import math

from ipmc_asym.kernels import _generated as G
from ipmc_asym.kernels import _generated_charge as GC
from ipmc_asym.kernels import _generated_sensing as GS
from ipmc_asym.kernels.jit import jit

__all__ = ["sense_point", "balance_hat", "SENSE_ROUNDING", "CROSS"]

#: relative rounding of the closed forms and of the Newton solution (measured <= 1e-15 against
#: 40-digit evaluations in tests/kernels/test_sensing.py)
SENSE_ROUNDING = 1e-13
#: coefficient of the exact rung's cross term (measured <= 3.7 against the BVP, module docstring)
CROSS = 8.0


@jit
def _q(Y, rho):
    """Signed layer charge ``sign(Y) Dhat(Y)`` (``derivations/charge.py``)."""
    if Y == 0.0:
        return 0.0
    d = G.dhat(Y, rho)
    return d if Y > 0.0 else -d


@jit
def balance_hat(b, rho0, phi4):
    """``(sigma/S, Y-)`` of the neutral-core layer balance at ``|b| < 1`` (``derivations.sensing``, result 2)."""
    if b == 0.0:
        return 0.0, 0.0
    delta = -2.0 * math.atanh(b)
    cp = 1.0 / (1.0 - b)
    cn = 1.0 / (1.0 + b)
    ep = rho0 + (1.0 - rho0) * cp  # eps_core/eps_moy at each face, eq (16)
    en = rho0 + (1.0 - rho0) * cn
    sp_ = math.sqrt(ep / (1.0 - phi4 * b))  # S+/S: phi4 C_moy ~ 1/(1 + tr eps)
    sn = math.sqrt(en / (1.0 + phi4 * b))
    rp = rho0 / ep
    rn = rho0 / en
    lo = min(0.0, -delta)
    hi = max(0.0, -delta)
    ym = b
    for _ in range(200):
        f = sp_ * _q(ym + delta, rp) + sn * _q(ym, rn)
        if f > 0.0:
            hi = ym
        else:
            lo = ym
        df = sp_ * GC.layer_capacitance(ym + delta, rp) + sn * GC.layer_capacitance(ym, rn)
        step = f / df
        nxt = ym - step
        if not (lo < nxt < hi):  # Newton left the bracket: bisect
            nxt = 0.5 * (lo + hi)
        if abs(nxt - ym) <= 1e-16 * abs(ym) or hi - lo <= 1e-16 * abs(ym):
            ym = nxt
            break
        ym = nxt
    return -sn * _q(ym, rn), ym


@jit
def sense_point(b, lam, rho0, phi4, order):
    """``(sigma_hat, v_hat, err_sigma, err_v)`` at ``|b| < 1``; ``order`` 1 closed form, 3 exact balance."""
    if b == 0.0:
        return 0.0, 0.0, 0.0, 0.0
    s1, v1 = GS.sense_linear(b, lam)
    art = math.atanh(b) / b - 1.0  # the Donnan law's departure from linearity
    if order == 1:
        c3 = abs(GS.sense_cubic(rho0, phi4))
        return (s1 * b, v1 * b, 2.0 * c3 * b * b * (1.0 + lam) + SENSE_ROUNDING,
                2.0 * abs(art) * (1.0 + lam) + SENSE_ROUNDING)
    nc, _ = balance_hat(b, rho0, phi4)
    r = nc / (-b) - 1.0
    return (nc * (-s1), v1 * b * (1.0 + art), CROSS * lam * abs(r) + SENSE_ROUNDING,
            CROSS * lam * abs(art) + SENSE_ROUNDING)
