"""A sweep on a process pool or a dask.distributed cluster, in chunks that are contiguous
row ranges of the serial sweep (so the result is the serial one, row for row)."""

from __future__ import annotations

import os

import numpy as np

from ipmc_asym.parallel.executors import chunk_slices, run_chunks
from ipmc_asym.studies.sweeps import sweep

__all__ = ["sweep_chunked"]


def _sweep_task(task):
    vary, kw = task
    return sweep(vary, **kw)


def sweep_chunked(vary: dict, scheduler=None, *, seconds_per_point: float | None = None,
                  workers: int | None = None, threads: int = 1, **sweep_kw):
    """:func:`ipmc_asym.studies.sweeps.sweep` on ``scheduler``, in chunks that are contiguous row ranges.

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
