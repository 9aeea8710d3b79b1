"""The moment-integral sweep driver with per-sample ``A3`` (``C_moy`` varying per sample).

:func:`ipmc_asym.integral.api.moment` takes one material, so ``A3 = -rho2 Z3/(C_moy F)`` is a
scalar of its driver; uncertainty propagation (:mod:`ipmc_asym.studies.uq`) samples ``C_moy`` and
needs it per point.  This is the same loop over the same compiled point kernel
(:func:`ipmc_asym.integral.api._point`) with ``A3`` an array.  Kept in its own small module so
that editing the UQ driver does not invalidate the Numba cache (hashed sources, ``_jit``).
"""

from __future__ import annotations

from ipmc_asym.integral.api import _point
from ipmc_asym.kernels.jit import jit_parallel, prange

__all__ = ["moment_samples"]


@jit_parallel
def moment_samples(lam, A2, A3, rho, model_id, order, sign, I, err, core):
    """Fill ``I`` (signed), ``err`` (relative error estimate), ``core`` for each sample.

    ``order``: 1 leading, 2 corrected, 0 quadrature (as :func:`ipmc_asym.integral.api._sweep`).
    """
    for i in prange(lam.size):
        Ii, e_i, b1, c = _point(lam[i], A2[i], A3[i], rho, model_id, order)
        I[i] = sign[i] * Ii
        err[i] = e_i
        core[i] = c
