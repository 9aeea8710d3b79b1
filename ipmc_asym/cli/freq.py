"""``ipmc-asym freq``: small-signal impedance and tip-deflection/voltage transfer function."""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import model_names
from ipmc_asym.base.units import fmt_length
from ipmc_asym.beam.dynamics import CLAMPED_OUTPUTS
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    CLAMPED_UNITS,
    add_beam_options,
    add_output_option,
    add_size_option,
    add_solver_option,
    add_strip_options,
    add_support_options,
    arg_type,
    diffusion_type,
    first_run_notice,
    fmt_num,
    frequency_type,
    model_help,
    print_clamped,
    sheet_resistance_type,
    strip_and_material,
    support_from_args,
    voltage_type,
)
from ipmc_asym.dynamics.circuit import FREQ_METHODS
from ipmc_asym.dynamics.entry import spectrum
from ipmc_asym.dynamics.reduction import transfer_function
from ipmc_asym.io.fileio import atomic_write

#: frequencies of one run (log-spaced: 1e5 points resolve any spectrum; the --json text stays ~10 MB);
#: settable with --max-points
MAX_POINTS = 10**5


def register(sub):
    p = sub.add_parser("freq", help=SUMMARIES["freq"])
    add_strip_options(p, voltage=False, mechanics=False)
    p.add_argument("--from", dest="f1", type=frequency_type("--from"), required=True, help="first frequency (e.g. 0.01Hz)")
    p.add_argument("--to", dest="f2", type=frequency_type("--to"), required=True, help="last frequency (e.g. 1kHz)")
    add_size_option(p, "--points", default=50, maximum=MAX_POINTS, minimum=2, help="log-spaced points")
    p.add_argument("--model", default="constant", choices=list(model_names()), help=model_help("constant"))
    add_solver_option(p, "freq", dest="method", default=None, choices=FREQ_METHODS,
                      help="pnp-linear (exact linearised PNP, closed form; the default at 0 V) or circuit "
                           "(R + 1/(i w C_d); the default with a --voltage bias, which pnp-linear does not support)")
    p.add_argument("--diffusion", type=diffusion_type(), default=None,
                   help="cation diffusion coefficient D (1e-10m2/s, 1e-6cm2/s; a bare number is m^2/s)")
    p.add_argument("--voltage", type=voltage_type("--voltage"), default=0.0,
                   help="DC bias (e.g. 0.5V): small signal about the biased static state (--solver circuit)")
    add_beam_options(p)
    p.add_argument("--sheet-resistance", dest="sheet_resistance", type=sheet_resistance_type, default=None,
                   help="sheet resistance of each electrode (2.5ohm/sq; a bare number is Ohm/sq; default 0 = ideal): "
                        "Z and w of the RC line along the strip, driven at the clamp")
    add_support_options(p)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_output_option(p, "--export", formats=(".json",), metavar="F.json", default=None,
                   help="write reduced-order models of V -> w and V -> charge over [--from, --to] (poles, residues, "
                        "state space, stated error; see ipmc_asym.transfer_function)")
    p.add_argument("--export-tol", type=arg_type(_tol_type, "--export-tol"), default=1e-4,
                   help="relative error the exported models aim at over the band, in (0, 1) (default 1e-4)")


def _tol_type(text):
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not 0.0 < v < 1.0:
        raise ValueError(f"--export-tol must be a number in (0, 1); got {text!r}")
    return v


