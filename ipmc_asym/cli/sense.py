"""``ipmc-asym sense``: the strip as a sensor -- charge and open-circuit voltage of an imposed bending, at rest
or, with ``--waveform``, in time (the tip displacement following the ``drive`` grammar in lengths)."""

from __future__ import annotations

import csv
import math

import numpy as np

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import fidelity_names, model_choices
from ipmc_asym.base.units import fmt_length, parse_length, parse_quantity
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_output_option,
    add_strip_options,
    arg_type,
    count_type,
    duration_type,
    first_run_notice,
    fmt_num,
    load_type,
    nu_type,
    sidecar_path,
    strip_and_material,
    tol_type,
    warn,
)
from ipmc_asym.forward.estimate import model_list
from ipmc_asym.forward.sensing import DEFAULT_NU, SENSE_SUPPORTS, sense
from ipmc_asym.io.fileio import atomic_write
from ipmc_asym.model.spread import spread_of

#: curvature units (1/m); a bare number is 1/m
_CURVATURE = {"1/m": 1.0, "m^-1": 1.0, "/m": 1.0, "1/mm": 1e3, "mm^-1": 1e3, "/mm": 1e3, "1/cm": 1e2, "cm^-1": 1e2,
              "/cm": 1e2}
#: the per-point columns of --out, in order
COLUMNS = ("curvature", "tip_displacement", "sigma", "Q", "V_oc", "Q_per_w", "error", "error_V_oc",
           "strain_parameter", "max_strain", "check_strain", "check_beam_regime", "valid", "fidelity_used")


def _curvature(text):
    return parse_quantity("curvature", text, _CURVATURE, "curvature")


def _tip(text):
    return parse_length("tip displacement", text)


#: the columns of --waveform's table and --out, in order (after "model")
TIME_COLUMNS = ("t", "w", "kappa", "emf", "Q", "V", "I", "power", "check_strain", "check_beam_regime",
                "check_one_way", "valid")
_TIME_UNITS = {"t": "s", "w": "m", "kappa": "1/m", "emf": "V", "Q": "C", "V": "V", "I": "A", "power": "W"}
#: --json holds every row in memory
MAX_JSON_ROWS = 100_000


def _length_waveform(text):
    from ipmc_asym.dynamics.waveforms import parse_waveform  # deferred: start-up

    return parse_waveform(text, quantity="length")




def register(sub):
    p = sub.add_parser("sense", help=SUMMARIES["sense"])
    add_strip_options(p, voltage=False, mechanics=True)
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--curvature", type=arg_type(_curvature, "curvature"),
                   help="curvature at the clamp kappa = w'' (uniform for --support free), e.g. 2/m: 1/m, m^-1, 1/mm "
                        "or a bare number in 1/m; its sign is the bending direction (+: toward the face z = +e)")
    g.add_argument("--tip-displacement", type=arg_type(_tip, "tip-displacement"),
                   help="imposed tip displacement w (small displacement), e.g. 1mm or -0.5mm")
    g.add_argument("--waveform", type=arg_type(_length_waveform, "--waveform"),
                   help="the tip displacement in time, the drive grammar in lengths: e.g. sine:1mm@0.01Hz, step:1mm, "
                        "dc:0.5mm+sine:0.2mm@5mHz, csv:PATH (t, w columns); needs --duration; the strip at rest "
                        "before t = 0 (docs/sensing.md, time domain)")
    p.add_argument("--duration", type=duration_type, default=None, help="with --waveform: end time (e.g. 100s)")
    p.add_argument("--points", type=count_type("--points", 2), default=2001,
                   help="with --waveform: output rows, uniform in [0, duration] (default 2001, at most 1e6)")
    p.add_argument("--support", default="tip-force", choices=SENSE_SUPPORTS,
                   help="free: an end moment, uniform curvature, w = kappa L^2/2; tip-force: a tip force on the "
                        "cantilever, kappa(x) = kappa0 (1 - x/L), w = kappa0 L^2/3 (default tip-force, as in every sensing entry)")
    p.add_argument("--load", type=arg_type(load_type, "--load"), default="short",
                   help="short (the charge that flows between short-circuited electrodes) or open (the voltage); "
                        "both are computed, this picks the one printed first. A resistive load at DC after "
                        "relaxation carries no current: it reads the open-circuit voltage. With --waveform: short, "
                        "open or a resistance R (e.g. 10kOhm: its voltage, current and power)")
    p.add_argument("--nu", type=arg_type(nu_type, "nu"), default=DEFAULT_NU,
                   help="drained Poisson ratio of the membrane (default 0, an assumption: the paper's section 3 "
                        "kinematics; no measured value was read; the answers scale as 1 - 2 nu)")
    p.add_argument("--model", default="all", choices=model_choices(), help="permittivity model (default all three)")
    p.add_argument("--fidelity", default="leading", choices=fidelity_names(),
                   help="rung to start from (default leading, the linear closed form); corrected and quadrature "
                        "start at exact (the closed form is exact in the Debye length already); escalated until "
                        "the error estimate meets --tol")
    p.add_argument("--tol", type=tol_type, default=None, help="relative accuracy required, e.g. 1e-4 or 1%% "
                   "(default settings.VALIDITY_LIMIT)")
    p.add_argument("--pressure-term", action="store_true",
                   help="keep the pressure term of the Nernst-Planck law (eq. (5)); linear order only")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_output_option(p, "--out", formats=(".csv", ".nc"), sidecar=True, default=None, metavar="F.csv|F.nc",
                      help="write the rows (one per model) to a CSV or NetCDF file (written atomically)")


