"""``ipmc-asym fit``: calibrate free parameters on measured deflection / blocking force."""

from __future__ import annotations

import sys

from ipmc_asym.base.registry import fidelity_names, model_names
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import add_strip_options, count_type, material_from_args, strip_from_args
from ipmc_asym.io.fileio import check_output_path
from ipmc_asym.io.jsonio import dumps
from ipmc_asym.parallel.executors import check_scheduler
from ipmc_asym.studies.calibrate import FREE_PARAMETERS, fit, read_data


def register(sub):
    p = sub.add_parser("fit", help=SUMMARIES["fit"],
                       description="Weighted least squares of DATA.csv (columns length, width, thickness "
                                   "(TOTAL 2e), voltage; measured deflection, blocking_force; optional "
                                   "sigma_<measured>), 95 %% profile-likelihood intervals, identifiability.")
    p.add_argument("data", metavar="DATA.csv", help="measurements (header row; SI or values with units)")
    p.add_argument("--free", required=True, metavar="NAME[,NAME...]",
                   help=f"free parameters among {', '.join(FREE_PARAMETERS)}; optional bounds NAME=LO:HI")
    p.add_argument("--model", default="constant", choices=list(model_names()), help="permittivity model")
    p.add_argument("--fidelity", default=None, choices=list(fidelity_names()),
                   help="force a fidelity (default: cheapest with error < 1/10 of the data's)")
    add_strip_options(p)
    p.add_argument("--multistart", type=count_type("--multistart", 0), default=0, metavar="N",
                   help="N extra starts, log-uniform in the bounds; the best is kept")
    p.add_argument("--seed", type=int, default=0, help="seed of the multistart starts")
    p.add_argument("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
                   help="run the multistart on dask.distributed (default: serial)")
    p.add_argument("--plot", default=None, metavar="F.png", help="data vs fitted model with residuals")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    if args.plot:
        check_output_path(args.plot, "file", "--plot")
    if args.scheduler is not None:

        check_scheduler(args.scheduler)
    data = read_data(args.data, strip_from_args(args))
    res = fit(data, args.free, model=args.model, material=material_from_args(args), fidelity=args.fidelity,
              multistart=args.multistart, seed=args.seed, scheduler=args.scheduler)
    if args.plot:
        from ipmc_asym.plotting.calibrate import plot_fit  # deferred: matplotlib (start-up)

        plot_fit(res, args.plot)
    if args.json:
        print(dumps(res.as_dict(), indent=2))
    else:
        print(f"fit of {data.source}: {res.n_points} measured values, model {res.model}, fidelity {res.fidelity}, "
              f"chi2_red = {res.chi2_red:.4g}")
        print(f"{'parameter':10s} {'value':>12s} {'stderr':>10s} {'95% interval (profile)':>28s}  unit")
        for n, p in res.parameters.items():
            unit = FREE_PARAMETERS[n][0]
            if p["identifiable"]:
                ci = f"[{p['ci95'][0]:.5g}, {p['ci95'][1]:.5g}]"
                print(f"{n:10s} {p['value']:12.6g} {p['stderr']:10.3g} {ci:>28s}  {unit}")
            else:
                lo, hi = p["ci95"]
                side = (f">= {lo:.4g}" if lo is not None else "") + (f"<= {hi:.4g}" if hi is not None else "")
                print(f"{n:10s} {p['value']:12.6g} {'-':>10s} {'NOT IDENTIFIABLE ' + side:>28s}  {unit}")
        names = list(res.parameters)
        if len(names) > 1:
            print("correlation: " + "; ".join(
                f"{names[a]}/{names[b]} = {res.correlation[a][b]:.3f}" if res.correlation[a][b] is not None
                else f"{names[a]}/{names[b]} = n/a" for a in range(len(names)) for b in range(a + 1, len(names))))
        if args.plot:
            print(f"figure: {args.plot}")
    sys.stderr.write(f"fit: {res.message}\n")
    return 0
