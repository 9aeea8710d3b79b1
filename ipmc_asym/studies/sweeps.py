"""Parameter sweeps on a grid (``ipmc-asym sweep``), vectorised end to end.

``sweep({"length": np.linspace(0.01, 0.04, 16)}, model="constant")`` returns a numpy
structured array with one row per grid point (and per model), SI columns::

    length width thickness voltage modulus  (inputs; width/thickness are TOTAL 2l / 2e)
    model fidelity I M_A theta w w_small F_block F_block_small regime B1 error valid

Each chunk of rows is one call of the vectorised forward model
:func:`ipmc_asym.forward.model.forward` (the moment integral once per distinct (thickness,
voltage) pair, then :func:`ipmc_asym.beam.statics.solve_beam` and the checks); nothing loops over
points in Python except the ``bvp`` fidelity.

CLI spec: ``--vary NAME=START:STOP:N`` (N points, linear) or ``NAME=START:STOP:N:log``;
NAME in length, width, thickness, voltage, modulus; units as in ``estimate``
(``1cm``, ``200um``, ``500mV``, ``130MPa``).  Several ``--vary`` make a grid.

Layer rule: stdlib + numpy at import.
"""

from __future__ import annotations

import contextvars
import functools
import io
import queue
import sys
import threading
from collections import deque
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from ipmc_asym.base import interrupt
from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.progress import progress as progress_bar
from ipmc_asym.base.registry import model_names
from ipmc_asym.base.settings import CHUNK_ROWS, MAX_ROWS
from ipmc_asym.base.units import SWEEP_VARIABLES as VARIABLES
from ipmc_asym.base.units import parse_vary, parse_vary_spec, vary_values
from ipmc_asym.forward.escalation import check_tol
from ipmc_asym.forward.estimate import SPREAD_KEYS
from ipmc_asym.forward.model import CHECKS, FREE_STRIP_KEYS, MECHANICAL_KEYS, WITHHOLD, forward
from ipmc_asym.integral.api import check_fidelity
from ipmc_asym.io.fileio import atomic_write
from ipmc_asym.io.textfmt import SHORTEST, format_table, shortest_text
from ipmc_asym.model.params import NAFION_LI, Material, Strip, check_voltages
from ipmc_asym.model.permittivity import get_model

__all__ = ["VARIABLES", "DTYPE", "LABELS", "CHECK_COLS", "SPREAD_COLS", "SPREAD_DTYPE", "parse_vary",
           "parse_vary_spec", "vary_values", "sweep", "iter_sweep",
           "prefetched", "count_rows",
           "withhold", "format_chunk", "warm_writer", "csv_header", "write_csv", "write_json"]


_FLOAT_COLS = ("length", "width", "thickness", "voltage", "modulus", "I", "M_A", "theta", "w", "w_small",
               "F_block", "F_block_small", "B1", "error", "max_strain")
#: per-row validity checks (columns ``check_<name>``); ``valid`` is their conjunction
CHECK_COLS = tuple(f"check_{c}" for c in CHECKS)
DTYPE = np.dtype([(c, "f8") for c in _FLOAT_COLS[:5]] + [("model", "U8"), ("fidelity", "U10"),
                 ("fidelity_used", "U10"), ("escalated", "?")]
                 + [(c, "f8") for c in _FLOAT_COLS[5:]] + [("regime", "U17")]
                 + [(c, "?") for c in CHECK_COLS] + [("valid", "?")])
#: column labels of the output files (CSV header, JSON keys) where the field name alone is
#: ambiguous: width and thickness are TOTAL (2l, 2e).  All columns are SI (m, V, Pa, N m, N, rad).
LABELS = {"width": "width_total_2l", "thickness": "thickness_total_2e"}
#: the free-strip and mechanical outputs (forward.model) that are columns here (no tip position)
_FREE = tuple(c for c in FREE_STRIP_KEYS if c in DTYPE.names)
_MECH = tuple(c for c in MECHANICAL_KEYS if c in DTYPE.names)
#: with ``spread=True``: per row, the range of each model-dependent output over the three
#: permittivity models of the paper's section 6 at the same grid point (the model-form spread of
#: ``estimate``, forward.estimate.SPREAD_KEYS), columns ``<name>_model_min`` / ``<name>_model_max``
SPREAD_COLS = tuple(f"{c}_model_{s}" for c in SPREAD_KEYS for s in ("min", "max"))
SPREAD_DTYPE = np.dtype(DTYPE.descr + [(c, "f8") for c in SPREAD_COLS])


