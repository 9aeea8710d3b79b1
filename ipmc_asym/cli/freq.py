"""``ipmc-asym freq``: small-signal impedance and tip-deflection/voltage transfer function; with
``--mode sensing`` the strip as a sensor and harvester (:func:`ipmc_asym.dynamics.sensing.sensing_response`)."""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import model_names
from ipmc_asym.base.settings import MAX_POINTS_CEILING
from ipmc_asym.base.units import fmt_length, parse_length
from ipmc_asym.beam.dynamics import CLAMPED_OUTPUTS
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    CLAMPED_UNITS,
    RecordGiven,
    _positive,
    add_beam_options,
    add_document_out,
    add_output_option,
    add_size_option,
    add_solver_option,
    add_strip_options,
    add_support_options,
    arg_type,
    column_rows,
    diffusion_type,
    first_run_notice,
    fmt_num,
    frequency_type,
    given,
    load_type,
    model_help,
    nu_type,
    print_clamped,
    sheet_resistance_type,
    strip_and_material,
    support_from_args,
    voltage_type,
    warn,
    write_document,
)
from ipmc_asym.dynamics.circuit import FREQ_METHODS
from ipmc_asym.dynamics.entry import spectrum
from ipmc_asym.dynamics.reduction import transfer_function
from ipmc_asym.forward.sensing import DEFAULT_NU
from ipmc_asym.io.fileio import atomic_write

#: the two directions of the small signal
MODES = ("actuation", "sensing")
#: frequencies of one run (log-spaced: 1e5 points resolve any spectrum; the --json text stays ~10 MB);
#: settable with --max-points
MAX_POINTS = 10**5


def register(sub):
    p = sub.add_parser("freq", help=SUMMARIES["freq"])
    add_strip_options(p, voltage=False, mechanics=False)
    p.add_argument("--from", dest="f1", type=frequency_type("--from"), required=True, help="first frequency (e.g. 0.01Hz)")
    p.add_argument("--to", dest="f2", type=frequency_type("--to"), required=True, help="last frequency (e.g. 1kHz)")
    add_size_option(p, "--points", default=50, maximum=MAX_POINTS, ceiling=MAX_POINTS_CEILING, minimum=2, help="log-spaced points")
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
    add_support_options(p, sensing=True)
    p.add_argument("--mode", default="actuation", choices=MODES,
                   help="actuation (default: a voltage drives the strip; the outputs above) or sensing (the tip is moved "
                        "sinusoidally: short-circuit charge, current and open-circuit voltage per tip displacement; with "
                        "--load R the load's voltage, current and mean power; docs/sensing.md)")
    p.add_argument("--load", type=arg_type(load_type, "--load"), default=None,
                   help="--mode sensing: short (default), open, or a resistance across the electrodes (10kOhm, 1MOhm, "
                        "470ohm; a bare number is ohms) for the load columns")
    p.add_argument("--nu", type=arg_type(nu_type, "nu"), default=None,
                   help="--mode sensing: drained Poisson ratio (default 0, an assumption; the answers scale as 1 - 2 nu)")
    p.add_argument("--amplitude", type=_positive("--amplitude", parse_length, "1mm"), default=None,
                   help="--mode sensing: peak tip displacement of the load columns (default 1mm)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_document_out(p, "frequency")
    add_output_option(p, "--export", formats=(".json",), metavar="F.json", default=None,
                   help="write reduced-order models of V -> w and V -> charge over [--from, --to] (poles, residues, "
                        "state space, stated error; see ipmc_asym.transfer_function)")
    p.add_argument("--export-tol", type=arg_type(_tol_type, "--export-tol"), default=1e-4, action=RecordGiven,
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
    if args.mode == "sensing":
        return _run_sensing(args)
    for opt, v in (("--load", args.load), ("--nu", args.nu), ("--amplitude", args.amplitude)):
        if v is not None:
            raise ValueError(f"{opt} is an option of --mode sensing")
    if args.support in ("free", "tip-force"):
        raise ValueError(f"--support {args.support} is how --mode sensing imposes the tip displacement; actuation "
                         "supports: clamped-free, clamped-pinned, clamped-clamped")
    # --export: its path and format checked before any work with every output (add_output_option)
    if args.export is None and given(args, "export_tol"):  # said, not silently dropped
        warn(f"--export-tol {args.export_tol:g} is not used: it is the tolerance of --export's models")
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
            "reference": ("pnp-linear (exact linearised Nernst-Planck/Gauss)" if args.voltage == 0.0 else
                          f"the Nernst-Planck/Gauss equations linearised about the static state at {args.voltage:g} V "
                          "(graded-mesh collocation, its error included; null where not computed)"),
            "electrode_area": strip.width * strip.length, "diffusion_coefficient": material.D,
            "units": {"f": "Hz", "Z": "Ohm (strip, electrode area 2l L)", "Z_abs": "Ohm", "Z_phase": "deg",
                      "w_amp": "m/V", "w_phase": "deg",
                      "theta_amp": "rad/V (free tip)", "theta_phase": "deg", "F_amp": "N/V (blocked tip)",
                      "F_phase": "deg", "error": "relative, of Z and w against the reference"},
            "notes": r.notes + [f"about phi0 = {args.voltage:g} V; w from the layers' charge, small displacements"]}
    if args.voltage != 0.0:  # about 0 V the output stays as it was, key for key
        head["check_voltage"] = r.check_voltage
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
    doc = dict(head, **cols)  # the --json document, also what --out F.json holds
    if args.out is not None:
        write_document(args.out, doc, column_rows(cols), head)
    if args.json:
        print(dumps(doc, indent=1))
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
              + ("" if not ecol else f" {'n/a':>9s}" if not np.isfinite(cols['error'][i]) else
                 f" {fmt_num(cols['error'][i], '9.2g')}"))
    print("legend: Z = impedance of the strip (electrode area 2l L), Z_abs and Z_phase as `fit` reads them; "
          "|w|/V, phase = free-tip deflection per volt and its phase against the voltage"
          + ("; error = relative error of Z and w against " + ("pnp-linear" if args.voltage == 0.0 else
             f"the PNP linearised about {args.voltage:g} V (n/a: not computed there)") if ecol else ""))
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
    if args.out is not None:
        print(f"wrote {args.out}")
    return 0


