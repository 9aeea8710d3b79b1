"""Compiled time steppers of the electrode charge: the reduced circuit and its RC line.

:func:`integrate_circuit` integrates the reduced charging model of
:mod:`ipmc_asym.dynamics.circuit` (``ds/dt = (psi0 - A)/2`` with ``s = sigma_hat(A)``, time in
units of ``tau``, voltages in ``R T/F``); :func:`integrate_line` the discretised RC line of
:mod:`ipmc_asym.dynamics.line_time` (one circuit per node, Kirchhoff's law between nodes).  Both
are variable-step BDF2 (first step backward Euler) over the static closed forms of
:mod:`ipmc_asym.kernels.charge` (``model_id`` as there).
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.kernels.charge import charge_hat_point
from ipmc_asym.kernels.jit import jit

__all__ = ["shat", "cd_hat_many", "integrate_circuit", "integrate_line"]


@jit
def shat(A, rho, mid, X, Wt):
    """Signed ``sigma_hat(A)`` and ``Cd_hat(|A|)`` at the thermal voltage ``A = F u/(R T)``."""
    s, c, _ = charge_hat_point(abs(A), rho, mid, 0, X, Wt)
    return (s if A >= 0.0 else -s), c


@jit
def cd_hat_many(A, rho, mid, X, Wt, out):
    """``Cd_hat(|A|)`` of every entry of the flat array ``A`` into ``out``: the layers' differential
    capacitance (per ``A``) that turns the charging rate into the layer voltage's rate."""
    for i in range(A.shape[0]):
        out[i] = shat(A[i], rho, mid, X, Wt)[1]


@jit
def integrate_circuit(tt, ps, rho, mid, X, Wt, A_out, s_out, state):
    """Variable-step BDF2 (first step backward Euler) for ds/dt = (psi0 - A)/2, s = s(A).

    Time in units of tau, voltages in R T/F.  Each implicit step solves the monotone scalar
    equation a0 s(A) + h A/2 = rhs by Newton with a bisection safeguard.  ``state`` =
    ``(A, A_prev, s, s_prev, h_prev)`` at ``tt[0]`` on entry (zeros: at rest, uncharged), at
    ``tt[-1]`` on return: a run split into chunks is the same run.
    """
    A = state[0]
    A_prev = state[1]
    s = state[2]
    s_prev = state[3]
    h_prev = state[4]
    A_out[0] = A
    s_out[0] = s
    for n in range(1, tt.shape[0]):
        h = tt[n] - tt[n - 1]
        if h <= 0.0:
            A_out[n] = A
            s_out[n] = s
            continue
        if h_prev == 0.0:
            a0 = 1.0
            rhs = s + 0.5 * h * ps[n]
        else:
            w = h / h_prev
            a0 = (1.0 + 2.0 * w) / (1.0 + w)
            rhs = (1.0 + w) * s - w * w / (1.0 + w) * s_prev + 0.5 * h * ps[n]
        # g(x) = a0 s(x) + h x / 2 - rhs is increasing: Newton from the linear predictor, with a
        # bracket collected on the way (bisection once both ends are known)
        lo = -math.inf
        hi = math.inf
        x = A + (A - A_prev) * (h / h_prev) if h_prev > 0.0 else A
        for _ in range(200):
            sx, cx = shat(x, rho, mid, X, Wt)
            g = a0 * sx + 0.5 * h * x - rhs
            if g > 0.0:
                hi = x
            else:
                lo = x
            xn = x - g / (a0 * cx + 0.5 * h)
            # x is the root as rounded (g = 0), or the step is below x's resolution (a subnormal A
            # under a subnormal drive): converged; the bracket below would be empty and send x away
            if xn == x:
                break
            if not (lo < xn < hi):
                if math.isinf(lo) or math.isinf(hi):
                    xn = x - 2.0 * (1.0 + abs(g)) if math.isinf(lo) else x + 2.0 * (1.0 + abs(g))
                else:
                    xn = 0.5 * (lo + hi)
            if abs(xn - x) <= 1e-13 * (1.0 + abs(x)):
                x = xn
                break
            x = xn
        s_prev = s
        s, _ = shat(x, rho, mid, X, Wt)
        A_prev = A
        A = x
        h_prev = h
        A_out[n] = A
        s_out[n] = s
    state[0] = A
    state[1] = A_prev
    state[2] = s
    state[3] = s_prev
    state[4] = h_prev


