"""``ipmc-asym step``: charging transient after a voltage step (reduced model or PNP solver)."""

from __future__ import annotations

import csv
import json
import os
import sys

import numpy as np

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import model_names
from ipmc_asym.base.settings import MAX_POINTS_CEILING
from ipmc_asym.base.units import fmt_length
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_beam_options,
    add_line_options,
    add_output_option,
    add_size_option,
    add_solver_option,
    add_strip_options,
    diffusion_type,
    duration_type,
    first_run_notice,
    fmt_num,
    given,
    model_help,
    sidecar_path,
    strip_and_material,
    time_tol_type,
    warn,
    waveform_type,
)
from ipmc_asym.dynamics.circuit import STEP_FIDELITIES
from ipmc_asym.dynamics.drive import (
    CHECK_COLUMNS,  # per time point: the forward model's checks, as drive
    LINE_COLUMNS,
)
from ipmc_asym.dynamics.entry import AUTO_TOL, stated_tol, time_path, time_response
from ipmc_asym.forward.model import CHECKS
from ipmc_asym.io.fileio import atomic_write

COLUMNS = ("t", "phi0", "sigma", "current_density", "M_A", "theta", "w")
#: output times of one run: the arrays of the integrator (~2 substeps per interval) and of the
#: forward model stay ~100 MB; settable with --max-points
MAX_POINTS = 10**5
#: the same with --fidelity pnp, whose solver keeps the profiles of every output time (~10 kB each:
#: 1e5 points reach 1 GB); applies where --max-points is left at its default
MAX_POINTS_PNP = 10**4



def _num(x, scale):
    """A withheld (NaN) value as n/a, like estimate."""
    return fmt_num(x * scale if np.isfinite(x) else None, ".4g")


#: units of the CSV columns (the sidecar's "units")
UNITS = {"t": "s", "phi0": "V", "sigma": "C/m^2", "sigma_error": "C/m^2", "current_density": "A/m^2",
         "current_error": "A/m^2", "M_A": "N m", "theta": "rad", "w": "m", "w_error": "m"}


def _write_rows(wr, model, values, flags):
    """CSV rows of one model: ``values`` and ``flags`` lists of column arrays (``model`` None: no
    model column); ``+ 0.0``: no "-0"."""
    vals = [np.asarray(a, dtype=float) + 0.0 for a in values]
    for i in range(vals[0].size):
        wr.writerow(([] if model is None else [model]) + [repr(float(a[i])) for a in vals]
                    + [str(bool(f[i])) for f in flags])


def _sidecar(args, strip, taus, fidelity, drive, beam, notes, **extra) -> None:
    """The CSV's metadata beside it (one header row in the CSV: ``pandas.read_csv`` reads it as is)."""
    meta = {"csv": os.path.basename(args.out), "tau": taus if len(taus) > 1 else next(iter(taus.values())),
            "thickness_total": strip.thickness, "half_thickness_e": strip.e, "voltage": strip.voltage,
            "model": args.model, "fidelity": fidelity, "drive": drive, "beam": beam, "notes": notes, **extra,
            "units": UNITS}
    with atomic_write(sidecar_path(args.out)) as fh:
        fh.write(json.dumps(meta, indent=1) + "\n")


def _stream_csv(args, strip, resps) -> int:
    """``step --out F.csv`` on a stepped path (:func:`ipmc_asym.dynamics.entry.time_response` with
    ``stream=True``: the circuit at the quasi-static beam, or the electrode line): each model's rows are
    computed and written chunk by chunk, so the memory does not grow with ``--points``."""
    models = list(resps)
    many = len(models) > 1
    r0 = resps[models[0]]
    line = r0.path == "line"
    columns = COLUMNS + (LINE_COLUMNS if line else ())
    seen, n_rows = {}, 0
    with atomic_write(args.out) as fh:
        wr = csv.writer(fh)
        wr.writerow((("model",) if many else ()) + columns + CHECK_COLUMNS)
        for mname, resp in resps.items():
            for ch in resp.chunks:
                for w in ch["warnings"]:
                    seen.setdefault((mname, w.split(":")[0]), f"{mname}: {w}" if many else w)
                _write_rows(wr, mname if many else None, [ch[c] for c in columns],
                            [np.asarray(ch[c]) != 0.0 for c in CHECK_COLUMNS])
                n_rows += ch["t"].size
    _sidecar(args, strip, {m: resps[m].info["tau"] for m in models}, "circuit", r0.drive.spec, r0.info["beam"],
             r0.info["notes"], warnings=list(seen.values()),
             **({"sheet_resistance": args.sheet_resistance, "line_segments": 2 * args.line_segments}
                if line else {}))
    for w in seen.values():
        sys.stderr.write(f"step: warning: {w}\n")
    sys.stderr.write(f"step: {n_rows} rows -> {args.out} (streamed; metadata: {sidecar_path(args.out)})\n")
    return 0


