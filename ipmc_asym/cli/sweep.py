"""``ipmc-asym sweep``: evaluate the strip on a grid of parameters (vectorised)."""

from __future__ import annotations

import sys
import time

from ..fileio import check_output_path
from ..fits import sweep_fits
from ..jsonio import dumps
from ..registry import fidelity_names, model_choices
from ..sweeps import parse_vary, rows_as_dicts, sweep, write_csv
from . import SUMMARIES
from .common import add_strip_options, material_from_args, strip_from_args


def register(sub):
    p = sub.add_parser("sweep", help=SUMMARIES["sweep"])
    p.add_argument("--vary", action="append", default=[], metavar="NAME=START:STOP:N[:log]",
                   help="length, width, thickness (TOTAL), voltage or modulus; repeat for a grid")
    add_strip_options(p)
    p.add_argument("--model", default="constant", choices=model_choices(), help="permittivity model (default constant)")
    p.add_argument("--fidelity", default="quadrature", choices=fidelity_names(),
                   help="rung of the fidelity ladder (default quadrature)")
    p.add_argument("--tol", type=float, default=None, help="tolerance of the 'small' beam regime (1%%)")
    p.add_argument("--out", default=None, help="CSV file (SI columns); default: stdout unless --json")
    p.add_argument("--json", action="store_true", help='print {"rows": [...], "fits": [...]}')
    p.add_argument("--no-progress", action="store_true")


def run(args) -> int:
    if not args.vary:
        raise ValueError("sweep needs at least one --vary NAME=START:STOP:N (e.g. length=1cm:4cm:16)")
    vary = {}
    for s in args.vary:
        k, v = parse_vary(s)
        if k in vary:
            raise ValueError(f"--vary {k} given twice")
        vary[k] = v
    if args.out:
        check_output_path(args.out, "file")
    base = strip_from_args(args)
    mat = material_from_args(args)
    t0 = time.perf_counter()
    arr = sweep(vary, args.model, args.fidelity, base, mat, args.tol,
                progress=False if args.no_progress else None)
    dt = time.perf_counter() - t0
    fits = sweep_fits(arr, list(vary)) if len(vary) == 1 else []
    if args.out:
        write_csv(arr, args.out)
        sys.stderr.write(f"sweep: {arr.size} rows in {dt:.3g} s -> {args.out}\n")
    if args.json:
        print(dumps({"rows": rows_as_dicts(arr), "fits": fits, "seconds": dt}, indent=1))
    elif not args.out:
        write_csv(arr, "-")
    if not args.json and fits:
        for f in fits:
            sys.stderr.write(
                f"fit [{f['model']}] |{f['quantity']}| ~ {f['prefactor']:.4g} * {f['variable']}^"
                f"{f['exponent']:.4g} (r={f['r']:.5f}, n={f['n']}, left out {f['n_left_out']})\n")
    return 0
