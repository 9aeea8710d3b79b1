"""The moment drivers pick their thread count by the work: one thread below
``PARALLEL_MIN_S`` of single-thread work, every thread above; the count changes no bit and the
caller's setting is restored."""

import numba
import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.integral import api


def _points(n):
    return np.geomspace(10e-6, 4e-3, n), np.linspace(-3.0, 3.0, n)


@pytest.mark.parametrize("fidelity", ["leading", "quadrature", "exact"])
def test_small_work_runs_on_one_thread_and_large_on_all(fidelity, monkeypatch):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one Numba thread only")
    small = max(1, int(0.5 * api.PARALLEL_MIN_S / api.COMPILED_S[fidelity]))
    large = int(4 * api.PARALLEL_MIN_S / api.COMPILED_S[fidelity]) + 1
    seen = []
    real = numba.set_num_threads
    monkeypatch.setattr(api.numba, "set_num_threads", lambda n: (seen.append(n), real(n))[1])
    real(2)
    try:
        for n, one in ((small, True), (large, False)):
            seen.clear()
            th, v = _points(n)
            got = ia.moment_integral(th, v, "constant", fidelity, on_invalid="nan")
            assert (seen[:1] == [1]) is one
            assert numba.get_num_threads() == 2  # the caller's setting, restored
            real(1)
            ref = ia.moment_integral(th, v, "constant", fidelity, on_invalid="nan")  # one thread throughout
            real(2)
            assert np.array_equal(got, ref, equal_nan=True)
    finally:
        real(numba.config.NUMBA_NUM_THREADS)
