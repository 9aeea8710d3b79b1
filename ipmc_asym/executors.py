"""Run independent chunks of work serially, on a local pool, or on a dask.distributed cluster.

``run_chunks(func, tasks, scheduler=None)`` returns ``[func(t) for t in tasks]`` in order,
whatever runs it:

``None``
    serially in this process;
``"local"``
    a ``dask.distributed.LocalCluster`` of worker processes (one per core, one thread
    each) when dask.distributed is installed (the ``dask`` extra), else a
    ``concurrent.futures`` process pool (spawn) with the same settings;
``"tcp://HOST:PORT"``
    an existing dask scheduler (``dask scheduler`` + ``dask worker`` started elsewhere,
    see README "Running on a Dask cluster");
a ``distributed.Client``
    used as is (the tests give one on their own ``LocalCluster``).

Why results are identical to the serial run: every task is a pure function of its chunk
(no random state, no reduction across chunks); the compiled kernels are elementwise, so
the number of Numba threads does not change a single bit; chunks are reassembled in order.

Workers are set up once each (:func:`worker_setup`): BLAS thread pools pinned to one
thread through ``OPENBLAS/OMP/MKL_NUM_THREADS=1`` (set in the environment the worker
processes are spawned with -- dask's nanny does this by default, and the local pool gets it
from here), Numba threads set to ``threads`` explicitly, and the compiled kernels loaded
from the on-disk cache.  The cache is warmed in the parent before any worker starts
(:func:`warm_kernels`), so workers only read it; on a remote host the first worker to
arrive warms it under a file lock and the others wait and read (no concurrent cache
writes).  Chunks are sized by :func:`chunk_slices` to carry >= 100 ms of work each so
scheduling overhead (~1 ms per dask task) stays below 1 %.

Importing this module imports neither dask nor distributed (deferred).
"""

from __future__ import annotations

import contextlib
import math
import os
import time

import numpy as np

from .registry import FIDELITIES, fidelity_names

__all__ = ["run_chunks", "chunk_slices", "warm_kernels", "worker_setup", "BLAS_ENV", "MIN_CHUNK_SECONDS",
           "check_scheduler", "time_per_item", "sweep_chunked"]

#: environment of every worker process: one BLAS/OpenMP thread (the parallelism is the workers)
BLAS_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
            "NUMBA_NUM_THREADS": "1"}
#: smallest amount of work per task
MIN_CHUNK_SECONDS = 0.1


def check_scheduler(scheduler):
    """``None``, ``"local"``, ``"tcp://HOST:PORT"`` or a Client; one-line ``ValueError`` otherwise."""
    if scheduler is None or scheduler == "local" or hasattr(scheduler, "submit"):
        return scheduler
    if isinstance(scheduler, str) and scheduler.startswith(("tcp://", "tls://")):
        hostport = scheduler.split("://", 1)[1]
        host, _, port = hostport.rpartition(":")
        if host and port.isdigit():
            return scheduler
    raise ValueError(f"--scheduler must be local or tcp://HOST:PORT; got {scheduler!r}")


#: the compiled rungs (kernel order >= 0 in the registry): what workers may call
COMPILED = tuple(f for f in fidelity_names() if FIDELITIES[f].order >= 0)


def warm_kernels(fidelities=COMPILED) -> float:
    """Compile (or load from the cache) every kernel a chunk may call; returns seconds.

    Called in the parent before workers start, so the on-disk Numba cache is complete and
    workers only read it.
    """
    t0 = time.perf_counter()
    from .integral import moment
    from .integral_samples import moment_samples
    from .registry import model_names

    one = np.ones(1)
    for f in fidelities:
        for m in model_names():
            if not FIDELITIES[f].closed_form and m != model_names()[0]:
                continue  # one kernel serves every model (rho is an argument)
            moment(np.array([200e-6]), np.array([1.0]), m, f)
        # the per-sample driver of ipmc_asym.uq (same signature for every model)
        mid = 0 if FIDELITIES[f].closed_form else -1
        moment_samples(0.01 * one, 40.0 * one, 0.3 * one, 1.0, mid, FIDELITIES[f].order, one,
                       np.empty(1), np.empty(1), np.empty(1))
    return time.perf_counter() - t0


def worker_setup(threads: int = 1, fidelities=COMPILED) -> dict:
    """Per-worker set-up: thread counts explicit, kernels loaded once (cache read).

    On a host whose cache is cold (remote worker), a file lock beside the cache serialises
    the one compilation: the first worker writes, the others then only read.
    """
    for k, v in BLAS_ENV.items():
        os.environ.setdefault(k, v)
    import numba

    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    from ._jit import CACHE_DIR

    os.makedirs(CACHE_DIR, exist_ok=True)
    with _file_lock(os.path.join(CACHE_DIR, ".warm.lock")):
        dt = warm_kernels(fidelities)
    return {"pid": os.getpid(), "numba_threads": numba.get_num_threads(), "warm_seconds": dt,
            "blas_env": {k: os.environ.get(k) for k in BLAS_ENV}}


