"""``ipmc-asym drive``: response to any voltage waveform (sums of step, ramp, sine, square, triangle, CSV)."""

from __future__ import annotations

import os
import sys

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.base.units import fmt_length, parse_length, parse_quantity, parse_sheet_resistance, parse_time
from ipmc_asym.beam.dynamics import SUPPORTS
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_output_option,
    add_strip_options,
    arg_type,
    count_type,
    diffusion_type,
    first_run_notice,
    material_from_args,
    sidecar_path,
    strip_from_args,
)
from ipmc_asym.dynamics.circuit import BEAM_CHOICES
from ipmc_asym.dynamics.drive import (
    CHECK_COLUMNS,
    CLAMPED_COLUMNS,
    DRIVE_COLUMNS,
    LINE_COLUMNS,
    MAX_DRIVE_POINTS,
    drive_chunks,
    drive_info,
)
from ipmc_asym.dynamics.line_time import DEFAULT_SEGMENTS, MAX_SEGMENTS
from ipmc_asym.dynamics.waveforms import parse_waveform
from ipmc_asym.io.fileio import atomic_path, atomic_write, check_output_path
from ipmc_asym.io.jsonio import dumps
from ipmc_asym.io.textfmt import format_table

#: --json holds every row in memory: at most this many (the CSV is streamed)
MAX_JSON_POINTS = 1_000_000

_VISCOSITY = {"Pa s": 1.0, "Pa*s": 1.0, "Pa.s": 1.0, "kPa s": 1e3, "kPa*s": 1e3, "MPa s": 1e6, "MPa*s": 1e6}


def viscous_modulus_type(name="--viscous-modulus"):
    def conv(text):
        v = parse_quantity(name, str(text).replace("·", " ").strip(), _VISCOSITY, "viscous modulus (Pa s)")
        if v < 0:
            raise ValueError(f"{name} must be >= 0 Pa s (e.g. 0, 1e4, '2kPa s'); got {text!r}")
        return v

    return arg_type(conv, name)


def _duration(text):
    v = parse_time("--duration", text)
    if v <= 0:
        raise ValueError(f"--duration must be > 0 (e.g. 0.5s, 200ms); got {text!r}")
    return v


def _waveform(text):
    return parse_waveform(text)


def _sheet_conv(text):
    v = parse_sheet_resistance("--sheet-resistance", text)
    if v < 0:
        raise ValueError(f"--sheet-resistance must be >= 0 Ohm/sq (e.g. 2.5ohm/sq); got {text!r}")
    return v


def _segments_conv(text):
    v = count_type("--line-segments", 2)(text)
    if v > MAX_SEGMENTS:
        raise ValueError(f"--line-segments must be an integer in [2, {MAX_SEGMENTS}]; got {text!r}")
    return v


def add_line_options(p):
    """``--sheet-resistance`` and ``--line-segments`` of the time-domain electrode line (step, drive)."""
    p.add_argument("--sheet-resistance", dest="sheet_resistance", type=arg_type(_sheet_conv, "--sheet-resistance"),
                   default=0.0,
                   help="sheet resistance of each electrode (2.5ohm/sq; a bare number is Ohm/sq; default 0 = ideal "
                        "electrodes, the uniform strip): the strip as a discretised RC line driven at the clamp "
                        "(circuit fidelity); adds the columns sigma_error and w_error (its stated error)")
    p.add_argument("--line-segments", dest="line_segments", type=arg_type(_segments_conv, "--line-segments"),
                   default=DEFAULT_SEGMENTS,
                   help=f"N: the line is run with 2N segments (reported) and N (its error estimate); default "
                        f"{DEFAULT_SEGMENTS}, at most {MAX_SEGMENTS}")


def _electrode_conv(text):
    parts = str(text).split(":")
    if len(parts) != 2:
        raise ValueError(f"--electrode must be X1:X2, the covered part of the length (e.g. 2mm:18mm); got {text!r}")
    return tuple(parse_length("--electrode", v.strip()) for v in parts)