@jit
def integrate_line(tt, ps, rho, mid, X, Wt, G, A_out, P_out, s_out, A, A_prev, s, s_prev, P, hp):
    """BDF2 for ``ds_j/dt = (psi_j - A_j)/2`` (time in tau, voltages in R T/F) on the ladder.

    ``psi_0 = ps`` (the drive); ``psi_{j-1} - 2 psi_j + psi_{j+1} = G_j (psi_j - A_j)``.  ``A``,
    ``A_prev``, ``s``, ``s_prev``, ``P`` (node voltages) and ``hp[0]`` (last step) are the state,
    updated in place; ``A_out``, ``P_out``, ``s_out`` get every step's values.  Returns the number
    of steps whose Newton iteration did not converge (0 on success).
    """
    n1 = A.shape[0]
    nn = n1 - 1
    F = np.empty(n1)
    d = np.empty(n1)
    x = np.empty(n1)
    dA = np.empty(n1)
    rhs = np.empty(n1)
    cp = np.empty(n1)
    dp = np.empty(n1)
    dpsi = np.zeros(n1)
    bad = 0
    for j in range(n1):
        A_out[0, j] = A[j]
        P_out[0, j] = P[j]
        s_out[0, j] = s[j]
    for k in range(1, tt.shape[0]):
        h = tt[k] - tt[k - 1]
        if h <= 0.0:
            for j in range(n1):
                A_out[k, j] = A[j]
                P_out[k, j] = P[j]
                s_out[k, j] = s[j]
            continue
        h_prev = hp[0]
        if h_prev == 0.0:
            a0 = 1.0
            for j in range(n1):
                rhs[j] = s[j]
        else:
            w = h / h_prev
            a0 = (1.0 + 2.0 * w) / (1.0 + w)
            for j in range(n1):
                rhs[j] = (1.0 + w) * s[j] - w * w / (1.0 + w) * s_prev[j]
        for j in range(n1):
            x[j] = A[j] + (A[j] - A_prev[j]) * (h / h_prev) if h_prev > 0.0 else A[j]
        P[0] = ps[k]
        hh = 0.5 * h
        done = False
        for _ in range(200):
            for j in range(n1):
                sx, cx = shat(x[j], rho, mid, X, Wt)
                F[j] = a0 * sx + hh * (x[j] - P[j]) - rhs[j]
                d[j] = a0 * cx + hh
            # tridiagonal system for the node corrections dpsi_1..dpsi_N (dpsi_0 = 0: the drive)
            for j in range(1, n1):
                g = G[j]
                if j < nn:
                    diag = -2.0 - g + g * hh / d[j]
                    e = P[j - 1] - 2.0 * P[j] + P[j + 1] - g * (P[j] - x[j])
                else:
                    diag = -1.0 - g + g * hh / d[j]
                    e = P[j - 1] - P[j] - g * (P[j] - x[j])
                r = -e + g * F[j] / d[j]
                if j == 1:
                    m = diag
                    dp[j] = r / m
                else:
                    m = diag - cp[j - 1]
                    dp[j] = (r - dp[j - 1]) / m
                cp[j] = (1.0 / m) if j < nn else 0.0
            dpsi[nn] = dp[nn]
            for j in range(nn - 1, 0, -1):
                dpsi[j] = dp[j] - cp[j] * dpsi[j + 1]
            big = 0.0
            for j in range(n1):
                dA[j] = (-F[j] + hh * dpsi[j]) / d[j]
                if abs(dA[j]) > big:
                    big = abs(dA[j])
            lim = 1.0 if big <= 2.0 else 2.0 / big
            conv = True
            for j in range(n1):
                x[j] += lim * dA[j]
                if j > 0:
                    P[j] += lim * dpsi[j]
                if abs(lim * dA[j]) > 1e-13 * (1.0 + abs(x[j])) or abs(lim * dpsi[j]) > 1e-13 * (1.0 + abs(P[j])):
                    conv = False
            if conv:
                done = True
                break
        if not done:
            bad += 1
        for j in range(n1):
            s_prev[j] = s[j]
            sx, _ = shat(x[j], rho, mid, X, Wt)
            s[j] = sx
            A_prev[j] = A[j]
            A[j] = x[j]
            A_out[k, j] = A[j]
            P_out[k, j] = P[j]
            s_out[k, j] = s[j]
        hp[0] = h
    return bad
