"""The per-sample moment driver (``forward`` with a per-point ``c_moy``, the uq path) picks its
thread count by the rule of :func:`ipmc_asym.integral.api.run_parallel`."""

import numba
import numpy as np
import pytest

from ipmc_asym.forward.model import forward
from ipmc_asym.integral import api


def _points(n):
    return np.geomspace(100e-6, 1e-3, n), np.linspace(0.1, 1.0, n)


def _spy(monkeypatch):
    seen = []
    real = numba.set_num_threads
    monkeypatch.setattr(api.numba, "set_num_threads", lambda n: (seen.append(n), real(n))[1])
    return seen, real


def test_per_sample_moment_follows_the_same_rule(monkeypatch):
    """``forward`` with a per-point ``c_moy`` (the uq path) runs ``moment_samples`` by the same
    rule: a few points on one thread, many on all; the same numbers on one thread."""
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one Numba thread only")
    per = api.COMPILED_S["corrected"]
    seen, real = _spy(monkeypatch)
    real(2)
    try:
        for n, one in ((3, True), (int(4 * api.PARALLEL_MIN_S / per) + 1, False)):
            seen.clear()
            th, v = _points(n)
            c = np.linspace(1000.0, 1200.0, n)
            got = forward(0.02, 5e-3, th, v, c_moy=c, fidelity="corrected")
            assert (seen[:1] == [1]) is one
            assert numba.get_num_threads() == 2
            real(1)
            ref = forward(0.02, 5e-3, th, v, c_moy=c, fidelity="corrected")
            real(2)
            assert np.array_equal(got.I, ref.I, equal_nan=True)
    finally:
        real(numba.config.NUMBA_NUM_THREADS)
