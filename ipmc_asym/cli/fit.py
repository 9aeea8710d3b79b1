"""``ipmc-asym fit``: calibrate free parameters on measured deflection / blocking force, time series and
impedance spectra (one or several files; each file's header decides its kind)."""

from __future__ import annotations

import sys

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import fidelity_names, model_names
from ipmc_asym.base.settings import MAX_DATA_ROWS_CEILING, MAX_MULTISTART_CEILING
from ipmc_asym.base.units import fmt_length
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_output_option,
    add_size_option,
    add_solver_option,
    add_strip_options,
    cap_type,
    diffusion_type,
    first_run_notice,
    fmt_num,
    given,
    load_type,
    model_help,
    nu_type,
    seed_type,
    sheet_resistance_type,
    strip_and_material,
    viscous_modulus_type,
    warn,
    waveform_type,
)
from ipmc_asym.dynamics.circuit import BEAM_CHOICES
from ipmc_asym.forward.sensing import DEFAULT_NU, SENSE_SUPPORTS
from ipmc_asym.io.fileio import FIGURE_FORMATS
from ipmc_asym.model.electrode import beam_label
from ipmc_asym.parallel.executors import check_scheduler
from ipmc_asym.studies.calibrate import FREE_ALIASES, FREE_PARAMETERS, MAX_DATA_ROWS, CalibrationData, free_warnings, parse_free
from ipmc_asym.studies.calibrate_dynamic import TIME_FIDELITIES, fit, read_file

#: data files of one fit (each read into memory, at most --max-rows rows)
MAX_FILES = 100

DESCRIPTION = (
    "Weighted least squares of one or several data files together, 95 % profile-likelihood intervals, "
    "identifiability. The header of each file decides its kind. STATIC rows: columns length, width, thickness "
    "(TOTAL 2e), voltage; measured deflection, blocking_force (magnitudes). TIME SERIES (a t column, s; the strip "
    "of --length/--width/--thickness, at rest at t = 0): the drive as a voltage column (V at each t, linear between "
    "rows; a constant column is a step at t = 0) or --waveform SPEC; measured, signed: current (A), charge (C), "
    "deflection (m, positive where a positive voltage bends the strip), blocking_force (N); model: the reduced "
    "circuit, checked at the optimum against the PNP solver and escalated to it where its error is not below a "
    "tenth of the noise. IMPEDANCE SPECTRA (an f column, Hz): Z_re, Z_im (Ohm, Z_im < 0) or Z_abs (Ohm), Z_phase "
    "(deg), about 0 V; model: the exact linearised PNP through the electrode line. Optional sigma_<measured> "
    "(one standard deviation) in every file or in none (then one relative noise scale is estimated). Free "
    "parameters: modulus, c_moy, eps0, deps (any data), diffusion (alias D; time series or spectra), "
    "viscous_modulus (time series of deflection/force, --beam dynamic), sheet_resistance (spectra); a parameter "
    "the data cannot see is refused naming the data that would identify it. SENSING data (columns t, s; w, m, the "
    "imposed tip displacement, the strip at rest before t = 0; and Q (C), I (A) and/or V (V), rows on a uniform grid "
    "t = k dt): the electrodes on --load (short by default; V needs open or OHMS), model: the sensing transient; "
    "free also nu (the drained Poisson ratio; fixed by --nu, default 0). Water transport is outside the model.")

#: extra starts of a multistart (each a full least-squares solve); settable with --max-multistart
MAX_MULTISTART = 1000


