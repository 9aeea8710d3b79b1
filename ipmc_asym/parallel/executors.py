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
    see docs/dask.md);
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

``imap_chunks(func, tasks, scheduler=None)`` yields the same results one at a time, in
order, with at most ``window`` tasks in flight: a caller that folds each result into an
accumulator as it arrives (``studies/uq.py``) holds a bounded number of results whatever the
number of tasks; ``tasks`` may be a generator.

Importing this module imports neither dask nor distributed (deferred).
"""

from __future__ import annotations

import collections
import contextlib
import math
import multiprocessing as mp
import os
import socket
import struct
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from ipmc_asym.base.registry import FIDELITIES, compiled_fidelities, model_names
from ipmc_asym.integral.api import moment
from ipmc_asym.integral.samples import moment_samples

__all__ = ["run_chunks", "imap_chunks", "chunk_slices", "warm_kernels", "worker_setup", "BLAS_ENV", "MIN_CHUNK_SECONDS",
           "check_scheduler", "worker_env", "probe_scheduler", "PROBE_TIMEOUT"]

#: environment of every worker process: one BLAS/OpenMP thread (the parallelism is the workers)
BLAS_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
            "NUMBA_NUM_THREADS": "1"}
#: smallest amount of work per task
MIN_CHUNK_SECONDS = 0.1


def check_scheduler(scheduler):
    """``None``, ``"local"``, ``"tcp://HOST:PORT"`` (answering like a dask peer, :func:`probe_scheduler`)
    or a Client; one-line ``ValueError`` otherwise."""
    if scheduler is None or scheduler == "local" or hasattr(scheduler, "submit"):
        return scheduler
    if isinstance(scheduler, str) and scheduler.startswith(("tcp://", "tls://")):
        hostport = scheduler.split("://", 1)[1]
        host, _, port = hostport.rpartition(":")
        if host and port.isdigit():
            # a server that is not dask, or silent: one line now, not a hang or a huge allocation
            # after the work has started
            probe_scheduler(scheduler)
            return scheduler
    raise ValueError(f"--scheduler must be local or tcp://HOST:PORT; got {scheduler!r}")


#: seconds to connect to a ``tcp://`` scheduler and to receive its first message (its handshake)
PROBE_TIMEOUT = 5.0
#: largest first message of a dask peer (its handshake is a few hundred bytes): a larger
#: length prefix is not dask (e.g. an HTTP reply read as a length would ask for exabytes)
MAX_HANDSHAKE_BYTES = 1 << 20


def probe_scheduler(address: str, timeout: float | None = None) -> None:
    """Check that ``tcp://HOST:PORT`` answers like a dask peer, within ``timeout`` seconds.

    A dask comm (``distributed.comm.tcp``) starts by sending its handshake: one message whose
    first 8 bytes are its length (little-endian unsigned 64-bit).  The probe connects, reads
    those 8 bytes and checks the length is that of a handshake; a server that is not dask, or
    accepts and stays silent, is refused in one line instead of a huge allocation or a hang.
    ``tls://`` addresses are checked for a connection only (the handshake is encrypted).

    Raises
    ------
    ValueError
        One line naming ``--scheduler`` and what went wrong.
    """
    timeout = PROBE_TIMEOUT if timeout is None else float(timeout)
    scheme, _, hostport = address.partition("://")
    host, _, port = hostport.rpartition(":")
    host = host.strip("[]")
    try:
        sock = socket.create_connection((host, int(port)), timeout=timeout)
    except TimeoutError:
        raise ValueError(f"--scheduler {address}: no connection within {timeout:g} s") from None
    except OSError as exc:
        raise ValueError(f"--scheduler {address}: cannot connect ({exc.strerror or exc.__class__.__name__})") from None
    with sock:
        if scheme != "tcp":
            return
        head = b""
        try:
            while len(head) < 8:
                got = sock.recv(8 - len(head))
                if not got:
                    raise ValueError(f"--scheduler {address}: the server closed the connection without a dask "
                                     "handshake (not a dask scheduler?)")
                head += got
        except TimeoutError:
            raise ValueError(f"--scheduler {address}: no dask handshake within {timeout:g} s (not a dask "
                             "scheduler?)") from None
        except OSError as exc:
            raise ValueError(f"--scheduler {address}: connection failed ({exc.strerror or exc.__class__.__name__})"
                             ) from None
    (n,) = struct.unpack("<Q", head)
    if not 0 < n <= MAX_HANDSHAKE_BYTES:
        raise ValueError(f"--scheduler {address}: the server does not speak the dask protocol (its first message "
                         f"would be {n} bytes; not a dask scheduler)")


#: the compiled rungs (``compiled`` in the registry): what workers may call
COMPILED = compiled_fidelities()


def warm_kernels(fidelities=COMPILED) -> float:
    """Compile (or load from the cache) every kernel a chunk may call; returns seconds.

    Called in the parent before workers start, so the on-disk Numba cache is complete and
    workers only read it.
    """
    t0 = time.perf_counter()

    one = np.ones(1)
    for f in fidelities:
        for m in model_names():
            if not FIDELITIES[f].closed_form and m != model_names()[0]:
                continue  # one kernel serves every model (rho is an argument)
            moment(np.array([200e-6]), np.array([1.0]), m, f)
        # the per-sample driver of ipmc_asym.studies.uq (same signature for every model)
        mid = 0 if FIDELITIES[f].closed_form else -1
        moment_samples(0.01 * one, 40.0 * one, 0.3 * one, 1.0, mid, FIDELITIES[f].kernel_code, one,
                       np.empty(1), np.empty(1), np.empty(1))
    return time.perf_counter() - t0


def worker_setup(threads: int = 1, fidelities=COMPILED) -> dict:
    """Per-worker set-up: thread counts explicit, kernels loaded once (cache read).

    On a host whose cache is cold (remote worker), a file lock beside the cache serialises
    the one compilation: the first worker writes, the others then only read.
    """
    for k, v in BLAS_ENV.items():
        os.environ.setdefault(k, v)
    import numba  # deferred: after the thread environment above is set

    # Numba re-reads the environment at every compilation and refuses a NUMBA_NUM_THREADS that
    # differs from the pool it already launched (a worker of the user's own cluster, or one
    # whose environment changed since Numba was imported): keep the variable at the value
    # Numba runs with; the count actually used is set just below
    os.environ["NUMBA_NUM_THREADS"] = str(numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    from ipmc_asym.kernels.jit import CACHE_DIR  # deferred: loads Numba: after the thread environment is set

    os.makedirs(CACHE_DIR, exist_ok=True)
    with _file_lock(os.path.join(CACHE_DIR, ".warm.lock")):
        dt = warm_kernels(fidelities)
    return {"pid": os.getpid(), "numba_threads": numba.get_num_threads(), "warm_seconds": dt,
            "blas_env": {k: os.environ.get(k) for k in BLAS_ENV}}


@contextlib.contextmanager
def _file_lock(path):
    try:
        import fcntl  # deferred: POSIX only
    except ImportError:  # pragma: no cover - non-POSIX: no lock, the parent warmed the cache
        yield
        return
    with open(path, "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


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
    with _scheduler_client(scheduler, nw, threads) as client:
        if client is None:
            return _on_pool(func, tasks, nw, threads, fidelities)
        return _on_client(client, func, tasks, threads, fidelities)


@contextlib.contextmanager
def _scheduler_client(scheduler, nw, threads):
    """The dask client of ``"local"`` (a local cluster of ``nw`` workers) or of an address;
    ``None`` for ``"local"`` without dask (the caller uses a process pool)."""
    if scheduler == "local":
        try:
            import distributed  # deferred: heavy import (start-up), optional extra
        except ImportError:
            yield None
            return
        # the nannies start each worker with this environment (the parent's is untouched)
        with distributed.LocalCluster(n_workers=nw, threads_per_worker=1, processes=True,
                                      dashboard_address=":0", env=worker_env(threads)) as cluster, \
                distributed.Client(cluster) as client:
            yield client
        return
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
        yield client


def imap_chunks(func, tasks, scheduler=None, workers: int | None = None, threads: int = 1,
                fidelities=COMPILED, window: int | None = None):
    """Yield ``func(t)`` for ``t`` in ``tasks``, in order, on ``scheduler`` (as :func:`run_chunks`).

    At most ``window`` tasks (default: twice the number of workers) are submitted ahead of
    the one being yielded, so results not yet consumed, and the tasks themselves (``tasks``
    is read lazily), stay bounded in number.

    Parameters
    ----------
    func, scheduler, workers, threads, fidelities
        As :func:`run_chunks`.
    tasks : iterable
    window : int, optional
        Tasks in flight (>= 1).
    """
    scheduler = check_scheduler(scheduler)
    tasks = iter(tasks)
    if scheduler is None:
        for t in tasks:
            yield func(t)
        return
    warm_kernels(fidelities)  # parent: complete cache before any worker starts
    nw = workers or os.cpu_count() or 1
    if hasattr(scheduler, "submit"):
        yield from _window_client(scheduler, func, tasks, threads, fidelities, window)
        return
    with _scheduler_client(scheduler, nw, threads) as client:
        if client is None:
            yield from _window_pool(func, tasks, nw, threads, fidelities, window or 2 * nw)
        else:
            yield from _window_client(client, func, tasks, threads, fidelities, window)


def _windowed(submit, tasks, window):
    """Results of ``submit(t).result()`` in order, ``window`` submissions ahead."""
    pending = collections.deque()
    for t in tasks:
        pending.append(submit(t))
        if len(pending) >= window:
            yield pending.popleft().result()
    while pending:
        yield pending.popleft().result()


def _window_client(client, func, tasks, threads, fidelities, window):
    client.run(worker_setup, threads, fidelities)
    nw = max(1, len(client.scheduler_info().get("workers", {})))
    yield from _windowed(lambda t: client.submit(func, t, pure=False), tasks, window or 2 * nw)


def _window_pool(func, tasks, nw, threads, fidelities, window):
    # spawned workers inherit this environment (workers start on demand: kept while submitting)
    with _env(worker_env(threads)):
        ctx = mp.get_context("spawn")
        with ProcessPoolExecutor(max_workers=nw, mp_context=ctx, initializer=worker_setup,
                                 initargs=(threads, fidelities)) as ex:
            yield from _windowed(lambda t: ex.submit(func, t), tasks, window)


def _on_client(client, func, tasks, threads, fidelities):
    client.run(worker_setup, threads, fidelities)
    # the chunks' data go straight to the workers (scatter), not inside the task graph
    data = client.scatter(tasks)
    futures = client.map(func, data, pure=False)
    return client.gather(futures)


def _on_pool(func, tasks, nw, threads, fidelities):

    with _env(worker_env(threads)):  # spawned workers inherit this environment
        ctx = mp.get_context("spawn")
        with ProcessPoolExecutor(max_workers=nw, mp_context=ctx, initializer=worker_setup,
                                 initargs=(threads, fidelities)) as ex:
            return list(ex.map(func, tasks))


def worker_env(threads: int = 1) -> dict:
    """Environment of a worker process: one BLAS thread, ``threads`` Numba threads."""
    return {**BLAS_ENV, "NUMBA_NUM_THREADS": str(max(1, int(threads)))}


@contextlib.contextmanager
def _env(values):
    """Set environment variables while worker processes are spawned (they inherit them: the
    BLAS and Numba thread counts must be set before the worker imports NumPy); restored after."""
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
