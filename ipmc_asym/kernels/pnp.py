"""Right-hand sides of the transient Nernst-Planck-Poisson solver, compiled.

The finite-volume scheme is :mod:`ipmc_asym.dynamics.transient`'s (its class notes hold the
derivation); these loops evaluate its right-hand side ``dS/dt = -N`` in one pass over the faces.
The integrator calls it ~1e5 times per run on a few hundred cells, where NumPy's per-call
overhead on small arrays would be most of the solver's time (measured with the NumPy form: ~12 of
27 s, affine model, 200 um, 1 V, tol 1e-2, under cProfile).
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.kernels.bernoulli import bernoulli_point
from ipmc_asym.kernels.jit import jit

__all__ = ["sg_rhs", "linear_rhs", "newton_delta"]


@jit
def sg_rhs(S, psi0, h, delta, lam2, rho):
    """``-N`` at the interior faces ``1..N-1``: Scharfetter-Gummel fluxes of the affine model.

    Parameters
    ----------
    S : ndarray (N-1,)  the charge displaced through each interior face (units of ``e C_moy``)
    psi0 : float  applied potential ``phi0/(R T/F)`` at this time
    h : ndarray (N,)  cell widths (``z/e``); delta : ndarray (N-1,)  centre-to-centre distances
    lam2 : float  ``(lambda/e)^2``; rho : float  ``eps0/eps_moy``

    With ``c_i = 1 + (S_{i+1} - S_i)/h_i`` (``S_0 = S_N = 0``), the face resistances
    ``r_f`` (half cells of ``h/epshat(c)``), the induction ``d_f = d_0 + S_f`` with ``d_0`` fixed
    by ``sum r_f d_f = lambda^2 psi0``, and the potential jump ``-r_f d_f/lambda^2`` across face ``f``.
    """
    N = h.size
    c = np.empty(N)
    half = np.empty(N)
    for i in range(N):
        sl = S[i - 1] if i > 0 else 0.0
        sr = S[i] if i < N - 1 else 0.0
        c[i] = 1.0 + (sr - sl) / h[i]
        half[i] = 0.5 * h[i] / (rho + (1.0 - rho) * c[i])
    # compensated sums (Neumaier): d_0 moves every face's potential jump alike, and near the
    # settled state the fluxes are differences of nearly equal terms, so a plain running sum's
    # rounding (~N eps) shows as noise in the right-hand side that the step control then chases
    rsum, crs = half[0] + half[N - 1], 0.0
    rS, crS = 0.0, 0.0
    for f in range(1, N):
        r = half[f - 1] + half[f]
        t = rsum + r
        crs += (rsum - t) + r if abs(rsum) >= abs(r) else (r - t) + rsum
        rsum = t
        q = r * S[f - 1]
        t = rS + q
        crS += (rS - t) + q if abs(rS) >= abs(q) else (q - t) + rS
        rS = t
    d0 = (lam2 * psi0 - (rS + crS)) / (rsum + crs)
    out = np.empty(N - 1)
    for f in range(1, N):
        x = -(half[f - 1] + half[f]) * (d0 + S[f - 1]) / lam2
        out[f - 1] = -(c[f - 1] * bernoulli_point(x) - c[f] * bernoulli_point(-x)) / delta[f - 1]
    return out


@jit(inline="always")
def _d0_of(x, a_L, a_R, GL, GR):
    """``(d_0, dd_0/ddelta)`` at ``delta = x`` (``c_L = c_R e^delta``), scaled by ``e^{-|x|}`` so that
    neither face concentration overflows (the scalar form of ``_LinearProblem._d0_of``)."""
    ex = math.exp(-abs(x))
    den = GL * ex + GR if x > 0.0 else GL + GR * ex
    d0 = (a_L * ex - a_R) / den if x > 0.0 else (a_L - a_R * ex) / den
    return d0, -(a_R * GL + a_L * GR) * ex / (den * den)


@jit
def newton_delta(a_L, a_R, GL, GR, W, I0, p0, x):
    """Root ``delta`` of ``F = d_0(delta) - (delta + psi0 - I0)/W`` (decreasing), scalars: Newton
    inside a bracket that every iterate narrows (the linear model's voltage constraint, see
    ``dynamics.transient._LinearProblem.solve_d0``); ``x`` is the start."""
    lo, hi = -math.inf, math.inf
    for _ in range(200):
        d0, dd = _d0_of(x, a_L, a_R, GL, GR)
        F = d0 - (x + p0 - I0) / W
        if F > 0.0:
            lo = x
        else:
            hi = x
        xn = x - F / (dd - 1.0 / W)
        # x is the root as rounded (F = 0), or the step is below x's resolution: converged; the
        # bracket below would be empty and send x away
        if xn == x:
            return x
        if not lo < xn < hi:
            step = 2.0 * (1.0 + abs(x))
            xn = x + step if math.isinf(hi) else x - step if math.isinf(lo) else 0.5 * (lo + hi)
        if abs(xn - x) <= 1e-14 * (1.0 + abs(x)):
            return xn
        x = xn
    return x


@jit
def linear_rhs(S, psi0, h, delta, lam2, wL, wR, GL, GR, x0):
    """``(-N, delta)`` of the linear model (``epshat = c``): the flux is linear in the state,
    ``N_f = -(c_f - c_{f-1})/delta_f + (d_0 + S_f)/lambda^2``, with ``d_0`` from the voltage
    constraint through ``delta = ln(c_L/c_R)`` (:func:`newton_delta`, started at ``x0``).

    ``wL``, ``wR`` (K,): the face polynomials' weights on the K cells next to each face;
    ``c_L = a_L - GL d_0``, ``c_R = a_R + GR d_0``.  A state with a non-positive cell
    concentration (a trial Newton iterate) gives NaN fluxes and returns ``x0``.
    """
    N = h.size
    c = np.empty(N)
    ok = True
    for i in range(N):
        sl = S[i - 1] if i > 0 else 0.0
        sr = S[i] if i < N - 1 else 0.0
        c[i] = 1.0 + (sr - sl) / h[i]
        if not c[i] > 0.0:
            ok = False
    K = wL.size
    a_L = 0.0
    a_R = 0.0
    for j in range(K):
        a_L += c[j] * wL[j]
        a_R += c[N - 1 - j] * wR[j]
    out = np.empty(N - 1)
    if not (ok and a_L * GR + a_R * GL > 0.0):
        out[:] = np.nan
        return out, x0
    W = 0.0
    I0 = 0.0
    for f in range(1, N):
        nhat = -(c[f] - c[f - 1]) / delta[f - 1] + S[f - 1] / lam2
        w = 0.5 * (h[f - 1] / c[f - 1] + h[f] / c[f])
        out[f - 1] = nhat
        W += w
        I0 += nhat * w
    x = newton_delta(a_L, a_R, GL, GR, W / lam2, I0, psi0, x0 if math.isfinite(x0) else 0.0)
    d0 = _d0_of(x, a_L, a_R, GL, GR)[0]
    for f in range(N - 1):
        out[f] = -(out[f] + d0 / lam2)
    return out, x
