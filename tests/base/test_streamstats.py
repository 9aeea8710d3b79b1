"""Mergeable moments and the quantile sketch against numpy on the same values."""

import numpy as np
import pytest

from ipmc_asym.base.streamstats import Moments, QuantileSketch

PROBS = [0.0, 0.001, 0.025, 0.3, 0.5, 0.975, 0.999, 1.0]


def test_moments_merge_equals_numpy_for_any_split():
    rng = np.random.default_rng(0)
    x = 1e6 + rng.normal(size=10_001)  # a large mean: the pairwise update must not cancel
    m = Moments()
    for a in range(0, x.size, 997):
        m.merge(Moments.of(x[a:a + 997]))
    assert m.n == x.size
    assert m.mean == pytest.approx(np.mean(x), rel=1e-15)
    assert m.var(ddof=1) == pytest.approx(np.var(x, ddof=1), rel=1e-9)


def test_sketch_exact_while_it_holds_every_value():
    x = np.random.default_rng(1).lognormal(size=3000)
    s = QuantileSketch(4096)
    for a in range(0, x.size, 700):
        s.add(x[a:a + 700])
    q, lo, hi = s.quantiles(PROBS)
    assert s.err == 0
    np.testing.assert_array_equal(q, np.quantile(x, PROBS))
    np.testing.assert_array_equal(lo, q)
    np.testing.assert_array_equal(hi, q)


@pytest.mark.parametrize("k, n, chunk", [(16, 5000, 77), (64, 20_000, 1000), (256, 100_000, 4096), (1024, 60_000, 60_000)])
def test_sketch_interval_holds_the_exact_quantile(k, n, chunk):
    """Compacted sketch: np.quantile of all values inside the stated interval; the estimate's
    rank within the stated rank error; ties (a repeated value) and both tails included."""
    rng = np.random.default_rng(k)
    x = rng.standard_t(3, size=n)
    x[::5] = 0.25
    s = QuantileSketch(k)
    for a in range(0, n, chunk):
        s.add(x[a:a + chunk])
    assert s.err > 0 and s.n == n
    q, lo, hi = s.quantiles(PROBS)
    exact = np.quantile(x, PROBS)
    assert np.all(lo <= exact) and np.all(exact <= hi), (lo, exact, hi)
    xs = np.sort(x)
    for p, v in zip(PROBS, q):
        # the estimate lies between the exact quantiles at p -/+ the rank error (plus one rank)
        e = s.rank_error + 1.0 / n
        assert np.quantile(xs, max(p - e, 0)) <= v <= np.quantile(xs, min(p + e, 1)), (p, v)
    assert s.nbytes() <= 8 * k * (np.log2(n / k) + 2)  # k items per level


def test_sketch_merge_keeps_the_bound():
    rng = np.random.default_rng(5)
    x = rng.normal(size=40_000)
    parts = [QuantileSketch(128).add(x[a:a + 5000]) for a in range(0, x.size, 5000)]
    s = parts[0]
    for p in parts[1:]:
        s.merge(p)
    q, lo, hi = s.quantiles(PROBS)
    exact = np.quantile(x, PROBS)
    assert np.all(lo <= exact) and np.all(exact <= hi)
    assert s.rank_error < 0.05


def test_sketch_refuses_nan():
    with pytest.raises(ValueError, match="finite"):
        QuantileSketch(8).add([1.0, np.nan])
