"""Closed-form layer functions against the Gauss-Legendre quadrature and mpmath."""

import mpmath as mp
import numpy as np
import pytest

from ipmc_asym.kernels.closed import layer_closed
from ipmc_asym.kernels.quadrature import layer_functions

RHO = {0: 1.0, 1: 0.0, 2: 5 / 1005}
mp.mp.dps = 25


def _w(y, r):
    y = mp.mpf(y)
    Q = (1 - r) * (mp.expm1(y) / y) ** 2 + r * 2 * (mp.expm1(y) - y) / y**2
    return ((1 - r) * mp.exp(y) + r) / mp.sqrt(Q)


@pytest.mark.parametrize("mid", [0, 1, 2])
def test_patches_and_asymptotics_match_quadrature(mid):
    Ys = np.concatenate([np.linspace(-80, 1.9, 800), [-31.7501, -31.7499, -31.5001, -31.4999, -31.0001, -30.9999,
                                                        -1e-9, 1e-9, 0.2499, 0.2501, 0.4999, 0.5001]])
    if mid == 0:
        Ys = np.concatenate([Ys, np.linspace(2, 9.7, 50), [9.4999, 9.5, 9.7499, 9.75]])
    for Y in Ys:
        a, b = layer_closed(Y, mid, 2)
        c, d, _ = layer_functions(Y, RHO[mid])
        assert abs(a - c) <= 1e-11 * max(abs(c), 1e-300)
        assert abs(b - d) <= 1e-10 * max(abs(d), 1e-300)


@pytest.mark.parametrize("Y,mid", [(-3.0, 0), (2.5, 0), (-12.0, 2), (0.7, 2)])
def test_quadrature_against_mpmath(Y, mid):
    r = RHO[mid]
    ref = mp.quad(lambda t: _w(t, r), [0, Y / 4, Y / 2, Y])
    assert layer_functions(Y, r)[0] == pytest.approx(float(ref), rel=1e-13)


@pytest.mark.parametrize("mid", [0, 1, 2])
def test_leading_truncation_of_the_patches(mid):
    """At order 1 the patches are cut to fewer coefficients (``patch_leading``): W0 within
    1e-7 (the ``leading`` error estimate adds ``TRUNCATION_LEADING`` = 1e-6 for it) and W1,
    which only feeds that estimate, within 1e-3, on the whole patched range (edges included)."""
    from ipmc_asym.kernels.closed import _Y_HI, _Y_LO, TRUNCATION_LEADING

    hi = _Y_HI if mid == 0 else 3.0
    Ys = np.concatenate([np.linspace(_Y_LO, hi, 1500), np.arange(_Y_LO, hi, 0.5)])
    for Y in Ys:
        a, b = layer_closed(Y, mid, 1)
        c, d, _ = layer_functions(Y, RHO[mid])
        assert abs(a - c) <= 0.1 * TRUNCATION_LEADING * max(abs(c), 1.0), Y
        assert abs(b - d) <= 1e-3 * max(abs(d), 1.0), Y
