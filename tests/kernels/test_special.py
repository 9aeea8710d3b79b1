"""Numerics primitives against mpmath (independent arbitrary-precision implementations)."""

import mpmath as mp
import numpy as np
import pytest

from ipmc_asym.kernels.special import e2rel, exprel, gauss_legendre, li2, li3

mp.mp.dps = 30


@pytest.mark.parametrize("u", [-7.0, -1.0, -0.75, -0.5, -0.3, 0.0, 1e-12, 0.3, 0.5, 0.51, 0.9, 1 - 1e-12, 1.0])
def test_polylogs_match_mpmath(u):
    for f, s in ((li2, 2), (li3, 3)):
        ref = float(mp.polylog(s, mp.mpf(u)))
        assert f(u) == pytest.approx(ref, rel=2e-15, abs=1e-300)


@pytest.mark.parametrize("y", [-700.0, -40.0, -1.0, -0.49, -1e-9, 0.0, 1e-9, 0.2, 0.49, 0.51, 3.0, 40.0])
def test_exprel_e2rel(y):
    yy = mp.mpf(y)
    r1 = 1 if y == 0 else mp.expm1(yy) / yy
    r2 = 1 if y == 0 else 2 * (mp.expm1(yy) - yy) / yy**2
    assert exprel(y) == pytest.approx(float(r1), rel=1e-14)
    assert e2rel(y) == pytest.approx(float(r2), rel=1e-13)


def test_cumulative_matrix_integrates_polynomials():
    x, w, S = gauss_legendre(10)
    f = 3 * x**8 - x**3 + 2.0
    F = x**9 / 3 - x**4 / 4 + 2 * x - (-1 / 3 - 1 / 4 - 2)
    assert np.allclose(S @ f, F, atol=1e-12)
    assert w.sum() == pytest.approx(2.0)
