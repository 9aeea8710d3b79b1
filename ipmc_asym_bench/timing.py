"""How the bench measures: CPU time for single-thread figures, wall time for parallel ones,
the load average printed beside every figure.

The machine the figures are stated for is shared: wall clock charges a figure with every other
process's share of the cores, CPU time (:func:`time.process_time`, this process's user + system
time) does not.  With one Numba thread, the process's CPU time is the figure's own cost; a
parallel figure (several threads) is a wall time, and the load beside it says how much of the
machine it had.  Repeats keep the minimum (the least disturbed run).
"""

from __future__ import annotations

import contextlib
import math
import os
import time

import numba

__all__ = ["cpu_best", "wall_best", "threads", "load", "clock_note"]


def load() -> float:
    """The 1-minute load average (``os.getloadavg()[0]``), printed beside the figures."""
    try:
        return float(os.getloadavg()[0])
    except OSError:  # not available on this platform
        return math.nan


def cpu_best(fn, repeats: int = 3) -> float:
    """Least CPU time (s, :func:`time.process_time`) of ``repeats`` calls of ``fn()``."""
    best = math.inf
    for _ in range(max(1, int(repeats))):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def wall_best(fn, repeats: int = 3) -> float:
    """Least wall time (s, :func:`time.perf_counter`) of ``repeats`` calls of ``fn()``."""
    best = math.inf
    for _ in range(max(1, int(repeats))):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


@contextlib.contextmanager
def threads(n: int):
    """Numba's thread count set to ``n`` (at most the pool's size) inside the block."""
    old = numba.get_num_threads()
    numba.set_num_threads(max(1, min(int(n), numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(old)


def clock_note(cpu: bool) -> str:
    """The note saying what a figure's clock is, with the load at the time of the call."""
    return (f"{'CPU time, 1 thread' if cpu else 'wall clock'}, load {load():.2f}")
