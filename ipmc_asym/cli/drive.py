"""``ipmc-asym drive``: response to any voltage waveform (sums of step, ramp, sine, square, triangle, CSV)."""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import model_names
from ipmc_asym.base.units import fmt_length
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (  # noqa: F401  (CLAMPED_UNITS, viscous_modulus_type: their old home)
    CLAMPED_UNITS,
    add_beam_options,
    add_line_options,
    add_output_option,
    add_solver_option,
    add_strip_options,
    add_support_options,
    arg_type,
    count_type,
    diffusion_type,
    duration_type,
    first_run_notice,
    print_clamped,
    sidecar_path,
    strip_and_material,
    support_from_args,
    time_tol_type,
    viscous_modulus_type,
    waveform_type,
)
from ipmc_asym.dynamics.circuit import STEP_FIDELITIES
from ipmc_asym.dynamics.drive import (
    CHECK_COLUMNS,
    CLAMPED_COLUMNS,
    DRIVE_COLUMNS,
    LINE_COLUMNS,
    MAX_DRIVE_POINTS,
    MAX_STATED_POINTS,
)
from ipmc_asym.dynamics.entry import (
    AUTO_TOL,
    AUTO_WORK,
    ERROR_COLUMNS,
    WORK_PER_SECOND,
    stated_tol,
    time_path,
    time_response,
)
from ipmc_asym.io.fileio import atomic_path, atomic_write, check_output_path
from ipmc_asym.io.textfmt import format_table

#: --json holds every row in memory: at most this many (the CSV is streamed)
MAX_JSON_POINTS = 1_000_000


def _voltage_in_waveform(text):
    raise ValueError(f"drive takes its voltage in --waveform (e.g. --waveform step:{text.strip()} or "
                     f"sine:{text.strip()}@1Hz); --voltage is step's and estimate's")