def register(sub):
    p = sub.add_parser("fit", help=SUMMARIES["fit"], description=DESCRIPTION)
    p.add_argument("data", metavar="DATA.csv", nargs="+",
                   help="measurements (header row; SI or values with units); several files are fitted together")
    p.add_argument("--free", required=True, metavar="NAME[,NAME...]",
                   help=f"free parameters among {', '.join(FREE_PARAMETERS)} "
                        f"({', '.join(f'{a} = {k}' for a, k in FREE_ALIASES.items())}); optional bounds "
                        f"NAME=LO:HI with units (modulus=50MPa:500MPa, D=1e-11m2/s:1e-9m2/s)")
    p.add_argument("--model", default="constant", choices=list(model_names()), help=model_help("constant"))
    p.add_argument("--fidelity", default=None, choices=list(fidelity_names()),
                   help="force a fidelity (default: cheapest with error < 1/10 of the data's)")
    add_strip_options(p)
    p.add_argument("--waveform", type=waveform_type, default=None, metavar="SPEC",
                   help="drive of the time series without a voltage column (as drive --waveform: 'step:0.5V', "
                        "'sine:1V@2Hz', 'csv:V.csv')")
    p.add_argument("--diffusion", type=diffusion_type(), default=None,
                   help="cation diffusion coefficient D when not free, and the start when free (1e-10m2/s)")
    p.add_argument("--sheet-resistance", dest="sheet_resistance", type=sheet_resistance_type, default=None,
                   help="electrode sheet resistance (Ohm/sq) of the spectra when not free, the start when free")
    p.add_argument("--load", default=None, metavar="short|open|OHMS",
                   help="sensing data: the load on the electrodes (default short; a V column needs open or a "
                        "resistance, e.g. 10kOhm)")
    p.add_argument("--support", default=None, choices=SENSE_SUPPORTS,
                   help="sensing data: how the tip displacement bends the strip (default tip-force, as sense: a "
                        "file sense --out wrote reads with the same defaults)")
    p.add_argument("--nu", type=nu_type, default=DEFAULT_NU,
                   help="sensing data: drained Poisson ratio when nu is not free, the start when free (default 0, "
                        "an assumption)")
    p.add_argument("--beam", default=None, choices=BEAM_CHOICES,
                   help="mechanics of the time series (default: dynamic when viscous_modulus is free, else "
                        "quasi-static)")
    p.add_argument("--viscous-modulus", dest="viscous_modulus", type=viscous_modulus_type(), default=0.0,
                   help="Kelvin-Voigt viscous modulus (Pa s) when not free, the start when free (default 0)")
    add_solver_option(p, "fit", dest="time_fidelity", default=None, choices=TIME_FIDELITIES,
                      help="force the time series' rung (default: circuit, escalated to pnp where its error is too "
                           "large; its error is checked either way)")
    add_size_option(p, "--multistart", default=0, maximum=MAX_MULTISTART, ceiling=MAX_MULTISTART_CEILING, minimum=0, metavar="N",
                    help="N extra starts, log-uniform in the bounds; the best is kept")
    p.add_argument("--max-rows", type=cap_type("--max-rows", MAX_DATA_ROWS_CEILING), default=MAX_DATA_ROWS,
                   help=f"refuse a DATA.csv of more data rows than this (default {MAX_DATA_ROWS:.0e})")
    p.add_argument("--seed", type=seed_type, default=0, help="seed of the multistart starts (integer >= 0, default 0)")
    p.add_argument("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
                   help="run the multistart on dask.distributed (default: serial)")
    add_output_option(p, "--plot", formats=FIGURE_FORMATS, default=None, metavar="F.png",
                   help=f"data vs fitted model with residuals ({', '.join(FIGURE_FORMATS)})")
    p.add_argument("--no-progress", action="store_true", help="no progress bar (model evaluations) on stderr")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    # every option checked before any work (the fit of a long file takes seconds to minutes);
    # --plot with every output (add_output_option)
    # said before the run (a fit searching where no strip is can be long), and not again after it
    early = free_warnings(parse_free(args.free))
    for w in early:
        sys.stderr.write(f"fit: warning: {w}\n")
    if args.scheduler is not None:
        check_scheduler(args.scheduler)
    if len(args.data) > MAX_FILES:
        raise ValueError(f"DATA.csv: {len(args.data)} files; at most {MAX_FILES}")
    strip, material, _ = strip_and_material(args)
    if args.sheet_resistance is not None:
        material = material.with_(sheet_resistance=args.sheet_resistance)
    load = None if args.load is None else load_type(args.load)
    support = args.support  # None: the sensing entries' one default (tip-force)
    files = [read_file(d, strip, waveform=args.waveform, load=load, support=support, max_rows=args.max_rows)
             for d in args.data]
    for d in files:  # a strip option the file's own column overrides: said, not silently dropped
        for k in getattr(d, "file_columns", ()):
            if given(args, k):
                flag = "--" + k
                warn(f"{flag} is not used for {d.source}: its {k} column gives each row's {k}")
    first_run_notice("fit")
    static_only = len(files) == 1 and isinstance(files[0], CalibrationData)
    if static_only:
        for opt, val in (("--waveform", args.waveform), ("--beam", args.beam), ("--time-fidelity", args.time_fidelity)):
            if val is not None:
                raise ValueError(f"{opt}: only for time series (a file with a t column); {files[0].source} holds "
                                 f"static rows")
    # the library's one entry chooses the static or the joint dynamic fit from the data
    res = fit(files, args.free, model=args.model, material=material, fidelity=args.fidelity,
              multistart=args.multistart, seed=args.seed, scheduler=args.scheduler,
              progress=False if args.no_progress else None, strip=strip, beam=args.beam,
              viscous_modulus=args.viscous_modulus, time_fidelity=args.time_fidelity, nu=args.nu)
    source = ", ".join(d.source for d in files)
    if args.plot:
        from ipmc_asym.plotting.calibrate import plot_fit, plot_fit_dynamic  # deferred: matplotlib (start-up)

        if static_only:
            plot_fit(res, args.plot)
        else:
            plot_fit_dynamic(res, args.plot)
    # the strip the rows were computed for where a file gives no geometry column (spectra and time
    # series always: their electrode area scales every current and impedance)
    strip_doc = {"length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
                 "half_thickness_e": strip.e,
                 "columns_from_files": {d.source: list(getattr(d, "file_columns", ())) for d in files}}
    if args.json:
        print(dumps(dict(res.as_dict(), strip=strip_doc), indent=2))
    else:
        if res.chi2_red is not None:
            gof = f"chi2_red = {res.chi2_red:.4g} (with the given sigma)"
        elif res.noise_scale is None:
            gof = "no goodness of fit (as many free parameters as measured values)"
        else:
            gof = (f"noise scale s = {res.noise_scale:.3g} (relative, estimated from the residuals; no sigma_ "
                   f"columns, so no chi2 goodness of fit)")
        print(f"fit of {source}: {res.n_points} measured values, model {res.model}, fidelity {res.fidelity}, "
              f"{gof}")
        given_cols = sorted({c for d in files for c in getattr(d, "file_columns", ())} - {"voltage"})
        print(f"strip: L = {fmt_length(strip.length)}, total width 2l = {fmt_length(strip.width)}, total thickness "
              f"2e = {fmt_length(strip.thickness)}" + (f" (where a file gives no {'/'.join(given_cols)} column)"
                                                      if given_cols else ""))
        if material.electrode.present:
            print(f"beam: {beam_label(material.electrode)} (start values of a freed layer parameter)")
        print(f"{'parameter':16s} {'value':>12s} {'stderr':>10s} {'95% interval (profile)':>28s}  unit")
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
            print(f"{n:16s} {p['value']:12.6g} {se} {ci:>28s}  {unit}")
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
    for w in (w for w in res.warnings if w not in early):
        sys.stderr.write(f"fit: warning: {w}\n")
    sys.stderr.write(f"fit: {res.message}\n")
    return 0