def _check_time_args(args):
    """One-line refusals before any work."""
    if args.waveform is None:
        for flag, v, dflt in (("--duration", args.duration, None), ("--points", args.points, 2001)):
            if v != dflt:
                raise ValueError(f"{flag} needs --waveform (the static sense has no time)")
        if not isinstance(args.load, str):
            raise ValueError("--load R: after relaxation (DC) a resistive load carries no current and reads the "
                             "open-circuit voltage (use open); a load in time: --waveform SPEC --load R; at a "
                             "frequency: ipmc-asym freq --mode sensing --load R")
        return
    from ipmc_asym.dynamics.sensing_time import MAX_SENSE_POINTS  # deferred: start-up

    if args.duration is None:
        raise ValueError("--waveform needs --duration (e.g. --duration 100s)")
    if args.points > MAX_SENSE_POINTS:
        raise ValueError(f"--points must be at most {MAX_SENSE_POINTS:g}; got {args.points:.6g}")
    if args.json and args.points > MAX_JSON_ROWS:
        raise ValueError(f"--json holds every row in memory: --points at most {MAX_JSON_ROWS:g} (use --out F.csv)")
    for flag, v in (("--fidelity", args.fidelity != "leading"), ("--tol", args.tol is not None),
                    ("--pressure-term", args.pressure_term)):
        if v:
            raise ValueError(f"{flag} is not read with --waveform (the time domain is the linear reduced circuit "
                             "with its stated error)")