def _run_sensing(args):
    """``--mode sensing``: the strip's tip moved sinusoidally (quasi-static beam), small signal."""
    from ipmc_asym.dynamics.sensing import DEFAULT_AMPLITUDE, sensing_response  # deferred: the sensing mode only

    for bad, what in ((args.voltage != 0.0, "--voltage (a DC bias)"), (args.sheet_resistance is not None, "--sheet-resistance"),
                      (args.electrode is not None, "--electrode"), (args.export is not None, "--export"),
                      (args.beam == "dynamic", "--beam dynamic (the tip displacement is imposed quasi-statically; base "
                                               "excitation through the beam's modes is not modelled)"),
                      (args.viscous_modulus != 0.0, "--viscous-modulus"),
                      (args.support is not None and args.support.startswith("clamped"),
                       f"--support {args.support} (it takes free or tip-force)")):
        if bad:
            raise ValueError(f"--mode sensing does not take {what}")
    strip, material, _ = strip_and_material(args)
    support = args.support or "tip-force"
    load = "short" if args.load is None else args.load
    nu = DEFAULT_NU if args.nu is None else args.nu
    amp = DEFAULT_AMPLITUDE if args.amplitude is None else args.amplitude
    f = np.geomspace(args.f1, args.f2, args.points)
    first_run_notice("freq")
    r = sensing_response(f, strip, model=args.model, material=material, method=args.method or "pnp-linear", load=load,
                         nu=nu, support=support, amplitude=amp)
    resistive = not isinstance(load, str)
    cols = {"f": r.f}
    for n in ("Q_per_w", "I_per_w", "V_oc_per_w"):
        cols[f"{n}_amp"], cols[f"{n}_phase"] = np.abs(getattr(r, n)), np.angle(getattr(r, n), deg=True)
    cols["Z_abs"], cols["Z_phase"] = np.abs(r.Z), np.angle(r.Z, deg=True)
    if resistive:
        cols["V_load_amp"], cols["V_load_phase"] = np.abs(r.V_load), np.angle(r.V_load, deg=True)
        cols["I_load_amp"], cols["I_load_phase"] = np.abs(r.I_load), np.angle(r.I_load, deg=True)
        cols["power"] = r.power
        cols["matched_power"] = r.power_at(np.abs(r.Z)).diagonal()
    if r.method == "circuit":
        cols["error"] = r.error
    cols["one_way_error"] = r.one_way_error
    cols["valid"] = r.valid
    warnings = []
    nbad = int(np.count_nonzero(~r.check_one_way))
    if nbad:
        f_bad = float(f[~r.check_one_way][0])
        warnings.append(f"{nbad} of {f.size} frequencies (from {f_bad:.4g} Hz) past the one-way coupling bound: the "
                        "streaming potential's pressure would deform the strip; kept, flagged valid = false")
    if not r.check_strain:
        warnings.append(f"amplitude {amp:g} m: face strain above the small-strain limit {material.strain_limit:g}; "
                        "kept, flagged valid = false")
    if not r.check_beam_regime:
        warnings.append(f"amplitude {amp:g} m: past a quarter turn (small-displacement beam); kept, flagged valid = false")
    for w in warnings:
        warn(w)
    units = {"f": "Hz", "Q_per_w_amp": "C/m", "I_per_w_amp": "A/m", "V_oc_per_w_amp": "V/m", "Z_abs": "Ohm",
             "one_way_error": "1", "valid": "bool"}
    units.update({f"{n}_phase": "deg" for n in ("Q_per_w", "I_per_w", "V_oc_per_w", "Z", "V_load", "I_load")})
    if resistive:
        units.update({"V_load_amp": "V (at the amplitude)", "I_load_amp": "A (at the amplitude)",
                      "power": "W (mean, at the amplitude)", "matched_power": "W (mean, into R = |Z|)"})
    if r.method == "circuit":
        units["error"] = "relative, against the exact linear form (pnp-linear)"
    head = {"mode": "sensing", "model": r.model, "method": r.method, "thickness_total": strip.thickness,
            "length": strip.length, "width_total": strip.width, "support": support, "nu": nu, "amplitude": amp,
            "load": load if isinstance(load, str) else "resistive", "load_resistance": None if not resistive else load,
            "tau": r.tau, "f_stream": r.f_stream, "f_d": r.f_d, "diffusion_coefficient": material.D,
            "units": units, "notes": r.notes, "warnings": warnings}
    doc = dict(head, **cols)  # the --json document, also what --out F.json holds
    if args.out is not None:
        write_document(args.out, doc, column_rows(cols), head)
    if args.json:
        print(dumps(doc, indent=1))
        return 0
    print(f"IPMC strip as a sensor, small signal: model {r.model}, method {r.method}, support {support}, L = "
          f"{fmt_length(strip.length)}, 2l = {fmt_length(strip.width)}, 2e = {fmt_length(strip.thickness)}, nu = {nu:g}; "
          f"tau = {r.tau:.4g} s, f_stream = 3D/(2 pi e^2) = {r.f_stream:.4g} Hz")
    hdr = (f"{'f [Hz]':>11s} {'|Q/w| [C/m]':>12s} {'phase':>7s} {'|V_oc/w| [V/m]':>14s} {'phase':>7s} {'|Z| [Ohm]':>11s}")
    if resistive:
        hdr += f" {'|V_load| [V]':>12s} {'|I_load| [A]':>12s} {'P [W]':>10s}"
    print(hdr + f" {'1-way':>7s}")
    for i in range(f.size):
        line = (f"{fmt_num(f[i], '11.4g')} {fmt_num(cols['Q_per_w_amp'][i], '12.5g')} {fmt_num(cols['Q_per_w_phase'][i], '7.1f')} "
                f"{fmt_num(cols['V_oc_per_w_amp'][i], '14.5g')} {fmt_num(cols['V_oc_per_w_phase'][i], '7.1f')} "
                f"{fmt_num(cols['Z_abs'][i], '11.5g')}")
        if resistive:
            line += (f" {fmt_num(cols['V_load_amp'][i], '12.5g')} {fmt_num(cols['I_load_amp'][i], '12.5g')} "
                     f"{fmt_num(cols['power'][i], '10.4g')}")
        print(line + f" {fmt_num(r.one_way_error[i], '7.2g')}" + ("" if r.valid[i] else "  not valid"))
    print("legend: Q/w, V_oc/w = short-circuit charge of the electrode z = -e and open-circuit voltage phi(-e) - phi(e) "
          "per tip displacement, phases in degrees against w; Z = the strip's impedance"
          + (f"; V_load, I_load, P = the load {load:g} Ohm at the tip amplitude {amp:g} m (P the mean power)"
             if resistive else "") + "; 1-way = estimate of the neglected pressure feedback")
    for n in head["notes"]:
        print(f"note: {n}")
    if args.out is not None:
        print(f"wrote {args.out}")
    return 0