def _models(model):
    if model == "all":
        return list(model_names())
    if isinstance(model, (list, tuple)):
        return list(model)
    return [model]


def _axes(vary: dict):
    for k in vary:
        if k not in VARIABLES:
            raise ValueError(f"vary: unknown variable {k!r}; use {', '.join(VARIABLES)}")
    axes = [np.atleast_1d(np.asarray(v, dtype=float)).ravel() for v in vary.values()]
    for k, a in zip(vary, axes):
        if a.size == 0:
            raise ValueError(f"vary: {k} has no values")
        if k == "voltage":
            check_voltages(a)
        elif not np.all(np.isfinite(a)) or np.any(a <= 0):
            raise ValueError(f"{k} must be finite and > 0")
    return axes


def count_rows(vary: dict, model="constant") -> int:
    """Rows a sweep would produce (grid points x models), without building anything."""
    n = 1
    for v in vary.values():
        n *= int(np.size(v))
    return n * len(_models(model))


def iter_sweep(vary: dict, model="constant", fidelity="quadrature", base: Strip | None = None,
               material: Material = NAFION_LI, tol=None, *, chunk_rows: int = CHUNK_ROWS,
               escalate: bool = True, progress=None, failures: list | None = None, spread: bool = False):
    """The sweep as a generator of structured-array chunks (dtype :data:`DTYPE`, or
    :data:`SPREAD_DTYPE` with ``spread``).

    Memory is ``O(chunk_rows)`` whatever the number of rows: each chunk's grid points are
    decoded from their flat index (``np.unravel_index``), never from a full meshgrid.  Rows
    come model by model, grid in C order (first ``vary`` key slowest).

    Parameters
    ----------
    vary, model, fidelity, base, material, tol : see :func:`sweep`
    chunk_rows : int
        Rows per chunk (default ``settings.CHUNK_ROWS``).
    escalate : bool
        Climb the fidelity ladder per point to the first valid rung (default).
    progress : tqdm-like, optional
        ``update(k)`` is called with the rows of each chunk computed.
    failures : list, optional
        Receives one line per chunk that has points with no valid rung (why).
    spread : bool
        Add the :data:`SPREAD_COLS`: each chunk's grid points are evaluated with all three
        permittivity models (three times the work per requested model).

    Yields
    ------
    numpy structured array
        Rows of :data:`DTYPE`.  Where no rung is valid the electrochemical and mechanical
        columns are NaN and ``check_electrochemistry``/``valid`` False (other rows kept);
        the beam checks are columns too (``regime``, ``max_strain``).
    """
    check_fidelity(fidelity)
    base = Strip() if base is None else base
    axes = _axes(vary)
    names = list(vary)
    shape = tuple(a.size for a in axes)
    n = int(np.prod(shape)) if axes else 1
    const = {"length": base.length, "width": base.width, "thickness": base.thickness,
             "voltage": base.voltage, "modulus": material.E}
    chunk_rows = max(1, int(chunk_rows))
    for m in _models(model):
        perm = get_model(m)
        for lo in range(0, n, chunk_rows):
            hi = min(n, lo + chunk_rows)
            k = hi - lo
            idx = np.unravel_index(np.arange(lo, hi), shape) if axes else ()
            cols = {}
            for c in VARIABLES:
                if c in names:
                    j = names.index(c)
                    cols[c] = axes[j][idx[j]]
                else:
                    cols[c] = np.full(k, float(const[c]))
            code = _pair_code(names, axes, idx, k)
            arr = _chunk(cols, perm, fidelity, material, tol, escalate, failures, code)
            yield _with_spread(arr, cols, fidelity, material, tol, escalate, code) if spread else arr
            if progress is not None:
                progress.update(k)


