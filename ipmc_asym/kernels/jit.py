"""The one place where Numba compile flags are set (py-pde style).

Kernels are plain module-level functions decorated with :func:`jit` (scalar kernels) or
:func:`jit_parallel` (sweep drivers that use ``prange``).  Every such function caches its
compiled code on disk in :data:`CACHE_DIR` (``NUMBA_CACHE_DIR`` if set), through a cache
object set on the function itself, so that a fresh process loads it instead of compiling and
no Numba setting of the user's process is changed.
"""

from __future__ import annotations

import ast
import hashlib
import os
import sys
import types
from pathlib import Path

import numba as nb
from numba.core import caching

__all__ = ["jit", "jit_parallel", "prange", "CACHE_DIR", "interpreted", "compile_notice_given"]


#: names whose import from this module marks a module that defines jitted code
_DECORATORS = frozenset({"jit", "jit_parallel"})


def _package_imports(path: Path, root: Path):
    """``(imports, defines_jitted)`` of one package module, read with ``ast``: the package's
    module files its module-level imports name, and whether it imports a decorator of this
    module.  Module level only: a jitted function reaches other code through its module's
    globals, which the module-level imports bind (a deferred import inside a function is
    plain Python, never compiled)."""
    tree = ast.parse(path.read_bytes(), filename=str(path))
    pkg = root.name
    found, jitted = set(), False

    def add(dotted: str) -> None:
        parts = dotted.split(".")
        if parts[0] != pkg:
            return
        base = root.joinpath(*parts[1:])
        for cand in (base.with_suffix(".py"), base / "__init__.py"):
            if cand.is_file():
                found.add(cand)
                return

    nodes = list(tree.body)
    while nodes:  # module level, including the bodies of module-level if/try blocks
        node = nodes.pop()
        if isinstance(node, ast.Import):
            for a in node.names:
                add(a.name)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            add(node.module)
            for a in node.names:
                add(f"{node.module}.{a.name}")  # ``from pkg.sub import module``
            if node.module == __name__ and any(a.name in _DECORATORS for a in node.names):
                jitted = True
        elif isinstance(node, (ast.If, ast.Try)):
            nodes += node.body + node.orelse + getattr(node, "finalbody", []) + \
                [b for h in getattr(node, "handlers", []) for b in h.body]
    return found, jitted


def hashed_sources() -> list:
    """The files the compiled code depends on: every package module that imports :func:`jit` or
    :func:`jit_parallel` from here, plus every package module those import, transitively
    (module-level imports, read with ``ast``; ``settings`` values such as
    ``EXACT_STATED_ERROR`` are frozen into the compiled drivers).  Sorted paths."""
    root = Path(__file__).resolve().parents[1]
    graph = {}

    def imports(p):
        if p not in graph:
            graph[p] = _package_imports(p, root)
        return graph[p]

    # only a file that names this module can import from it: parse those, then what they reach
    me = __name__.encode()
    todo = [p for p in root.rglob("*.py") if me in p.read_bytes() and imports(p)[1]]
    seen = set(todo)
    while todo:
        for q in imports(todo.pop())[0]:
            if q not in seen:
                seen.add(q)
                todo.append(q)
    return sorted(seen)


def _memo_sources(here: Path, base: str) -> list:
    """:func:`hashed_sources`, memoised on disk under the hash of every package source: parsing
    the import graph costs ~0.1-0.5 s a process, reading and hashing the files ~10 ms."""
    files = sorted(here.rglob("*.py"))
    h = hashlib.sha256()
    for p in files:
        h.update(p.relative_to(here).as_posix().encode())
        h.update(p.read_bytes())
    memo = Path(base, "ipmc_asym", f"sources-{h.hexdigest()[:16]}.txt")
    try:
        return [here / r for r in memo.read_text().split()]
    except OSError:
        pass
    out = hashed_sources()
    try:
        memo.parent.mkdir(parents=True, exist_ok=True)
        memo.write_text("\n".join(p.relative_to(here).as_posix() for p in out))
    except OSError:  # a read-only cache: the list is recomputed next time
        pass
    return out


