"""Compiled recursion of a small linear time-invariant system driven by a piecewise-linear input.

``x' = A x + B u`` with ``u`` linear on each segment ``[t_k, t_k+1]`` (values ``u_start[k]`` at
its start, slope ``u_slope[k]``) has the exact update ``x_k+1 = Phi x_k + G0 u_start + G1 u_slope``
with ``[Phi, G0, G1]`` the first block row of ``expm(h [[A, B, 0], [0, 0, 1], [0, 0, 0]])``
(computed by the caller, one table entry per distinct segment length, ``which[k]`` its index).
Used by :mod:`ipmc_asym.dynamics.sensing_time` (the sensing circuit in the time domain).
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.kernels.jit import jit

__all__ = ["lti_foh"]


@jit
def lti_foh(Phi, G0, G1, which, u_start, u_slope, kick_at, kick, x0, out):
    """States at every segment end: ``out[k]`` = ``x(t_k+1)`` (``out`` shape ``(n_seg, n)``).

    ``Phi`` (n_tab, n, n), ``G0``, ``G1`` (n_tab, n); ``x0`` the state at ``t_0``; ``kick[i]`` is
    added to the state at the start of segment ``kick_at[i]`` (sorted): the state's jump under an
    impulse of the input (``B`` times its weight).
    """
    n = x0.shape[0]
    x = np.empty(n)
    y = np.empty(n)
    for i in range(n):
        x[i] = x0[i]
    ik = 0
    for k in range(which.shape[0]):
        while ik < kick_at.shape[0] and kick_at[ik] == k:
            for i in range(n):
                x[i] += kick[ik, i]
            ik += 1
        j = which[k]
        for i in range(n):
            acc = G0[j, i] * u_start[k] + G1[j, i] * u_slope[k]
            for m in range(n):
                acc += Phi[j, i, m] * x[m]
            y[i] = acc
        for i in range(n):
            x[i] = y[i]
            out[k, i] = y[i]
