"""Chunked work on a process pool or a dask.distributed cluster, with warm Numba caches in
the workers."""