def run(args):
    if args.f2 <= args.f1:
        raise ValueError(f"--to must be above --from; got {args.f1:g} Hz .. {args.f2:g} Hz")
    # --export: its path and format checked before any work with every output (add_output_option)
    support, electrode = support_from_args(args)
    strip, material, _ = strip_and_material(args)
    clamped = support == "clamped-clamped"
    if args.export is not None and (clamped or electrode is not None):
        raise ValueError("--export models the full-electrode strip (free tip): not with --support clamped-clamped or "
                         "--electrode")
    f = np.geomspace(args.f1, args.f2, args.points)
    first_run_notice("freq")
    # the library chooses the solver (dynamics.entry.spectrum): the electrode line with --sheet-resistance
    r = spectrum(f, strip, model=args.model, material=material, method=args.method, beam=args.beam,
                 viscous_modulus=args.viscous_modulus, voltage=args.voltage, sheet_resistance=args.sheet_resistance,
                 support=support, electrode=electrode)
    # phases in degrees, as every phase the commands read or write (drive's sine PHASE_deg, fit's Z_phase);
    # |Z| (Ohm) and its phase: the impedance-spectrum columns `fit` reads (Z_im < 0, phase < 0 for a
    # capacitive strip; studies/calibrate_dynamic.py)
    cols = {"f": r.f, "Z_re": r.Z.real, "Z_im": r.Z.imag, "Z_abs": np.abs(r.Z), "Z_phase": np.angle(r.Z, deg=True),
            "w_amp": r.w_amp, "w_phase": np.degrees(r.w_phase),
            "theta_amp": np.abs(r.H_theta), "theta_phase": np.angle(r.H_theta, deg=True),
            "F_amp": np.abs(r.H_F), "F_phase": np.angle(r.H_F, deg=True)}
    if r.error is not None:
        cols["error"] = r.error
    for n in CLAMPED_OUTPUTS if clamped else ():
        cols[f"{n}_amp"], cols[f"{n}_phase"] = np.abs(r.H_clamped[n]), np.angle(r.H_clamped[n], deg=True)
    head = {"tau": r.tau, "model": r.model, "method": r.method, "thickness_total": strip.thickness,
            "f_d": r.f_d, "voltage": args.voltage, "beam": args.beam,
            "viscous_modulus": args.viscous_modulus,
            "resonances": r.resonances,
            "error_max": None if r.error is None else r.error_max,
            "reference": "pnp-linear (exact linearised Nernst-Planck/Gauss)",
            "electrode_area": strip.width * strip.length, "diffusion_coefficient": material.D,
            "units": {"f": "Hz", "Z": "Ohm (strip, electrode area 2l L)", "Z_abs": "Ohm", "Z_phase": "deg",
                      "w_amp": "m/V", "w_phase": "deg",
                      "theta_amp": "rad/V (free tip)", "theta_phase": "deg", "F_amp": "N/V (blocked tip)",
                      "F_phase": "deg", "error": "relative, of Z and w against pnp-linear"},
            "notes": r.notes + [f"about phi0 = {args.voltage:g} V; w from the layers' charge, small displacements"]}
    if support is not None or electrode is not None:
        head["support"] = support
        head["electrode"] = None if electrode is None else list(electrode)
        head["units"].update({f"{n}_amp": CLAMPED_UNITS[n].replace(" (", "/V (", 1) for n in CLAMPED_OUTPUTS if clamped})
        head["units"].update({f"{n}_phase": "deg" for n in CLAMPED_OUTPUTS if clamped})
    if args.sheet_resistance is not None:
        head["sheet_resistance"] = args.sheet_resistance
        head["units"]["sheet_resistance"] = "Ohm/sq (each electrode)"
        if args.beam == "dynamic":
            # the modal quadrature and truncation of the distributed moment (relative, on w, theta, F)
            head["beam_error_max"] = float(np.max(r.beam_error)) if r.beam_error.size else 0.0
    if args.export is not None:
        fits = {o: transfer_function(args.f1, args.f2, strip=strip, model=args.model, material=material, output=o,
                                     method=r.method, tol=args.export_tol, beam=args.beam,
                                     viscous_modulus=args.viscous_modulus, voltage=args.voltage,
                                     **({} if args.sheet_resistance is None else
                                        {"sheet_resistance": args.sheet_resistance}))
                for o in ("w", "charge")}
        doc = {"models": {o: t.to_dict() for o, t in fits.items()}, "thickness_total": strip.thickness,
               "electrode_area": strip.width * strip.length, "diffusion_coefficient": material.D,
               "notes": ["current = s x charge (the bulk's geometric capacitance makes V -> current improper)"]}
        with atomic_write(args.export) as fh:
            fh.write(dumps(doc, indent=1))
        head["export"] = {"path": str(args.export), **{o: t.message for o, t in fits.items()}}
        bad = [o for o, t in fits.items() if not t.success]
    if args.json:
        out = dict(head)
        out.update(cols)
        print(dumps(out, indent=1))
        return 0
    line = "" if args.sheet_resistance is None else f", electrode sheet resistance {args.sheet_resistance:g} Ohm/sq"
    print(f"small signal about {args.voltage:g} V, model {r.model}, method {r.method}, beam {args.beam}, total "
          f"thickness 2e = {fmt_length(strip.thickness)}{line}: tau = {r.tau:.4g} s, D = {material.D:.3g} m^2/s")
    if head["resonances"]:
        print(f"resonances: free tip {', '.join(f'{v:.4g}' for v in head['resonances']['clamped-free'])} Hz; "
              f"blocked tip {', '.join(f'{v:.4g}' for v in head['resonances']['clamped-pinned'])} Hz"
              + (f"; clamped-clamped {', '.join(f'{v:.4g}' for v in head['resonances']['clamped-clamped'])} Hz"
                 if clamped else ""))
    ecol = "error" in cols
    print(f"{'f [Hz]':>11s} {'Z_re [Ohm]':>12s} {'Z_im [Ohm]':>12s} {'Z_abs [Ohm]':>12s} {'Z_phase [deg]':>13s} "
          f"{'|w|/V [mm/V]':>13s} {'phase [deg]':>11s}" + (f" {'error':>9s}" if ecol else ""))
    for i in range(f.size):
        print(f"{fmt_num(f[i], '11.4g')} {fmt_num(cols['Z_re'][i], '12.5g')} {fmt_num(cols['Z_im'][i], '12.5g')} "
              f"{fmt_num(cols['Z_abs'][i], '12.5g')} {fmt_num(cols['Z_phase'][i], '13.4g')} "
              f"{fmt_num(cols['w_amp'][i] * 1e3, '13.5g')} {fmt_num(cols['w_phase'][i], '11.4g')}"
              + (f" {fmt_num(cols['error'][i], '9.2g')}" if ecol else ""))
    print("legend: Z = impedance of the strip (electrode area 2l L), Z_abs and Z_phase as `fit` reads them; "
          "|w|/V, phase = free-tip deflection per volt and its phase against the voltage"
          + ("; error = relative error of Z and w against pnp-linear" if ecol else ""))
    if clamped:  # amplitudes per volt
        print_clamped("f [Hz]", f, {n: cols[f"{n}_amp"] for n in CLAMPED_OUTPUTS}, per="/V")
    for n in head["notes"]:
        print(f"note: {n}")
    if args.export is not None:
        for o in ("w", "charge"):
            print(f"exported V -> {o}: {head['export'][o]}")
        print(f"wrote {args.export}")
        if bad:
            print(f"warning: the fit of {', '.join(bad)} misses --export-tol {args.export_tol:g} (its error is stated)")
    return 0