def _run_time(args, strip, material):
    from ipmc_asym.dynamics.sensing_time import sensing_transient  # deferred: start-up

    results = {m: sensing_transient(args.waveform, args.duration, args.points, strip, model=m, material=material,
                                    load=args.load, nu=args.nu, support=args.support)
               for m in model_list(args.model)}
    load_txt = args.load if isinstance(args.load, str) else f"{args.load:g} Ohm"
    warnings = []
    for m, r in results.items():
        for c, what in (("check_strain", f"face strain above the small-strain limit {material.strain_limit:g}"),
                        ("check_beam_regime", "|kappa0| L past a quarter turn (the small-displacement beam)"),
                        ("check_one_way", "core voltage past twice the static EMF of the largest bend (one-way coupling)")):
            bad = int(np.count_nonzero(~getattr(r, c)))
            if bad:
                warnings.append(f"{m}: {bad} of {r.t.size} rows: {what}; kept, flagged valid = false")
    for w in warnings:
        warn(w)
    r0 = next(iter(results.values()))
    notes = list(r0.notes)
    inputs = {"length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
              "support": args.support, "load": args.load, "nu": args.nu, "c_moy": material.C_moy,
              "waveform": args.waveform.spec, "duration": args.duration, "points": args.points}
    if args.out:
        _write_time(args.out, results)
        _sidecar(args.out, inputs, notes, warnings)
    summary = {m: {"error": r.error, "error_circuit": r.error_circuit, "error_emf": r.error_emf,
                   "error_interp": r.error_interp, "error_linear": r.error_linear,
                   "error_settled": r.error_settled, "tau": r.tau, "f_stream": r.f_stream, "f_top": r.f_top,
                   "mean_power": r.mean_power} for m, r in results.items()}
    if args.json:
        rows = [{"model": m, **{c: (bool(v) if isinstance(v, np.bool_) else float(v))
                                for c, v in zip(TIME_COLUMNS, vals)}}
                for m, r in results.items() for vals in zip(*(getattr(r, c) for c in TIME_COLUMNS))]
        print(dumps({"inputs": inputs, "summary": summary, "results": rows, "notes": notes, "warnings": warnings},
                    indent=2))
        return 0
    print(f"IPMC strip as a sensor in time: L = {fmt_length(strip.length)}, total width 2l = {fmt_length(strip.width)}, "
          f"total thickness 2e = {fmt_length(strip.thickness)}, support {args.support}, load {load_txt}, "
          f"w(t) = {args.waveform.spec}")
    cols = ["t", "w", "kappa"] + (["V"] if args.load == "open" else ["Q", "I"] if args.load == "short"
                                  else ["Q", "V", "I", "power"])
    show = np.unique(np.linspace(0, args.points - 1, min(args.points, 11)).astype(int))
    for m, r in results.items():
        print(f"{m}: stated relative error {r.error:.2g} (circuit {r.error_circuit:.2g}, EMF {r.error_emf:.2g} up to "
              f"{r.f_top:.3g} Hz, interpolation {r.error_interp:.1g}, linearisation {r.error_linear:.1g}); relaxed rows "
              f"{r.error_settled:.1g}; tau = {r.tau:.4g} s, f_stream = {r.f_stream:.4g} Hz"
              + ("" if isinstance(args.load, str) else
                 f"; mean power {fmt_num(None if math.isnan(r.mean_power) else r.mean_power, '.4g')} W"))
        print("  " + " ".join(f"{c + ' [' + _TIME_UNITS[c] + ']':>13s}" for c in cols))
        for i in show:
            print("  " + " ".join(f"{float(getattr(r, c)[i]):13.5g}" for c in cols)
                  + ("" if r.valid[i] else "  not valid (see warning)"))
    for n in notes:
        print("note: " + n)
    if args.out:
        print(f"wrote {args.out}" + (f" and {sidecar_path(args.out)}" if _csv(args.out) else ""))
    return 0