def _cache_dir() -> str:
    """Numba's on-disk cache, keyed by a hash of the sources the compiled code depends on.

    Numba invalidates a cached function when ITS file changes, not when a function it
    calls from another module does (a sweep driver in integral.py inlines the kernels of
    kernels/*.py).  Keying the whole cache on the sources of :func:`hashed_sources` (the
    import graph of every module with jitted code) makes any edit or upgrade start from a
    clean cache.  ``NUMBA_CACHE_DIR``, if set, wins.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.environ["NUMBA_CACHE_DIR"]
    here = Path(__file__).resolve().parents[1]
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    h = hashlib.sha256()
    for p in _memo_sources(here, base):
        h.update(p.relative_to(here).as_posix().encode())
        h.update(p.read_bytes())
    return os.path.join(base, "ipmc_asym", f"numba-{nb.__version__}-{h.hexdigest()[:16]}")


CACHE_DIR = _cache_dir()


class _PackageCacheLocator(caching.UserProvidedCacheLocator):
    """Numba's user-directory locator, pointed at :data:`CACHE_DIR` for this package's
    functions only: ``numba.config.CACHE_DIR`` (every other library's cache in the user's
    process) is left as it is."""

    def __init__(self, py_func, py_file):
        super().__init__(py_func, py_file)
        self._cache_path = os.path.join(CACHE_DIR, self.get_suitable_cache_subpath(py_file))

    @classmethod
    def get_suitable_cache_subpath(cls, py_file):
        """The module's folder relative to the package (Numba's default hashes its absolute path):
        :data:`CACHE_DIR` is keyed on the sources' content already, so two installs of the same
        sources (a clone and a site-packages copy, two venvs) share the compiled code."""
        root = Path(__file__).resolve().parents[1]
        try:
            rel = Path(py_file).resolve().parent.relative_to(root)
        except ValueError:  # not a module of this package: Numba's own layout
            return super().get_suitable_cache_subpath(py_file)
        return "_".join((root.name, *rel.parts))

    @classmethod
    def from_function(cls, py_func, py_file):
        # skip UserProvidedCacheLocator's test of numba.config.CACHE_DIR: ours is always set
        return super(caching.UserProvidedCacheLocator, cls).from_function(py_func, py_file)


class _PackageCacheImpl(caching.CompileResultCacheImpl):
    _locator_classes = [_PackageCacheLocator]


#: whether this process has said on stderr that it compiles (once: by the command line's own notice,
#: ``ipmc-asym warmup``'s, or :meth:`_PackageFunctionCache.load_overload`)
_NOTICE = {"given": False}


def compile_notice_given() -> None:
    """Record that a line about compiling has been written (the command line's notices): the
    library then does not write its own."""
    _NOTICE["given"] = True


class _PackageFunctionCache(caching.FunctionCache):
    _impl_class = _PackageCacheImpl

    def load_overload(self, sig, target_context):
        """The cached code for ``sig``, or None: Numba then compiles, which takes from seconds (a
        kernel) to minutes (a fused driver and what it calls: ~35 s for the moment's); a library
        call that waits that long says so on stderr, once per process, before the compiler runs."""
        data = super().load_overload(sig, target_context)
        if data is None and not _NOTICE["given"]:
            _NOTICE["given"] = True
            name = getattr(self._py_func, "__qualname__", "a kernel")
            sys.stderr.write(f"ipmc_asym: compiling the Numba kernels this call needs (first: {name}), once per "
                             f"install: ~20 s to a few minutes; later runs load them from {CACHE_DIR} "
                             "('ipmc-asym warmup' compiles all of them at once)\n")
            sys.stderr.flush()
        return data


def _cached(dispatcher):
    """``dispatcher`` with its on-disk cache in :data:`CACHE_DIR` (set per function)."""
    dispatcher._cache = _PackageFunctionCache(dispatcher.py_func)
    return dispatcher

prange = nb.prange

_FLAGS = dict(nopython=True, fastmath=False, nogil=True, error_model="numpy")


def jit(func=None, **kw):
    """``numba.njit`` with the project's flags (serial kernels)."""
    opts = {**_FLAGS, **kw}
    if func is None:
        return lambda f: _cached(nb.jit(f, **opts))
    return _cached(nb.jit(func, **opts))


def jit_parallel(func=None, **kw):
    """``numba.njit(parallel=True)`` with the project's flags: only for ``prange`` drivers."""
    opts = {**_FLAGS, "parallel": True, **kw}
    if func is None:
        return lambda f: _cached(nb.jit(f, **opts))
    return _cached(nb.jit(func, **opts))


# --------------------------------------------------------------------------------------
# Interpreted twins: the same source run by the Python interpreter
# --------------------------------------------------------------------------------------
#: twin of each jitted function (by id of its Python function) and twin globals of each module
_TWINS: dict = {}
_TWIN_GLOBALS: dict = {}
_PACKAGE = __name__.rsplit(".", 1)[0] + "."


def _is_jitted(obj) -> bool:
    return isinstance(obj, nb.core.dispatcher.Dispatcher)


class _TwinModule:
    """A module of this package seen from a twin: its jitted attributes are twins too."""

    def __init__(self, module):
        self._module = module

    def __getattr__(self, name):
        value = getattr(self._module, name)
        return interpreted(value) if _is_jitted(value) else value


def _fill_twin_globals(g: dict) -> None:
    """Replace, in a module's twin globals ``g``, jitted functions and package modules by twins."""
    for k, v in list(g.items()):
        if _is_jitted(v):
            g[k] = interpreted(v)
        elif isinstance(v, types.ModuleType) and v.__name__.startswith(_PACKAGE):
            g[k] = _TwinModule(v)


def interpreted(func):
    """The jitted ``func`` as plain Python: its own source, run by the interpreter, calling
    the twins of the jitted functions it calls (nothing is compiled or loaded from the cache).

    Why: loading one compiled driver from the cache costs a fresh process ~0.5 s (Numba's
    typing and target registries, and SciPy's BLAS that Numba's array library imports),
    ~1000x the interpreted cost of a few closed-form points.  Semantics differ from the
    compiled code only where that returns inf/NaN without complaint: the interpreter raises
    (``ZeroDivisionError``, ``OverflowError``, ``ValueError`` from ``math``, or
    ``FloatingPointError`` under ``np.errstate(all="raise")``), and the caller then uses the
    compiled function.  Not jitted: ``func`` itself.
    """
    if not _is_jitted(func):
        return func
    py = func.py_func
    twin = _TWINS.get(id(py))
    if twin is None:
        fresh = id(py.__globals__) not in _TWIN_GLOBALS
        g = _TWIN_GLOBALS.setdefault(id(py.__globals__), dict(py.__globals__))
        # a function compiled per integrand (a factory's closure) calls twins of its cells too
        cells = None if py.__closure__ is None else tuple(
            types.CellType(interpreted(c.cell_contents)) for c in py.__closure__)
        twin = _TWINS[id(py)] = types.FunctionType(py.__code__, g, py.__name__, py.__defaults__, cells)
        twin.__doc__ = py.__doc__
        if fresh:  # after registering the twin: the module's other functions may call it
            _fill_twin_globals(g)
    return twin
