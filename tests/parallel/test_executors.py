"""Chunked runs on a 2-worker dask LocalCluster are identical to the serial run."""

import subprocess
import sys

import numpy as np
import pytest

from ipmc_asym.parallel.executors import check_scheduler, chunk_slices, imap_chunks, run_chunks
from ipmc_asym.studies.sweep_chunks import sweep_chunked
from ipmc_asym.studies.sweeps import sweep

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster, distributed.Client(cluster) as c:
        yield c


def _same(a, b):
    """Rows equal; floats to 1e-15 relative (the target; the outputs are pointwise, so they
    are bitwise equal in practice, but another process may run another numpy build)."""
    for k in a.dtype.names:
        if a.dtype[k].kind == "f":
            np.testing.assert_allclose(a[k], b[k], rtol=1e-15, atol=0)  # NaN == NaN
        else:
            assert (a[k] == b[k]).all(), k


@pytest.mark.slow
def test_bvp_sweep_2d_identical_on_cluster(client):
    vary = {"thickness": np.array([150e-6, 250e-6]), "voltage": np.array([0.5, 2.0])}
    serial = sweep(vary, model="constant", fidelity="bvp", progress=False)
    dist = sweep_chunked(vary, client, seconds_per_point=0.1,  # 4 chunks of one point
                         model="constant", fidelity="bvp")
    assert dist.size == serial.size == 4
    _same(serial, dist)
    # both workers were set up: one BLAS/OpenMP thread, Numba threads set explicitly to 1
    info = client.run(_threads)
    assert len(info) == 2
    assert all(v == ("1", "1", 1) for v in info.values()), info


def _threads():
    import os

    import numba

    return os.environ.get("OMP_NUM_THREADS"), os.environ.get("OPENBLAS_NUM_THREADS"), numba.get_num_threads()


def test_uq_identical_on_cluster(client):
    from ipmc_asym.studies.uq import run_uq

    sc = {"name": "t", "voltage": "1V", "tolerance": 1e-3, "outputs": ["I", "tip_deflection", "blocking_force"],
          "uncertain": {"thickness": {"dist": "normal", "mean": "200um", "sd": "10um"},
                        "c_moy": {"dist": "triangular", "low": 2900, "mode": 3082, "high": 3200},
                        "modulus": {"dist": "lognormal", "median": "130MPa", "sigma": 0.2}}}
    a = run_uq(sc, 4096, chunk_rows=1000)
    b = run_uq(sc, 4096, chunk_rows=1000, scheduler=client)
    for o in a.outputs:
        np.testing.assert_array_equal(a.outputs[o], b.outputs[o])
    assert a.sobol == b.sobol and a.summary == b.summary and a.fidelity == b.fidelity


def test_uq_default_chunks_on_cluster(client):
    """The scheduler's own chunk sizes (chunk_slices, whole groups): the same statistics as
    in-process chunks, to rounding (moments and Sobol' sums merge in another grouping)."""
    from ipmc_asym.studies.uq import run_uq

    sc = {"name": "t", "voltage": "1V", "tolerance": 1e-2, "outputs": ["I", "rotation"],
          "uncertain": {"thickness": {"dist": "normal", "mean": "200um", "sd": "10um"},
                        "modulus": {"dist": "lognormal", "median": "130MPa", "sigma": 0.4}}}
    a = run_uq(sc, 8000, fidelity="leading", chunk_rows=1000)
    b = run_uq(sc, 8000, fidelity="leading", scheduler=client)
    assert a.n_outside == b.n_outside > 0 and a.fidelity == b.fidelity and a.n_stored == b.n_stored
    for o in a.summary:
        for k in ("q2.5", "q50", "q97.5", "n"):  # exact while the sketch holds every value
            assert a.summary[o][k] == b.summary[o][k]
        assert b.summary[o]["mean"] == pytest.approx(a.summary[o]["mean"], rel=1e-13)
        assert b.summary[o]["sd"] == pytest.approx(a.summary[o]["sd"], rel=1e-9)
        for p, v in a.sobol[o].items():
            for k, x in v.items():
                assert b.sobol[o][p][k] == pytest.approx(x, rel=1e-9, abs=1e-12), (o, p, k)


def test_uq_streamed_on_cluster_keeps_few_tasks_in_flight(client):
    """imap_chunks yields in task order with at most ``window`` tasks submitted ahead: a lazy
    task generator is read only as results are consumed."""
    read = []

    def tasks():
        for t in range(12):
            read.append(t)
            yield -t

    it = imap_chunks(abs, tasks(), scheduler=client, window=3)
    assert next(it) == 0 and len(read) == 3
    assert list(it) == list(range(1, 12)) and len(read) == 12


