"""The one place where Numba compile flags are set (py-pde style).

Kernels are plain module-level functions decorated with :func:`jit` (scalar kernels) or
:func:`jit_parallel` (sweep drivers that use ``prange``).  ``cache=True`` writes the compiled
code next to the sources (or to ``NUMBA_CACHE_DIR``) so that a fresh process loads it
instead of compiling.
"""

from __future__ import annotations

import numba as nb

__all__ = ["jit", "jit_parallel", "prange"]

prange = nb.prange

_FLAGS = dict(nopython=True, cache=True, fastmath=False, nogil=True, error_model="numpy")


def jit(func=None, **kw):
    """``numba.njit`` with the project's flags (serial kernels)."""
    opts = {**_FLAGS, **kw}
    if func is None:
        return lambda f: nb.jit(f, **opts)
    return nb.jit(func, **opts)


def jit_parallel(func=None, **kw):
    """``numba.njit(parallel=True)`` with the project's flags: only for ``prange`` drivers."""
    opts = {**_FLAGS, "parallel": True, **kw}
    if func is None:
        return lambda f: nb.jit(f, **opts)
    return nb.jit(func, **opts)