def register(sub):
    p = sub.add_parser("drive", help=SUMMARIES["drive"])
    add_strip_options(p, voltage=False)
    # not an option of drive: the voltage is the waveform's; said, where argparse would say only
    # "unrecognized arguments"
    p.add_argument("--voltage", dest="voltage_refused", type=arg_type(_voltage_in_waveform, "--voltage"), default=None,
                   help=argparse.SUPPRESS)
    p.add_argument("--waveform", type=waveform_type, required=True,
                   help="SPEC: terms joined by '+': dc:V, step:V[@T0], ramp:V/TR[@T0], sine:V@F[,PHASE_deg], "
                        "square:V@F, triangle:V@F, csv:FILE (t, V); e.g. 'dc:0.2V+sine:0.5V@10Hz'")
    p.add_argument("--duration", type=duration_type, required=True, help="end time (e.g. 2s, 500ms)")
    p.add_argument("--points", type=count_type("--points", 2), default=10001,
                   help=f"equally spaced output times (default 10001, at most {MAX_DRIVE_POINTS:g})")
    p.add_argument("--model", default="constant", choices=list(model_names()), help="permittivity model")
    p.add_argument("--diffusion", type=diffusion_type(), default=None,
                   help="cation diffusion coefficient D (1e-10m2/s, 1e-6cm2/s; a bare number is m^2/s)")
    add_solver_option(p, "drive", dest="fidelity", default="circuit", choices=STEP_FIDELITIES,
                      help="circuit (reduced nonlinear capacitor, stepped chunk by chunk) or pnp (transient "
                           "Nernst-Planck/Gauss, in memory, at most %d points; its errors stated)" % MAX_STATED_POINTS)
    p.add_argument("--tol", type=time_tol_type, default="auto",
                   help="relative accuracy required of sigma at every output time, e.g. 1e-2 or 1%% (in [1e-8, 0.5)): "
                        "the circuit's error is bounded against a PNP run over the same waveform and the PNP is used "
                        "where it fails, as in step; adds the columns " + ", ".join(ERROR_COLUMNS) + " (in memory, at "
                        f"most {MAX_STATED_POINTS} points); default auto: {AUTO_TOL:g} where the error can be stated "
                        f"and its reference run costs at most {AUTO_WORK:.3g} cell-evaluations (~{AUTO_WORK / WORK_PER_SECOND:.0f} s CPU; "
                        "2 s of a 1 Hz sine: ~2.4 s (constant model) to ~9 s (affine), ~11 s at 10 Hz; the cost grows "
                        "with the periods and jumps in the duration: beyond the cap no error is stated, said in a "
                        "note, after a sixth of the cap or less), as in step; none: the bare circuit streamed, no "
                        "error stated (~1 s)")
    add_beam_options(p)
    add_line_options(p)
    add_support_options(p)
    add_output_option(p, "--out", formats=(".csv",), default=None, help="CSV file, written as computed (columns " + ", ".join(DRIVE_COLUMNS)
                   + ", then the forward model's check_* and valid per time point, 1 or 0; with --tol or --solver "
                   "pnp then " + ", ".join(ERROR_COLUMNS) + ")")
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
        raise ValueError(f"--points must be at most {MAX_DRIVE_POINTS:g}; got {args.points:.6g}")
    if args.json and args.points > MAX_JSON_POINTS:
        raise ValueError(f"--json holds every row in memory: --points at most {MAX_JSON_POINTS:g} (use --out F.csv)")
    support, electrode = support_from_args(args)
    # what --tol auto means here (the library's rule, dynamics.entry.stated_tol; time_response applies
    # the same and says in the notes why where it states no error)
    tol, _ = stated_tol(args.tol, fidelity=args.fidelity, points=args.points, sheet_resistance=args.sheet_resistance,
                        support=support, electrode=electrode)
    stated = tol is not None or args.fidelity == "pnp"
    if stated and args.points > MAX_STATED_POINTS:
        raise ValueError(f"--points with --tol or --solver pnp (solved in memory, the PNP's profiles at every output "
                         f"time) must be at most {MAX_STATED_POINTS}; got {args.points:.6g}")
    if args.out:
        check_output_path(args.out, "file", formats=(".csv",))
        check_output_path(sidecar_path(args.out), "file")
    # the choice's refusals first (a tolerance with the electrode line or a support), before any work
    time_path(fidelity=args.fidelity, tol=tol, beam=args.beam, sheet_resistance=args.sheet_resistance,
              support=support, electrode=electrode, stream=True, beam_grid="output")
    strip, material, _ = strip_and_material(args)
    clamped = support == "clamped-clamped"
    # the rows stepped on the output grid and streamed (the dynamic beam too: the grid must resolve the
    # first mode), whatever --out or --json do with them; with --tol or the PNP, solved in memory
    first_run_notice("step-pnp" if stated else None)

    def notice():
        # the in-memory PNP run is the long part (seconds to minutes): said as it starts, after the refusals
        what = "the PNP" if args.fidelity == "pnp" else f"the circuit and a reference PNP run (tol {tol:g})"
        cap = (f"; under --tol auto at most ~{AUTO_WORK / WORK_PER_SECOND:.0f} s, beyond which no error is stated; "
               f"--tol none skips it" if args.fidelity == "circuit" and args.tol == "auto" else "")
        sys.stderr.write(f"drive: {what} over {args.points} output times, in memory (the nominal strip, a "
                         f"sine over 2 s: ~2-9 s CPU at 1 Hz, ~11 s at 10 Hz{cap})\n")
        sys.stderr.flush()

    resp = time_response(strip, args.waveform, duration=args.duration, points=args.points, model=args.model,
                         material=material, fidelity=args.fidelity, tol=args.tol, beam=args.beam,
                         viscous_modulus=args.viscous_modulus, sheet_resistance=args.sheet_resistance,
                         line_segments=args.line_segments, support=support, electrode=electrode, stream=True,
                         beam_grid="output", notice=notice)
    info = resp.info
    # the tolerance the run met (auto states none where the reference PNP run refuses the strip)
    stated = stated and (args.fidelity == "pnp" or info.get("tol") is not None)
    columns = COLUMNS + (LINE_COLUMNS if args.sheet_resistance > 0.0 else ()) + (CLAMPED_COLUMNS if clamped else ()) + (
        ERROR_COLUMNS if stated else ())
    source = "electrode line" if args.sheet_resistance > 0.0 else "circuit against the PNP, or the PNP's own"
    head = dict(info, waveform=args.waveform.spec, duration=args.duration, points=args.points,
                thickness_total=strip.thickness, half_thickness_e=strip.e, diffusion_coefficient=material.D,
                units={"t": "s", "phi0": "V", "sigma": "C/m^2 (face z = -e)", "current_density": "A/m^2",
                       "layer_voltage": "V", "M_A": "N m", "theta": "rad (free tip)", "w": "m (free tip)",
                       "F_block": "N (blocked tip)", "sigma_error": f"C/m^2 ({source}, stated)",
                       "w_error": f"m ({source}, stated)",
                       **({"current_error": f"A/m^2 ({source}, stated)"} if stated else {}),
                       **(CLAMPED_UNITS if clamped else {})})
    gen = resp.iter_chunks()
    shown_cols = DRIVE_COLUMNS + (CLAMPED_COLUMNS if clamped else ()) + (ERROR_COLUMNS if stated else ())
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
    pm = f" {'+-':>9s}" if stated else ""  # the stated errors beside their values
    print(f"{'t [s]':>11s} {'phi0 [V]':>9s} {'sigma [C/m^2]':>14s}{pm} {'J [A/m^2]':>11s}{pm} {'M_A [N m]':>11s} "
          f"{'th. [rad]':>9s} {'w [mm]':>9s}{pm} {'F_block [mN]':>12s}")

    def num(x, scale, spec):  # undefined or not stated: n/a, never a bare nan
        return f"{x * scale:{spec}}" if np.isfinite(x) else f"{'n/a':>{spec.split('.')[0]}s}"

    for r in shown:
        r = {k: v + 0.0 for k, v in r.items()}  # no "-0" in the table
        # w and F_block are undefined past a quarter turn / on the multi-turn branch (the forward
        # model's beam regime, as `estimate` prints it)
        e = {c: " " + num(r[c], 1e3 if c == "w_error" else 1.0, "9.2g") for c in ERROR_COLUMNS} if stated else \
            dict.fromkeys(ERROR_COLUMNS, "")
        print(f"{r['t']:11.4g} {r['phi0']:9.4g} {r['sigma']:14.6g}{e['sigma_error']} "
              f"{num(r['current_density'], 1.0, '11.4g')}{e['current_error']} {r['M_A']:11.4g} "
              f"{num(r['theta'], 1.0, '9.4g')} {num(r['w'], 1e3, '9.4g')}{e['w_error']} {num(r['F_block'], 1e3, '12.4g')}")
    if clamped:
        print_clamped("t [s]", [r["t"] for r in shown], {c: [r[c] for r in shown] for c in CLAMPED_COLUMNS})
    if len(shown) < args.points:  # the table is a sample of the rows computed
        print(f"rows: {len(shown)} of the {args.points} output times shown, equally spaced; --out F.csv or --json "
              "gives every row")
    for n in info["notes"]:
        print(f"note: {n}")
    return 0