def test_imap_chunks_serial_is_lazy():
    read = []

    def tasks():
        for t in range(5):
            read.append(t)
            yield t

    it = imap_chunks(abs, tasks())
    assert next(it) == 0 and read == [0]
    assert list(it) == [1, 2, 3, 4]


def test_run_chunks_order_and_serial():
    tasks = list(range(7))
    assert run_chunks(abs, [-t for t in tasks]) == tasks


def test_chunks_carry_100ms():
    sl = chunk_slices(10**6, 1e-7, workers=2)  # 0.1 s total: one chunk
    assert len(sl) == 1
    sl = chunk_slices(100, 0.03, workers=2)  # BVP points: >= 4 per chunk, <= 4 chunks per worker
    assert all(s.stop - s.start >= 4 for s in sl[:-1]) and len(sl) <= 8
    assert sum(s.stop - s.start for s in sl) == 100


@pytest.mark.parametrize("bad", ["remote", "tcp://host", "http://x:1"])
def test_bad_scheduler(bad):
    with pytest.raises(ValueError, match="--scheduler must be local or tcp://HOST:PORT"):
        check_scheduler(bad)


def test_import_does_not_load_dask():
    code = ("import sys, ipmc_asym, ipmc_asym.parallel.executors, ipmc_asym.studies.uq, ipmc_asym.studies.calibrate, ipmc_asym.io.datasets;"
            "print(any(m == 'dask' or m.startswith(('dask.', 'distributed')) for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_fit_multistart_identical_on_cluster(client):
    from ipmc_asym.studies.calibrate import CalibrationData, fit, predict

    th = np.repeat([200e-6, 300e-6], 4)
    v = np.tile(np.linspace(0.3, 1.2, 4), 2)
    geom = {"length": np.full(8, 0.015), "width": np.full(8, 5e-3), "thickness": th, "voltage": v}
    out, _, _ = predict({"modulus": 1e8, "c_moy": 2600.0}, geom, "constant", "quadrature")
    rng = np.random.default_rng(1)
    meas = {k: out[k] * (1 + 0.02 * rng.standard_normal(8)) for k in out}
    data = CalibrationData(geom, meas, {k: 0.02 * out[k] for k in out})
    free = {"modulus": (3e7, 3e8), "c_moy": (1500.0, 5000.0)}
    a = fit(data, free, multistart=3)
    b = fit(data, free, multistart=3, scheduler=client)
    assert a.as_dict() == b.as_dict()
    assert "best of 4 starts" in b.message


def _env_of_worker(_):
    import os

    import numba

    return os.environ.get("OPENBLAS_NUM_THREADS"), os.environ.get("MKL_NUM_THREADS"), numba.get_num_threads()


def test_process_pool_fallback_sets_threads():
    """Without dask, "local" is a spawn process pool; its workers get the same settings."""
    from ipmc_asym.parallel.executors import _on_pool

    out = _on_pool(_env_of_worker, [0, 1, 2], 2, 1, ("leading",))
    assert out == [("1", "1", 1)] * 3


@pytest.mark.slow
def test_windowed_process_pool_sets_threads():
    """The streamed variant of the pool fallback: same worker settings, results in order."""
    from ipmc_asym.parallel.executors import _window_pool

    out = list(_window_pool(_env_of_worker, iter([0, 1, 2]), 2, 1, ("leading",), 2))
    assert out == [("1", "1", 1)] * 3


def test_chunked_sweep_row_order_3d_all_models():
    """Chunks (one first-axis value x a block of the second axis) reassemble the serial rows."""
    vary = {"length": np.array([0.01, 0.02, 0.03]), "thickness": np.geomspace(1e-4, 4e-4, 5),
            "voltage": np.array([-1.0, 0.5, 2.0])}
    serial = sweep(vary, model="all", fidelity="corrected", progress=False)
    chunked = sweep_chunked(vary, None, seconds_per_point=0.04, workers=2, model="all", fidelity="corrected")
    _same(serial, chunked)


def test_tcp_address_of_an_existing_cluster(client):
    """``--scheduler tcp://HOST:PORT``: connect to a running scheduler by its address."""
    addr = client.scheduler.address
    assert addr.startswith("tcp://")
    assert run_chunks(abs, [-3, -1, -2], scheduler=addr) == [3, 1, 2]