def prefetched(chunks, depth: int = 1, threads: int | None = None):
    """``chunks`` computed one step ahead in a background thread.

    The consumer (formatting and writing a chunk, compiled and without the GIL) then runs on
    one core while the next chunk is computed on the other; memory grows by ``depth`` chunks.
    An exception in the producer is raised in the consumer, at the chunk where it happened.
    The producer starts at once.  While it runs, the caller must not launch parallel kernels
    itself (Numba's workqueue layer is not re-entrant): the consumer's kernels (the text
    formatter, run by a few plain threads) are serial ones.
    ``threads``: Numba threads of the producer's kernels (e.g. 1: one core computes while the
    consumer uses the other).
    """

    q: queue.Queue = queue.Queue(maxsize=max(1, int(depth)))
    done = object()
    stop = threading.Event()

    def produce():
        try:
            if threads is not None:  # Numba's thread count is per calling thread

                numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
            for c in chunks:
                while not stop.is_set():
                    try:
                        q.put((c, None), timeout=0.1)
                        break
                    except queue.Full:
                        continue
                if stop.is_set():
                    return
            q.put((done, None))
        except BaseException as exc:  # noqa: BLE001 -- re-raised in the consumer
            q.put((done, exc))

    # the caller's context (NumPy's errstate lives in a context variable)
    ctx = contextvars.copy_context()
    t = threading.Thread(target=ctx.run, args=(produce,), name="ipmc-sweep-producer", daemon=True)
    t.start()  # now, not at the first next(): the caller may prepare its writer meanwhile

    def drain():
        try:
            while True:
                c, exc = q.get()
                if c is done:
                    if exc is not None:
                        raise exc
                    return
                yield c
        finally:
            stop.set()

    return drain()


def _pair_code(names, axes, idx, k):
    """Integer code of each row's (thickness, voltage) grid pair: equal codes, equal ``I``."""
    code = np.zeros(k, dtype=np.int64)
    for c in ("thickness", "voltage"):
        if c in names:
            j = names.index(c)
            code = code * axes[j].size + idx[j]
    return code


def _chunk(cols, perm, fidelity, material, tol, escalate, failures, code):
    """One chunk of rows (dtype :data:`DTYPE`) from :func:`ipmc_asym.forward.model.forward`;
    ``code``: the rows' (thickness, voltage) grid codes (:func:`_pair_code`), so that ``I`` is
    evaluated once per distinct pair."""
    r = forward(cols["length"], cols["width"], cols["thickness"], cols["voltage"], modulus=cols["modulus"],
                material=material, model=perm, fidelity=fidelity, tol=tol, escalate=escalate, pair_code=code)
    arr = np.empty(cols["length"].size, dtype=DTYPE)
    for c in VARIABLES:
        arr[c] = cols[c]
    arr["model"] = perm.name
    arr["fidelity"] = fidelity
    for c in ("fidelity_used", "escalated", "I", "M_A") + _MECH + ("regime", "max_strain", "B1", "error"):
        arr[c] = getattr(r, c)
    for c in CHECK_COLS:
        arr[c] = getattr(r, c[len("check_"):])
    arr["valid"] = r.valid
    if failures is not None and not bool(np.all(r.moment_valid)):
        failures.append(r.moment_message)
    return arr


def _with_spread(arr, cols, fidelity, material, tol, escalate, code):
    """``arr`` with the :data:`SPREAD_COLS` of its grid points: signed min and max of each of
    SPREAD_KEYS over the three permittivity models, of the values the output shows (withheld
    ones, NaN, left out as in ``estimate``'s model_spread; NaN where every model withholds)."""
    runs = [withhold(arr) if m == arr["model"][0] else
            withhold(_chunk(cols, get_model(m), fidelity, material, tol, escalate, None, code), copy=False)
            for m in model_names()]
    out = np.empty(arr.size, SPREAD_DTYPE)
    for c in DTYPE.names:
        out[c] = arr[c]
    for c in SPREAD_KEYS:
        vals = [r[c] for r in runs]
        out[f"{c}_model_min"] = functools.reduce(np.fmin, vals)
        out[f"{c}_model_max"] = functools.reduce(np.fmax, vals)
    return out


