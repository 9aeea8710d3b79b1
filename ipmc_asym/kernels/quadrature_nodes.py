"""Gauss-Legendre nodes and weights, computed once per order (numpy only, no compiler).

Every Gauss-Legendre rule of the package comes from :func:`leggauss`: the compiled layer
and exact panels (through :func:`ipmc_asym.kernels.special.gauss_legendre`), the charge
kernels, the BVP's post-processing of the linear model and the beam's branch integrals.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["leggauss", "leggauss01"]


@functools.lru_cache(maxsize=None)
def leggauss(n: int):
    """``(x, w)``: the ``n``-point Gauss-Legendre rule on [-1, 1] (cached, read-only).

    Parameters
    ----------
    n : int   number of nodes (>= 1); exact for polynomials of degree ``2n - 1``

    Returns
    -------
    x, w : ndarray   C-contiguous float64, shape ``(n,)``, not writeable (shared by callers)
    """
    x, w = np.polynomial.legendre.leggauss(int(n))
    x, w = np.ascontiguousarray(x), np.ascontiguousarray(w)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


@functools.lru_cache(maxsize=None)
def leggauss01(n: int):
    """``(t, w)``: the ``n``-point Gauss-Legendre rule mapped to [0, 1] (cached, read-only)."""
    x, w = leggauss(n)
    t, v = 0.5 * (x + 1.0), 0.5 * w
    t.flags.writeable = False
    v.flags.writeable = False
    return t, v