def _line_in_memory(args, strip, material, resps) -> int:
    """``step --sheet-resistance`` printed or as ``--json``: the electrode line (the ladder of reduced
    circuits, the forward model at every node, its stated error) per model."""
    models = list(resps)
    drive = resps[models[0]].drive.spec
    columns = COLUMNS + LINE_COLUMNS
    out = {m: (resp.info, resp.columns) for m, resp in resps.items()}
    if args.json:
        def one(info, r):
            return {"tau": info["tau"], "R": info["R"], "model": info["model"], "fidelity": "circuit",
                    "voltage": strip.voltage, "thickness_total": strip.thickness, "half_thickness_e": strip.e,
                    "diffusion_coefficient": material.D, "notes": info["notes"], "waveform": drive,
                    "beam": args.beam, "sheet_resistance": args.sheet_resistance,
                    "line_segments": info["line_segments"], **{c: r[c] for c in columns},
                    **{c: r[c].astype(bool) for c in CHECK_COLUMNS}}
        doc = (one(*out[models[0]]) if len(models) == 1 else
               {"model": "all", "thickness_total": strip.thickness, "models": {m: one(*out[m]) for m in models}})
        print(dumps(doc, indent=1))
        return 0
    for mname in models:
        info, r = out[mname]
        what = f"step {strip.voltage:g} V" if args.waveform is None else f"waveform {drive}"
        print(f"{what}, total thickness 2e = {fmt_length(strip.thickness)}, model {info['model']}, fidelity circuit, "
              f"beam {args.beam}, electrode sheet resistance {args.sheet_resistance:g} Ohm/sq "
              f"({info['line_segments']} segments): tau = {info['tau']:.4g} s")
        idx = np.unique(np.linspace(0, r["t"].size - 1, min(r["t"].size, 11)).astype(int))
        print(f"{'t [s]':>11s} {'sigma [C/m^2]':>14s} {'+-':>9s} {'J [A/m^2]':>11s} {'M_A [N m]':>11s} {'th. [rad]':>9s} "
              f"{'w [mm]':>9s} {'+-':>9s} valid")
        for i in idx:
            print(f"{fmt_num(r['t'][i], '11.4g')} {fmt_num(r['sigma'][i], '14.6g')} {fmt_num(r['sigma_error'][i], '9.2g')} "
                  f"{fmt_num(r['current_density'][i], '11.4g')} {fmt_num(r['M_A'][i], '11.4g')} "
                  f"{_num(r['theta'][i], 1.0):>9s} {_num(r['w'][i], 1e3):>9s} {fmt_num(r['w_error'][i] * 1e3, '9.2g')} "
                  f"{'yes' if r['valid'][i] else 'no'}")
    for n in out[models[0]][0]["notes"]:
        print(f"note: {n}")
    return 0