def sweep(vary: dict, model="constant", fidelity="quadrature", base: Strip | None = None,
          material: Material = NAFION_LI, tol=None, progress: bool | None = None, *,
          escalate: bool = True, max_rows: int | None = None, spread: bool = False) -> np.ndarray:
    """Evaluate the strip on the grid spanned by ``vary`` (name -> 1-D values, SI), in memory.

    Parameters
    ----------
    vary : dict
        Keys among :data:`VARIABLES`; each value a 1-D array.  The grid is their outer
        product (first key slowest).  Variables not in ``vary`` take ``base`` / ``material``.
        ``thickness`` and ``width`` are TOTAL (2e, 2l).
    model : str, list of str or "all"
    fidelity : str
        Cheapest rung tried; escalated per point to the first valid rung (``fidelity_used``,
        ``escalated`` columns) unless ``escalate=False``.
    base : Strip, default nominal
    material : Material (``modulus`` overrides ``material.E``)
    tol : float, optional   accuracy required of ``I`` and tolerance of the "small" beam regime
    max_rows : int, optional
        Refuse (one-line ``ValueError``) above this many rows (default ``settings.MAX_ROWS``);
        for more, stream with :func:`iter_sweep`.
    spread : bool
        Add, per row, the range of each model-dependent output over the three permittivity
        models at that grid point (:data:`SPREAD_COLS`; the model-form spread).

    Returns
    -------
    numpy structured array (dtype :data:`DTYPE`), one row per grid point and model.
    Rows where a check failed keep their inputs and say which check (``check_*``,
    ``valid``); an output :func:`ipmc_asym.evaluate` gives as None is NaN here (:func:`withhold`:
    ``I`` and the mechanics where no rung is valid, the tip position ``w``, ``w_small``,
    ``x_tip``, ``y_tip`` past a full turn, ``F_block`` where its large-displacement branch is not
    tracked).
    """
    check_fidelity(fidelity)
    tol = check_tol(tol)
    _axes(vary)
    n = count_rows(vary, model)
    limit = MAX_ROWS if max_rows is None else int(max_rows)
    if n > limit:
        raise ValueError(f"sweep of {n} rows exceeds max_rows {limit} (settings.MAX_ROWS); "
                         "stream it with iter_sweep or ipmc-asym sweep --out")
    show = (n > 20000 or fidelity == "bvp") if progress is None else progress
    bar = progress_bar(n, "sweep", enabled=show, unit="row")
    try:
        parts = list(iter_sweep(vary, model, fidelity, base, material, tol, escalate=escalate, progress=bar,
                                spread=spread))
    finally:
        bar.close()
    # the outputs withheld where evaluate, scene and the CLI withhold them (NaN here, None there)
    return withhold(np.concatenate(parts), copy=False) if parts else np.empty(0, SPREAD_DTYPE if spread else DTYPE)


def withhold(arr: np.ndarray, copy: bool = True) -> np.ndarray:
    """``arr`` (a copy unless ``copy=False``) with the withheld outputs set to NaN (what the CLI prints).

    The rule of :data:`ipmc_asym.forward.model.WITHHOLD`: everything computed where no rung is
    valid (already NaN); the free strip's tip position past a full turn.  A failed model
    assumption withholds nothing (its ``check_*`` column says so).
    """
    out = arr.copy() if copy else arr
    # rows with no valid rung are NaN already
    for regime, keys in WITHHOLD[1:]:
        bad = out["regime"] == regime
        if bad.any():  # only the rows concerned are written (strided fields are slow to sweep)
            idx = np.flatnonzero(bad)
            for c in keys:
                if c in out.dtype.names:
                    out[c][idx] = np.nan
    return out