def add_support_options(p):
    """``--support`` and ``--electrode`` (freq, drive)."""
    p.add_argument("--support", default=None, choices=SUPPORTS,
                   help="strip support: clamped-free and clamped-pinned give the default outputs (free tip w, theta; "
                        "blocked tip F_block); clamped-clamped adds the clamps' reaction moments and forces M_root, "
                        "M_tip, F_root, F_tip and the midspan deflection w_mid (small displacements)")
    p.add_argument("--electrode", type=arg_type(_electrode_conv, "--electrode"), default=None,
                   help="X1:X2 covered part of the length (e.g. 2mm:18mm, 0 <= X1 < X2 <= L; default the whole strip): "
                        "the active moment acts there only, the beam outputs are small-displacement")


def support_from_args(args, strip):
    """``(support, electrode)`` checked against the strip and the other options (one-line ValueError)."""
    el = args.electrode
    if el is not None:
        x1, x2 = el
        if not 0.0 <= x1 < x2 <= strip.length:
            raise ValueError(f"--electrode X1:X2 must satisfy 0 <= X1 < X2 <= L = {fmt_length(strip.length)}; "
                             f"got {fmt_length(x1)}:{fmt_length(x2)}")
    if el is not None or args.support == "clamped-clamped":
        what = "--support clamped-clamped" if args.support == "clamped-clamped" else "--electrode"
        if getattr(args, "sheet_resistance", None):
            raise ValueError(f"{what} is not supported with --sheet-resistance (the electrode line's moment is "
                             "distributed over the full strip, free or blocked tip)")
    return args.support, el


def print_clamped(t_name, t, rows, per=""):
    """Text table of the clamped-clamped outputs (``rows``: dict name -> values at ``t``; ``per``: "/V" for amplitudes)."""
    print(f"clamped-clamped: {t_name:>9s} {f'|M_root| [N m{per}]' if per else 'M_root [N m]':>13s} "
          f"{f'|M_tip| [N m{per}]' if per else 'M_tip [N m]':>13s} {f'|F_root| [mN{per}]' if per else 'F_root [mN]':>12s} "
          f"{f'|F_tip| [mN{per}]' if per else 'F_tip [mN]':>12s} {f'|w_mid| [mm{per}]' if per else 'w_mid [mm]':>11s}")
    for i in range(len(t)):
        r = {k: float(v[i]) + 0.0 for k, v in rows.items()}
        print(f"                 {float(t[i]):9.4g} {r['M_root']:13.5g} {r['M_tip']:13.5g} {r['F_root'] * 1e3:12.5g} "
              f"{r['F_tip'] * 1e3:12.5g} {r['w_mid'] * 1e3:11.5g}")


CLAMPED_UNITS = {"M_root": "N m (reaction moment of the clamp x = 0)", "M_tip": "N m (reaction moment of the clamp x = L)",
                 "F_root": "N (force of the clamp x = 0 on the strip, +z)",
                 "F_tip": "N (force of the clamp x = L on the strip, +z; the sign of F_block)",
                 "w_mid": "m (deflection at x = L/2)"}


def add_beam_options(p, default):
    p.add_argument("--beam", default=default, choices=BEAM_CHOICES,
                   help=f"strip mechanics: dynamic (inertia, Kelvin-Voigt damping, resonances) or quasi-static "
                        f"(default {default})")
    p.add_argument("--viscous-modulus", dest="viscous_modulus", type=viscous_modulus_type(), default=0.0,
                   help="Kelvin-Voigt viscous modulus eta_E (Pa s; '2kPa s'); default 0: no source gives a value")


