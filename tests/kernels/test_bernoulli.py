"""The Scharfetter-Gummel Bernoulli function against mpmath at 30 digits, both signs, from the
series region to where ``e^|x|`` overflows."""

import mpmath as mp
import numpy as np
import pytest

from ipmc_asym.kernels.bernoulli import bernoulli_array, bernoulli_point


def _exact(x):
    with mp.workdps(30):
        xm = mp.mpf(float(x))
        return 1.0 if x == 0.0 else float(xm / mp.expm1(xm))


X = np.array([0.0, 1e-12, -3e-9, 9.99e-5, -9.99e-5, 1.0001e-4, -1.0001e-4, 0.03, -0.7, 1.0, -5.0, 37.0,
              -40.0, 300.0, -700.0, 745.0, -800.0])


def test_both_signs_within_a_few_ulp():
    bp, bm = bernoulli_array(X), bernoulli_array(-X)
    for x, p, m in zip(X, bp, bm):
        for got, want in ((p, _exact(x)), (m, _exact(-x))):
            assert got == pytest.approx(want, rel=4e-16, abs=1e-300), x


def test_the_array_is_the_point_at_both_signs():
    x = np.random.default_rng(3).normal(scale=20.0, size=1000)
    bp, bm = bernoulli_array(x), bernoulli_array(-x)
    assert np.array_equal(bp, [bernoulli_point(v) for v in x]) and np.array_equal(bm, [bernoulli_point(-v) for v in x])
    # B(-x) = B(x) + x (exact identity; here where it has no cancellation, x > 0)
    pos = x > 0
    np.testing.assert_allclose(bm[pos], bp[pos] + x[pos], rtol=1e-15)
