"""The moment-integral sweep drivers with per-sample ``A3`` (``C_moy`` varying per sample).

:func:`ipmc_asym.integral.api.moment` takes one material, so ``A3 = -rho2 Z3/(C_moy F)`` is a
scalar of its driver; uncertainty propagation (:mod:`ipmc_asym.studies.uq`) samples ``C_moy`` and
needs it per point.  This is the same loop over the same compiled point kernels
(:func:`ipmc_asym.integral.api._closed_point`, :func:`ipmc_asym.integral.api._point`) with ``A3`` an
array.  Kept in its own small module so that editing the UQ driver does not invalidate the Numba
cache (hashed sources, ``_jit``).
"""

from __future__ import annotations

from ipmc_asym.integral.api import _closed_point, _point
from ipmc_asym.kernels.jit import jit, jit_parallel, prange

__all__ = ["moment_samples"]


def moment_samples(lam, A2, A3, rho, model_id, order, sign, I, err, core):
    """Fill ``I`` (signed), ``err`` (relative error estimate), ``core`` for each sample.

    ``order``: 1 leading, 2 corrected, 0 quadrature (as :func:`ipmc_asym.integral.api._sweep`).
    The rung's driver is chosen here, in Python, as :func:`ipmc_asym.integral.api._fused_driver`
    does: a compiled branch on ``order`` would compile every rung on a first ``leading`` call.
    """
    driver = _closed_samples if order in (1, 2) else _point_samples
    driver(lam, A2, A3, rho, model_id, order, sign, I, err, core)


@jit(inline="always")
def _put(i, sign, Ii, e_i, c, I, err, core):
    I[i] = sign[i] * Ii
    err[i] = e_i
    core[i] = c


@jit_parallel
def _closed_samples(lam, A2, A3, rho, model_id, order, sign, I, err, core):
    """:func:`moment_samples` of the closed forms (``order`` 1, 2)."""
    for i in prange(lam.size):
        Ii, e_i, _, c = _closed_point(lam[i], A2[i], A3[i], rho, model_id, order)
        _put(i, sign, Ii, e_i, c, I, err, core)


@jit_parallel
def _point_samples(lam, A2, A3, rho, model_id, order, sign, I, err, core):
    """:func:`moment_samples` of the other rungs (``order`` 0 quadrature)."""
    for i in prange(lam.size):
        Ii, e_i, _, c = _point(lam[i], A2[i], A3[i], rho, model_id, order)
        _put(i, sign, Ii, e_i, c, I, err, core)