def register(sub):
    p = sub.add_parser("drive", help=SUMMARIES["drive"])
    add_strip_options(p, voltage=False)
    p.add_argument("--waveform", type=arg_type(_waveform, "--waveform"), required=True,
                   help="SPEC: terms joined by '+': dc:V, step:V[@T0], ramp:V/TR[@T0], sine:V@F[,PHASE_deg], "
                        "square:V@F, triangle:V@F, csv:FILE (t, V); e.g. 'dc:0.2V+sine:0.5V@10Hz'")
    p.add_argument("--duration", type=arg_type(_duration, "duration"), required=True, help="end time (e.g. 2s, 500ms)")
    p.add_argument("--points", type=count_type("--points", 2), default=10001,
                   help=f"equally spaced output times (default 10001, at most {MAX_DRIVE_POINTS:g})")
    p.add_argument("--model", default="constant", choices=list(model_names()), help="permittivity model")
    p.add_argument("--diffusion", type=diffusion_type(), default=None,
                   help="cation diffusion coefficient D (1e-10m2/s, 1e-6cm2/s; a bare number is m^2/s)")
    add_beam_options(p, "dynamic")
    add_line_options(p)
    add_support_options(p)
    add_output_option(p, "--out", formats=(".csv",), default=None, help="CSV file, written as computed (columns " + ", ".join(DRIVE_COLUMNS)
                   + ", then the forward model's check_* and valid per time point, 1 or 0)")
    p.add_argument("--json", action="store_true", help=f"print one JSON object (at most {MAX_JSON_POINTS:g} points)")


COLUMNS = DRIVE_COLUMNS + CHECK_COLUMNS


def _csv_rows(chunk, columns=COLUMNS):
    cols = [("f", np.ascontiguousarray(chunk[c], dtype=float) + 0.0) for c in columns]  # + 0.0: no "-0"
    text = format_table(cols, [""] + [","] * (len(cols) - 1), 17, nonfinite="nan", row_end="\n", row_sep="")
    if text is None:  # a rounding too close to call for the compiled formatter: Python's repr
        n = chunk["t"].size
        text = "".join(",".join(repr(float(chunk[c][i]) + 0.0) for c in columns) + "\n" for i in range(n))
    return text


def _note_warnings(ch, seen, counts):
    """Collect a chunk's assumption warnings (first text of each) and count the failed points per check."""
    for w in ch["warnings"]:
        key = w.split(":")[0]
        seen.setdefault(key, w)
    for c in CHECK_COLUMNS[:-1]:
        counts[c] = counts.get(c, 0) + int(np.count_nonzero(ch[c] == 0.0))