def _write_time(path, results):
    if str(path).lower().endswith(".nc"):
        import xarray as xr  # deferred: xarray is heavy (start-up)

        from ipmc_asym.io.datasets import write_netcdf  # deferred: loads xarray (start-up)

        ds = xr.concat([r.to_xarray() for r in results.values()], dim="model")
        write_netcdf(ds.assign_coords(model=list(results)), path)
        return
    with atomic_write(path, newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(("model",) + TIME_COLUMNS)  # SI units (docs/commands.md)
        for m, r in results.items():
            arrs = [getattr(r, c) for c in TIME_COLUMNS]
            for vals in zip(*arrs):
                wr.writerow([m] + [str(bool(v)) if isinstance(v, np.bool_) else repr(float(v)) for v in vals])


def run(args):
    _check_time_args(args)
    strip, material, _ = strip_and_material(args)
    first_run_notice()
    if args.waveform is not None:
        return _run_time(args, strip, material)
    kw = {"curvature": args.curvature} if args.curvature is not None else {"tip_displacement": args.tip_displacement}
    results = {m: sense(strip, support=args.support, load=args.load, model=m, fidelity=args.fidelity, tol=args.tol,
                        nu=args.nu, material=material, pressure_term=args.pressure_term, **kw)
               for m in model_list(args.model)}
    rows = []
    for m, r in results.items():
        row = {"model": m}
        for c in COLUMNS:
            v = getattr(r, c)[0]
            row[c] = str(v) if c == "fidelity_used" else (bool(v) if c in ("check_strain", "check_beam_regime", "valid") else float(v))
        rows.append(row)
    warnings = []
    for m, r in results.items():
        if not bool(r.check_strain[0]):
            warnings.append(f"{m}: face strain {float(r.max_strain[0]):.3g} above the small-strain limit "
                            f"{material.strain_limit:g} (Material.strain_limit); kept, flagged valid = false")
        if not bool(r.check_beam_regime[0]):
            warnings.append(f"{m}: |kappa0| L = {abs(float(r.curvature[0])) * strip.length:.3g} past a quarter turn: "
                            "the small-displacement beam relating w and kappa does not hold; kept, flagged valid = false")
        if bool(r.check_strain[0]) and bool(r.check_beam_regime[0]) and not bool(r.valid[0]):
            warnings.append(f"{m}: {r.message}; kept, flagged valid = false")
    for w in warnings:
        warn(w)
    notes = ["Q: charge of the electrode z = -e in short circuit (the other carries -Q), after relaxation; V_oc = "
             "phi(-e) - phi(e) in open circuit; both are odd in the curvature",
             f"drained Poisson ratio nu = {args.nu:g} (an assumption; the answers scale as 1 - 2 nu at linear order)",
             "reciprocity: dQ/dw (tip force) / dF_block/dV = (1 - 2 nu)/(3 (1 + A3)) in the paper's model "
             "(docs/sensing.md): its actuation and sensing do not derive from one free energy"]
    inputs = {"length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
              "support": args.support, "load": args.load, "nu": args.nu, "c_moy": material.C_moy}
    # the model-form spread over the permittivity models shown, as estimate and charge give it
    spread = ({k: spread_of({r["model"]: r[k] for r in rows}, max(max(r["error"], r["error_V_oc"]) for r in rows))
               for k in ("Q", "V_oc", "Q_per_w")} if len(rows) > 1 else None)
    if args.out:
        _write(args.out, results, rows)
        _sidecar(args.out, inputs, notes, warnings)
    if args.json:
        doc = {"inputs": inputs, "results": rows, "notes": notes, "warnings": warnings}
        if spread is not None:
            doc["model_spread"] = spread
        print(dumps(doc, indent=2))
        return 0
    r0 = next(iter(results.values()))
    print(f"IPMC strip as a sensor: L = {fmt_length(strip.length)}, total width 2l = {fmt_length(strip.width)}, "
          f"total thickness 2e = {fmt_length(strip.thickness)}, support {args.support}, "
          f"kappa0 = {float(r0.curvature[0]):.6g} 1/m, w = {float(r0.tip_displacement[0]):.6g} m")
    first, second = (("Q", "C"), ("V_oc", "V")) if args.load == "short" else (("V_oc", "V"), ("Q", "C"))
    print(f"{'model':9s} {'fidelity':9s} {first[0] + ' [' + first[1] + ']':>14s} {second[0] + ' [' + second[1] + ']':>14s}"
          f" {'Q/w [C/m]':>12s} {'rel.err':>8s}")
    for row in rows:
        err = max(row["error"], row["error_V_oc"])
        print(f"{row['model']:9s} {row['fidelity_used']:9s} {row[first[0]]:14.6g} {row[second[0]]:14.6g} "
              f"{row['Q_per_w']:12.5g} {err:8.1e}" + ("" if row["valid"] else "  not valid (see warning)"))
    if spread is not None:
        print(f"model-form spread over the {len(rows)} permittivity models:")
        for k, unit in (("Q", "C"), ("V_oc", "V"), ("Q_per_w", "C/m")):
            d = spread[k]
            ratio = "" if d["ratio"] is None else f" (x{d['ratio']:.3g})"
            print(f"  {k + ' [' + unit + ']':14s} {d['min']:.4g} .. {d['max']:.4g}{ratio}   numerical rel.err <= "
                  f"{d['numerical_error']:.1e}")
    for n in notes:
        print("note: " + n)
    if args.out:
        print(f"wrote {args.out}" + (f" and {sidecar_path(args.out)}" if _csv(args.out) else ""))
    return 0


def _csv(path) -> bool:
    return not str(path).lower().endswith(".nc")


def _sidecar(path, inputs, notes, warnings):
    """The strip and the conditions of a CSV's rows beside it (``F.csv.json``, as drive's and
    estimate's): the CSV keeps one header row; a NetCDF file carries them itself."""
    if _csv(path):
        meta = {"inputs": dict(inputs, half_thickness_e=0.5 * inputs["thickness_total"]), "notes": notes,
                "warnings": warnings, "units": "SI (m, C, V, A, W, 1/m)"}
        with atomic_write(sidecar_path(path)) as fh:
            fh.write(dumps(meta, indent=2) + "\n")


def _write(path, results, rows):
    if str(path).lower().endswith(".nc"):
        import xarray as xr  # deferred: xarray is heavy (start-up)

        from ipmc_asym.io.datasets import write_netcdf  # deferred: loads xarray (start-up)

        ds = xr.concat([r.to_xarray() for r in results.values()], dim="model")
        ds = ds.assign_coords(model=list(results))
        write_netcdf(ds, path)
        return
    with atomic_write(path, newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(("model",) + COLUMNS)
        for row in rows:
            wr.writerow([row["model"]] + [repr(row[c]) if isinstance(row[c], float) else row[c] for c in COLUMNS])
