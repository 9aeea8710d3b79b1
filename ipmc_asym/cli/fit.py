"""``ipmc-asym fit``: calibrate free parameters on measured deflection / blocking force."""

from __future__ import annotations

import sys

from ipmc_asym.base.registry import fidelity_names, model_names
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_size_option,
    add_strip_options,
    count_type,
    fmt_num,
    material_from_args,
    model_help,
    seed_type,
    strip_from_args,
)
from ipmc_asym.io.fileio import FIGURE_FORMATS, check_output_path
from ipmc_asym.io.jsonio import dumps
from ipmc_asym.parallel.executors import check_scheduler
from ipmc_asym.studies.calibrate import FREE_PARAMETERS, MAX_DATA_ROWS, fit, parse_free, read_data

#: extra starts of a multistart (each a full least-squares solve); settable with --max-multistart
MAX_MULTISTART = 1000


def register(sub):
    p = sub.add_parser("fit", help=SUMMARIES["fit"],
                       description="Weighted least squares of DATA.csv (columns length, width, thickness "
                                   "(TOTAL 2e), voltage; measured deflection, blocking_force; optional "
                                   "sigma_<measured>), 95 % profile-likelihood intervals, identifiability.")
    p.add_argument("data", metavar="DATA.csv", help="measurements (header row; SI or values with units)")
    p.add_argument("--free", required=True, metavar="NAME[,NAME...]",
                   help=f"free parameters among {', '.join(FREE_PARAMETERS)}; optional bounds NAME=LO:HI")
    p.add_argument("--model", default="constant", choices=list(model_names()), help=model_help("constant"))
    p.add_argument("--fidelity", default=None, choices=list(fidelity_names()),
                   help="force a fidelity (default: cheapest with error < 1/10 of the data's)")
    add_strip_options(p)
    add_size_option(p, "--multistart", default=0, maximum=MAX_MULTISTART, minimum=0, metavar="N",
                    help="N extra starts, log-uniform in the bounds; the best is kept")
    p.add_argument("--max-rows", type=count_type("--max-rows"), default=MAX_DATA_ROWS,
                   help=f"refuse a DATA.csv of more data rows than this (default {MAX_DATA_ROWS:.0e})")
    p.add_argument("--seed", type=seed_type, default=0, help="seed of the multistart starts (integer >= 0, default 0)")
    p.add_argument("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
                   help="run the multistart on dask.distributed (default: serial)")
    p.add_argument("--plot", default=None, metavar="F.png",
                   help=f"data vs fitted model with residuals ({', '.join(FIGURE_FORMATS)})")
    p.add_argument("--no-progress", action="store_true", help="no progress bar (model evaluations) on stderr")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    # every option checked before any work (the fit of a long file takes seconds to minutes)
    if args.plot:
        check_output_path(args.plot, "file", "--plot", formats=FIGURE_FORMATS)
    if args.scheduler is not None:
        check_scheduler(args.scheduler)
    parse_free(args.free)
    material = material_from_args(args)
    data = read_data(args.data, strip_from_args(args), max_rows=args.max_rows)
    res = fit(data, args.free, model=args.model, material=material, fidelity=args.fidelity,
              multistart=args.multistart, seed=args.seed, scheduler=args.scheduler,
              progress=False if args.no_progress else None)
    if args.plot:
        from ipmc_asym.plotting.calibrate import plot_fit  # deferred: matplotlib (start-up)

        plot_fit(res, args.plot)
    if args.json:
        print(dumps(res.as_dict(), indent=2))
    else:
        if res.chi2_red is not None:
            gof = f"chi2_red = {res.chi2_red:.4g} (with the given sigma)"
        else:
            gof = (f"noise scale s = {res.noise_scale:.3g} (relative, estimated from the residuals; no sigma_ "
                   f"columns, so no chi2 goodness of fit)")
        print(f"fit of {data.source}: {res.n_points} measured values, model {res.model}, fidelity {res.fidelity}, "
              f"{gof}")
        print(f"{'parameter':10s} {'value':>12s} {'stderr':>10s} {'95% interval (profile)':>28s}  unit")
        for n, p in res.parameters.items():
            unit = FREE_PARAMETERS[n][0]
            lo, hi = p["ci95"]
            se = fmt_num(p["stderr"], "10.3g") if p["stderr"] is not None else f"{'-':>10s}"
            if p["identifiable"]:
                ci = f"[{lo:.5g}, {hi:.5g}]"
            else:
                side = " ".join(x for x in ((f">= {lo:.4g}" if lo is not None else ""),
                                            (f"<= {hi:.4g}" if hi is not None else "")) if x)
                ci = ("AT THE BOUND " if p.get("status") == "at_bound" else "NOT IDENTIFIABLE ") + side
            print(f"{n:10s} {p['value']:12.6g} {se} {ci:>28s}  {unit}")
        names = list(res.parameters)
        if len(names) > 1:
            print("correlation: " + "; ".join(
                f"{names[a]}/{names[b]} = {res.correlation[a][b]:.3f}" if res.correlation[a][b] is not None
                else f"{names[a]}/{names[b]} = n/a" for a in range(len(names)) for b in range(a + 1, len(names))))
        for n, p in res.parameters.items():
            if p.get("note"):
                print(f"note: {n}: {p['note']}")
        if args.plot:
            print(f"figure: {args.plot}")
    sys.stdout.flush()  # the stdout lines before the stderr ones (never interleaved mid-line)
    for w in res.warnings:
        sys.stderr.write(f"fit: warning: {w}\n")
    sys.stderr.write(f"fit: {res.message}\n")
    return 0
