"""Closed-form fidelities ``leading`` and ``corrected``: evaluation of the derived forms.

All formulas live in :mod:`._generated` (written by ``derivations/``); this module only
picks the piece that applies to a given ``Y`` (Taylor patch about a multiple of 1/2, depletion or
accumulation asymptotics) and assembles ``I = lam J1 (+ lam^2 J2)``.
"""

from __future__ import annotations

import math

from ipmc_asym.kernels import _generated as G
from ipmc_asym.kernels.jit import jit

__all__ = ["layer_closed", "moment_closed", "closed_b1", "b1_model", "closed_finish", "TRUNCATION"]


#: truncation of the patches (10 coefficients at ratio <= 1/24 of the radius: <= 2e-14) and of
#: the asymptotic pieces (O(T e^{-T}) at T = 31.75); checked against the quadrature in the tests.
TRUNCATION = 1e-11

_KMIN = G.K_MIN
_KMAX = G.K_MAX
_STEP = float(G.PATCH_STEP)
#: the patches cover [_Y_LO, _Y_HI]: depletion asymptotics below, accumulation above
_Y_LO = _STEP * _KMIN - 0.5 * _STEP
_Y_HI = _STEP * _KMAX + 0.5 * _STEP


@jit
def _patch_tables(model_id):
    if model_id == 0:
        return G.PATCH_W0_CONSTANT, G.PATCH_W1_CONSTANT
    if model_id == 1:
        return G.PATCH_W0_LINEAR, G.PATCH_W1_LINEAR
    return G.PATCH_W0_AFFINE, G.PATCH_W1_AFFINE


#: At order 1 (``leading``, whose own error lam J2/J1 is >~1e-5 anyway) the generated
#: ``patch_leading`` / ``sqrtq_leading`` evaluate fewer coefficients (counts set in
#: ``derivations/closed_forms.py``): W0 to ~1e-8, W1 (error estimate only) to ~3e-5,
#: sqrt(Qhat) to ~1e-8.  Truncation of W0 at order 1 (added to the error estimate):
TRUNCATION_LEADING = 1e-6


@jit
def _sqrtq(c, x, order):
    """The sqrt(Qhat) series to the accuracy of ``order`` (1: ~1e-8; 2: ~1e-16)."""
    return G.sqrtq_leading(c, x) if order == 1 else G.sqrtq_full(c, x)


@jit
def layer_closed(Y, model_id, need_w1):
    """``(W0(Y), W1(Y))`` from the closed forms.

    ``need_w1``: 2 = full accuracy for both; 1 = the order-1 (``leading``) accuracy: W0 to
    ~1e-8 and W1 to ~3e-5 (for the error estimate only).
    """
    if not Y == Y:  # NaN: no table row to look up
        return math.nan, math.nan
    if Y < _Y_LO:
        if model_id == 0:
            return G.depletion_constant(Y)
        if model_id == 1:
            return G.depletion_linear(Y)
        return G.depletion_affine(Y)
    if Y > _Y_HI:
        if model_id == 0:
            return G.accumulation_constant(Y)
        # linear/affine cathodes never get there (Y = ln B1 < 2 up to kV); be explicit
        return math.nan, math.nan
    k = int(math.floor(Y / _STEP + 0.5))  # the nearest centre (Y / 0.5 and Y - 0.5 k: exact)
    if k > _KMAX:
        k = _KMAX
    h = Y - _STEP * k
    t0, t1 = _patch_tables(model_id)
    row = k - _KMIN
    if need_w1 == 2:
        return G.patch_full(t0, t1, row, h)
    return G.patch_leading(t0, t1, row, h)


@jit
def closed_b1(A2, model_id):
    """Stage 1 of :func:`moment_closed`: ``(e^{-A2}, B1, ln B1)``."""
    if A2 > 1.0:  # e^{-A2} - 1 <= -0.63: no cancellation, and exp is cheaper than expm1
        em = math.exp(-A2)
        em1 = em - 1.0
    else:
        em1 = math.expm1(-A2)
        em = 1.0 + em1
    if model_id == 0:
        B1 = G.b1_constant(A2, em1)
    elif model_id == 1:
        B1 = G.b1_linear(A2, em1)
    else:
        B1 = G.b1_affine(A2, em1)
    return em, B1, math.log(B1)


@jit
def b1_model(A2, rho, model_id):
    """``B1`` from electroneutrality of a neutral core (paper section 4) for a model id of
    the compiled kernels.

    ``model_id`` 0..2: the closed forms' specialisations (:func:`closed_b1`); ``< 0``: the
    root for any ``rho = eps0/eps_core`` in [0, 1].  The same root in numpy:
    :func:`ipmc_asym.model.groups.b1_neutral`.
    """
    if model_id < 0:
        return G.b1_exact(A2, rho)
    return closed_b1(A2, model_id)[1]


