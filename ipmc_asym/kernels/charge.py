"""Compiled kernels of the static electrode charge ``sigma`` and differential capacitance ``C_d``.

The point kernels and the ``prange`` sweep drivers behind :func:`ipmc_asym.integral.charge.charge`
(derivation: ``derivations/charge.py``, generated into :mod:`ipmc_asym.kernels._generated_charge`;
the exact rung: :mod:`ipmc_asym.kernels.charge_exact`).  Hats: ``sigma = S sigma_hat`` with
``S = sqrt(phi4 C_moy eps_core R T)``, ``C_d = (S F/(R T)) Cd_hat``; ``A2 = F|phi0|/(R T)``.

``kernel_code`` (the registry's ``FidelitySpec.kernel_code``): 1 ``leading`` and 2 ``corrected``
(the same closed form: the lambda-expansion of the face induction stops at first order),
0 ``quadrature`` (the layer integral by Gauss-Legendre panels, generic-rho kernels), 3 ``exact``.
``model_id``: 0/1/2 the paper's models (per-model kernels), -1 any ``rho`` (generic kernels).
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.base.settings import EXACT_STATED_ERROR
from ipmc_asym.kernels import _generated as G
from ipmc_asym.kernels import _generated_charge as GC
from ipmc_asym.kernels.charge_exact import TINY_A2, charge_exact_point, closed_charge_errors, layer_potentials
from ipmc_asym.kernels.jit import jit, jit_parallel, prange
from ipmc_asym.kernels.quadrature import doubling_panels
from ipmc_asym.kernels.special import gauss_legendre

__all__ = ["CLOSED_TRUNCATION", "NEAR_LIMIT", "GL_X", "GL_W", "charge_hat_point", "closed_point", "near_errors",
           "exact_point", "closed_sweep", "near_sweep", "exact_sweep"]

#: rounding of the closed forms (Yc, Dhat, chat are cancellation-free): relative; measured
#: <= 4.4e-16 against the exact rung where the layers are apart (tests/dynamics/test_electrode.py)
CLOSED_TRUNCATION = 2e-14
#: above this neutral-core error estimate the closed forms' error is measured against the exact rung
NEAR_LIMIT = 1e-3
#: 20-point Gauss-Legendre nodes and weights of the layer integral's panels
GL_X, GL_W, _ = gauss_legendre(20)
GL_X = np.ascontiguousarray(GL_X)
GL_W = np.ascontiguousarray(GL_W)


@jit
def _chat(y, rho, model_id):
    if model_id == 0:
        return GC.layer_capacitance_constant(y)
    if model_id == 1:
        return GC.layer_capacitance_linear(y)
    if model_id == 2:
        return GC.layer_capacitance_affine(y)
    return GC.layer_capacitance(y, rho)


@jit
def _dhat(Y, rho, model_id):
    if model_id == 0:
        return G.dhat_constant(Y)
    if model_id == 1:
        return abs(math.expm1(Y))
    if model_id == 2:
        return G.dhat_affine(Y)
    return G.dhat(Y, rho)


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _chat_generic(u, sgn, rho, wt):
    """``wt chat(sgn u)`` (generic rho): the integrand of :func:`_layer_integral`."""
    return wt * GC.layer_capacitance(sgn * u, rho)


_chat_panels = doubling_panels(_chat_generic)


@jit
def _layer_integral(Yc, rho, X, Wt):
    """``int_0^Yc chat(y) dy`` (generic rho) on panels with breakpoints 0, 1/2, 1, 2, 4, ..."""
    if Yc == 0.0:
        return 0.0
    sgn = 1.0 if Yc > 0.0 else -1.0
    return _chat_panels(abs(Yc), sgn, rho, X, Wt)


@jit
def charge_hat_point(A2, rho, model_id, quad, X, Wt):
    """``(sigma_hat, Cd_hat, Ya)`` of the neutral-core closed forms at ``A2 = F|phi0|/(R T) >= 0``.

    ``sigma = S sigma_hat``, ``C_d = (S F/R T) Cd_hat``; ``model_id`` 0/1/2 the paper's
    models (per-model kernels), -1 any ``rho`` (generic kernels).  ``quad`` = 1: ``sigma_hat``
    by Gauss-Legendre of the layer capacitance instead of the closed form ``Dhat``.
    """
    if A2 == 0.0:  # no field: sigma = 0, two layers of chat(0) = 1 in series
        return 0.0, 0.5, 0.0
    mid = -1 if quad == 1 else model_id
    Yc, Ya, _ = layer_potentials(A2, rho, mid)
    if quad == 1:
        sh = _layer_integral(Yc, rho, X, Wt)
    else:
        sh = _dhat(Yc, rho, mid)
    cd = GC.series_capacitance(_chat(Yc, rho, mid), _chat(Ya, rho, mid))
    return sh, cd, Ya


@jit
def _core(Ya, lam, rho):
    """Neutral core (units of e) of the closed forms' picture, for information.

    Depletion zone ``lam sqrt(2 rho (|Ya| - 1))`` plus ~10 Debye lengths of exponential tail per
    layer (kernels/closed.py); the validity of a rung follows its error estimate alone.
    """
    return 2.0 - lam * math.sqrt(2.0 * rho * max(-Ya - 1.0, 0.0)) - 20.0 * lam


@jit
def _tiny_point(A2, lam, rho, order):
    """:func:`closed_point` and :func:`exact_point` below ``TINY_A2``: the Debye-Hueckel limit
    (linearised Poisson-Boltzmann, eps = eps_core): ``sigma_hat/A2`` and ``Cdhat`` are 1/2 (neutral
    core) or coth(1/lam)/2 (exact), up to relative O(A2) < 1e-29; the closed forms' core error is
    its value in that limit (independent of A2)."""
    if order == 3:
        c = 0.5 / math.tanh(1.0 / lam)
        return c, c, EXACT_STATED_ERROR + 10.0 * A2, EXACT_STATED_ERROR + 10.0 * A2, 2.0
    Yc, Ya = 0.5 * TINY_A2, -0.5 * TINY_A2
    es, ec = closed_charge_errors(lam, Yc, Ya, rho, 1.0, 1.0)
    return 0.5, 0.5, CLOSED_TRUNCATION + 10.0 * A2 + es, CLOSED_TRUNCATION + 10.0 * A2 + ec, _core(Ya, lam, rho)


@jit
def closed_point(A2, lam, rho, model_id, order, X, Wt):
    """``(g, Cdhat, error_sigma, error_C, core, near)`` of the neutral-core rungs (``order`` 1/2 closed
    forms, 0 quadrature) at ``A2 >= 0``, ``g = sigma_hat/A2``, up to the overlap measurement.

    ``near``: the neutral-core error estimate is above ``NEAR_LIMIT`` (overlapping layers), where
    :func:`near_errors` replaces the errors by the difference from the exact rung.  No exact code is
    reachable from here, so a driver of these rungs compiles without it (the exact rung is most of
    the charge's compile: ~6 of 14 s in a fresh cache).
    """
    if A2 < TINY_A2:
        g, cd, es, ec, core = _tiny_point(A2, lam, rho, order)
        return g, cd, es, ec, core, False
    mid = -1 if order == 0 else model_id
    Yc, Ya, sb = layer_potentials(A2, rho, mid)
    if order == 0:
        sh = _layer_integral(Yc, rho, X, Wt)
    else:
        sh = _dhat(Yc, rho, mid)
    cc = _chat(Yc, rho, mid)
    ca = _chat(Ya, rho, mid)
    g = sh / A2
    cd = GC.series_capacitance(cc, ca)
    es, ec = closed_charge_errors(lam, Yc, Ya, rho, cc, ca)
    return (g, cd, CLOSED_TRUNCATION + sb + es, CLOSED_TRUNCATION + sb + ec, _core(Ya, lam, rho),
            max(es, ec) > NEAR_LIMIT)


@jit
def near_errors(A2, lam, rho, model_id, order, g, cd, err, errc):
    """The errors of a ``near`` point of :func:`closed_point` (``g``, ``cd``, ``err``, ``errc`` its
    values): overlapping layers, where the neutral-core asymptotics of kappa loosen (up to ~300x at
    1 um, 20 V, constant model), so the difference from the exact rung is the error there; ``err``,
    ``errc`` kept where the exact iteration fails."""
    mid = -1 if order == 0 else model_id
    Yc, Ya, sb = layer_potentials(A2, rho, mid)
    gx, cdx, _, niter = charge_exact_point(lam, A2, rho, Yc, Ya)
    if niter <= 0:
        return err, errc
    es = 2.0 * abs(g / gx - 1.0) + 2.0 * EXACT_STATED_ERROR
    ec = 2.0 * (abs(cd / cdx - 1.0) if cdx > 0.0 else (0.0 if cd == 0.0 else math.inf)) + 2.0 * EXACT_STATED_ERROR
    return CLOSED_TRUNCATION + sb + es, CLOSED_TRUNCATION + sb + ec


@jit
def exact_point(A2, lam, rho, model_id):
    """``(g, Cdhat, error_sigma, error_C, core)`` of the exact rung (``kernels/charge_exact.py``) at
    ``A2 >= 0``; ``g = sigma_hat/A2``."""
    if A2 < TINY_A2:
        return _tiny_point(A2, lam, rho, 3)
    Yc, Ya, sb = layer_potentials(A2, rho, model_id)
    g, cd, t, niter = charge_exact_point(lam, A2, rho, Yc, Ya)
    e = EXACT_STATED_ERROR + sb if niter > 0 else math.inf
    return g, cd, e, e, _core(Ya, lam, rho)


@jit_parallel
def closed_sweep(A2, lam, rho, model_id, order, X, Wt, g, cd, err, errc, core, near):
    """:func:`closed_point` at every ``A2[i]``, ``lam[i]`` (flat arrays) into the output arrays
    (``near``: uint8)."""
    for i in prange(A2.size):
        g[i], cd[i], err[i], errc[i], core[i], nr = closed_point(A2[i], lam[i], rho, model_id, order, X, Wt)
        near[i] = nr


@jit_parallel
def near_sweep(idx, A2, lam, rho, model_id, order, g, cd, err, errc):
    """:func:`near_errors` at the points ``idx`` of a :func:`closed_sweep` (its outputs, in place)."""
    for k in prange(idx.size):
        i = idx[k]
        err[i], errc[i] = near_errors(A2[i], lam[i], rho, model_id, order, g[i], cd[i], err[i], errc[i])


@jit_parallel
def exact_sweep(A2, lam, rho, model_id, g, cd, err, errc, core):
    """:func:`exact_point` at every ``A2[i]``, ``lam[i]`` (flat arrays) into the output arrays."""
    for i in prange(A2.size):
        g[i], cd[i], err[i], errc[i], core[i] = exact_point(A2[i], lam[i], rho, model_id)
