"""The one place where Numba compile flags are set (py-pde style).

Kernels are plain module-level functions decorated with :func:`jit` (scalar kernels) or
:func:`jit_parallel` (sweep drivers that use ``prange``).  ``cache=True`` writes the compiled
code next to the sources (or to ``NUMBA_CACHE_DIR``) so that a fresh process loads it
instead of compiling.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba as nb

__all__ = ["jit", "jit_parallel", "prange", "CACHE_DIR"]


def hashed_sources() -> list:
    """The modules that define jitted functions (and what they inline: ``settings`` values
    such as ``EXACT_STATED_ERROR`` are frozen into the compiled sweep driver)."""
    here = Path(__file__).resolve().parent
    return sorted([here / "_jit.py", here / "integral.py", here / "integral_samples.py", here / "settings.py",
                   here / "electrode.py", here / "circuit.py",
                   *(here / "kernels").glob("*.py")])


def _cache_dir() -> str:
    """Numba's on-disk cache, keyed by a hash of this package's sources.

    Numba invalidates a cached function when ITS file changes, not when a function it
    calls from another module does (a sweep driver in integral.py inlines the kernels of
    kernels/*.py).  Keying the whole cache on the sources of every module with jitted code
    makes any edit or upgrade start from a clean cache.  ``NUMBA_CACHE_DIR``, if set, wins.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.environ["NUMBA_CACHE_DIR"]
    here = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for p in hashed_sources():
        h.update(p.relative_to(here).as_posix().encode())
        h.update(p.read_bytes())
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "ipmc_asym", f"numba-{nb.__version__}-{h.hexdigest()[:16]}")


CACHE_DIR = _cache_dir()
nb.config.CACHE_DIR = CACHE_DIR

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