def _row_format(names, sep, json_keys=False, dtype=SPREAD_DTYPE):
    parts = []
    for c in names:
        kind = dtype[c].kind
        f = ("%s" if json_keys else "%.10g") if kind == "f" else "%s"  # JSON: shortest_text strings
        if json_keys:
            key = LABELS.get(c, c)
            f = f'"{key}": ' + (f if kind in "fb?" else f'"{f}"')
        parts.append(f)
    return sep.join(parts)


#: rows formatted at once: the per-row Python objects of ``tolist`` (~1 kB/row) stay ~30 MB
FORMAT_ROWS = 2**15


def _pieces(arr):
    for lo in range(0, arr.size, FORMAT_ROWS):
        yield arr[lo:lo + FORMAT_ROWS]


def format_chunk(arr: np.ndarray, kind: str = "csv") -> str:
    """Text of one chunk (no header), one line per row: floats ``%.10g`` (CSV) or the shortest
    text that reads back as the same double (JSON, :func:`ipmc_asym.io.textfmt.shortest_text`),
    non-finite floats an empty CSV field / JSON ``null``, booleans
    ``True``/``False`` (CSV) or ``true``/``false`` (JSON).

    Written by the compiled formatter (:mod:`ipmc_asym.io.textfmt`), byte for byte the text of
    one Python ``%`` per row (:func:`_format_chunk_python`, tested equal), which remains the
    fallback where a rounding is too close for the compiled one to call.
    """
    text = _format_chunk_compiled(arr, kind)
    return _format_chunk_python(arr, kind) if text is None else text


def _format_chunk_bytes(arr: np.ndarray, kind: str) -> bytes:
    """:func:`format_chunk` as ASCII bytes (what the writers write)."""
    text = _format_chunk_compiled(arr, kind, as_bytes=True)
    return _format_chunk_python(arr, kind).encode("ascii") if text is None else text


def _format_chunk_compiled(arr: np.ndarray, kind: str, as_bytes: bool = False):
    names = arr.dtype.names
    csv = kind == "csv"
    cols = []
    for c in names:
        a = arr[c]
        if a.dtype.kind == "f":
            cols.append(("f", a))
        elif a.dtype.kind == "b":
            cols.append(("s", (a.view(np.uint8), ["False", "True"] if csv else ["false", "true"])))
        else:
            cols.append(("u", a))
    if csv:
        return format_table(cols, [""] + [","] * (len(names) - 1), 10, nonfinite="", row_sep="\n",
                            as_bytes=as_bytes)
    keys = [f'"{LABELS.get(c, c)}": ' for c in names]
    return format_table(cols, keys[:1] + [", " + k for k in keys[1:]], SHORTEST, nonfinite="null", row_start="{",
                        row_end="}", row_sep=",\n", quote_strings=True, as_bytes=as_bytes)


def _format_chunk_python(arr: np.ndarray, kind: str = "csv") -> str:
    """:func:`format_chunk` with one ``%`` format per row (``np.savetxt`` style): the reference
    the compiled formatter is tested against, and its fallback."""
    names = arr.dtype.names
    cols = []
    for c in names:
        a = arr[c]
        if a.dtype.kind == "b":
            cols.append(a.tolist() if kind == "csv" else np.where(a, "true", "false").tolist())
        elif a.dtype.kind == "f" and kind != "csv":
            cols.append([shortest_text(v) for v in a.tolist()])
        else:
            cols.append(a.tolist())
    if kind == "csv":
        fmt = _row_format(names, ",")
        text = "\n".join(map(fmt.__mod__, zip(*cols)))
        # no string column can contain these tokens (model, fidelity, regime vocabularies)
        return text.replace("-inf", "").replace("inf", "").replace("nan", "")
    fmt = "{" + _row_format(names, ", ", json_keys=True) + "}"
    text = ",\n".join(map(fmt.__mod__, zip(*cols)))
    return text.replace("-inf", "null").replace("inf", "null").replace("nan", "null")


