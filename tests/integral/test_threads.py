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


def _spy(monkeypatch):
    seen = []
    real = numba.set_num_threads
    monkeypatch.setattr(api.numba, "set_num_threads", lambda n: (seen.append(n), real(n))[1])
    return seen, real


@pytest.mark.parametrize("fidelity", ["leading", "exact"])
def test_charge_driver_follows_the_same_rule(fidelity, monkeypatch):
    """The charge sweep (and through it the dynamics' electrode charge) picks its threads by
    ``CHARGE_COMPILED_S`` and ``PARALLEL_MIN_S``; any count gives the one-thread numbers."""
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one Numba thread only")
    from ipmc_asym.integral import charge as ch

    per = ch.CHARGE_COMPILED_S[fidelity]
    small = max(1, int(0.5 * api.PARALLEL_MIN_S / per))
    large = int(4 * api.PARALLEL_MIN_S / per) + 1
    seen, real = _spy(monkeypatch)
    real(2)
    try:
        for n, one in ((small, True), (large, False)):
            seen.clear()
            th, v = _points(n)
            got = ia.charge(th, v, "constant", fidelity)
            assert (seen[:1] == [1]) is one
            assert numba.get_num_threads() == 2
            real(1)
            ref = ia.charge(th, v, "constant", fidelity)
            real(2)
            assert np.array_equal(got.sigma, ref.sigma, equal_nan=True)
            assert np.array_equal(got.C_diff, ref.C_diff, equal_nan=True)
    finally:
        real(numba.config.NUMBA_NUM_THREADS)

