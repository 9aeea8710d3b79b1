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
    Ys = np.concatenate([np.linspace(-80, 1.9, 800), [-31.0001, -30.9999, -1e-9, 1e-9]])
    if mid == 0:
        Ys = np.concatenate([Ys, np.linspace(2, 8.9, 50)])
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