@jit
def closed_finish(lam, A2, A3, rho, model_id, order, em, B1, Yc, W0c, W1c, W0a, W1a):
    """Stage 3 of :func:`moment_closed`: ``(I, error, B1, core)`` from the stage-1 values and
    the layer functions at the cathode (``W0c, W1c``) and the anode (``W0a, W1a``)."""
    Ya = Yc - A2
    cm = B1 * em
    # Dhat: straight from C = B1 when C - 1 is not small (no exp, no cancellation), else the
    # Taylor series of sqrt(Qhat) at 0 (no exp either)
    big = Yc > 0.5
    if model_id == 0:
        dh = G.dhat_from_c_constant(B1, Yc) if big else Yc * _sqrtq(G.SQRTQ_CONSTANT, Yc, order)
        J1, J2 = G.assemble_j_constant(A2, A3, B1, cm, dh, W0c, W0a, W1c, W1a)
    elif model_id == 1:
        dh = G.dhat_from_c_linear(B1, Yc) if big else Yc * _sqrtq(G.SQRTQ_LINEAR, Yc, order)
        J1, J2 = G.assemble_j_linear(A2, A3, B1, cm, dh, W0c, W0a, W1c, W1a)
    else:
        dh = G.dhat_from_c_affine(B1, Yc) if big else Yc * _sqrtq(G.SQRTQ_AFFINE, Yc, order)
        J1, J2 = G.assemble_j_affine(A2, A3, B1, cm, dh, W0c, W0a, W1c, W1a)
    if order == 1:
        I = lam * J1
        # t = |lam J2 / J1| + truncation is the first neglected term relative to lam J1;
        # relative to I = lam J1 (1 + lam J2/J1) the error is at most t / (1 - t), here
        # a / d = t |J1| / ((1 - t) |J1|): one division instead of two
        a = abs(lam * J2) + TRUNCATION_LEADING * abs(J1)
        d = abs(J1) - a
        err = a / d if d > 0.0 else math.inf
    else:
        I = lam * J1 + lam * lam * J2
        err = TRUNCATION * (1.0 + abs(lam * J2 / J1))
    # widths: depletion zone (eps ~ A1 there) ~ lam sqrt(2 rho (|Ya| - 1)), plus the
    # exponential tails (~10 Debye lengths each side)
    if Yc > _Y_HI:  # leading accumulation asymptotics (constant model, > ~80 V)
        err += 0.1 * Yc * math.exp(-Yc)
    s = -Ya - 1.0
    # no square root where there is no depletion zone (s <= 0, or the linear model's rho = 0):
    # 0 * s is the 0 that sqrt(0) gave, and NaN for a NaN input
    dep = lam * math.sqrt(2.0 * rho * s) if s > 0.0 and rho > 0.0 else 0.0 * s
    core = 2.0 - dep - 20.0 * lam
    return I, err, B1, core


@jit
def moment_closed(lam, A2, A3, rho, model_id, order):
    """``I`` at order 1 (``leading``: lam J1) or 2 (``corrected``: lam J1 + lam^2 J2).

    ``rho`` must be the model's own (``A1/(A0+A1)``: 1, 0, 5/1005); the per-model kernels
    have it built in and the caller (:func:`ipmc_asym.integral.api.moment`) guarantees it.
    Three stages (:func:`closed_b1`, :func:`layer_closed` at both faces,
    :func:`closed_finish`), which the block drivers of :mod:`ipmc_asym.integral.api` run stage by
    stage over a block of points: the same operations, bit for bit.

    Returns
    -------
    I, error, B1, core : floats
        ``error`` is a relative estimate: at order 1, ``t / (1 - t)`` (inf if ``t >= 1``)
        with ``t`` the first neglected term ``|lam J2 / J1|`` (from the closed form of
        ``J2``) plus the truncation of the layer functions, a bound relative to ``I`` itself;
        at order 2, the truncation of the layer functions.  ``core`` (the neutral core
        length) is estimated from the depletion width ``lam * sqrt(2 (|Ya| - 1))`` and
        ``~ 10 lam`` per layer.
    """
    em, B1, Yc = closed_b1(A2, model_id)
    # at order 1, J2 only feeds the error estimate: W1 to ~1e-6 is enough
    acc = 2 if order == 2 else 1
    W0c, W1c = layer_closed(Yc, model_id, acc)
    W0a, W1a = layer_closed(Yc - A2, model_id, acc)
    return closed_finish(lam, A2, A3, rho, model_id, order, em, B1, Yc, W0c, W1c, W0a, W1a)
