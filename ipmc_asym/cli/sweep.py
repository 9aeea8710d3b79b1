"""``ipmc-asym sweep``: evaluate the strip on a grid of parameters (vectorised, streamed)."""

from __future__ import annotations

import functools
import math
import sys
import time
import warnings

import numpy as np

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.progress import progress
from ipmc_asym.base.registry import fidelity_names, model_choices, model_names
from ipmc_asym.base.settings import MAX_ROWS, MAX_ROWS_CEILING
from ipmc_asym.base.units import parse_vary_spec, vary_values
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_output_option,
    add_strip_options,
    cap_type,
    first_run_notice,
    model_help,
    strip_and_material,
    tol_type,
    warn,
)
from ipmc_asym.forward.model import ASSUMPTION_CHECKS, ASSUMPTION_LIMITS
from ipmc_asym.io.datasets import sweep_dataset, write_netcdf
from ipmc_asym.io.fileio import atomic_write
from ipmc_asym.model.limits import value_warning
from ipmc_asym.model.materials import material_comments
from ipmc_asym.parallel.executors import check_scheduler
from ipmc_asym.studies.fits import axis_fits
from ipmc_asym.studies.sweep_chunks import sweep_chunked
from ipmc_asym.studies.sweeps import DTYPE, SPREAD_DTYPE, iter_sweep, prefetched, warm_writer, withhold, write_csv, write_json

#: extensions of --out (the format follows the extension)
OUT_FORMATS = (".csv", ".json", ".nc")
#: most rows of a sweep held in memory (--out F.nc, a NetCDF dataset written at once, and
#: --scheduler, whose chunks come back as arrays): ~630 bytes a row at the peak (tracemalloc,
#: tests/cli/test_sweep_memory.py), so under 1 GB; a CSV or JSON --out is streamed (no cap but
#: --max-rows)
MAX_MEMORY_ROWS = 10**6


def register(sub):
    p = sub.add_parser("sweep", help=SUMMARIES["sweep"])
    p.add_argument("--vary", action="append", default=[], metavar="NAME=START:STOP:N[:log]",
                   help="length, width (TOTAL 2l), thickness (TOTAL 2e), voltage or modulus, with units "
                        "(e.g. length=1cm:4cm:16, thickness=10um:1mm:20:log); repeat for a grid")
    add_strip_options(p)
    p.add_argument("--model", default="constant", choices=model_choices(),
                   help=model_help("constant", all_allowed=True))
    p.add_argument("--fidelity", default="quadrature", choices=fidelity_names(),
                   help="cheapest rung tried per point (default quadrature); escalated where not valid "
                        "(fidelity_used / escalated columns)")
    p.add_argument("--no-escalate", action="store_true",
                   help="use --fidelity only; rows where it is not valid are marked and left empty")
    p.add_argument("--tol", type=tol_type, default=None,
                   help="relative accuracy required of I, and tolerance of the 'small' beam regime "
                        "(e.g. 1e-3 or 0.1%%; default 1%%)")
    p.add_argument("--max-rows", type=cap_type("--max-rows", MAX_ROWS_CEILING), default=MAX_ROWS,
                   help=f"refuse a sweep of more rows than this (default {MAX_ROWS:.0e}, settings.MAX_ROWS)")
    add_output_option(p, "--out", formats=OUT_FORMATS, default=None,
                   help="output file, written in chunks and atomically; the format follows the extension: .csv "
                        "(SI columns), .json, or .nc for a labelled NetCDF dataset (xarray; held in memory: at most "
                        f"{MAX_MEMORY_ROWS:g} rows); "
                        "default: CSV on stdout")
    p.add_argument("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
                   help="run the sweep's chunks on dask.distributed (results identical to the serial run; "
                        "held in memory)")
    p.add_argument("--json", action="store_true",
                   help='JSON {"rows": [...], "fits": [...]} on stdout (with --out F.csv: a summary only)')
    p.add_argument("--spread", action="store_true",
                   help="add per row the range of M_A, theta, w, w_small, F_block, F_block_small over the three "
                        "permittivity models at that point (columns <name>_model_min, <name>_model_max: the "
                        "model-form spread beside the numerical error column; three times the work)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")


#: threads formatting the output text while the producer computes (the text is the same)
FORMAT_WORKERS = 2


def _fit_line(f) -> str:
    var = "total thickness 2e" if f["variable"] == "thickness" else f["variable"]
    head = f"fit [{f['model']}] |{f['quantity']}| vs {var}"
    thr = f" (through {', '.join(f'{k}={v:g}' for k, v in f['through'].items())})" if "through" in f else ""
    if not (math.isfinite(f["exponent"]) and math.isfinite(f["prefactor"])):
        return f"{head}: no fit: {f.get('note', 'fewer than 2 usable points')}{thr}"
    if not math.isfinite(f["r"]):
        return (f"{head}: constant over the range ({f['prefactor']:.4g}): no power law to fit, exponent 0"
                f"{thr}")
    if f["n"] == 2:
        return (f"{head} ~ {f['prefactor']:.4g} * {f['variable']}^{f['exponent']:.4g} "
                f"(n=2, left out {f['n_left_out']}: {f['note']}){thr}")
    return (f"{head} ~ {f['prefactor']:.4g} * {f['variable']}^{f['exponent']:.4g} "
            f"(r={f['r']:.5f}, n={f['n']}, left out {f['n_left_out']}){thr}")


