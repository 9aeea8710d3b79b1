"""Closed-form fidelities ``leading`` and ``corrected``: evaluation of the derived forms.

All formulas live in :mod:`._generated` (written by ``derivations/``); this module only
picks the piece that applies to a given ``Y`` (Taylor patch about ``2k``, depletion or
accumulation asymptotics) and assembles ``I = lam J1 (+ lam^2 J2)``.
"""

from __future__ import annotations

import math

from .._jit import jit
from . import _generated as G

__all__ = ["MODEL_IDS", "layer_closed", "moment_closed", "TRUNCATION"]

MODEL_IDS = {"constant": 0, "linear": 1, "affine": 2}

#: truncation of the patches (18 terms at ratio <= 1/6 of the radius) and of the
#: asymptotic pieces (O(T e^{-T}) at T = 31); checked against the quadrature in the tests.
TRUNCATION = 1e-11

_W0 = (G.PATCH_W0_CONSTANT, G.PATCH_W0_LINEAR, G.PATCH_W0_AFFINE)
_W1 = (G.PATCH_W1_CONSTANT, G.PATCH_W1_LINEAR, G.PATCH_W1_AFFINE)
_KMIN = G.K_MIN
_KMAX = G.K_MAX


@jit
def _horner(tab, row, h):
    n = tab.shape[1]
    acc = tab[row, n - 1]
    for k in range(n - 2, -1, -1):
        acc = acc * h + tab[row, k]
    return acc


@jit
def _patch_tables(model_id):
    if model_id == 0:
        return G.PATCH_W0_CONSTANT, G.PATCH_W1_CONSTANT
    if model_id == 1:
        return G.PATCH_W0_LINEAR, G.PATCH_W1_LINEAR
    return G.PATCH_W0_AFFINE, G.PATCH_W1_AFFINE


@jit
def layer_closed(Y, model_id, need_w1):
    """``(W0(Y), W1(Y))`` from the closed forms (W1 = 0 when ``need_w1`` is False)."""
    if Y < 2.0 * _KMIN - 1.0:
        if model_id == 0:
            return G.depletion_constant(Y)
        if model_id == 1:
            return G.depletion_linear(Y)
        return G.depletion_affine(Y)
    if Y > 2.0 * _KMAX + 1.0:
        if model_id == 0:
            return G.accumulation_constant(Y)
        # linear/affine cathodes never get there (Y = ln B1 < 2 up to kV); be explicit
        return math.nan, math.nan
    k = int(math.floor(0.5 * (Y + 1.0)))
    if k > _KMAX:
        k = _KMAX
    h = Y - 2.0 * k
    t0, t1 = _patch_tables(model_id)
    row = k - _KMIN
    w0 = _horner(t0, row, h)
    w1 = _horner(t1, row, h) if need_w1 else 0.0
    return w0, w1


@jit
def moment_closed(lam, A2, A3, rho, model_id, order):
    """``I`` at order 1 (``leading``: lam J1) or 2 (``corrected``: lam J1 + lam^2 J2).

    ``rho`` must be the model's own (``A1/(A0+A1)``: 1, 0, 5/1005); the per-model kernels
    have it built in and the caller (:func:`ipmc_asym.moment.moment`) guarantees it.

    Returns
    -------
    I, error, B1, core : floats
        ``error`` is a relative estimate: the first neglected term (``lam^2 |J2|``, only at
        order 1, estimated from the closed form of ``J2``) plus the truncation of the layer
        functions.  ``core`` (the neutral core length) is estimated from the depletion
        width ``lam * sqrt(2 (|Ya| - 1))`` and ``~ 10 lam`` per layer.
    """
    em = math.exp(-A2)
    if model_id == 0:
        B1 = G.b1_constant(A2)
    elif model_id == 1:
        B1 = G.b1_linear(A2)
    else:
        B1 = G.b1_affine(A2)
    Yc = math.log(B1)
    Ya = Yc - A2
    cm = B1 * em
    # J2 is needed for the error estimate at order 1 as well
    W0c, W1c = layer_closed(Yc, model_id, True)
    W0a, W1a = layer_closed(Ya, model_id, True)
    big = Yc > 0.5  # C - 1 not small: Dhat straight from C = B1 (no exp, no cancellation)
    if model_id == 0:
        dh = G.dhat_from_c_constant(B1, Yc) if big else G.dhat_constant(Yc)
        J1, J2 = G.assemble_j_constant(A2, A3, B1, cm, dh, W0c, W0a, W1c, W1a)
    elif model_id == 1:
        dh = G.dhat_from_c_linear(B1, Yc) if big else G.dhat_linear(Yc)
        J1, J2 = G.assemble_j_linear(A2, A3, B1, cm, dh, W0c, W0a, W1c, W1a)
    else:
        dh = G.dhat_from_c_affine(B1, Yc) if big else G.dhat_affine(Yc)
        J1, J2 = G.assemble_j_affine(A2, A3, B1, cm, dh, W0c, W0a, W1c, W1a)
    if order == 1:
        I = lam * J1
        err = abs(lam * J2 / J1) + TRUNCATION
    else:
        I = lam * J1 + lam * lam * J2
        err = TRUNCATION * (1.0 + abs(lam * J2 / J1))
    # widths: depletion zone (eps ~ A1 there) ~ lam sqrt(2 rho (|Ya| - 1)), plus the
    # exponential tails (~10 Debye lengths each side)
    if Yc > 2.0 * _KMAX + 1.0:  # leading accumulation asymptotics (constant model, > ~80 V)
        err += 0.1 * Yc * math.exp(-Yc)
    dep = lam * math.sqrt(2.0 * rho * max(-Ya - 1.0, 0.0))
    core = 2.0 - dep - 20.0 * lam
    return I, err, B1, core