def register(sub):
    p = sub.add_parser("step", help=SUMMARIES["step"])
    add_strip_options(p)
    p.add_argument("--duration", type=duration_type, default=None,
                   help="end time (e.g. 0.2s, 50ms; default 5 tau)")
    add_solver_option(p, "step", dest="fidelity", default="circuit", choices=STEP_FIDELITIES,
                      help="circuit (reduced nonlinear capacitor) or pnp (transient Nernst-Planck/Gauss)")
    p.add_argument("--model", default="constant", choices=list(model_names()) + ["all"],
                   help=model_help("constant") + "; all: each in turn")
    p.add_argument("--diffusion", type=diffusion_type(), default=None,
                   help="cation diffusion coefficient D (1e-10m2/s, 1e-6cm2/s; a bare number is m^2/s)")
    p.add_argument("--tol", type=time_tol_type, default="auto",
                   help="relative accuracy required of sigma at every output time, e.g. 1e-3 or 0.1%% (in [1e-8, 0.5)): "
                        "the circuit's error is bounded against a reference PNP run and the PNP is used where it fails; "
                        f"default auto: {AUTO_TOL:g} where the error can be stated (at most 10001 output times, no "
                        "--sheet-resistance: the electrode line states its own), 1e-6 for pnp; none: the bare circuit, "
                        "no error stated (~100 times faster)")
    add_size_option(p, "--points", default=1000, maximum=MAX_POINTS, ceiling=MAX_POINTS_CEILING, minimum=2,
                    help=f"output times (with --fidelity pnp at most {MAX_POINTS_PNP:.0e} unless --max-points is given)")
    p.add_argument("--waveform", type=waveform_type, default=None,
                   help="instead of the step of --voltage: a SPEC such as 'sine:1V@10Hz' or 'step:1V+square:0.1V@5Hz' "
                        "(see ipmc-asym drive --help)")
    add_beam_options(p)
    add_line_options(p)
    add_output_option(p, "--out", formats=(".csv",), sidecar=True, default=None, metavar="F.csv",
                   help="CSV file (header row t, phi0, sigma, current_density, M_A, theta, w, check_* and valid per "
                        "time point; SI; a first column model with --model all), with the metadata (tau, total "
                        "thickness, model, units) in the sidecar F.csv.json")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args):
    if args.fidelity == "pnp" and args.max_points == MAX_POINTS and args.points > MAX_POINTS_PNP:
        raise ValueError(f"--points {args.points:g} with --fidelity pnp is above {MAX_POINTS_PNP:g} (the pnp solver keeps "
                         f"every output time's profiles: ~10 kB each); lower --points or set --max-points")
    strip, material, _ = strip_and_material(args)
    if args.waveform is not None and given(args, "voltage"):  # said, not silently dropped
        warn(f"--voltage {args.voltage:g} V is not used: --waveform sets the voltage (its amplitudes are in the SPEC)")
    models = list(model_names()) if args.model == "all" else [args.model]
    stream = bool(args.out) and not args.json
    # what --tol auto means here (the library's rule, dynamics.entry.stated_tol; time_response applies
    # the same and says in the notes why where it states no error)
    tol, _ = stated_tol(args.tol, fidelity=args.fidelity, points=args.points, sheet_resistance=args.sheet_resistance)
    # the choice's refusals first (a refused command compiles nothing), then the first-run notice
    time_path(fidelity=args.fidelity, tol=tol, beam=args.beam, sheet_resistance=args.sheet_resistance,
              stream=stream)
    first_run_notice("step-pnp" if args.fidelity == "pnp" or tol is not None else "step")
    said = []

    def notice():
        # the reference PNP run is the long part: said when it starts (after the refusals), once
        if tol is not None and args.fidelity == "circuit" and not said:
            said.append(True)
            sys.stderr.write(f"step: the circuit and a reference PNP run (tol {tol:g}) that bounds its error, "
                             f"{len(models)} model{'s' if len(models) > 1 else ''} (nominal strip, each: ~1.5-2.5 s "
                             f"CPU for a 1 V step, ~6 s for 1 s of a 10 Hz sine; --tol none skips it)\n")
            sys.stderr.flush()

    # the library chooses the solver (dynamics.entry.time_path): rows streamed to --out where a stepped
    # path serves, the in-memory solve otherwise
    resps = {m: time_response(strip, args.waveform, duration=args.duration, points=args.points, model=m,
                              material=material, fidelity=args.fidelity, tol=args.tol, beam=args.beam,
                              viscous_modulus=args.viscous_modulus, sheet_resistance=args.sheet_resistance,
                              line_segments=args.line_segments, stream=stream, notice=notice)
             for m in models}
    path = resps[models[0]].path
    if path == "line" and resps[models[0]].chunks is None:
        return _line_in_memory(args, strip, material, resps)
    if path != "memory":
        return _stream_csv(args, strip, resps)
    results = {m: resp.result for m, resp in resps.items()}
    # the tolerance the runs met (auto states none where the reference PNP run refuses the strip)
    if any(resp.info.get("tol") is None for resp in resps.values()) and args.fidelity == "circuit":
        tol = None

    # the errors wherever they are stated: with --tol, and always for the pnp (its default tolerance)
    stated = tol is not None or args.fidelity == "pnp"
    # (the deflection's error: through the quasi-static beam, or through the beam's modes with --beam dynamic)
    columns = COLUMNS + (("sigma_error", "current_error") if stated else ()) + (
        ("w_error",) if stated else ())

    def cols_of(r):
        cols = {"t": r.t, "phi0": r.phi0, "sigma": r.sigma, "sigma_error": r.sigma_error,
                "current_density": r.current_density, "current_error": r.current_error, "M_A": r.M_A,
                "theta": r.theta, "w": r.w, "w_error": r.w_error}
        return {c: cols[c] for c in columns}

    def flags_of(r):
        flags = {f"check_{c}": r.checks[c] for c in CHECKS}
        flags["valid"] = r.valid
        return flags

    r0 = results[models[0]]
    drive = "step" if args.waveform is None else args.waveform.spec
    if args.out:
        many = len(models) > 1
        with atomic_write(args.out) as fh:
            wr = csv.writer(fh)
            wr.writerow((("model",) if many else ()) + columns + CHECK_COLUMNS)
            for mname in models:
                cols, flags = cols_of(results[mname]), flags_of(results[mname])
                _write_rows(wr, mname if many else None, [cols[c] for c in columns], [flags[c] for c in CHECK_COLUMNS])
        _sidecar(args, strip, {m: results[m].tau for m in models}, r0.fidelity, drive, args.beam, r0.notes)
        sys.stderr.write(f"step: {sum(r.t.size for r in results.values())} rows -> {args.out} "
                         f"(metadata: {sidecar_path(args.out)})\n")

    def head_of(r):
        return {"tau": r.tau, "R": r.R, "C_d0": r.C_d0, "model": r.model, "fidelity": r.fidelity,
                "voltage": strip.voltage, "thickness_total": strip.thickness, "half_thickness_e": strip.e,
                "diffusion_coefficient": material.D, "seconds": r.seconds, "notes": r.notes, "message": r.message,
                "waveform": drive, "beam": args.beam, "warnings": r.warnings,
                # the tolerance the run met: --tol, or the pnp's default
                "tol": tol if tol is not None else r.extra.get("tol"),
                "valid_from": r.extra.get("valid_from")}

    for mname in models:  # the forward model's flags, one line each (also in --json's "warnings")
        for w in results[mname].warnings:
            sys.stderr.write(f"step: warning: {mname}: {w}\n" if len(models) > 1 else f"step: warning: {w}\n")

    if args.json:
        if len(models) == 1:
            out = head_of(r0)
            out.update(cols_of(r0))
            out.update(flags_of(r0))
        else:
            out = {"model": "all", "notes": r0.notes, "thickness_total": strip.thickness,
                   "models": {m: dict(head_of(results[m]), **cols_of(results[m]), **flags_of(results[m])) for m in models}}
        print(dumps(out, indent=1))
        return 0
    if not args.out:
        for mname in models:
            r = results[mname]
            what = f"step {strip.voltage:g} V" if args.waveform is None else f"waveform {drive}"
            print(f"{what}, total thickness 2e = {fmt_length(strip.thickness)}, model {r.model}, "
                  f"fidelity {r.fidelity}, beam {args.beam}: tau = {r.tau:.4g} s (R = {r.R:.4g} Ohm m^2, "
                  f"C_d(0) = {r.C_d0:.4g} F/m^2, D = {material.D:.3g} m^2/s)")
            idx = np.unique(np.linspace(0, r.t.size - 1, min(r.t.size, 11)).astype(int))
            if "w_error" in columns:  # the stated errors beside their values
                print(f"{'t [s]':>11s} {'sigma [C/m^2]':>14s} {'+-':>9s} {'J [A/m^2]':>11s} {'+-':>9s} "
                      f"{'M_A [N m]':>11s} {'th. [rad]':>9s} {'w [mm]':>9s} {'+-':>9s} valid")
                for i in idx:
                    print(f"{fmt_num(r.t[i], '11.4g')} {fmt_num(r.sigma[i], '14.6g')} "
                          f"{fmt_num(r.sigma_error[i], '9.2g')} {_num(r.current_density[i], 1.0):>11s} "
                          f"{_num(r.current_error[i], 1.0):>9s} {fmt_num(r.M_A[i], '11.4g')} "
                          f"{_num(r.theta[i], 1.0):>9s} {_num(r.w[i], 1e3):>9s} {_num(r.w_error[i], 1e3):>9s} "
                          f"{'yes' if r.valid[i] else 'no'}")
                continue
            print(f"{'t [s]':>11s} {'sigma [C/m^2]':>14s} {'J [A/m^2]':>11s} {'M_A [N m]':>11s} {'th. [rad]':>9s} "
                  f"{'w [mm]':>9s} valid")
            for i in idx:
                print(f"{fmt_num(r.t[i], '11.4g')} {fmt_num(r.sigma[i], '14.6g')} {fmt_num(r.current_density[i], '11.4g')} "
                      f"{fmt_num(r.M_A[i], '11.4g')} {_num(r.theta[i], 1.0):>9s} {_num(r.w[i], 1e3):>9s} "
                      f"{'yes' if r.valid[i] else 'no'}")
        for n in r0.notes:
            print(f"note: {n}")
    return 0