def warm_writer(kind: str = "csv") -> None:
    """Load the compiled formatter (from Numba's cache) now, e.g. while a producer computes."""
    format_chunk(np.zeros(1, DTYPE), kind)


def csv_header(names=DTYPE.names) -> str:
    return ",".join(LABELS.get(c, c) for c in names)


def _texts(chunks, kind: str, workers: int):
    """``(ASCII bytes, rows)`` of each piece of each chunk, in order.  With ``workers`` > 1 the pieces
    are formatted by that many threads at once (the compiled formatter releases the GIL; no
    parallel kernel is launched), at most ``2 * workers`` pieces in flight (bounded memory)."""
    if workers <= 1:
        for c in chunks:
            for piece in _pieces(c):
                interrupt.check()  # between pieces: a signal swallowed in compiled code stops the writer
                yield _format_chunk_bytes(piece, kind), piece.size
        return

    pending: deque = deque()
    with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="ipmc-format") as pool:
        for c in chunks:
            for piece in _pieces(c):
                pending.append((pool.submit(_format_chunk_bytes, piece, kind), piece.size))
                while len(pending) > 2 * workers:
                    interrupt.check()
                    f, k = pending.popleft()
                    yield f.result(), k
        while pending:
            f, k = pending.popleft()
            yield f.result(), k


def _byte_writer(fh):
    """A function writing ASCII bytes to ``fh``: its binary buffer where it has one (after
    flushing its text layer), else the decoded text (e.g. a ``StringIO``)."""
    buf = getattr(fh, "buffer", None)
    if buf is not None:
        fh.flush()
        return buf.write
    if isinstance(fh, (io.RawIOBase, io.BufferedIOBase)):
        return fh.write
    return lambda b: fh.write(b.decode("utf-8"))


def write_csv(arr, path, progress=None, workers: int = 1, comments=(), names=DTYPE.names):
    """CSV with SI columns (header labels say units and TOTAL thickness/width).

    ``arr`` is a structured array or an iterable of chunks (streamed, memory independent of
    the number of rows); ``path`` ``None``/``"-"`` is stdout, otherwise written atomically.
    ``workers``: threads formatting pieces at once (the text is the same).  ``comments``:
    lines written first, each after ``# `` (e.g. the material set and its sources).  ``names``:
    the columns of the header (the chunks' fields; :data:`SPREAD_DTYPE` ``.names`` with the
    spread).  Returns the number of rows written.
    """
    chunks = [arr] if isinstance(arr, np.ndarray) else arr

    def rows(fh):
        put = _byte_writer(fh)
        for c in comments:
            put(("# " + " ".join(str(c).split()) + "\n").encode("utf-8"))
        put((csv_header(names) + "\n").encode("ascii"))
        n = 0
        for text, k in _texts(chunks, "csv", int(workers)):
            put(text)
            put(b"\n")
            n += k
            if progress is not None:
                progress.update(k)
        return n

    if path in (None, "-"):
        return rows(sys.stdout)
    with atomic_write(path) as fh:
        return rows(fh)


def write_json(chunks, fh, extra_before: dict | None = None, extra_after=None, workers: int = 1):
    """Stream ``{"rows": [...], ...}`` chunk by chunk; ``extra_after`` is a callable giving
    the keys written after the rows (e.g. fits, timing); ``workers`` as in :func:`write_csv`.
    Returns the number of rows."""

    put = _byte_writer(fh)

    def say(text):  # keys and metadata: UTF-8 (the rows are ASCII)
        put(text.encode("utf-8"))

    say("{\n")
    for k, v in (extra_before or {}).items():
        say(f"{dumps(k)}: {dumps(v, indent=None)},\n")
    say('"rows": [\n')
    n = 0
    first = True
    for text, k in _texts([chunks] if isinstance(chunks, np.ndarray) else chunks, "json", int(workers)):
        if not first:
            put(b",\n")
        put(text)
        first = False
        n += k
    say("\n]")
    for k, v in (extra_after() if extra_after else {}).items():
        say(f",\n{dumps(k)}: {dumps(v, indent=1)}")
    say("\n}\n")
    return n