@contextlib.contextmanager
def _file_lock(path):
    try:
        import fcntl
    except ImportError:  # pragma: no cover - non-POSIX: no lock, the parent warmed the cache
        yield
        return
    with open(path, "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def time_per_item(func, sample_task, n_items: int, repeat: int = 2) -> float:
    """Seconds per item of ``func(sample_task)`` (``n_items`` items), best of ``repeat``."""
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        func(sample_task)
        best = min(best, time.perf_counter() - t0)
    return best / max(n_items, 1)


def chunk_slices(n: int, seconds_per_item: float, workers: int = 1,
                 min_seconds: float = MIN_CHUNK_SECONDS, max_items: int | None = None) -> list:
    """Split ``range(n)`` into slices of >= ``min_seconds`` of work each.

    As many chunks as that allows, but no more than ~4 per worker (load balance without
    overhead); never fewer items per chunk than the 100 ms floor implies; ``max_items``
    bounds the memory of one chunk.
    """
    if n <= 0:
        return []
    floor = max(1, math.ceil(min_seconds / max(seconds_per_item, 1e-12)))
    per = max(floor, math.ceil(n / max(4 * workers, 1)))
    if max_items is not None:
        per = max(1, min(per, int(max_items)))
    return [slice(i, min(i + per, n)) for i in range(0, n, per)]


def run_chunks(func, tasks, scheduler=None, workers: int | None = None, threads: int = 1,
               fidelities=COMPILED) -> list:
    """``[func(t) for t in tasks]`` on ``scheduler`` (see module docstring), in order.

    Parameters
    ----------
    func : callable
        A module-level (picklable) function of one task.
    tasks : sequence
    scheduler : None, "local", "tcp://HOST:PORT" or distributed.Client
    workers : int, optional
        Workers of a local cluster/pool (default: the number of cores).
    threads : int
        Numba threads per worker (BLAS: always 1).
    fidelities : tuple
        Kernels to warm in the parent and to load once per worker.
    """
    tasks = list(tasks)
    scheduler = check_scheduler(scheduler)
    if scheduler is None or not tasks:
        return [func(t) for t in tasks]
    warm_kernels(fidelities)  # parent: complete cache before any worker starts
    nw = workers or os.cpu_count() or 1
    if hasattr(scheduler, "submit"):
        return _on_client(scheduler, func, tasks, threads, fidelities)
    if scheduler == "local":
        try:
            import distributed  # deferred: heavy import (start-up), optional extra
        except ImportError:
            return _on_pool(func, tasks, nw, threads, fidelities)
        env = _worker_env(threads)
        with _env(env):
            with distributed.LocalCluster(n_workers=nw, threads_per_worker=1, processes=True,
                                          dashboard_address=":0", env=env) as cluster, \
                    distributed.Client(cluster) as client:
                return _on_client(client, func, tasks, threads, fidelities)
    try:
        import distributed  # deferred: heavy import (start-up), optional extra
    except ImportError:
        raise ValueError(f"--scheduler {scheduler}: dask.distributed is not installed "
                         "(pip install \".[dask]\")") from None
    try:
        client = distributed.Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise ValueError(f"--scheduler {scheduler}: cannot connect ({exc.__class__.__name__})") from None
    with client:
        return _on_client(client, func, tasks, threads, fidelities)


def _on_client(client, func, tasks, threads, fidelities):
    client.run(worker_setup, threads, fidelities)
    # the chunks' data go straight to the workers (scatter), not inside the task graph
    data = client.scatter(tasks)
    futures = client.map(func, data, pure=False)
    return client.gather(futures)


def _on_pool(func, tasks, nw, threads, fidelities):
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with _env(_worker_env(threads)):  # spawned workers inherit this environment
        ctx = mp.get_context("spawn")
        with ProcessPoolExecutor(max_workers=nw, mp_context=ctx, initializer=worker_setup,
                                 initargs=(threads, fidelities)) as ex:
            return list(ex.map(func, tasks))


def _worker_env(threads):
    return {**BLAS_ENV, "NUMBA_NUM_THREADS": str(max(1, int(threads)))}


def _sweep_task(task):
    from .sweeps import sweep

    vary, kw = task
    return sweep(vary, **kw)


def sweep_chunked(vary: dict, scheduler=None, *, seconds_per_point: float | None = None,
                  workers: int | None = None, threads: int = 1, **sweep_kw):
    """:func:`ipmc_asym.sweeps.sweep` on ``scheduler``, in chunks that are contiguous row ranges.

    The grid is the outer product of ``vary`` in C order (first key slowest), so one value of
    the first axis with a contiguous block of the second axis (all of the rest) is a
    contiguous range of the serial sweep's rows: chunks of that shape, concatenated in
    order, are exactly the serial rows.  Each chunk carries >= 100 ms of work
    (``seconds_per_point``: default 30 ms for ``bvp``, 1 us otherwise), and there are up to
    ~4 chunks per worker for load balance (BVP points differ in cost).
    """
    names = list(vary)
    if not names:
        raise ValueError("sweep needs at least one varied parameter")
    axes = {k: np.atleast_1d(np.asarray(vary[k], float)) for k in names}
    first = axes[names[0]]
    nmod = 3 if sweep_kw.get("model") == "all" else 1
    spp = seconds_per_point or (0.03 if sweep_kw.get("fidelity") == "bvp" else 1e-6)
    nw = workers or os.cpu_count() or 1
    kw = dict(sweep_kw, progress=False)
    tasks = []
    if len(names) == 1:
        for s in chunk_slices(first.size, spp * nmod, nw if scheduler is not None else 1):
            tasks.append(({names[0]: first[s]}, kw))
    else:
        second = axes[names[1]]
        rest = int(np.prod([axes[k].size for k in names[2:]])) if len(names) > 2 else 1
        lines = chunk_slices(first.size * second.size, spp * rest * nmod, nw if scheduler is not None else 1)
        per = max(1, lines[0].stop - lines[0].start) if lines else 1
        for i in range(first.size):
            for j0 in range(0, second.size, per):
                sub = {names[0]: first[i:i + 1], names[1]: second[j0:j0 + per]}
                sub.update({k: axes[k] for k in names[2:]})
                tasks.append((sub, kw))
    parts = run_chunks(_sweep_task, tasks, scheduler, workers=workers, threads=threads)
    if nmod == 1:
        return np.concatenate(parts)
    # several models: each chunk is model-major; regroup so the rows follow the serial order
    by_model = [np.concatenate([p.reshape(nmod, -1)[i] for p in parts]) for i in range(nmod)]
    return np.concatenate(by_model)


@contextlib.contextmanager
def _env(values):
    """Temporarily set environment variables (inherited by processes spawned meanwhile)."""
    old = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def bench_section(quick: bool = False, shape: tuple | None = None, repeats: int | None = None) -> dict:
    """``ipmc-asym bench`` section: a 2-D BVP sweep on a 2-worker LocalCluster vs 1 worker.

    LocalClusters of 1 and 2 worker processes (one thread each), started and warmed first;
    the sweep then runs alternately on each (best of 3), side by side in one run; cluster
    start-up excluded (paid once per session); the results are checked identical.
    """
    try:
        import distributed  # deferred: heavy import (start-up), optional extra
    except ImportError:
        return {"figures": [{"what": "distributed BVP sweep speed-up", "value": None, "unit": "x", "target": 1.7,
                             "pass": None, "note": "dask.distributed not installed (pip install \".[dask]\")"}]}
    from .sweeps import sweep

    # 200 points (10 x 20), the size issue 10 states its target for; few chunks of a tiny
    # sweep cannot balance two workers, so a smaller grid understates the speed-up
    nt, nv = shape if shape is not None else ((2, 4) if quick else (10, 20))
    vary = {"thickness": np.geomspace(100e-6, 400e-6, nt), "voltage": np.linspace(0.5, 2.0, nv)}
    kw = dict(model="constant", fidelity="bvp")
    warm_kernels()
    sweep({"thickness": vary["thickness"][:1], "voltage": vary["voltage"][:1]}, progress=False, **kw)
    times, results = {1: math.inf, 2: math.inf}, {}
    env = _worker_env(1)
    warm_task = ({"thickness": vary["thickness"][:1], "voltage": vary["voltage"][:1]}, dict(kw, progress=False))
    with contextlib.ExitStack() as stack:
        stack.enter_context(_env(env))
        clients = {}
        for nw in (1, 2):
            cl = stack.enter_context(distributed.LocalCluster(n_workers=nw, threads_per_worker=1, processes=True,
                                                              dashboard_address=":0", env=env))
            clients[nw] = stack.enter_context(distributed.Client(cl))
            clients[nw].run(worker_setup, 1)
            clients[nw].run(_sweep_task, warm_task)  # SciPy imports, first-call costs on every worker
        # alternate 1 / 2 workers and keep the best of each: the machine is shared, and a
        # burst of someone else's load should not decide the ratio
        for _ in range(repeats if repeats is not None else (1 if quick else 2)):
            for nw in (1, 2):
                t0 = time.perf_counter()
                # the same chunks for both (sized for 2 workers)
                results[nw] = sweep_chunked(vary, clients[nw], seconds_per_point=0.1, workers=2, **kw)
                times[nw] = min(times[nw], time.perf_counter() - t0)
    same = all(np.array_equal(results[1][k], results[2][k], equal_nan=results[1].dtype[k].kind == "f")
               for k in results[1].dtype.names)
    sp = times[1] / times[2]
    return {"figures": [
        {"what": f"distributed BVP sweep {nt}x{nv}: 2 workers vs 1", "value": sp, "unit": "x", "target": 1.7,
         "pass": bool(sp >= 1.7), "note": f"1 worker {times[1]:.3g} s, 2 workers {times[2]:.3g} s; "
                                          f"results identical: {same}"},
    ], "identical": same}