def run(args):
    if args.points > MAX_DRIVE_POINTS:
        raise ValueError(f"--points must be at most {MAX_DRIVE_POINTS:g}; got {args.points}")
    if args.json and args.points > MAX_JSON_POINTS:
        raise ValueError(f"--json holds every row in memory: --points at most {MAX_JSON_POINTS:g} (use --out F.csv)")
    if args.out:
        check_output_path(args.out, "file", formats=(".csv",))
        check_output_path(sidecar_path(args.out), "file")
    material = material_from_args(args)
    if args.diffusion is not None:
        material = material.with_(D=args.diffusion)
    strip = strip_from_args(args)
    support, electrode = support_from_args(args, strip)
    clamped = support == "clamped-clamped"
    info = drive_info(strip, args.model, material, args.beam, args.viscous_modulus, args.sheet_resistance,
                      args.line_segments, support=support, electrode=electrode)
    columns = COLUMNS + (LINE_COLUMNS if args.sheet_resistance > 0.0 else ()) + (CLAMPED_COLUMNS if clamped else ())
    head = dict(info, waveform=args.waveform.spec, duration=args.duration, points=args.points,
                thickness_total=strip.thickness, half_thickness_e=strip.e, diffusion_coefficient=material.D,
                units={"t": "s", "phi0": "V", "sigma": "C/m^2 (face z = -e)", "current_density": "A/m^2",
                       "layer_voltage": "V", "M_A": "N m", "theta": "rad (free tip)", "w": "m (free tip)",
                       "F_block": "N (blocked tip)", "sigma_error": "C/m^2 (electrode line, stated)",
                       "w_error": "m (electrode line, stated)", **(CLAMPED_UNITS if clamped else {})})
    first_run_notice()
    gen = drive_chunks(args.waveform, args.duration, args.points, strip=strip, model=args.model, material=material,
                       beam=args.beam, viscous_modulus=args.viscous_modulus, sheet_resistance=args.sheet_resistance,
                       line_segments=args.line_segments, support=support, electrode=electrode)
    shown_cols = DRIVE_COLUMNS + (CLAMPED_COLUMNS if clamped else ())
    show = set(np.unique(np.linspace(0, args.points - 1, min(args.points, 11)).astype(int)).tolist())
    shown, kept = [], []
    seen, counts = {}, {}
    i0 = 0
    if args.out:
        # one header row (pandas.read_csv reads it as is); the metadata in the sidecar F.csv.json,
        # written last: its temporary file is renamed after the CSV's, and both are removed on
        # any failure or interruption before (no sidecar without its CSV)
        with atomic_path(sidecar_path(args.out)) as side_tmp:
            with atomic_write(args.out) as fh:
                fh.write(",".join(columns) + "\n")
                for ch in gen:
                    _note_warnings(ch, seen, counts)
                    fh.write(_csv_rows(ch, columns))
                    n = ch["t"].size
                    shown += [{c: float(ch[c][i - i0]) for c in shown_cols} for i in range(i0, i0 + n) if i in show]
                    i0 += n
                with open(side_tmp, "w", encoding="utf-8") as sh:
                    sh.write(dumps({"csv": os.path.basename(args.out), **head}, indent=1) + "\n")
        sys.stderr.write(f"drive: {args.points} rows -> {args.out}\n")
    else:
        for ch in gen:
            _note_warnings(ch, seen, counts)
            n = ch["t"].size
            if args.json:
                kept.append(ch)
            shown += [{c: float(ch[c][i - i0]) for c in shown_cols} for i in range(i0, i0 + n) if i in show]
            i0 += n
    # the forward model's failed assumptions: one line each (kept numbers, flagged rows)
    warn_lines = list(seen.values())
    for w in warn_lines:
        sys.stderr.write(f"drive: warning: {w}\n")
    head["warnings"] = warn_lines
    if args.json:
        out = dict(head)
        if kept:
            out.update({c: np.concatenate([k[c] for k in kept]) for c in DRIVE_COLUMNS + columns[len(COLUMNS):]})
            out.update({c: np.concatenate([k[c] for k in kept]).astype(bool) for c in CHECK_COLUMNS})
        print(dumps(out, indent=1))
        return 0
    print(f"drive {args.waveform.spec}, total thickness 2e = {fmt_length(strip.thickness)}, model {info['model']}, "
          f"beam {args.beam}: tau = {info['tau']:.4g} s")
    if "resonances" in info:
        print(f"first resonances: free tip {', '.join(f'{v:.4g}' for v in info['resonances']['clamped-free'])} Hz; "
              f"blocked tip {', '.join(f'{v:.4g}' for v in info['resonances']['clamped-pinned'])} Hz"
              + (f"; clamped-clamped {', '.join(f'{v:.4g}' for v in info['resonances']['clamped-clamped'])} Hz"
                 if clamped else ""))
    print(f"{'t [s]':>11s} {'phi0 [V]':>9s} {'sigma [C/m^2]':>14s} {'J [A/m^2]':>11s} {'M_A [N m]':>11s} "
          f"{'theta':>9s} {'w [mm]':>9s} {'F_block [mN]':>12s}")
    for r in shown:
        r = {k: v + 0.0 for k, v in r.items()}  # no "-0" in the table
        print(f"{r['t']:11.4g} {r['phi0']:9.4g} {r['sigma']:14.6g} {r['current_density']:11.4g} {r['M_A']:11.4g} "
              f"{r['theta']:9.4g} {r['w'] * 1e3:9.4g} {r['F_block'] * 1e3:12.4g}")
    if clamped:
        print_clamped("t [s]", [r["t"] for r in shown], {c: [r[c] for r in shown] for c in CLAMPED_COLUMNS})
    for n in info["notes"]:
        print(f"note: {n}")
    return 0