def run(args) -> int:
    if not args.vary:
        raise ValueError("sweep needs at least one --vary NAME=START:STOP:N (e.g. length=1cm:4cm:16)")
    specs = {}
    for s in args.vary:
        spec = parse_vary_spec(s)
        if spec[0] in specs:
            raise ValueError(f"--vary {spec[0]} given twice")
        specs[spec[0]] = spec
    # refuse before building anything (a 10^8-point axis alone would take 800 MB)
    n = (len(model_names()) if args.model == "all" else 1) * math.prod(sp[3] for sp in specs.values())
    if n > args.max_rows:
        raise ValueError(f"the sweep has {n:.3g} rows, more than --max-rows {args.max_rows:g}; "
                         "narrow it or raise --max-rows")
    to_nc = bool(args.out) and args.out.lower().endswith(".nc")
    if (to_nc or args.scheduler is not None) and n > MAX_MEMORY_ROWS:
        what = "--out F.nc writes its dataset at once" if to_nc else "--scheduler returns its chunks as arrays"
        raise ValueError(f"the sweep has {n:.3g} rows; {what}, held in memory: at most {MAX_MEMORY_ROWS:g} rows "
                         "(< 1 GB); narrow it, or write --out F.csv / F.json (streamed)")
    if args.spread and (to_nc or args.scheduler is not None):
        raise ValueError("--spread: written to CSV or JSON only (stdout or --out F.csv / F.json), "
                         "not with --out F.nc or --scheduler")
    # each axis' ends held to the plausible ranges, as --thickness is (a bare 200 is 200 m): one line an axis
    for text in args.vary:
        name, rng = (x.strip() for x in text.split("=", 1))
        for end, v in zip(rng.split(":")[:2], specs[name][1:3]):
            line = value_warning(name, end.strip(), v, f"--vary {name}")
            if line:
                warn(line)
                break
    vary = {k: vary_values(*sp[1:]) for k, sp in specs.items()}
    # --out: its path and format checked before any work with every output (add_output_option)
    if args.scheduler is not None:
        check_scheduler(args.scheduler)
    first_run_notice()

    base, mat, _ = strip_and_material(args)
    t0 = time.perf_counter()
    failures: list = []
    outside = dict.fromkeys(ASSUMPTION_CHECKS, 0)

    def counted(c):  # rows outside each model assumption (kept and flagged), for one summary line each
        for k in outside:
            outside[k] += int(np.count_nonzero(~c["check_" + k] & c["check_electrochemistry"]))
        return c

    bar = progress(n, "sweep", enabled=False if args.no_progress else None, unit="row")
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        # no NumPy RuntimeWarning with internal paths: non-finite results are columns/notes
        warnings.simplefilter("ignore", RuntimeWarning)
        if args.scheduler is not None or to_nc:
            # the whole grid in memory: a NetCDF dataset is written at once, and distributed
            # chunks come back as arrays (refused above --max-rows like every sweep)

            arr = sweep_chunked(vary, args.scheduler, model=args.model, fidelity=args.fidelity, base=base,
                                material=mat, tol=args.tol, escalate=not args.no_escalate)
            bar.update(arr.size)
            bad = ~arr["check_electrochemistry"]
            if np.any(bad):
                failures.append(f"{int(bad.sum())} row(s) with no valid rung of the fidelity ladder")
            chunks = [counted(withhold(arr, copy=False))]
        else:
            # computed one chunk ahead of the formatting and writing: one core each
            chunks = prefetched((counted(withhold(c, copy=False)) for c in iter_sweep(
                vary, args.model, args.fidelity, base, mat, args.tol, escalate=not args.no_escalate,
                progress=bar, failures=failures, spread=args.spread)), threads=1)
            # meanwhile, the formatter loads from the cache (serial code: no second parallel
            # launch); CSV and JSON share the one compiled kernel
            warm_writer()
        try:
            # the fits after the rows: their (small) sweeps would otherwise run while the
            # producer thread is computing chunks, two parallel kernels at once
            @functools.cache
            def fits_and_notes():
                return axis_fits(vary, args.model, args.fidelity, base, mat, args.tol, escalate=not args.no_escalate)

            def tail():
                fits, notes = fits_and_notes()
                return {"fits": fits, "fit_notes": notes, "seconds": time.perf_counter() - t0}

            names = (SPREAD_DTYPE if args.spread else DTYPE).names
            to_json_file = bool(args.out) and args.out.lower().endswith(".json")
            head = {"n_rows": n, "material": mat.name, "material_sources": list(mat.sources)}
            if to_nc:

                write_netcdf(sweep_dataset(chunks[0], vary, base=base, material=mat), args.out)
                rows = chunks[0].size
            elif args.out and to_json_file:
                with atomic_write(args.out) as fh:
                    rows = write_json(chunks, fh, head, tail, workers=FORMAT_WORKERS)
            elif args.out:
                rows = write_csv(chunks, args.out, workers=FORMAT_WORKERS, comments=material_comments(mat),
                                 names=names)
            elif args.json:
                rows = write_json(chunks, sys.stdout, head, tail)
            else:
                rows = write_csv(chunks, "-", names=names)
        finally:
            bar.close()
        fits, notes = fits_and_notes()
    dt = time.perf_counter() - t0
    if args.out:
        sys.stderr.write(f"sweep: {rows} rows in {dt:.3g} s -> {args.out}\n")
        if args.json and not to_json_file:
            print(dumps({"out": args.out, "n_rows": rows, "fits": fits, "fit_notes": notes, "seconds": dt},
                        indent=1))
    for k, cnt in outside.items():
        if cnt:
            sys.stderr.write(f"sweep: warning: {cnt} row(s) outside the model assumption {ASSUMPTION_LIMITS[k]}; "
                             f"numbers kept, check_{k} = false\n")
    if failures:
        sys.stderr.write(f"sweep: rows with no valid fidelity are kept with valid=False and empty "
                         f"results; first: {failures[0]}\n")
    if not args.json:
        for f in fits:
            sys.stderr.write(_fit_line(f) + "\n")
        for note in notes:
            sys.stderr.write(note + "\n")
    return 0
